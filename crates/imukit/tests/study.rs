//! The outage study on the example road (`examples/study/tunnel.toml`): for each preset — the
//! MPU-6050 too, with the rest before the drive and the 36-state filter — the Monte Carlo RMS
//! horizontal error through the 30 s tunnel matches the filter's own one-sigma (its uncertainty
//! is honest) along the whole outage, runs give the same numbers in any order, and bad study
//! files are refused by key.
use std::path::{Path, PathBuf};

use imukit::run::study::{RunOutcome, Study, StudySpec};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn study(presets: &[&str], runs: u64) -> Study {
    study_smoothed(presets, runs, false)
}

fn study_smoothed(presets: &[&str], runs: u64, smooth: bool) -> Study {
    let spec = StudySpec {
        scenario: "car_tunnel.toml".into(),
        presets: presets.iter().map(|p| p.to_string()).collect(),
        runs,
        odometer: false,
        baro: false,
        nhc_sigma_m_s: None,
        sensor_errors: Some(true),
        rest_s: Some(20.0),
        smooth,
        draw_parts: true,
    };
    Study::new(&spec, &examples(), "test study").unwrap()
}

/// Every run of every preset of `s`, the presets on threads of their own.
fn run_on_threads(s: &Study, presets: usize, runs: u64) -> Vec<Vec<RunOutcome>> {
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..presets)
            .map(|c| scope.spawn(move || (0..runs).map(|r| s.run_one(c, r).unwrap()).collect()))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

#[test]
fn through_the_tunnel_the_rms_error_matches_the_filters_sigma_for_each_preset() {
    let presets = [
        "mpu-6050",
        "icm-42688-p",
        "adis16465-1",
        "stim300",
        "hg1700",
    ];
    let runs = 100;
    let s = study(&presets, runs);
    let outcomes = run_on_threads(&s, presets.len(), runs);
    let (table, summaries) = s.summarise(&outcomes).unwrap();
    let t = table.column("t_s").unwrap();
    // One row per IMU sample of the outage (100 Hz, 30 s, up to the first fix after it).
    assert_eq!(t.len(), 3000);
    assert!((t[2999] - 29.99).abs() < 1e-9);
    for m in &summaries {
        assert_eq!(m.completed, 100, "{m:?}");
        let (e, sigma) = (m.rms_error_m.unwrap(), m.sigma_m.unwrap());
        eprintln!("{}: {e:.3} m (σ {sigma:.3} m)", m.preset);
        // The error grows through the outage: at its end well above its start.
        let rms = table.column(&format!("{}_rms_error_m", m.preset)).unwrap();
        let sig = table.column(&format!("{}_sigma_m", m.preset)).unwrap();
        assert!(e > 2.0 * rms[0], "{}: {rms:?} → {e}", m.preset);
        // RMS over 100 runs of an error that lies mostly along one axis: relative standard
        // error up to 1/√(2·100) = 7 %; the bound, 25 %, at 10, 20 and 30 s.
        for i in [999, 1999, 2999] {
            assert!(
                (rms[i] / sig[i] - 1.0).abs() < 0.25,
                "{} at {} s: {} m vs σ {} m",
                m.preset,
                t[i],
                rms[i],
                sig[i]
            );
        }
    }
}

/// With `smooth`, the study reports the smoothed error beside the filter's: the same filtered
/// numbers, and a smoothed RMS through the tunnel well below the filter's at its end.
#[test]
fn a_smoothed_study_reports_both_side_by_side() {
    let (plain, smoothed) = (
        study(&["stim300"], 4),
        study_smoothed(&["stim300"], 4, true),
    );
    let outcomes = run_on_threads(&smoothed, 1, 4);
    let (table, summaries) = smoothed.summarise(&outcomes).unwrap();
    let (_, plain_summaries) = plain.summarise(&run_on_threads(&plain, 1, 4)).unwrap();
    let m = &summaries[0];
    assert_eq!(m.rms_error_m, plain_summaries[0].rms_error_m);
    let (end, worst) = m.smoothed_rms_error_m.unwrap();
    let filtered = m.rms_error_m.unwrap();
    assert!(worst < 0.5 * filtered && end <= worst, "{m:?}");
    assert!(table.column("stim300_smoothed_rms_error_m").is_some());
    assert!(plain_summaries[0].smoothed_rms_error_m.is_none());
}

#[test]
fn a_run_is_the_same_whichever_order_runs_are_computed_in() {
    let s = study(&["stim300"], 3);
    let forward: Vec<RunOutcome> = (0..3).map(|r| s.run_one(0, r).unwrap()).collect();
    let backward: Vec<RunOutcome> = (0..3).rev().map(|r| s.run_one(0, r).unwrap()).collect();
    assert_eq!(forward[0], backward[2]);
    assert_eq!(forward[2], backward[0]);
    assert_ne!(forward[0], forward[1]);
}

