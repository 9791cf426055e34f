//! Throughput (samples/s) of the 3D strapdown step (coning, sculling, gravity, trapezoidal
//! position) on rate input, flat and on the WGS-84 Earth (the same increments scheme with Earth
//! rate, transport rate, Coriolis and normal gravity; and RK4 on both), and of planar dead
//! reckoning.
//!
//! Run: `cargo bench -p imu-benches --bench strapdown`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::earth::{FlatEarth, Geodetic, Wgs84};
use imu_core::strapdown::planar::{PlanarSample, PlanarScheme, PlanarState, dead_reckon};
use imu_core::strapdown::{
    NavState, StrapdownOptions, strapdown_increments, strapdown_rates, strapdown_rates_rk4,
};
use imu_core::{Enu, Ned};

type FlatNavState = NavState<FlatEarth<Enu>>;
type EarthNavState = NavState<Wgs84<Ned>>;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("strapdown");
    for n in [2usize, 100_000] {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let gyro: Vec<[f64; 3]> = t
            .iter()
            .map(|s| [0.3 * s.sin(), 0.2, -0.1 * s.cos()])
            .collect();
        let accel: Vec<[f64; 3]> = t.iter().map(|s| [0.5 * s.cos(), 0.1, 9.81]).collect();
        let flat = FlatEarth::<Enu>::new(9.81);
        let mut out = vec![FlatNavState::default(); n];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new("3d_rates", n), |b| {
            b.iter(|| {
                strapdown_rates(
                    flat,
                    &t,
                    &gyro,
                    &accel,
                    None,
                    NavState::default(),
                    StrapdownOptions::default(),
                    &mut out,
                )
                .expect("valid")
            });
        });
        // Increments, flat and on the Earth: the same scheme, the Earth terms added.
        let dth: Vec<[f64; 3]> = gyro.iter().map(|w| w.map(|x| x * 1e-3)).collect();
        let dv: Vec<[f64; 3]> = accel.iter().map(|f| f.map(|x| x * 1e-3)).collect();
        group.bench_function(BenchmarkId::new("3d_increments_flat", n), |b| {
            b.iter(|| {
                strapdown_increments(
                    flat,
                    &t,
                    &dth,
                    &dv,
                    None,
                    NavState::default(),
                    StrapdownOptions::default(),
                    &mut out,
                )
                .expect("valid")
            });
        });
        let start = EarthNavState {
            position: Geodetic::from_degrees(45.0, 7.0, 300.0),
            ..EarthNavState::default()
        };
        let mut eout = vec![EarthNavState::default(); n];
        group.bench_function(BenchmarkId::new("3d_increments_earth", n), |b| {
            b.iter(|| {
                strapdown_increments(
                    Wgs84::default(),
                    &t,
                    &dth,
                    &dv,
                    None,
                    start,
                    StrapdownOptions::default(),
                    &mut eout,
                )
                .expect("valid")
            });
        });
        if n >= 6 {
            group.bench_function(BenchmarkId::new("3d_rk4_flat", n), |b| {
                b.iter(|| {
                    strapdown_rates_rk4(
                        flat,
                        &t,
                        &gyro,
                        &accel,
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
                        &t,
                        &gyro,
                        &accel,
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
