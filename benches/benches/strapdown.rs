//! Throughput (samples/s) of the 3D strapdown step (coning, sculling, gravity, trapezoidal
//! position) on rate input, flat and on the WGS-84 Earth (the same increments scheme with Earth
//! rate, transport rate, Coriolis and normal gravity; and RK4 on both), and of planar dead
//! reckoning.
//!
//! Run: `cargo bench -p imu-benches --bench strapdown`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_benches::{StrapdownInput, earth_start};
use imu_core::earth::{FlatEarth, Wgs84};
use imu_core::strapdown::planar::{PlanarSample, PlanarScheme, PlanarState, dead_reckon};
use imu_core::strapdown::{NavState, StrapdownOptions, strapdown_rates_rk4};
use imu_core::{Enu, Ned};

type FlatNavState = NavState<FlatEarth<Enu>>;
type EarthNavState = NavState<Wgs84<Ned>>;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("strapdown");
    for n in [2usize, 100_000] {
        let input = StrapdownInput::new(n);
        let (t, gyro, accel) = (&input.t_s, &input.gyro_rad_s, &input.accel_m_s2);
        let flat = FlatEarth::<Enu>::new(9.81);
        let mut out = vec![FlatNavState::default(); n];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new("3d_rates", n), |b| {
            b.iter(|| input.rates_flat(&mut out));
        });
        // Increments, flat and on the Earth: the same scheme, the Earth terms added.
        group.bench_function(BenchmarkId::new("3d_increments_flat", n), |b| {
            b.iter(|| input.increments(flat, NavState::default(), &mut out));
        });
        let start = earth_start();
        let mut eout = vec![EarthNavState::default(); n];
        group.bench_function(BenchmarkId::new("3d_increments_earth", n), |b| {
            b.iter(|| input.increments(Wgs84::default(), start, &mut eout));
        });
        if n >= 6 {
            group.bench_function(BenchmarkId::new("3d_rk4_flat", n), |b| {
                b.iter(|| {
                    strapdown_rates_rk4(
                        flat,
                        t,
                        gyro,
                        accel,
                        None,
                        NavState::default(),
                        StrapdownOptions::default(),
                        4,
                        &mut out,
                    )
                    .expect("valid")
                });
            });
            group.bench_function(BenchmarkId::new("3d_rk4_earth", n), |b| {
                b.iter(|| {
                    strapdown_rates_rk4(
                        Wgs84::default(),
                        t,
                        gyro,
                        accel,
                        None,
                        start,
                        StrapdownOptions::default(),
                        4,
                        &mut eout,
                    )
                    .expect("valid")
                });
            });
        }
        let planar: Vec<PlanarSample> = t
            .iter()
            .map(|&s| PlanarSample {
                t_s: s,
                accel_x_m_s2: 0.1,
                accel_y_m_s2: 0.2 * s.sin(),
                gyro_z_rad_s: 0.05,
            })
            .collect();
        let mut pout = vec![PlanarState::default(); n];
        group.bench_function(BenchmarkId::new("planar_trapezoid", n), |b| {
            b.iter(|| {
                dead_reckon(
                    &planar,
                    PlanarScheme::Trapezoid,
                    PlanarState::default(),
                    &mut pout,
                )
                .expect("valid")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
