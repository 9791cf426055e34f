//! Throughput (samples/s) of the full accel-gyro-mag error model with every term on: bias,
//! misalignment, white noise, bias instability (MATLAB filter and flicker), random walk,
//! temperature, g-sensitivity, saturation, quantisation; 27 normals per sample.
//!
//! Run: `cargo bench -p imu-benches --bench sensor`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::sensor::{
    BiasInstabilityModel, GyroAccelerationInput, ImuModel, ImuReading, ImuState, InlineBuffer,
    NoiseSource, SeededNormals, SensorSet, Temperatures,
};

/// The core's inline filter storage, named once for the struct literals below.
type SensorParams = imu_core::sensor::SensorParams<InlineBuffer>;
use imu_core::{Body, Enu, EulerZyx, ImuMount, Ned, Rotation, Truth};

fn every_term(model: BiasInstabilityModel) -> SensorParams {
    SensorParams {
        measurement_range: 1e3,
        resolution: 1e-5,
        constant_bias: [0.01, -0.02, 0.03],
        axes_misalignment_pct: SensorParams::misalignment_from_vector([0.1, 0.2, 0.3]),
        noise_density: [1e-3; 3],
        bias_instability: [1e-4; 3],
        bias_instability_model: model,
        random_walk: [1e-5; 3],
        temperature_bias: [1e-4; 3],
        temperature_scale_factor_pct: [0.01; 3],
        acceleration_bias: [1e-4; 3],
        ..SensorParams::default()
    }
}

fn bench_sensor(c: &mut Criterion) {
    let mut group = c.benchmark_group("sensor_model/accel-gyro-mag");
    let truth = Truth::<Enu>::default();
    for (label, bi) in [
        ("matlab_filter", BiasInstabilityModel::default()),
        (
            "flicker",
            BiasInstabilityModel::Flicker {
                tau_min_s: 1.0,
                tau_max_s: 1000.0,
            },
        ),
    ] {
        let p = every_term(bi);
        let model = ImuModel::new(
            ImuMount::<Enu>::default(),
            SensorSet {
                gyroscope: true,
                magnetometer: true,
            },
            GyroAccelerationInput::BodySpecificForce,
            [&p, &p, &p],
            100.0,
        )
        .expect("valid parameters");
        let temps = Temperatures::uniform(30.0);
        for n in [1usize, 100_000] {
            let mut out = vec![ImuReading::default(); n];
            group.throughput(Throughput::Elements(n as u64));
            group.bench_function(BenchmarkId::new(label, n), |b| {
                let mut state = ImuState::default();
                let mut noise = SeededNormals::new(1);
                b.iter(|| {
                    for o in out.iter_mut() {
                        *o = model.measure(&truth, &temps, &mut state, &mut noise);
                    }
                });
            });
            // The same readings with each block's normals drawn first, as a simulation makes them.
            let many = vec![truth; n];
            group.bench_function(BenchmarkId::new(format!("{label}/many"), n), |b| {
                let mut state = ImuState::default();
                let mut noise = SeededNormals::new(1);
                b.iter(|| model.measure_many(&many, |_| temps, &mut state, &mut noise, &mut out));
            });
            group.bench_function(BenchmarkId::new(format!("{label}/no_noise"), n), |b| {
                let mut state = ImuState::default();
                b.iter(|| {
                    for o in out.iter_mut() {
                        *o = model.measure(
                            &truth,
                            &temps,
                            &mut state,
                            &mut imu_core::sensor::NoNoise,
                        );
                    }
                });
            });
        }
    }
    // The 27 normals a sample alone, for the share of the generator in the readings' time.
    let n = 100_000;
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("27_normals", n), |b| {
        let mut noise = SeededNormals::new(1);
        let mut drawn = [0.0; 27];
        b.iter(|| {
            for _ in 0..n {
                for d in &mut drawn {
                    *d = noise.standard_normal();
                }
                std::hint::black_box(&drawn);
            }
        });
    });
    // The same 27 drawn by one fill, as a simulation's block draws them (its generator state in
    // a local).
    group.bench_function(BenchmarkId::new("27_normals_fill", n), |b| {
        let mut noise = SeededNormals::new(1);
        let mut drawn = [0.0; 27];
        b.iter(|| {
            for _ in 0..n {
                noise.fill_standard_normal(&mut drawn);
                std::hint::black_box(&drawn);
            }
        });
    });
    group.finish();
}

/// MATLAB's batch call shape (`ImuModel::measure_nav_into`: nav-frame acceleration and angular
/// velocity, attitude quaternions) on 10⁶ varying samples, output buffer reused: the Rust figure
/// that the Python `ImuSensor` call is compared with (`benches/compare_numpy.py`).
fn bench_matlab_call(c: &mut Criterion) {
    let mut group = c.benchmark_group("sensor_model/matlab_call");
    let p = every_term(BiasInstabilityModel::default());
    let model = ImuModel::new(
        ImuMount::<Ned>::default(),
        SensorSet {
            gyroscope: true,
            magnetometer: true,
        },
        GyroAccelerationInput::NavAcceleration,
        [&p, &p, &p],
        100.0,
    )
    .expect("valid parameters");
    let n = 1_000_000;
    let t = |k: usize| k as f64 * 0.01;
    let acc: Vec<[f64; 3]> = (0..n)
        .map(|k| [t(k).sin(), (2.0 * t(k)).cos(), 0.1])
        .collect();
    let omega: Vec<[f64; 3]> = (0..n).map(|k| [0.1, 0.2 * t(k).cos(), 0.3]).collect();
    let attitude: Vec<Rotation<Body, Ned>> = (0..n)
        .map(|k| Rotation::from_euler(EulerZyx::new(0.3 * t(k), 0.2, 0.1 * t(k).sin())))
        .collect();
    let temps = Temperatures::uniform(30.0);
    let mut out = vec![ImuReading::default(); n];
    group.throughput(Throughput::Elements(n as u64));
    group.sample_size(10);
    group.bench_function(BenchmarkId::new("accel-gyro-mag", n), |b| {
        let mut state = ImuState::default();
        let mut noise = SeededNormals::new(1);
        b.iter(|| {
            model.measure_nav_into(
                &acc, &omega, &attitude, &temps, &mut state, &mut noise, &mut out,
            );
        });
    });
    group.finish();
}

criterion_group!(benches, bench_sensor, bench_matlab_call);
criterion_main!(benches);
