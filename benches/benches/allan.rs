//! Throughput (samples/s) of the overlapping Allan deviation at octave cluster sizes, on a
//! caller-owned θ buffer: a short and a long record.
//!
//! Run: `cargo bench -p imu-benches --bench allan`.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imu_core::allan::{allan_deviation, octave_cluster_sizes};
use imu_core::sensor::{NoiseSource, SeededNormals};

fn bench_allan(c: &mut Criterion) {
    let mut group = c.benchmark_group("allan/overlapping_octave");
    for n in [10_000usize, 1_000_000] {
        let mut noise = SeededNormals::new(3);
        let x: Vec<f64> = (0..n).map(|_| noise.standard_normal()).collect();
        let mut m = [0usize; 64];
        let count = octave_cluster_sizes(n, &mut m);
        let mut theta = vec![0.0; n];
        let mut adev = vec![0.0; count];
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                allan_deviation(&x, 100.0, &m[..count], &mut theta, &mut adev).expect("valid")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_allan);
criterion_main!(benches);
