//! Throughput of the error-state filter per IMU sample (propagation of the nominal state and the
//! 15 × 15 covariance, or 36 × 36 with the sensor-error states), and of a GNSS
//! position-and-velocity update, next to the sensor model's per-sample cost in `sensor.rs`; on
//! the flat Earth and on WGS-84 (the same filter, the Earth's terms and couplings added).
//!
//! Run: `cargo bench -p imu-benches --bench fusion`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_benches::{BenchEarth, propagate};
use imu_core::earth::{FlatEarth, Wgs84};
use imu_core::fusion::{BASE_STATES, Eskf, FULL_STATES, GnssFix};
use imu_core::{Enu, Ned, Vec3};

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
    g.update(&fix, imu_core::fusion::gate::Gate::Off)
        .expect("valid")
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
