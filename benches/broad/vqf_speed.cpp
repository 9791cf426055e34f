// VQF's C++ core timed per sample on recorded readings, in the format that imukit's
// `orientation_speed` example reads (little-endian f64 rows of nine values: accelerometer,
// gyroscope, magnetometer). `benches/broad/broad.py --speed` builds it beside vqf.cpp and
// vqf.hpp (MIT; shipped in the `vqf` Python package's `cpp` folder, or from
// https://github.com/dlaidig/vqf) with `g++ -O2 -std=c++17` and runs both on one trial.
// Usage: vqf_speed FILE RATE_HZ [REPEATS]; prints "6D <ns>" and "9D <ns>", best of REPEATS.
#include "vqf.hpp"
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>
int main(int argc, char** argv) {
    if (argc < 3) { std::fprintf(stderr, "usage: vqf_speed FILE RATE_HZ [REPEATS]\n"); return 2; }
    const double rate = std::atof(argv[2]);
    const int repeats = argc > 3 ? std::atoi(argv[3]) : 10;
    FILE* f = std::fopen(argv[1], "rb");
    if (!f || rate <= 0 || repeats <= 0) { std::fprintf(stderr, "bad file or arguments\n"); return 2; }
    std::vector<double> v;
    double buf[9];
    while (std::fread(buf, sizeof(double), 9, f) == 9) v.insert(v.end(), buf, buf + 9);
    std::fclose(f);
    const size_t n = v.size() / 9;
    if (n == 0) { std::fprintf(stderr, "no rows\n"); return 2; }
    for (int nine = 0; nine < 2; nine++) {
        double best = 1e300, sink = 0;
        for (int r = 0; r < repeats; r++) {
            VQF filter(1.0 / rate);
            double q[4];
            auto t0 = std::chrono::steady_clock::now();
            for (size_t i = 0; i < n; i++) {
                double* row = &v[9 * i];
                if (nine) { filter.update(row + 3, row, row + 6); filter.getQuat9D(q); }
                else { filter.update(row + 3, row); filter.getQuat6D(q); }
                sink += q[0];
            }
            double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / n;
            if (ns < best) best = ns;
        }
        if (sink == 42.0) std::printf("!");
        std::printf("%s %.1f\n", nine ? "9D" : "6D", best);
    }
}
