//! Runs per second of the outage study (`imukit study`): one run of the example tunnel road
//! (17 001 samples at 100 Hz: simulated truth and STIM300 readings, GNSS, then fused), on one
//! core — with the 15-state filter, with wheels, and as the example studies run it (the 20 s
//! rest and the 36 states); `imukit study` spreads runs over all cores.
//!
//! Run: `cargo bench -p imu-benches --bench study`.
#![allow(missing_docs)]

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imukit::study::{Study, StudySpec};

fn bench(c: &mut Criterion) {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut group = c.benchmark_group("study");
    group.sample_size(10);
    for (name, odometer, full, smooth) in [
        ("tunnel_run", false, false, false),
        ("tunnel_run_with_wheels", true, false, false),
        ("tunnel_run_rest_and_36_states", false, true, false),
        ("tunnel_run_rest_and_36_states_smoothed", false, true, true),
    ] {
        let spec = StudySpec {
            scenario: "car_tunnel.toml".into(),
            presets: vec!["stim300".into()],
            runs: 2,
            odometer,
            baro: false,
            nhc_sigma_m_s: odometer.then_some(0.05),
            sensor_errors: Some(full),
            rest_s: Some(if full { 20.0 } else { 0.0 }),
            smooth,
            draw_parts: true,
        };
        let study = Study::new(&spec, &examples, "bench").expect("the example study resolves");
        group.throughput(Throughput::Elements(1));
        group.bench_function(name, |b| {
            let mut run = 0;
            b.iter(|| {
                run += 1;
                study.run_one(0, run).expect("a run")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
