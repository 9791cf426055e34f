//! `imukit simulate SCENARIO --out IMU.csv [--truth TRUTH.csv] [--runs N] [--threads N]`.
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use imukit::io::TableFormat;
use imukit::io::bag::BagOptions;
use imukit::io::description::Description;
use imukit::io::output::{check_outputs, check_table_outputs, create_folder_within};
use imukit::io::table::run_path;
use imukit::pipeline::{RunThreads, available_cores};
use imukit::scenario::report::RunReport;
use imukit::simulate::StreamOutputs;
use imukit::{Scenario, ScenarioSpec};
use rayon::prelude::*;

use super::CliError;
use crate::cli::BagOutArgs;

/// The files `simulate` writes, and a bag's options.
pub struct Outputs<'a> {
    pub out: &'a Path,
    pub truth: Option<&'a Path>,
    pub gnss: Option<&'a Path>,
    pub baro: Option<&'a Path>,
    pub odometer: Option<&'a Path>,
    pub bag: Option<&'a BagOptions>,
}

/// The bag options given (`None` when none is), refused unless `--out` names a bag.
pub fn bag_options(
    args: &BagOutArgs,
    out: &Path,
    layout: bool,
) -> Result<Option<BagOptions>, CliError> {
    let given = [
        ("--bag-topic", args.bag_topic.is_some()),
        ("--bag-frame-id", args.bag_frame_id.is_some()),
        ("--bag-start-s", args.bag_start_s.is_some()),
    ];
    let Some((flag, _)) = given.iter().find(|(_, g)| *g) else {
        return Ok(None);
    };
    if layout || TableFormat::of(out) != TableFormat::Mcap {
        return Err(imukit::Error::Invalid {
            field: (*flag).into(),
            message: format!(
                "applies to a ROS 2 bag written by --out NAME.mcap, not to {}",
                out.display()
            ),
        }
        .into());
    }
    let options = BagOptions::new(
        args.bag_topic.as_deref(),
        args.bag_frame_id.as_deref(),
        args.bag_start_s,
    )?;
    Ok(Some(options))
}

/// Refuses an output that would overwrite an input or another output, every run's file counted.
fn check_files(
    scenario: &Path,
    spec: &ScenarioSpec,
    o: &Outputs<'_>,
    runs: Option<u64>,
    sc: &Scenario,
) -> Result<(), CliError> {
    let base = scenario.parent().unwrap_or_else(|| Path::new("."));
    let files = spec.input_files(base);
    let mut inputs = vec![("scenario file", scenario)];
    inputs.extend(files.iter().map(|(what, p)| (*what, p.as_path())));
    let per_run = |path: &Path| -> Vec<std::path::PathBuf> {
        match runs {
            Some(n) => (0..n).map(|r| run_path(path, r, n)).collect(),
            None => vec![path.to_path_buf()],
        }
    };
    let run_files = per_run(o.out);
    let gnss_files = o.gnss.map(per_run).unwrap_or_default();
    let baro_files = o.baro.map(per_run).unwrap_or_default();
    let odometer_files = o.odometer.map(per_run).unwrap_or_default();
    let mut outputs: Vec<(&str, &Path)> =
        run_files.iter().map(|p| ("--out", p.as_path())).collect();
    // The truth once, or per run when it differs by run.
    let truth_files = match (o.truth, runs) {
        (Some(t), Some(_)) if !sc.truth_columns_of_each_run().is_empty() => per_run(t),
        (t, _) => t.map(Path::to_path_buf).into_iter().collect(),
    };
    outputs.extend(truth_files.iter().map(|p| ("--truth", p.as_path())));
    outputs.extend(gnss_files.iter().map(|p| ("--gnss", p.as_path())));
    outputs.extend(baro_files.iter().map(|p| ("--baro", p.as_path())));
    outputs.extend(odometer_files.iter().map(|p| ("--odometer", p.as_path())));
    check_outputs(&inputs, &outputs)?;
    check_table_outputs(&outputs)?;
    Ok(())
}

