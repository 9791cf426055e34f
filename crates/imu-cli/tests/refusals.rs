//! Bad input to any command: a non-zero exit, a message naming what and where, no output left.
use crate::common::{imukit, run_in, table_text, temp_dir};

#[test]
fn bad_input_exits_non_zero_with_a_located_message_and_no_output_file() {
    let dir = temp_dir("bad");
    let dir = dir.path();
    let scenario = dir.join("bad.toml");
    std::fs::write(
        &scenario,
        "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"expression\"\nposition_m = [\"t\", \"0\", \"cos(2*pi*q*t)\"]\n",
    )
    .unwrap();
    let out_csv = dir.join("imu.csv");
    let out = imukit()
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&out_csv)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(65));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("position_m[2]")
            && err.contains("unknown variable 'q'")
            && err.contains("column 10"),
        "{err}"
    );
    assert!(!out_csv.exists());
    let missing = imukit()
        .args(["simulate", "/nonexistent/s.toml", "--out"])
        .arg(&out_csv)
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(74));
    assert!(
        String::from_utf8(missing.stderr)
            .unwrap()
            .contains("/nonexistent/s.toml")
    );
}

#[test]
fn integrate_refuses_bad_input_with_its_line() {
    let dir = temp_dir("integrate");
    let dir = dir.path();
    std::fs::write(dir.join("bad.dat"), "0 0 0 0\n0.1 0 0 0 9\n").unwrap();
    let out = imukit()
        .arg("integrate")
        .arg(dir.join("bad.dat"))
        .args(["--planar", "--out"])
        .arg(dir.join("n.csv"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(65));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("bad.dat") && err.contains("line 2") && err.contains("found 5"),
        "{err}"
    );
    std::fs::write(dir.join("rep.dat"), "0 0 0 0\n0.1 0 0 0\n0.1 0 0 0\n").unwrap();
    let out = imukit()
        .arg("integrate")
        .arg(dir.join("rep.dat"))
        .args(["--planar", "--out"])
        .arg(dir.join("n.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("sample 2") && err.contains("does not increase"),
        "{err}"
    );
    assert!(!dir.join("n.csv").exists());
    let out = imukit()
        .arg("integrate")
        .arg(dir.join("rep.dat"))
        .args(["--planar", "--scheme", "euler", "--out"])
        .arg(dir.join("n.csv"))
        .output()
        .unwrap();
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("unknown scheme \"euler\"")
    );
}

