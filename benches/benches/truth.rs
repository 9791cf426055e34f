//! Truth + ideal IMU throughput (samples/s) on the figure-8: exact (formula strings, compiled)
//! and sampled (finite differences, order 6, tangent attitude); and the exact truth alone. Also
//! the vector kernels' `sin_cos` (as this CPU runs it, and its baseline copy) against `wide`'s own
//! and the C library's (values/s).
//!
//! Run: `cargo bench -p imu-benches --bench truth`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::kinematics::sampled::{SampledAttitude, SampledOptions, truth_from_samples};
use imu_core::{Enu, IdealReading, ImuMount, Truth, Vec3};
use imukit::motion::ExpressionMotion;
use imukit::motion::analytic::{AnalyticOptions, truth_from_motion};
use imukit::scenario::builtin;
use imukit::scenario::{TrajectorySpec, sample_times};

fn figure8() -> ExpressionMotion {
    match builtin::spec("figure8").expect("built-in").trajectory {
        TrajectorySpec::Expression(e) => e.motion().expect("parses"),
        _ => unreachable!("figure8 is an expression trajectory"),
    }
}

fn bench_truth(c: &mut Criterion) {
    let motion = figure8();
    let mount = ImuMount::<Enu> {
        lever_arm_m: Vec3::new(-0.075, -0.075, 0.025),
        ..ImuMount::default()
    };
    let mut group = c.benchmark_group("truth_and_ideal_imu/figure8");
    for seconds in [0.0, 10.0] {
        let t = sample_times(2000.0, seconds).expect("times");
        let n = t.len();
        let mut truth = vec![Truth::<Enu>::default(); n];
        let mut readings = vec![IdealReading::default(); n];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::new("exact", n), &t, |b, t| {
            b.iter(|| {
                truth_from_motion(&motion, t, AnalyticOptions::default(), &mut truth)
                    .expect("truth");
                mount.read_into(&truth, &mut readings);
            });
        });
        group.bench_with_input(BenchmarkId::new("exact_truth_only", n), &t, |b, t| {
            b.iter(|| {
                truth_from_motion(&motion, t, AnalyticOptions::default(), &mut truth)
                    .expect("truth");
            });
        });
        if n >= 10 {
            truth_from_motion(&motion, &t, AnalyticOptions::default(), &mut truth).expect("truth");
            let pos: Vec<[f64; 3]> = truth.iter().map(|s| s.position_m.to_array()).collect();
            group.bench_with_input(BenchmarkId::new("sampled_order6", n), &t, |b, t| {
                b.iter(|| {
                    truth_from_samples(
                        t,
                        &pos,
                        SampledAttitude::Tangent,
                        SampledOptions::default(),
                        &mut truth,
                    )
                    .expect("truth");
                    mount.read_into(&truth, &mut readings);
                });
            });
        }
    }
    group.finish();
}

fn bench_sin_cos(c: &mut Criterion) {
    let x: Vec<f64> = (0..4096).map(|k| 0.37 * k as f64 - 700.0).collect();
    let (mut s, mut co) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    let mut group = c.benchmark_group("sin_cos/4096");
    group.throughput(Throughput::Elements(x.len() as u64));
    // The kernel as this CPU runs it (AVX2 where it has it), then its baseline copy.
    group.bench_function("kernel", |b| {
        b.iter(|| imu_core::trig::sin_cos_into(&x, &mut s, &mut co));
    });
    imu_core::cpu::allow_avx2(false);
    group.bench_function("kernel_baseline", |b| {
        b.iter(|| imu_core::trig::sin_cos_into(&x, &mut s, &mut co));
    });
    imu_core::cpu::allow_avx2(true);
    group.bench_function("wide", |b| {
        b.iter(|| {
            for ((v, s), c) in x
                .chunks_exact(4)
                .zip(s.chunks_exact_mut(4))
                .zip(co.chunks_exact_mut(4))
            {
                let (vs, vc) = wide::f64x4::from([v[0], v[1], v[2], v[3]]).sin_cos();
                s.copy_from_slice(&vs.to_array());
                c.copy_from_slice(&vc.to_array());
            }
        });
    });
    group.bench_function("libm", |b| {
        b.iter(|| {
            for ((v, s), c) in x.iter().zip(s.iter_mut()).zip(co.iter_mut()) {
                (*s, *c) = v.sin_cos();
            }
        });
    });
    group.finish();
}

criterion_group!(benches, bench_truth, bench_sin_cos);
criterion_main!(benches);