pub fn run(
    scenario: &Path,
    o: &Outputs<'_>,
    runs: Option<u64>,
    threads: Option<i64>,
) -> Result<(), CliError> {
    // One run's stages, or the runs at a time: refused before anything is read if below 1.
    let run_threads = RunThreads::at_most(threads, "--threads")?;
    let spec = ScenarioSpec::from_file(scenario)?;
    let base = scenario.parent().unwrap_or_else(|| Path::new("."));
    let sc = spec.resolve(base)?;
    check_files(scenario, &spec, o, runs, &sc)?;
    for w in &sc.warnings {
        crate::report::warn(w);
    }
    // What the files hold, written into those whose format has room for it.
    let description = sc.description(std::fs::read_to_string(scenario).ok());
    match runs {
        None => one_run(&sc, o, run_threads, &description),
        Some(runs) => many_runs(&sc, o, runs, threads, &description),
    }
}

/// One run, streamed: chunks are written as they are made, so memory does not grow with duration.
fn one_run(
    sc: &Scenario,
    o: &Outputs<'_>,
    run_threads: RunThreads,
    description: &Description,
) -> Result<(), CliError> {
    let outputs = StreamOutputs {
        imu: Some(o.out),
        truth: o.truth,
        gnss: o.gnss,
        baro: o.baro,
        odometer: o.odometer,
        description,
        asl: false,
        bag: o.bag,
    };
    let report = sc.stream_to_files(None, run_threads, &outputs)?;
    for w in report.warnings(sc.sample_rate_hz) {
        crate::report::warn(&w);
    }
    let mut written = format!("IMU readings in {}", o.out.display());
    for (what, path) in [
        ("truth", o.truth),
        ("GNSS fixes", o.gnss),
        ("barometer readings", o.baro),
        ("odometer readings", o.odometer),
    ] {
        if let Some(p) = path {
            written += &format!(", {what} in {}", p.display());
        }
    }
    crate::note!("imukit: {} samples; {written}", sc.t_s.len());
    Ok(())
}

