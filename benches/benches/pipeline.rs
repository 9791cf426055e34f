//! The whole pipeline of the formula job (`benches/formula_job.toml`: formula strings in; exact
//! truth; accelerometer, gyroscope and magnetometer with MATLAB imuSensor's full error model
//! out), as `imukit simulate` runs it without the process start: streamed to a file of each
//! format (CSV, Parquet, `.npy`, `.npz`), and gathered into tables as Python's
//! `imukit.simulate` returns them. Samples per second, on one thread; `two_threads` adds the
//! truth a chunk ahead on a second one (what a single run does when a second core is free).
//!
//! Run: `cargo bench -p imu-benches --bench pipeline`.
#![allow(missing_docs)]

use std::path::Path;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imukit::pipeline::RunThreads;
use imukit::simulate::StreamOutputs;
use imukit::{Scenario, ScenarioSpec};

const JOB: &str = include_str!("../formula_job.toml");

fn job(samples: usize) -> Scenario {
    let mut spec = ScenarioSpec::from_toml(JOB, "formula_job.toml").expect("the job parses");
    let rate = spec.rate_hz.expect("the job has a rate");
    spec.duration_s = Some((samples - 1) as f64 / rate);
    spec.resolve(Path::new(".")).expect("the job resolves")
}

fn bench_pipeline(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("imukit-bench-pipeline-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let mut group = c.benchmark_group("formula_job");
    group.sample_size(10);
    let n = 200_000;
    let sc = job(n);
    group.throughput(Throughput::Elements(n as u64));
    for (threads, name) in [(RunThreads::One, ""), (RunThreads::Two, "_two_threads")] {
        for ext in ["csv", "parquet", "npy", "npz"] {
            let out = dir.join(format!("imu.{ext}"));
            group.bench_function(BenchmarkId::new(format!("to_file{name}"), ext), |b| {
                b.iter(|| {
                    let outputs = StreamOutputs {
                        imu: Some(&out),
                        ..StreamOutputs::default()
                    };
                    sc.stream_to_files(None, threads, &outputs)
                        .expect("written");
                });
            });
        }
        // What `imukit.simulate(..., truth=False)` runs: the readings into one caller's array.
        let columns = sc.gathered_shape().expect("a shape").imu_columns.len();
        let mut readings = vec![0.0; n * columns];
        group.bench_function(BenchmarkId::new(format!("into_array{name}"), "imu"), |b| {
            b.iter(|| {
                sc.simulate_streamed_into(None, threads, None, &mut readings)
                    .expect("simulated")
            });
        });
        if threads == RunThreads::One {
            // The same with the AVX2 copies forbidden (`imu_core::cpu`): the baseline build's
            // speed on this CPU, same numbers.
            imu_core::cpu::allow_avx2(false);
            group.bench_function(BenchmarkId::new("into_array_baseline", "imu"), |b| {
                b.iter(|| {
                    sc.simulate_streamed_into(None, threads, None, &mut readings)
                        .expect("simulated")
                });
            });
            imu_core::cpu::allow_avx2(true);
        }
        group.bench_function(
            BenchmarkId::new(format!("tables{name}"), "truth+imu"),
            |b| {
                b.iter(|| sc.simulate_streamed(None, threads).expect("simulated"));
            },
        );
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench_pipeline);
criterion_main!(benches);
