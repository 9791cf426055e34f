//! Simulate → integrate → compare, through the tables the CLI and Python use.
use std::path::Path;

use imu_core::AccelSign;
use imukit::ScenarioSpec;
use imukit::io::conventions::NavFrameName;
use imukit::run::compare::compare;
use imukit::run::navigate::{InitialState, NavSetup, integrate};

fn scenario(extra_imu: &str, frame: &str) -> imukit::Simulation {
    let text = format!(
        "rate_hz = 400.0\nduration_s = 10.0\nnav_frame = \"{frame}\"\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"5*cos(0.5*t)\", \"5*sin(0.5*t)\", \"0.3*t\"]\n\
         yaw_rad = \"0.5*t + pi/2\"\npitch_rad = \"0.05\"\nroll_rad = \"0.4*sin(1.7*t)\"\n[imu]\n{extra_imu}"
    );
    ScenarioSpec::from_toml(&text, "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap()
}

#[test]
fn rates_and_increments_round_trip_in_both_frames_and_signs() {
    for frame in ["ENU", "NED"] {
        let sim = scenario("", frame);
        let init = InitialState::from_table(&sim.truth).unwrap();
        let setup = NavSetup {
            nav_frame: if frame == "ENU" {
                NavFrameName::ENU
            } else {
                NavFrameName::NED
            },
            ..NavSetup::default()
        };
        let nav = integrate(&sim.imu, &init, &setup).unwrap();
        let c = compare(&sim.truth, &nav).unwrap();
        assert!(
            c.summary.position.unwrap().last() < 1e-3
                && c.summary.attitude.expect("compared").last() < 1e-5,
            "{frame}: {c:?}"
        );
        // MATLAB's sign, flipped back, gives the same numbers.
        let matlab = scenario("accel_sign = \"matlab\"\n", frame);
        let nav_m = integrate(
            &matlab.imu,
            &init,
            &NavSetup {
                accel_sign: AccelSign::Matlab,
                ..setup
            },
        )
        .unwrap();
        assert_eq!(nav_m, nav);
        // Increments (trapezoid of the same readings) give the same trajectory to rounding.
        let inc = scenario("output = \"increments\"\n", frame);
        let nav_i = integrate(&inc.imu, &init, &setup).unwrap();
        let d = compare(&nav, &nav_i).unwrap();
        assert!(d.summary.position.unwrap().last() < 1e-9, "{d:?}");
    }
}

#[test]
fn compare_reports_zero_against_itself_and_refuses_times_outside_the_truth() {
    let sim = scenario("", "ENU");
    let c = compare(&sim.truth, &sim.truth).unwrap();
    assert_eq!(
        (
            c.summary.position.unwrap().rms(),
            c.summary.velocity.unwrap().last()
        ),
        (0.0, 0.0)
    );
    assert!(c.summary.attitude.expect("compared").rms() < 1e-7);
    let mut shifted = sim.truth.clone();
    let w = shifted.columns.len();
    for r in 0..shifted.rows() {
        shifted.data[r * w] += 20.0;
    }
    let e = compare(&sim.truth, &shifted).unwrap_err().to_string();
    assert!(e.contains("(row 2) is after the truth's last, 10 s"), "{e}");
    let e = integrate(
        &imukit::Table::new(&["t_s", "accel_x_m_s2"]),
        &InitialState::default(),
        &NavSetup::default(),
    );
    assert!(
        e.unwrap_err()
            .to_string()
            .contains("dtheta_x/y/z_rad (increments)")
    );
}

#[test]
fn rk4_recovers_the_figure8_to_a_micrometre_after_60_s_at_1_khz() {
    use imukit::run::navigate::NavScheme;
    let mut spec = imukit::scenario::builtin::spec("figure8").unwrap();
    spec.rate_hz = Some(1000.0);
    spec.duration_s = Some(60.0);
    spec.imu.lever_arm_m = Some([0.0; 3]); // the reference point is what the strapdown tracks
    let sim = spec.resolve(Path::new(".")).unwrap().simulate().unwrap();
    let init = InitialState::from_table(&sim.truth).unwrap();
    let rk4 = NavSetup {
        scheme: NavScheme::Rk4 { substeps: 4 },
        ..NavSetup::default()
    };
    let c = compare(&sim.truth, &integrate(&sim.imu, &init, &rk4).unwrap()).unwrap();
    let coning = compare(
        &sim.truth,
        &integrate(&sim.imu, &init, &NavSetup::default()).unwrap(),
    )
    .unwrap();
    eprintln!(
        "figure-8, 60 s at 1 kHz: final position error {:e} m (rk4), {:e} m (coning/sculling)",
        c.summary.position.unwrap().last(),
        coning.summary.position.unwrap().last()
    );
    let max = c
        .table
        .column("pos_err_m")
        .unwrap()
        .into_iter()
        .fold(0.0, f64::max);
    assert!(max <= 1e-6, "{max}");
    assert!(coning.summary.position.unwrap().last() > 1e-2);
    // rk4 takes rates only.
    let inc = scenario("output = \"increments\"\n", "ENU");
    let e = integrate(
        &inc.imu,
        &InitialState::from_table(&inc.truth).unwrap(),
        &rk4,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("needs rates"), "{e}");
}

#[test]
fn gaps_are_integrated_across_and_reported_and_disorder_is_named() {
    let sim = scenario("", "ENU");
    let init = InitialState::from_table(&sim.truth).unwrap();
    // Drop samples 100..110: a gap between rows 101 and 102 of the file (header is row 1).
    let w = sim.imu.columns.len();
    let mut gappy = imukit::Table::new(
        &sim.imu
            .columns
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    for r in (0..sim.imu.rows()).filter(|r| !(100..110).contains(r)) {
        gappy.push_row(&sim.imu.data[r * w..(r + 1) * w]);
    }
    let nav = integrate(&gappy, &init, &NavSetup::default()).unwrap();
    assert_eq!(nav.rows(), gappy.rows());
    let t = gappy.column("t_s").unwrap();
    let gaps = imukit::io::rows::Gaps::of_times(&t, 2);
    assert_eq!((gaps.count, gaps.longest_after_row), (1, 101));
    assert!(
        (gaps.longest_s - 11.0 * gaps.median_s).abs() < 1e-9,
        "{gaps:?}"
    );
    let m = gaps.message("imu.csv").unwrap();
    assert!(
        m.starts_with("imu.csv: 1 gap longer than 2.5 median intervals") && m.contains("row 101"),
        "{m}"
    );
    assert_eq!(
        imukit::io::rows::Gaps::of_times(&sim.imu.column("t_s").unwrap(), 2).message("x"),
        None
    );
    let mut swapped = sim.imu.clone();
    swapped.data[5 * w] = swapped.data[4 * w];
    let e = integrate(&swapped, &init, &NavSetup::default())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("row 7 does not increase"), "{e}");
}

#[test]
fn a_streamed_file_integrates_to_the_numbers_of_the_whole_table() {
    use imukit::io::rows::GAP_WINDOW;
    use imukit::run::navigate::{NavScheme, integrate_csv};
    let dir = tempfile::Builder::new()
        .prefix("imukit-nav-stream-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    // 4001 rows: the gap check's look-ahead window and the rest.
    let rk4 = NavScheme::Rk4 { substeps: 2 };
    for (extra, frame, sign, scheme) in [
        (
            "",
            "ENU",
            AccelSign::SpecificForce,
            NavScheme::ConingSculling,
        ),
        (
            "output = \"increments\"\n",
            "NED",
            AccelSign::SpecificForce,
            NavScheme::ConingSculling,
        ),
        (
            "accel_sign = \"matlab\"\n",
            "ENU",
            AccelSign::Matlab,
            NavScheme::ConingSculling,
        ),
        ("", "NED", AccelSign::SpecificForce, rk4),
        ("accel_sign = \"matlab\"\n", "ENU", AccelSign::Matlab, rk4),
    ] {
        let sim = scenario(extra, frame);
        assert!(sim.imu.rows() > 2 * GAP_WINDOW);
        let init = InitialState::from_table(&sim.truth).unwrap();
        let setup = NavSetup {
            nav_frame: if frame == "ENU" {
                NavFrameName::ENU
            } else {
                NavFrameName::NED
            },
            accel_sign: sign,
            scheme,
            ..NavSetup::default()
        };
        let (input, out) = (dir.join("imu.csv"), dir.join("nav.csv"));
        sim.imu.write_csv(&input).unwrap();
        let summary = integrate_csv(&input, &init, &setup, Default::default(), &out).unwrap();
        let whole = integrate(&sim.imu, &init, &setup).unwrap();
        let streamed = imukit::io::read::read_table(&out).unwrap();
        assert_eq!(summary.rows, whole.rows());
        assert!(
            streamed == whole,
            "{extra} {frame} {scheme:?}: streamed output differs"
        );
    }
    // RK4 on files of 6 to 12 rows (the windows at both ends overlap) and on too few rows.
    let sim = scenario("", "ENU");
    let init = InitialState::from_table(&sim.truth).unwrap();
    let setup = NavSetup {
        scheme: rk4,
        ..NavSetup::default()
    };
    for rows in (5..=12).chain([GAP_WINDOW + 7]) {
        let mut short = sim.imu.clone();
        short.data.truncate(rows * short.columns.len());
        let (input, out) = (dir.join("short.csv"), dir.join("short_nav.csv"));
        short.write_csv(&input).unwrap();
        match (
            integrate_csv(&input, &init, &setup, Default::default(), &out),
            integrate(&short, &init, &setup),
        ) {
            (Ok(summary), Ok(whole)) => {
                assert_eq!(summary.rows, rows);
                assert!(
                    imukit::io::read::read_table(&out).unwrap() == whole,
                    "{rows} rows"
                );
            }
            (Err(e), Err(_)) => {
                assert_eq!(rows, 5);
                assert!(e.to_string().contains("at least 6 samples, got 5"), "{e}");
                assert!(!out.exists());
            }
            (a, b) => panic!(
                "{rows} rows: streamed {:?}, whole {:?}",
                a.is_ok(),
                b.is_ok()
            ),
        }
    }
    // A gap after the look-ahead window is integrated across and reported by its row; the
    // streamed file gives the whole table's numbers.
    let sim = scenario("", "ENU");
    let mut gappy = sim.imu.clone();
    let w = gappy.columns.len();
    for r in 3000..gappy.rows() {
        gappy.data[r * w] += 0.1;
    }
    let (input, out) = (dir.join("gappy.csv"), dir.join("gappy_nav.csv"));
    gappy.write_csv(&input).unwrap();
    let summary = integrate_csv(
        &input,
        &InitialState::default(),
        &NavSetup::default(),
        Default::default(),
        &out,
    )
    .unwrap();
    assert_eq!(
        (summary.gaps.count, summary.gaps.longest_after_row),
        (1, 3001)
    );
    let whole = integrate(&gappy, &InitialState::default(), &NavSetup::default()).unwrap();
    assert!(imukit::io::read::read_table(&out).unwrap() == whole);
    let _ = std::fs::remove_dir_all(dir);
}

/// A state table on `times` with position `[t, 2t, 0] + offset`, velocity `[1, 2, 0]` and a yaw
/// of `0.1 t` (the quaternion interpolates exactly by slerp).
fn linear_states(times: &[f64], offset: [f64; 3]) -> imukit::Table {
    let mut t = imukit::Table::new(imukit::io::columns::STATE_COLUMNS);
    for &s in times {
        let h = 0.05 * s;
        t.push_row(&[
            s,
            s + offset[0],
            2.0 * s + offset[1],
            offset[2],
            1.0,
            2.0,
            0.0,
            h.cos(),
            0.0,
            0.0,
            h.sin(),
        ]);
    }
    t
}

#[test]
fn compare_brackets_each_estimate_time_and_streams_files_to_the_same_numbers() {
    use imukit::run::compare::compare_csv;
    let dir = tempfile::Builder::new()
        .prefix("imukit-compare-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let truth_times: Vec<f64> = (0..200)
        .map(|k| 0.1 * k as f64 + 0.001 * (k % 3) as f64)
        .collect();
    let last = *truth_times.last().unwrap();
    // Times on, between, repeated and at the very end of the truth's samples.
    let mut est_times: Vec<f64> = (0..150).map(|k| 0.13 * k as f64).collect();
    est_times.extend([0.13 * 149.0, last - 1e-3, last, last + 5e-10]);
    let truth = linear_states(&truth_times, [0.0; 3]);
    let estimate = linear_states(&est_times, [0.3, -0.4, 0.0]);
    let c = compare(&truth, &estimate).unwrap();
    assert_eq!(c.summary.rows(), est_times.len());
    for r in 0..c.table.rows() {
        let row = &c.table.data[r * 9..(r + 1) * 9];
        // (The last estimate lies 5e-10 s past the truth, which is held there: 1.2e-9 m.)
        assert!(
            (row[4] - 0.5).abs() < 2e-9,
            "row {r}: position error {}",
            row[4]
        );
        assert!(row[8].abs() < 1e-7, "row {r}: attitude error {}", row[8]);
    }
    assert!((c.summary.position.unwrap().rms() - 0.5).abs() < 1e-10);
    // The same through files, streamed.
    let (tp, ep, out) = (dir.join("t.csv"), dir.join("e.csv"), dir.join("err.csv"));
    truth.write_csv(&tp).unwrap();
    estimate.write_csv(&ep).unwrap();
    let s = compare_csv(&tp, &ep, Some(&out)).unwrap();
    assert_eq!(s, c.summary);
    assert!(imukit::io::read::read_table(&out).unwrap() == c.table);
    // A single-row truth compares only at its own time.
    let one = linear_states(&[1.0], [0.0; 3]);
    assert_eq!(
        compare(&one, &linear_states(&[1.0], [0.0; 3]))
            .unwrap()
            .summary
            .position
            .unwrap()
            .last(),
        0.0
    );
    // Refusals, and no output file left.
    std::fs::remove_file(&out).unwrap();
    for (times, needle) in [
        (vec![0.5, 0.4], "row 3) goes back"),
        (vec![-0.1], "(row 2) is before the truth's first, 0 s"),
        (
            vec![1.0, last + 0.01],
            "(row 3) is after the truth's last, 19.9",
        ),
    ] {
        linear_states(&times, [0.0; 3]).write_csv(&ep).unwrap();
        let e = compare_csv(&tp, &ep, Some(&out)).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_default_scheme_is_the_best_for_rate_samples_on_a_coning_motion() {
    use imu_core::{Body, Enu, Rotation, Vec3};
    use imukit::run::navigate::{NavRequest, NavScheme, SchemeName};
    // Classic coning (docs/models.md §4): a 5° cone at 2 Hz, 200 Hz rate samples, 30 s, at rest.
    let (a, w) = (5f64.to_radians(), 2.0 * std::f64::consts::TAU);
    let attitude = |t: f64| {
        let (s, c) = (a / 2.0).sin_cos();
        Rotation::<Body, Enu>::from_wxyz([c, 0.0, s * (w * t).cos(), s * (w * t).sin()]).unwrap()
    };
    let mut imu = imukit::Table::new(&[
        "t_s",
        "accel_x_m_s2",
        "accel_y_m_s2",
        "accel_z_m_s2",
        "gyro_x_rad_s",
        "gyro_y_rad_s",
        "gyro_z_rad_s",
    ]);
    for k in 0..=6000 {
        let t = f64::from(k) / 200.0;
        let f = attitude(t)
            .inverse()
            .apply(Vec3::new(0.0, 0.0, 9.81))
            .to_array();
        let omega = [
            -2.0 * w * (a / 2.0).sin().powi(2),
            -w * a.sin() * (w * t).sin(),
            w * a.sin() * (w * t).cos(),
        ];
        imu.push_row(&[t, f[0], f[1], f[2], omega[0], omega[1], omega[2]]);
    }
    let initial = InitialState {
        quaternion: attitude(0.0).to_wxyz(),
        ..InitialState::default()
    };
    let end = |scheme: SchemeName| {
        let setup = NavRequest {
            scheme,
            gravity_m_s2: 9.81,
            ..NavRequest::default()
        }
        .setup()
        .unwrap();
        let nav = integrate(&imu, &initial, &setup).unwrap();
        let last = |c: &str| *nav.column(c).unwrap().last().unwrap();
        (
            last("pos_x_m")
                .hypot(last("pos_y_m"))
                .hypot(last("pos_z_m")),
            setup.scheme,
        )
    };
    let (auto, scheme) = end(SchemeName::Auto);
    let (coning, _) = end(SchemeName::Coning);
    eprintln!("coning motion, 30 s: {auto:e} m (auto), {coning:e} m (coning)");
    assert_eq!(scheme.for_input(true, true), NavScheme::Rk4 { substeps: 4 });
    assert!(auto < 1e-5, "{auto}");
    assert!(coning > 0.1, "{coning}");
}