/// `runs` seeded runs at a time (every core, or at most `threads`), each on one thread, each
/// run's files named by [`run_path`]; the truth once (per run when it differs by run).
fn many_runs(
    sc: &Scenario,
    o: &Outputs<'_>,
    runs: u64,
    threads: Option<i64>,
    description: &Description,
) -> Result<(), CliError> {
    if runs == 0 {
        return Err(imukit::Error::Invalid {
            field: "--runs".into(),
            message: "must be ≥ 1".into(),
        }
        .into());
    }
    let progress = crate::report::Progress::start(runs, "runs");
    let done = AtomicU64::new(0);
    let cores = available_cores();
    let pool_threads = threads.map_or(cores, |n| {
        usize::try_from(n).unwrap_or(usize::MAX).min(cores)
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(pool_threads)
        .build()
        .map_err(|e| imukit::Error::Invalid {
            field: "--threads".into(),
            message: format!("could not start {pool_threads} threads: {e}"),
        })?;
    let merged = std::sync::Mutex::new(RunReport::default());
    pool.install(|| {
        (0..runs)
            .into_par_iter()
            .try_for_each(|r| -> Result<(), CliError> {
                let per = |p: Option<&Path>| p.map(|p| run_path(p, r, runs));
                // The truth once, unless it differs by run (random vibration): then per run.
                let truth_file = if sc.truth_columns_of_each_run().is_empty() {
                    o.truth.filter(|_| r == 0).map(Path::to_path_buf)
                } else {
                    per(o.truth)
                };
                let (imu_file, gnss_file, baro_file, odometer_file) = (
                    run_path(o.out, r, runs),
                    per(o.gnss),
                    per(o.baro),
                    per(o.odometer),
                );
                let report = sc.stream_to_files(
                    Some(r),
                    RunThreads::One,
                    &StreamOutputs {
                        imu: Some(&imu_file),
                        truth: truth_file.as_deref(),
                        gnss: gnss_file.as_deref(),
                        baro: baro_file.as_deref(),
                        odometer: odometer_file.as_deref(),
                        description,
                        asl: false,
                        bag: o.bag,
                    },
                )?;
                if let Ok(mut m) = merged.lock() {
                    m.merge(&report);
                }
                done.fetch_add(1, Ordering::Relaxed);
                progress.inc();
                Ok(())
            })
    })?;
    progress.finish();
    if let Ok(m) = merged.into_inner() {
        for w in m.warnings(sc.sample_rate_hz) {
            crate::report::warn(&format!("over the {runs} runs, {w}"));
        }
    }
    let truth = match o.truth {
        Some(t) if sc.truth_columns_of_each_run().is_empty() => {
            format!("; truth in {}", t.display())
        }
        Some(t) => format!(
            "; truth (its vibration differs by run) in {} … {}",
            run_path(t, 0, runs).display(),
            run_path(t, runs - 1, runs).display()
        ),
        None => String::new(),
    };
    crate::note!(
        "imukit: {} runs of {} samples; IMU readings in {} … {}{truth}",
        done.load(Ordering::Relaxed),
        sc.t_s.len(),
        run_path(o.out, 0, runs).display(),
        run_path(o.out, runs - 1, runs).display()
    );
    Ok(())
}

/// `imukit simulate SCENARIO --layout euroc --out DIR`: one run as a EuRoC sequence, the
/// readings and the truth in the ASL layout under `DIR/mav0/`.
pub fn euroc(
    scenario: &Path,
    out: &Path,
    truth: Option<&Path>,
    runs: Option<u64>,
    threads: Option<i64>,
) -> Result<(), CliError> {
    if truth.is_some() {
        return Err(imukit::Error::Invalid {
            field: "--truth".into(),
            message: "a EuRoC sequence keeps its ground truth in \
                      DIR/mav0/state_groundtruth_estimate0/data.csv: leave --truth out"
                .into(),
        }
        .into());
    }
    if runs.is_some() {
        return Err(imukit::Error::Invalid {
            field: "--runs".into(),
            message: "--layout euroc writes one run".into(),
        }
        .into());
    }
    let run_threads = RunThreads::at_most(threads, "--threads")?;
    let spec = ScenarioSpec::from_file(scenario)?;
    let base = scenario.parent().unwrap_or_else(|| Path::new("."));
    let files = spec.input_files(base);
    let mut inputs = vec![("scenario file", scenario)];
    inputs.extend(files.iter().map(|(what, p)| (*what, p.as_path())));
    let sc = spec.resolve(base)?;
    for w in &sc.warnings {
        crate::report::warn(w);
    }
    // The folders under DIR are made here, following no link planted inside DIR.
    let (imu, truth) = (
        create_folder_within(out, Path::new("mav0/imu0"), "--out")?.join("data.csv"),
        create_folder_within(out, Path::new("mav0/state_groundtruth_estimate0"), "--out")?
            .join("data.csv"),
    );
    check_outputs(
        &inputs,
        &[("--out", imu.as_path()), ("--out", truth.as_path())],
    )?;
    let description = sc.description(None);
    let outputs = StreamOutputs {
        imu: Some(&imu),
        truth: Some(&truth),
        description: &description,
        asl: true,
        ..StreamOutputs::default()
    };
    let report = sc.stream_to_files(None, run_threads, &outputs)?;
    for w in report.warnings(sc.sample_rate_hz) {
        crate::report::warn(&w);
    }
    crate::note!(
        "imukit: {} samples as a EuRoC sequence: readings in {}, ground truth in {}",
        sc.t_s.len(),
        imu.display(),
        truth.display()
    );
    Ok(())
}
