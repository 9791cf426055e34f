//! Throughput of the error-state filter per IMU sample (propagation of the nominal state and the
//! 15 × 15 covariance, or 36 × 36 with the sensor-error states), and of a GNSS
//! position-and-velocity update, next to the sensor model's per-sample cost in `sensor.rs`; on
//! the flat Earth and on WGS-84 (the same filter, the Earth's terms and couplings added).
//!
//! Run: `cargo bench -p imu-benches --bench fusion`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::earth::{EarthModel, FlatEarth, Geodetic, Wgs84};
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfNoise, EskfState, FULL_STATES, GnssFix, InitialSigma, SensorErrorSigma,
};
use imu_core::strapdown::NavState;
use imu_core::{Enu, Ned, Rotation, Vec3};

/// An Earth to run on and a position near its origin, `offset_m` north-east of it.
trait BenchEarth: EarthModel {
    fn make() -> Self;
    fn at(offset_m: f64) -> Self::Position;
}

impl BenchEarth for FlatEarth<Enu> {
    fn make() -> Self {
        FlatEarth::new(9.81)
    }
    fn at(offset_m: f64) -> Vec3<Enu> {
        Vec3::new(offset_m, offset_m, 0.0)
    }
}

impl BenchEarth for Wgs84<Ned> {
    fn make() -> Self {
        Wgs84::default()
    }
    fn at(offset_m: f64) -> Geodetic {
        Geodetic::from_degrees(
            45.0 + offset_m / 111_000.0,
            7.0 + offset_m / 78_800.0,
            300.0,
        )
    }
}

fn filter<E: BenchEarth, const S: usize>() -> Eskf<E, S> {
    let start = EskfState::<E> {
        nav: NavState {
            t_s: 0.0,
            position: E::at(0.0),
            velocity_m_s: Vec3::new(10.0, 0.0, 0.0),
            attitude: Rotation::identity(),
        },
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
    let f = Eskf::new(E::make(), &start, &sigma, noise).expect("valid");
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
fn propagate<E: BenchEarth, const S: usize>(n: usize, interval_s: f64) -> Eskf<E, S> {
    let mut f = filter::<E, S>()
        .with_covariance_interval(interval_s)
        .expect("valid");
    for k in 0..n {
        let t = k as f64 * 0.01;
        let up = -<E::Frame as imu_core::NavFrame>::Z_UP;
        f.propagate(t, [0.01, -0.02, 0.1 * t.sin()], [0.2, 1.0, -up * 9.81])
            .expect("valid");
    }
    f
}

/// One GNSS position-and-velocity update of a filter of `S` states.
fn gnss_update<E: BenchEarth, const S: usize>(f: &Eskf<E, S>) -> imu_core::fusion::UpdateOutcome {
    let mut g = *f;
    let fix = GnssFix {
        position: E::at(0.15),
        velocity_m_s: Some(Vec3::new(10.0, 0.0, 0.0)),
        lever_arm_m: Vec3::new(0.0, 0.0, -1.0),
        position_sigma_m: [1.0, 1.0, 2.0],
        velocity_sigma_m_s: [0.1; 3],
        age_s: 0.0,
    };
    g.update_gnss(&fix, f64::INFINITY).expect("valid")
}

fn bench_earth<E: BenchEarth>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    suffix: &str,
) {
    let n = 10_000usize;
    group.throughput(Throughput::Elements(n as u64));
    // 100 Hz samples; the covariance with every sample, and at 20 Hz (imukit fuse's default).
    for (name, interval_s) in [("propagate", 0.0), ("propagate_covariance_20hz", 0.05)] {
        group.bench_function(BenchmarkId::new(format!("{name}{suffix}"), n), |b| {
            b.iter(|| propagate::<E, BASE_STATES>(n, interval_s));
        });
        group.bench_function(
            BenchmarkId::new(format!("{name}_36_states{suffix}"), n),
            |b| {
                b.iter(|| propagate::<E, FULL_STATES>(n, interval_s));
            },
        );
    }
    group.throughput(Throughput::Elements(1));
    let base = propagate::<E, BASE_STATES>(2, 0.0);
    group.bench_function(format!("gnss_update_position_velocity{suffix}"), |b| {
        b.iter(|| gnss_update(&base));
    });
    let full = propagate::<E, FULL_STATES>(2, 0.0);
    group.bench_function(
        format!("gnss_update_position_velocity_36_states{suffix}"),
        |b| {
            b.iter(|| gnss_update(&full));
        },
    );
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("fusion");
    bench_earth::<FlatEarth<Enu>>(&mut group, "");
    bench_earth::<Wgs84<Ned>>(&mut group, "_earth");
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
