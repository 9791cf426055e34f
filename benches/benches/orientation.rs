//! Throughput (samples/s) of every orientation filter on a static, gently noisy IMU: imukit's
//! robust filter (6D and 9D), the Kalman filters (imufilter and ahrsfilter), the e-compass,
//! Madgwick, Mahony and the complementary filter (with a magnetometer where they take one);
//! 1 sample and 10⁵ samples. `benches/broad/broad.py --speed` times the robust filter's core
//! beside VQF's C++ core on a recorded trial (the example `orientation_speed` and
//! `benches/broad/vqf_speed.cpp`), and both through their Python packages.
//!
//! Run: `cargo bench -p imu-benches --bench orientation`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::orientation::{
    Complementary, Ecompass, FilterInput, KalmanFilter, KalmanParams, Madgwick, Mahony,
    OrientationFilter, RobustFilter, RobustParams,
};
use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::{AccelSign, Ned};

fn inputs(n: usize) -> Vec<FilterInput> {
    let mut noise = SeededNormals::new(3);
    let mut jitter = |s: f64| s * noise.standard_normal();
    (0..n)
        .map(|_| FilterInput {
            accel_m_s2: [jitter(0.02), jitter(0.02), 9.81 + jitter(0.02)],
            gyro_rad_s: [jitter(1e-3), jitter(1e-3), jitter(1e-3)],
            mag_ut: [27.5 + jitter(0.1), -2.4 + jitter(0.1), -16.1 + jitter(0.1)],
            interval_s: None,
        })
        .collect()
}

fn bench<F: OrientationFilter<Ned> + Clone>(c: &mut Criterion, name: &str, filter: F) {
    let mut group = c.benchmark_group("orientation");
    for n in [1usize, 100_000] {
        let data = inputs(n);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new(name, n), |b| {
            let mut f = filter.clone();
            f.update(&data[0]).expect("valid reading");
            b.iter(|| {
                for s in &data {
                    std::hint::black_box(f.update(s).expect("valid reading"));
                }
            });
        });
    }
    group.finish();
}

fn filters(c: &mut Criterion) {
    let sign = AccelSign::Matlab;
    for (name, magnetometer) in [("robust_6d", false), ("robust_9d", true)] {
        let params = RobustParams {
            accel_sign: sign,
            magnetometer,
            ..RobustParams::default()
        };
        bench(c, name, RobustFilter::new(params).unwrap());
    }
    let p = KalmanParams::default();
    bench(c, "imufilter", KalmanFilter::<Ned>::imu(p).unwrap());
    bench(c, "ahrsfilter", KalmanFilter::<Ned>::ahrs(p).unwrap());
    bench(c, "ecompass", Ecompass { accel_sign: sign });
    bench(
        c,
        "madgwick_marg",
        Madgwick::new(100.0, 0.041, true, sign).unwrap(),
    );
    bench(
        c,
        "mahony_marg",
        Mahony::new(100.0, 1.0, 0.3, true, sign).unwrap(),
    );
    bench(
        c,
        "complementary",
        Complementary::new(100.0, 0.01, 0.01, true, sign).unwrap(),
    );
}

criterion_group!(benches, filters);
criterion_main!(benches);