#[test]
fn orient_refuses_bad_input_by_name_and_row_and_leaves_no_output() {
    let dir = temp_dir("orient");
    let dir = dir.path();
    let header =
        "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s";
    let good = format!("{header}\n0.00,0,0,9.81,0,0,0\n0.01,0,0,9.81,0,0,0\n0.02,0,0,9.81,0,0,0\n");
    std::fs::write(dir.join("imu.csv"), &good).unwrap();
    let bad = good.replace("0.01,0,0,9.81,0,0,0", "0.01,0,0,9.81,0,NaN,0");
    std::fs::write(dir.join("nan.csv"), bad).unwrap();
    let out_file = dir.join("o.csv");
    let orient = |input: &str, args: &[&str]| {
        let out = imukit()
            .arg("orient")
            .arg(dir.join(input))
            .args(args)
            .arg("--out")
            .arg(&out_file)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8(out.stderr).unwrap())
    };
    for (input, args, needle) in [
        (
            "imu.csv",
            vec!["--filter", "kalman"],
            "invalid value 'kalman' for '--filter <FILTER>'\n  [possible values: robust, imufilter, ahrsfilter, ecompass, madgwick, mahony, complementary]",
        ),
        (
            "imu.csv",
            vec!["--param", "GyroNoise=1"],
            "GyroNoise: unknown setting for robust",
        ),
        (
            "imu.csv",
            vec!["--param", "GyroscopeNoise"],
            "is not key=value",
        ),
        (
            "imu.csv",
            vec!["--filter", "imufilter", "--param", "GyroscopeNoise=-2"],
            "GyroscopeNoise = -2: must be finite and > 0",
        ),
        ("imu.csv", vec!["--filter", "ahrsfilter"], "missing"),
        (
            "imu.csv",
            vec!["--conventions", "nasa"],
            "invalid value 'nasa' for '--conventions <CONVENTIONS>'\n  [possible values: imukit, matlab]",
        ),
        (
            "nan.csv",
            vec![],
            "nan.csv, row 3, column gyro_y_rad_s: not a finite number",
        ),
    ] {
        let (code, err) = orient(input, &args);
        let usage = needle.starts_with("invalid value");
        assert_eq!(code, Some(if usage { 2 } else { 65 }), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out_file.exists(), "{args:?}");
    }
    // +g on z is level in imukit's conventions (ENU, specific force: the default) and in
    // MATLAB's (NED, gravity minus acceleration), asked for at once or flag by flag.
    for args in [
        vec![],
        vec!["--conventions", "matlab"],
        vec!["--nav-frame", "NED", "--accel-sign", "matlab"],
    ] {
        let (code, err) = orient("imu.csv", &args);
        assert_eq!(code, Some(0), "{args:?}: {err}");
        let text = table_text(&out_file);
        assert_eq!(text.lines().count(), 4);
        // The default filter (robust) adds its bias estimate and flags.
        assert!(text.starts_with(
            "t_s,q_w,q_x,q_y,q_z,yaw_rad,pitch_rad,roll_rad,gyro_bias_x_rad_s,gyro_bias_y_rad_s,\
             gyro_bias_z_rad_s,at_rest,accel_rejected,mag_disturbed\n0.0,"
        ));
        let q: Vec<f64> = text
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .skip(1)
            .take(4)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(
            (q[0].abs() - 1.0).abs() < 1e-12 && q[1..].iter().all(|c| c.abs() < 1e-12),
            "{args:?}: {text}"
        );
    }
    // Down is up in the other frame: MATLAB's conventions on imukit's data turn it over.
    let (code, err) = orient(
        "imu.csv",
        &["--conventions", "matlab", "--accel-sign", "specific-force"],
    );
    assert_eq!(code, Some(0), "{err}");
    let text = table_text(&out_file);
    let roll: f64 = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(7)
        .unwrap()
        .parse()
        .unwrap();
    assert!((roll.abs() - std::f64::consts::PI).abs() < 1e-9, "{text}");
}

#[test]
fn a_duplicated_column_or_a_missing_position_is_refused_not_a_panic() {
    let dir = temp_dir("columns");
    let dir = dir.path();
    let dup = dir.join("dup.csv");
    std::fs::write(
        &dup,
        "t_s,gyro_x_rad_s,gyro_x_rad_s\n0,0.1,0.2\n0.01,0.1,0.2\n",
    )
    .unwrap();
    let out = imukit()
        .arg("allan")
        .arg(&dup)
        .arg("--out")
        .arg(dir.join("a.csv"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(65));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("column gyro_x_rad_s appears twice in the header (fields 2 and 3)"),
        "{err}"
    );
    assert!(!dir.join("a.csv").exists());
    // A truth table without pos_y_m: the trajectory panel cannot be drawn.
    let truth = dir.join("truth.csv");
    let columns: Vec<&str> = imukit::io::columns::TRUTH_COLUMNS
        .iter()
        .copied()
        .filter(|c| *c != "pos_y_m")
        .collect();
    let row = |t: &str| {
        let mut r = vec!["0"; columns.len()];
        r[0] = t;
        r[columns.iter().position(|c| *c == "q_w").unwrap()] = "1";
        r.join(",")
    };
    std::fs::write(
        &truth,
        format!("{}\n{}\n{}\n", columns.join(","), row("0"), row("0.1")),
    )
    .unwrap();
    let out = imukit()
        .arg("plot")
        .arg(&truth)
        .arg("--out")
        .arg(dir.join("t.png"))
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(65), "{err}");
    assert!(err.contains("no pos_y_m column"), "{err}");
    assert!(!dir.join("t.png").exists());
}

#[test]
fn an_allan_deviation_that_overflows_is_refused_and_nothing_is_written() {
    let dir = temp_dir("allan-overflow");
    let dir = dir.path();
    let mut text = String::from("t_s,gyro_x_rad_s\n");
    for k in 0..200 {
        let v = if k == 5 { "1e200" } else { "0.001" };
        text += &format!("{},{v}\n", f64::from(k) * 0.01);
    }
    std::fs::write(dir.join("imu.csv"), text).unwrap();
    let (code, err) = run_in(
        dir,
        &["allan", "imu.csv", "--out", "a.csv", "--plot", "a.png"],
    );
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("imu.csv, column gyro_x_rad_s: the Allan deviation at τ = 0.01 s overflows (values up to 1e200)"),
        "{err}"
    );
    assert!(!dir.join("a.csv").exists() && !dir.join("a.png").exists());
}

