//! Throughput of the error-state filter per IMU sample (propagation of the nominal state and the
//! 15 × 15 covariance, or 36 × 36 with the sensor-error states), and of a GNSS
//! position-and-velocity update, next to the sensor model's per-sample cost in `sensor.rs`.
//!
//! Run: `cargo bench -p imu-benches --bench fusion`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfNoise, EskfState, FULL_STATES, InitialSigma, SensorErrorSigma,
};
use imu_core::{Enu, Rotation, Vec3};

fn filter<const S: usize>() -> Eskf<Enu, S> {
    let start = EskfState::<Enu> {
        t_s: 0.0,
        position_m: Vec3::zeros(),
        velocity_m_s: Vec3::new(10.0, 0.0, 0.0),
        attitude: Rotation::identity(),
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let sigma = InitialSigma {
        position_m: 1.0,
        velocity_m_s: 0.1,
        attitude_rad: [0.01, 0.01, 0.05],
        accel_bias_m_s2: 0.01,
        gyro_bias_rad_s: 1e-4,
    };
    let noise = EskfNoise {
        accel_psd: 3e-3,
        gyro_psd: 2e-4,
        accel_bias_psd: 2e-4,
        gyro_bias_psd: 2e-6,
    };
    let f = Eskf::new(&start, &sigma, noise, 9.81).expect("valid");
    if S == FULL_STATES {
        f.with_sensor_error_sigma(&SensorErrorSigma {
            accel_scale_factor: 1e-3,
            accel_misalignment: 1e-3,
            gyro_scale_factor: 1e-3,
            gyro_misalignment: 1e-3,
            gyro_g_sensitivity: 1e-5,
        })
        .expect("valid")
    } else {
        f
    }
}

/// `n` samples at 100 Hz through a filter of `S` states, the covariance every `interval_s`.
fn propagate<const S: usize>(n: usize, interval_s: f64) -> Eskf<Enu, S> {
    let mut f = filter::<S>()
        .with_covariance_interval(interval_s)
        .expect("valid");
    for k in 0..n {
        let t = k as f64 * 0.01;
        f.propagate(t, [0.01, -0.02, 0.1 * t.sin()], [0.2, 1.0, 9.81])
            .expect("valid");
    }
    f
}

/// One GNSS position-and-velocity update of a filter of `S` states.
fn gnss_update<const S: usize>(f: &Eskf<Enu, S>) -> imu_core::fusion::UpdateOutcome {
    let mut g = *f;
    g.update_gnss(
        Vec3::new(0.1, 0.2, 0.0),
        Some(Vec3::new(10.0, 0.0, 0.0)),
        Vec3::new(0.0, 0.0, -1.0),
        [1.0, 1.0, 2.0],
        [0.1; 3],
        f64::INFINITY,
    )
    .expect("valid")
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("fusion");
    let n = 10_000usize;
    group.throughput(Throughput::Elements(n as u64));
    // 100 Hz samples; the covariance with every sample, and at 20 Hz (imukit fuse's default).
    for (name, interval_s) in [("propagate", 0.0), ("propagate_covariance_20hz", 0.05)] {
        group.bench_function(BenchmarkId::new(name, n), |b| {
            b.iter(|| propagate::<BASE_STATES>(n, interval_s));
        });
        group.bench_function(BenchmarkId::new(format!("{name}_36_states"), n), |b| {
            b.iter(|| propagate::<FULL_STATES>(n, interval_s));
        });
    }
    group.throughput(Throughput::Elements(1));
    let base = propagate::<BASE_STATES>(2, 0.0);
    group.bench_function("gnss_update_position_velocity", |b| {
        b.iter(|| gnss_update(&base));
    });
    let full = propagate::<FULL_STATES>(2, 0.0);
    group.bench_function("gnss_update_position_velocity_36_states", |b| {
        b.iter(|| gnss_update(&full));
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
