//! The whole pipeline of the formula job (`benches/formula_job.toml`: formula strings in; exact
//! truth; accelerometer, gyroscope and magnetometer with MATLAB imuSensor's full error model
//! out), as `imukit simulate` runs it without the process start: streamed to a file of each
//! format (CSV, Parquet, `.npy`, `.npz`), and gathered into tables as Python's
//! `imukit.simulate` returns them. Samples per second, on one thread; `two_threads` adds the
//! truth a chunk ahead on a second one (what a single run does when a second core is free).
//!
//! `chain` times the same job's readings with a signal chain (`[imu.chain]`: the motion at 20×
//! the output rate, a second-order low-pass on each sensor, every 20th sample kept) beside the
//! plain job, per output sample.
//!
//! Run: `cargo bench -p imu-benches --bench pipeline` (`-- chain` for the chain alone).
#![allow(missing_docs)]

use std::path::Path;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imukit::pipeline::RunThreads;
use imukit::simulate::StreamOutputs;
use imukit::{Scenario, ScenarioSpec};

const JOB: &str = include_str!("../formula_job.toml");

fn job(samples: usize) -> Scenario {
    job_with(samples, "")
}

/// The job with `extra` TOML after it (a table of its own).
fn job_with(samples: usize, extra: &str) -> Scenario {
    let text = format!("{JOB}\n{extra}");
    let mut spec = ScenarioSpec::from_toml(&text, "formula_job.toml").expect("the job parses");
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

/// The job's readings with and without a chain at 20× its rate, per output sample.
fn bench_chain(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain");
    group.sample_size(10);
    let n = 50_000;
    group.throughput(Throughput::Elements(n as u64));
    let chain = "[imu.chain]\ninternal_rate_hz = 2000\n\
                 accelerometer = { filter = \"butterworth\", order = 2, cutoff_hz = 40 }\n\
                 gyroscope = { filter = \"butterworth\", order = 2, cutoff_hz = 40 }\n\
                 magnetometer = { filter = \"butterworth\", order = 2, cutoff_hz = 40 }\n";
    for (name, sc) in [("plain", job(n)), ("internal_20x", job_with(n, chain))] {
        let columns = sc.gathered_shape().expect("a shape").imu_columns.len();
        let mut readings = vec![0.0; n * columns];
        group.bench_function(BenchmarkId::new("into_array", name), |b| {
            b.iter(|| {
                sc.simulate_streamed_into(None, RunThreads::One, None, &mut readings)
                    .expect("simulated")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_pipeline, bench_chain);
criterion_main!(benches);