#[test]
fn compare_refuses_truth_times_that_repeat_or_go_back_anywhere_in_the_file() {
    let dir = temp_dir("compare-times");
    let dir = dir.path();
    let header = "t_s,pos_x_m,pos_y_m,pos_z_m,vel_x_m_s,vel_y_m_s,vel_z_m_s,q_w,q_x,q_y,q_z\n";
    let rows = |times: &[&str]| {
        let mut s = header.to_string();
        for t in times {
            s += &format!("{t},0,0,0,0,0,0,1,0,0,0\n");
        }
        s
    };
    std::fs::write(dir.join("zero.csv"), rows(&["0", "0", "0"])).unwrap();
    std::fs::write(dir.join("back.csv"), rows(&["0", "2", "1"])).unwrap();
    std::fs::write(dir.join("est.csv"), rows(&["0", "0.5", "1"])).unwrap();
    let (code, err) = run_in(dir, &["compare", "zero.csv", "zero.csv"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("zero.csv, row 3: truth time 0 s does not increase (previous 0 s)"),
        "{err}"
    );
    // The bad row lies past every estimate time: it is found all the same.
    let (code, err) = run_in(dir, &["compare", "back.csv", "est.csv", "--out", "e.csv"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("back.csv, row 4: truth time 1 s does not increase (previous 2 s)"),
        "{err}"
    );
    assert!(!dir.join("e.csv").exists());
}

#[test]
fn samples_whose_times_go_back_are_named_by_row_not_by_a_sample_rate() {
    let dir = temp_dir("samples-back");
    let dir = dir.path();
    let mut csv = String::from("t_s,pos_x_m,pos_y_m,pos_z_m\n");
    for (k, t) in [0.0, 0.2, 0.1, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]
        .iter()
        .enumerate()
    {
        csv += &format!("{t},{k},0,0\n");
    }
    std::fs::write(dir.join("dec.csv"), csv).unwrap();
    std::fs::write(
        dir.join("dec.toml"),
        "[trajectory]\ntype = \"samples\"\nfile = \"dec.csv\"\nattitude = \"tangent\"\n",
    )
    .unwrap();
    let (code, err) = run_in(dir, &["simulate", "dec.toml", "--out", "o.csv"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains(
            "dec.csv, row 4: time at sample 2 (0.1 s) does not increase after sample 1 (0.2 s)"
        ),
        "{err}"
    );
    assert!(!err.contains("sample_rate_hz"), "{err}");
}

#[test]
fn a_filter_that_may_use_a_magnetometer_names_a_missing_mag_column() {
    let dir = temp_dir("orient-mag");
    let dir = dir.path();
    let header = "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,mag_x_ut,mag_y_ut";
    let mut text = format!("{header}\n");
    for k in 0..10 {
        text += &format!("{},0,0,9.81,0,0,0,27,0\n", f64::from(k) * 0.01);
    }
    std::fs::write(dir.join("imu.csv"), text).unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "orient",
            "imu.csv",
            "--filter",
            "complementary",
            "--out",
            "o.csv",
        ],
    );
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("missing column(s) mag_z_ut"), "{err}");
    assert!(!dir.join("o.csv").exists());
}

