// VQF's C++ core timed per sample on the same input as imukit's criterion bench `orientation`
// (robust_6d, robust_9d): build it beside vqf.cpp and vqf.hpp from https://github.com/dlaidig/vqf
// (MIT), `g++ -O2 -std=c++17 -o vqf_speed vqf_speed.cpp vqf.cpp && ./vqf_speed`, and run
// `cargo bench -p imu-benches --bench orientation -- robust` right after, on the same idle machine.
#include "vqf.hpp"
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>
int main() {
    const int n = 100000;
    std::mt19937_64 rng(3);
    std::normal_distribution<double> z(0.0, 1.0);
    std::vector<double> acc(3 * n), gyr(3 * n), mag(3 * n);
    for (int i = 0; i < n; i++) {
        acc[3*i] = 0.02*z(rng); acc[3*i+1] = 0.02*z(rng); acc[3*i+2] = 9.81 + 0.02*z(rng);
        gyr[3*i] = 1e-3*z(rng); gyr[3*i+1] = 1e-3*z(rng); gyr[3*i+2] = 1e-3*z(rng);
        mag[3*i] = 27.5 + 0.1*z(rng); mag[3*i+1] = -2.4 + 0.1*z(rng); mag[3*i+2] = -16.1 + 0.1*z(rng);
    }
    for (int nine = 0; nine < 2; nine++) {
        double best = 1e9;
        for (int r = 0; r < 20; r++) {
            VQF f(0.01);
            double q[4], sink = 0;
            auto t0 = std::chrono::steady_clock::now();
            for (int i = 0; i < n; i++) {
                if (nine) { f.update(&gyr[3*i], &acc[3*i], &mag[3*i]); f.getQuat9D(q); }
                else { f.update(&gyr[3*i], &acc[3*i]); f.getQuat6D(q); }
                sink += q[0];
            }
            auto t1 = std::chrono::steady_clock::now();
            double ns = std::chrono::duration<double, std::nano>(t1 - t0).count() / n;
            if (ns < best) best = ns;
            if (sink == 42.0) std::printf("!");
        }
        std::printf("%s %.1f ns/sample\n", nine ? "9D" : "6D", best);
    }
}