#[test]
fn bad_study_files_are_refused_by_key() {
    let dir = tempfile::Builder::new()
        .prefix("imukit-study-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let scenario = examples().join("car_tunnel.toml");
    let write = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let s = scenario.display();
    let cases = [
        (
            format!("scenario = \"{s}\"\npresets = []\nruns = 5\n"),
            "presets",
        ),
        (
            format!("scenario = \"{s}\"\npresets = [\"stim300\"]\nruns = 1\n"),
            "runs",
        ),
        (
            format!("scenario = \"{s}\"\npresets = [\"stim300\", \"stim300\"]\nruns = 5\n"),
            "presets[1]",
        ),
        (
            format!("scenario = \"{s}\"\npresets = [\"nosuch\"]\nruns = 5\n"),
            "presets[0]",
        ),
        (
            format!("scenario = \"{s}\"\npresets = [\"stim300\"]\nruns = 5\ncolour = 1\n"),
            "colour",
        ),
    ];
    for (k, (text, key)) in cases.iter().enumerate() {
        let e = Study::from_file(&write(&format!("s{k}.toml"), text.clone()))
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("s{k}.toml")) && e.contains(key), "{e}");
    }
    // A scenario without an outage.
    let no_outage = std::fs::read_to_string(&scenario)
        .unwrap()
        .replace("[[gnss.outages]]\nstart_s = 120.0\nduration_s = 30.0\n", "");
    let plain = write("plain.toml", no_outage);
    let e = Study::from_file(&write(
        "s_plain.toml",
        format!(
            "scenario = \"{}\"\npresets = [\"stim300\"]\nruns = 5\n",
            plain.display()
        ),
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("no [[gnss.outages]]"), "{e}");
}

#[test]
fn an_odometer_and_the_vehicle_constraints_shrink_the_drift_through_the_tunnel() {
    // The same road with a 10 Hz wheel odometer (σ 0.05 m/s) and the non-holonomic
    // constraints: the consumer part's error at the tunnel's end falls well below the GNSS-only
    // figure, and the filter still knows it (RMS within 25 % of its sigma).
    let run = |wheels: bool| {
        let spec = StudySpec {
            scenario: "car_tunnel.toml".into(),
            presets: vec!["icm-42688-p".into()],
            runs: 100,
            odometer: wheels,
            baro: false,
            nhc_sigma_m_s: wheels.then_some(0.05),
            sensor_errors: Some(true),
            rest_s: Some(20.0),
            smooth: false,
            draw_parts: true,
        };
        let s = Study::new(&spec, &examples(), "wheels study").unwrap();
        let (_, summaries) = s.summarise(&s.run_all().unwrap()).unwrap();
        let m = &summaries[0];
        (m.rms_error_m.unwrap(), m.sigma_m.unwrap())
    };
    let (gnss_only, _) = run(false);
    let (wheels, sigma) = run(true);
    eprintln!(
        "ICM-42688-P through the tunnel: GNSS only {gnss_only:.3} m, with wheels {wheels:.3} m (σ {sigma:.3} m)"
    );
    assert!(wheels < 0.5 * gnss_only, "{wheels} vs {gnss_only}");
    assert!((wheels / sigma - 1.0).abs() < 0.25, "{wheels} vs σ {sigma}");
}

#[test]
fn parts_not_described_alike_are_named_before_the_study_runs() {
    // The ICM-42688-P preset gives noise only; the STIM300 a turn-on bias, a drift and
    // scale-factor and misalignment errors, on both sensors: six terms, each named.
    let lines = study(&["stim300", "icm-42688-p"], 2).undescribed();
    assert_eq!(lines.len(), 6, "{lines:#?}");
    for (sensor, term) in [
        ("accelerometer", "turn-on bias"),
        ("gyroscope", "bias drift"),
        ("gyroscope", "scale-factor and misalignment errors"),
    ] {
        let line = format!("icm-42688-p: no {sensor} {term}");
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with(&line) && l.contains("(given by stim300")),
            "{line}: {lines:#?}"
        );
    }
    // Parts described alike (neither gives any of the terms): nothing to say.
    assert!(study(&["ideal", "icm-42688-p"], 2).undescribed().is_empty());
}

/// A study sets each preset's filter up as `imukit fuse` does with the same scenario and
/// options: the same request ([`StudySpec::request`]) through the same policy, also for what a
/// study file leaves out (the sensor-error states when the part warrants them, the rest found
/// in the readings).
#[test]
fn a_study_sets_the_filter_up_as_fuse_does() {
    use imukit::ScenarioSpec;
    use imukit::run::fuse::FuseRequest;
    use imukit::run::navigate::InitialState;
    let presets = ["mpu-6050", "stim300"];
    let spec = StudySpec {
        scenario: "car_tunnel.toml".into(),
        presets: presets.iter().map(|p| p.to_string()).collect(),
        runs: 2,
        odometer: false,
        baro: false,
        nhc_sigma_m_s: Some(0.05),
        sensor_errors: None,
        rest_s: None,
        smooth: false,
        draw_parts: true,
    };
    let s = Study::new(&spec, &examples(), "test study").unwrap();
    let initial = InitialState::default();
    let asked_of_fuse = FuseRequest {
        start: Some(imukit::run::fuse::Start::State(&initial)),
        nhc_sigma_m_s: Some(0.05),
        ..FuseRequest::default()
    };
    let mut seen = 0;
    for (preset, setup) in s.setups() {
        let mut scenario = ScenarioSpec::from_file(&examples().join("car_tunnel.toml")).unwrap();
        scenario.imu.preset = Some(preset.to_string());
        let scenario = scenario.resolve(&examples()).unwrap();
        let (fused, _) = asked_of_fuse.setup(&scenario).unwrap();
        assert_eq!(*setup, fused, "{preset}");
        assert!(
            setup.detect_rest,
            "{preset}: the rest is found, as fuse finds it"
        );
        seen += 1;
    }
    assert_eq!(seen, presets.len());
    // The consumer part's figures warrant the sensor-error states; the tactical part's do not.
    let full: Vec<bool> = s.setups().map(|(_, s)| s.estimate_sensor_errors).collect();
    assert_eq!(full, [true, false]);
}