#[test]
fn a_matlab_parameter_file_with_unknown_keys_is_read_with_warnings() {
    let dir = temp_dir("matlab-vendor");
    let dir = dir.path();
    std::fs::write(
        dir.join("p.json"),
        r#"{"Part": {"Vendor": "ACME", "Gyroscope": {"NoiseDensity": 0.001, "Colour": "blue"}}}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n[imu]\nparams = \"p.json\"\n",
    )
    .unwrap();
    let (code, err) = run_in(dir, &["simulate", "s.toml", "--out", "o.csv"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: ") && err.contains("Part: Vendor: not a sensor, skipped"),
        "{err}"
    );
    assert!(
        err.contains("Gyroscope.Colour: unknown property, skipped"),
        "{err}"
    );
    assert!(dir.join("o.csv").exists());
}

#[test]
fn a_bad_start_is_blamed_on_where_it_came_from_not_on_the_imu_file() {
    let dir = temp_dir("bad-start");
    let dir = dir.path();
    let scenario =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/expression.toml");
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            scenario.to_str().unwrap(),
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(
        dir,
        &[
            "integrate",
            "imu.csv",
            "--euler0-rad",
            "nan",
            "0",
            "0",
            "--out",
            "n.csv",
        ],
    );
    assert_eq!(code, Some(65));
    assert!(
        err.contains("--euler0-rad: must be finite, got [NaN, 0.0, 0.0]"),
        "{err}"
    );
    // A zero quaternion in the --init file's first row.
    let truth = table_text(dir.join("truth.csv"));
    let mut lines: Vec<String> = truth.lines().map(str::to_string).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let q: Vec<usize> = ["q_w", "q_x", "q_y", "q_z"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    let mut first: Vec<String> = lines[1].split(',').map(str::to_string).collect();
    for i in q {
        first[i] = "0".into();
    }
    lines[1] = first.join(",");
    std::fs::write(dir.join("zero_q.csv"), lines.join("\n") + "\n").unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "integrate",
            "imu.csv",
            "--init",
            "zero_q.csv",
            "--out",
            "n.csv",
        ],
    );
    assert_eq!(code, Some(65));
    assert!(
        err.contains("zero_q.csv, row 2: the initial quaternion has zero norm"),
        "{err}"
    );
    assert!(!err.contains("imu.csv"), "{err}");
    assert!(!dir.join("n.csv").exists());
}

/// A bag's topic, frame id and start stamp are options of a bag output only, checked by name.
#[test]
fn bag_options_apply_to_a_bag_and_are_checked() {
    let dir = temp_dir("bag-options");
    let dir = dir.path();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 100.0\nduration_s = 1.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "run.mcap",
            "--bag-topic",
            "/sensors/imu",
            "--bag-frame-id",
            "imu",
            "--bag-start-s",
            "1700000000",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(
        dir,
        &[
            "integrate",
            "run.mcap",
            "--topic",
            "/sensors/imu",
            "--out",
            "nav.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    for (args, needle) in [
        (
            &["--out", "run.csv", "--bag-topic", "/x"][..],
            "--bag-topic: applies to a ROS 2 bag",
        ),
        (
            &["--out", "b.mcap", "--bag-topic", "imu"][..],
            "--bag-topic: \"imu\" is not a ROS 2 topic name",
        ),
        (
            &["--out", "b.mcap", "--bag-frame-id", "my frame"][..],
            "--bag-frame-id:",
        ),
        (
            &["--out", "b.mcap", "--bag-start-s", "-5"][..],
            "--bag-start-s: -5 is not a ROS time stamp",
        ),
    ] {
        let mut all = vec!["simulate", "s.toml"];
        all.extend_from_slice(args);
        let (code, err) = run_in(dir, &all);
        assert_eq!(code, Some(65), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!dir.join("run.csv").exists() && !dir.join("b.mcap").exists());
    }
}

/// The Allan deviation takes samples as evenly spaced: times that go back are refused by row,
/// and a gap is said (for `identify` too, which reads the log the same way).
#[test]
fn allan_refuses_times_that_go_back_and_warns_of_gaps() {
    let dir = temp_dir("allan-times");
    let dir = dir.path();
    let mut text = String::from("t_s,gyro_x_rad_s\n");
    for k in (0..3000).filter(|k| !(1000..1500).contains(k)) {
        let noise = ((k * 7919) % 1000) as f64 * 1e-6 - 5e-4;
        text += &format!("{},{noise}\n", f64::from(k) * 0.01);
    }
    std::fs::write(dir.join("gap.csv"), text).unwrap();
    for command in ["allan", "identify"] {
        let (code, err) = run_in(dir, &[command, "gap.csv", "--out", "a.csv"]);
        assert_eq!(code, Some(0), "{command}: {err}");
        assert!(
            err.contains("gap.csv: 1 interval(s) longer than 2.5 median intervals")
                && err.contains("after row 1001"),
            "{command}: {err}"
        );
    }
    std::fs::write(
        dir.join("back.csv"),
        "t_s,gyro_x_rad_s\n0,0\n0.01,0\n0.005,0\n0.02,0\n",
    )
    .unwrap();
    let (code, err) = run_in(dir, &["allan", "back.csv", "--out", "b.csv"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("back.csv: time at row 4 does not increase"),
        "{err}"
    );
    assert!(!dir.join("b.csv").exists());
}
