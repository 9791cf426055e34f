//! The `imukit` binary as a user runs it.
use std::process::Command;

fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-cli-{name}-"))
        .tempdir()
        .unwrap()
}

/// A CSV table's text after its description line (`# imukit: {…}`, which must be there).
fn table_text(path: impl AsRef<std::path::Path>) -> String {
    let text = std::fs::read_to_string(path.as_ref()).unwrap();
    let (first, rest) = text.split_once('\n').unwrap();
    assert!(first.starts_with("# imukit: {\"kind\": "), "{first}");
    rest.to_string()
}

#[test]
fn demo_writes_its_outputs_and_says_where() {
    let dir = temp_dir("demo");
    let dir = dir.path();
    let out = imukit()
        .args(["demo", "--out-dir"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains(&dir.display().to_string()), "{stdout}");
    for f in [
        "scenario.toml",
        "truth.csv",
        "imu.csv",
        "summary.txt",
        "truth.png",
        "imu.png",
        "animation.html",
    ] {
        assert!(dir.join(f).metadata().unwrap().len() > 0, "{f}");
    }
    let imu = table_text(dir.join("imu.csv"));
    assert_eq!(imu.lines().count(), 2002); // header + 2001 samples at 2 kHz over 1 s
}

#[test]
fn every_builtin_printed_as_toml_simulates_to_the_same_numbers() {
    let dir = temp_dir("roundtrip");
    let dir = dir.path();
    let list = imukit().arg("scenario").output().unwrap();
    let names = String::from_utf8(list.stdout).unwrap();
    assert_eq!(
        names.lines().count(),
        imukit::scenario::builtin::NAMES.len()
    );
    for name in names.lines() {
        let toml = imukit().args(["scenario", name]).output().unwrap();
        assert!(toml.status.success());
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, toml.stdout).unwrap();
        let out = dir.join(format!("{name}.csv"));
        let status = imukit()
            .arg("simulate")
            .arg(&path)
            .arg("--out")
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "{name}");
        let direct = imukit::scenario::builtin::spec(name)
            .unwrap()
            .resolve(dir)
            .unwrap()
            .simulate()
            .unwrap();
        let reread =
            imukit::io::read::read_columns(&out, &["accel_x_m_s2", "gyro_z_rad_s"], "").unwrap();
        assert_eq!(
            reread.get("accel_x_m_s2"),
            direct.imu.column("accel_x_m_s2").unwrap().as_slice(),
            "{name}"
        );
        assert_eq!(
            reread.get("gyro_z_rad_s"),
            direct.imu.column("gyro_z_rad_s").unwrap().as_slice(),
            "{name}"
        );
    }
}

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
fn exercise_writes_the_datasets_trajectories_and_figure() {
    let dir = temp_dir("exercise");
    let dir = dir.path();
    let out = imukit()
        .args(["exercise", "--out-dir"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "inertial_data.dat",
        "inertial_data_errors.dat",
        "truth.csv",
        "inertial_data_exercise.csv",
        "inertial_data_trapezoid.csv",
        "inertial_data_errors_exercise.csv",
        "inertial_data_errors_trapezoid.csv",
        "summary.txt",
    ] {
        assert!(dir.join(f).metadata().unwrap().len() > 0, "{f}");
    }
    let svg = std::fs::read_to_string(dir.join("trajectories.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.matches("<polyline").count() >= 5, "five trajectories");
    // The clean data through the default scheme closes the lap near the start.
    let nav = imukit::io::read::read_columns(
        dir.join("inertial_data_trapezoid.csv"),
        &["pos_x_m", "pos_y_m"],
        "",
    )
    .unwrap();
    let (x, y) = (nav.get("pos_x_m"), nav.get("pos_y_m"));
    assert!((x[x.len() - 1] - 100.0).hypot(y[y.len() - 1] - 100.0) < 0.5);
    // The same file through `imukit integrate` gives the same trajectory.
    let again = dir.join("again.csv");
    let status = imukit()
        .arg("integrate")
        .arg(dir.join("inertial_data.dat"))
        .args(["--planar", "--scheme", "trapezoid", "--out"])
        .arg(&again)
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(dir.join("inertial_data_trapezoid.csv")).unwrap()
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
fn simulate_integrate_compare_closes_the_loop() {
    let dir = temp_dir("loop");
    let dir = dir.path();
    std::fs::write(
        dir.join("helix.toml"),
        "rate_hz = 400.0\nduration_s = 10.0\nnav_frame = \"NED\"\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"5*cos(0.5*t)\", \"5*sin(0.5*t)\", \"-0.3*t\"]\nyaw_rad = \"0.5*t + pi/2\"\n\
         pitch_rad = \"0.05\"\nroll_rad = \"0.4*sin(1.7*t)\"\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        let out = imukit().current_dir(dir).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    run(&[
        "simulate",
        "helix.toml",
        "--out",
        "imu.csv",
        "--truth",
        "truth.csv",
    ]);
    run(&[
        "integrate",
        "imu.csv",
        "--init",
        "truth.csv",
        "--nav-frame",
        "NED",
        "--out",
        "nav.csv",
    ]);
    let report = run(&["compare", "truth.csv", "nav.csv", "--out", "err.csv"]);
    assert!(
        report.contains("position") && report.contains("attitude"),
        "{report}"
    );
    let err =
        imukit::io::read::read_columns(dir.join("err.csv"), &["pos_err_m", "att_err_rad"], "")
            .unwrap();
    let last = |c: &str| *err.get(c).last().unwrap();
    assert!(
        last("pos_err_m") < 1e-3 && last("att_err_rad") < 1e-5,
        "{} {}",
        last("pos_err_m"),
        last("att_err_rad")
    );
    // The fourth-order scheme closes the loop far tighter.
    run(&[
        "integrate",
        "imu.csv",
        "--init",
        "truth.csv",
        "--nav-frame",
        "NED",
        "--scheme",
        "rk4",
        "--out",
        "nav4.csv",
    ]);
    run(&["compare", "truth.csv", "nav4.csv", "--out", "err4.csv"]);
    let err4 = imukit::io::read::read_columns(dir.join("err4.csv"), &["pos_err_m"], "").unwrap();
    assert!(*err4.get("pos_err_m").last().unwrap() < 1e-6);
    // The files say what they hold (NED, flat Earth, gravity, sign), so no flag is needed: the
    // same numbers as with the flag, from CSV and from Parquet alike.
    let readings = std::fs::read_to_string(dir.join("imu.csv")).unwrap();
    let description = readings.lines().next().unwrap();
    for entry in [
        "# imukit: {\"kind\": \"readings\"",
        "\"nav_frame\": \"NED\", \"body_frame\": \"FRD\", \"earth\": \"flat\"",
        "\"gravity_m_s2\": 9.81",
        "\"scenario\": \"rate_hz = 400.0",
    ] {
        assert!(description.contains(entry), "{entry}: {description}");
    }
    run(&[
        "integrate",
        "imu.csv",
        "--init",
        "truth.csv",
        "--out",
        "plain.csv",
    ]);
    let nav_text = std::fs::read_to_string(dir.join("nav.csv")).unwrap();
    assert_eq!(
        std::fs::read_to_string(dir.join("plain.csv")).unwrap(),
        nav_text
    );
    assert!(nav_text.starts_with(
        "# imukit: {\"kind\": \"navigation\", \"nav_frame\": \"NED\", \"body_frame\": \"FRD\", \"earth\": \"flat\""
    ));
    run(&[
        "simulate",
        "helix.toml",
        "--out",
        "imu.parquet",
        "--truth",
        "truth.parquet",
    ]);
    run(&[
        "integrate",
        "imu.parquet",
        "--init",
        "truth.parquet",
        "--out",
        "parquet.csv",
    ]);
    assert_eq!(
        std::fs::read_to_string(dir.join("parquet.csv")).unwrap(),
        nav_text
    );
    // A flag that contradicts the files is refused by name, naming the file and both frames,
    // and nothing is written; so are inputs that disagree.
    for (args, needles) in [
        (
            vec!["imu.csv", "--init", "truth.csv", "--nav-frame", "ENU"],
            vec!["--nav-frame: ENU contradicts imu.csv", "says NED"],
        ),
        (
            vec!["imu.parquet", "--earth", "wgs84"],
            vec!["--earth: wgs84 contradicts imu.parquet", "says flat"],
        ),
        (
            vec!["imu.csv", "--gravity-m-s2", "9.80665"],
            vec!["--gravity-m-s2: 9.80665 contradicts imu.csv", "says 9.81"],
        ),
    ] {
        let out = imukit()
            .current_dir(dir)
            .arg("integrate")
            .args(&args)
            .args(["--out", "wrong.csv"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(65), "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: {err}");
        }
        assert!(!dir.join("wrong.csv").exists());
    }
    let enu = readings.replace(
        "\"nav_frame\": \"NED\", \"body_frame\": \"FRD\"",
        "\"nav_frame\": \"ENU\", \"body_frame\": \"FLU\"",
    );
    std::fs::write(dir.join("enu.csv"), enu).unwrap();
    let out = imukit()
        .current_dir(dir)
        .args([
            "integrate",
            "enu.csv",
            "--init",
            "truth.csv",
            "--out",
            "wrong.csv",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(65), "{err}");
    assert!(
        err.contains("the inputs disagree: enu.csv says ENU, truth.csv says NED"),
        "{err}"
    );
    // Missing columns are named.
    std::fs::write(dir.join("few.csv"), "t_s,accel_x_m_s2\n0,0\n0.1,0\n").unwrap();
    let out = imukit()
        .current_dir(dir)
        .args(["integrate", "few.csv", "--out", "n.csv"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(65));
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("gyro_x/y/z_rad_s")
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
fn gravity_flag_carries_its_unit_and_keeps_the_old_spelling() {
    let dir = temp_dir("gravity");
    let dir = dir.path();
    let scenario = dir.join("static.toml");
    std::fs::write(
        &scenario,
        "rate_hz = 10.0\nduration_s = 2.0\ngravity_m_s2 = 9.8\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
    )
    .unwrap();
    let imu = dir.join("imu.csv");
    let ok = imukit()
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&imu)
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    // Integrating with the gravity the readings were made with keeps the IMU at rest (to
    // rounding); both spellings of the flag mean the same.
    for flag in ["--gravity-m-s2", "--gravity"] {
        let nav = dir.join(format!("nav{flag}.csv"));
        let out = imukit()
            .arg("integrate")
            .arg(&imu)
            .args([flag, "9.8", "--out"])
            .arg(&nav)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&nav).unwrap();
        let last: Vec<f64> = text
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        let drift = last[1].hypot(last[2]).hypot(last[3]);
        assert!(drift < 1e-12, "{flag}: {drift} m");
    }
    let bad = imukit()
        .arg("integrate")
        .arg(&imu)
        .args(["--gravity-m-s2", "inf", "--out"])
        .arg(dir.join("bad.csv"))
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(65));
    let err = String::from_utf8(bad.stderr).unwrap();
    assert!(
        err.contains("--gravity-m-s2: must be a finite number"),
        "{err}"
    );
    assert!(!dir.join("bad.csv").exists());
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
fn a_deeply_nested_or_very_long_formula_is_refused_without_a_crash() {
    let dir = temp_dir("nesting");
    let dir = dir.path();
    let nested = format!("{}t{}", "(".repeat(5000), ")".repeat(5000));
    let sum = vec!["t"; 40_000].join("+");
    for (formula, message) in [
        (
            nested.as_str(),
            "trajectory.position_m[0]: nested deeper than 64 levels (parentheses, signs, powers, calls) at column 65",
        ),
        (
            sum.as_str(),
            "trajectory.position_m[0]: more than 1000 operations deep",
        ),
    ] {
        let scenario = dir.join("deep.toml");
        std::fs::write(
            &scenario,
            format!(
                "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"expression\"\n\
                 position_m = [\"{formula}\", \"0\", \"0\"]\n"
            ),
        )
        .unwrap();
        let out = imukit()
            .arg("simulate")
            .arg(&scenario)
            .arg("--out")
            .arg(dir.join("imu.csv"))
            .arg("--truth")
            .arg(dir.join("truth.csv"))
            .output()
            .unwrap();
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(65), "{err}");
        assert!(err.contains(message), "{err}");
        let left: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(
            left,
            [std::ffi::OsString::from("deep.toml")],
            "no output left behind"
        );
    }
}

/// Runs `imukit` in `dir` with `args` and returns (exit code, stderr).
fn run_in(dir: &std::path::Path, args: &[&str]) -> (Option<i32>, String) {
    let out = imukit().current_dir(dir).args(args).output().unwrap();
    (out.status.code(), String::from_utf8(out.stderr).unwrap())
}

#[test]
fn outputs_never_overwrite_inputs_or_each_other_and_special_files_stay_special() {
    let dir = temp_dir("outputs");
    let dir = dir.path();
    let scenario = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/expression.toml"),
    )
    .unwrap();
    std::fs::write(dir.join("s.toml"), &scenario).unwrap();
    let (code, err) = run_in(dir, &["simulate", "s.toml", "--out", "s.toml"]);
    assert_eq!(code, Some(65));
    assert!(
        err.contains("--out: s.toml is also the scenario file"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("s.toml")).unwrap(),
        scenario
    );
    let (code, err) = run_in(
        dir,
        &["simulate", "s.toml", "--out", "i.csv", "--truth", "./i.csv"],
    );
    assert_eq!(code, Some(65));
    assert!(err.contains("--truth: ./i.csv is also the --out"), "{err}");
    std::fs::create_dir_all(dir.join("folder")).unwrap();
    let (code, err) = run_in(
        dir,
        &["simulate", "s.toml", "--out", "i.csv", "--truth", "folder"],
    );
    assert_eq!(code, Some(65));
    assert!(err.contains("folder is a folder"), "{err}");
    let (code, err) = run_in(dir, &["simulate", "s.toml", "--out", "-"]);
    assert_eq!(code, Some(65));
    assert!(err.contains("/dev/stdout"), "{err}");
    // Nothing was written by the refused runs.
    let mut left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["folder", "s.toml"]);

    // The usual way to discard outputs: /dev/null is written, not replaced.
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "/dev/null",
            "--truth",
            "/dev/null",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let null = std::fs::metadata("/dev/null").unwrap();
    assert!(!null.is_file(), "/dev/null must stay a device");

    // A long legal name still gets a temporary name within the file-name limit.
    let long = format!("{}.csv", "x".repeat(250));
    let (code, err) = run_in(
        dir,
        &["simulate", "s.toml", "--out", &long, "--truth", "t.csv"],
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.join(&long).exists());

    // Each command compares its outputs with its inputs (a CSV may have any extension).
    std::fs::copy(dir.join("t.csv"), dir.join("t.svg")).unwrap();
    for args in [
        vec!["integrate", &long, "--out", &long],
        vec!["integrate", &long, "--init", "t.csv", "--out", "t.csv"],
        vec!["orient", &long, "--out", &long],
        vec!["compare", "t.csv", "t.csv", "--out", "t.csv"],
        vec!["allan", &long, "--out", &long],
        vec!["plot", "t.svg", "--out", "t.svg"],
    ] {
        let before = std::fs::read(dir.join(args.last().unwrap())).unwrap();
        let (code, err) = run_in(dir, &args);
        assert_eq!(code, Some(65), "{args:?}: {err}");
        assert!(
            err.contains("writing it would destroy the input"),
            "{args:?}: {err}"
        );
        assert_eq!(
            std::fs::read(dir.join(args.last().unwrap())).unwrap(),
            before
        );
    }
    // A figure extension is checked before the table is written.
    let (code, err) = run_in(dir, &["allan", &long, "--out", "a.csv", "--plot", "a.txt"]);
    assert_eq!(code, Some(74));
    assert!(
        err.contains("a.txt: the figure file must end in .svg or .png"),
        "{err}"
    );
    assert!(!dir.join("a.csv").exists());
    // An unknown built-in leaves no folder behind.
    let (code, _) = run_in(
        dir,
        &["demo", "--scenario", "nosuch", "--out-dir", "newdir"],
    );
    assert_eq!(code, Some(65));
    assert!(!dir.join("newdir").exists());
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

#[test]
fn orient_with_decimation_says_how_many_samples_end_without_an_orientation() {
    let dir = temp_dir("orient-decimation");
    let dir = dir.path();
    let header =
        "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s";
    let mut text = format!("{header}\n");
    for k in 0..50 {
        text += &format!("{},0,0,9.81,0,0,0\n", f64::from(k) * 0.01);
    }
    std::fs::write(dir.join("imu.csv"), text).unwrap();
    let out = imukit()
        .current_dir(dir)
        .args(["orient", "imu.csv", "--filter", "imufilter"])
        .args(["--param", "DecimationFactor=3"])
        .args(["--out", "o.csv"])
        .output()
        .unwrap();
    // Notes go to standard error, as every command's do; standard output stays empty.
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(out.stdout.is_empty());
    assert!(stderr.contains(": 16 orientations in o.csv"), "{stderr}");
    assert!(
        stderr.contains("the last 2 samples do not fill a block"),
        "{stderr}"
    );
    // -q keeps them back.
    let quiet = imukit()
        .current_dir(dir)
        .args([
            "-q",
            "orient",
            "imu.csv",
            "--filter",
            "imufilter",
            "--out",
            "q.csv",
        ])
        .output()
        .unwrap();
    assert_eq!(quiet.status.code(), Some(0));
    assert!(
        quiet.stderr.is_empty() && quiet.stdout.is_empty(),
        "{quiet:?}"
    );
    let rows = table_text(dir.join("o.csv")).lines().count();
    assert_eq!(rows, 17);
}

#[test]
fn integrate_on_the_wgs84_earth_recovers_a_wgs84_flight_and_names_what_is_missing() {
    let dir = temp_dir("earth-integrate");
    let dir = dir.path();
    std::fs::write(
        dir.join("flight.toml"),
        "rate_hz = 50.0\nduration_s = 120.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = { latitude_deg = 47.0, longitude_deg = 8.0, height_m = 500.0 }\n\
         [trajectory]\ntype = \"expression\"\n\
         position_m = [\"3000*sin(0.03*t) + 20*t\", \"3000*(1 - cos(0.03*t))\", \"-100*sin(0.01*t)\"]\n\
         attitude = \"tangent\"\n[imu]\nkind = \"accel-gyro\"\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "flight.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let truth_header = table_text(dir.join("truth.csv"));
    assert!(
        truth_header
            .lines()
            .next()
            .unwrap()
            .ends_with(",lat_rad,lon_rad,height_m,ecef_x_m,ecef_y_m,ecef_z_m")
    );
    let integrate = |extra: &[&str], out: &str| {
        let mut args = vec!["integrate", "imu.csv", "--nav-frame", "NED", "--out", out];
        args.extend(extra);
        run_in(dir, &args)
    };
    let (code, err) = integrate(&["--init", "truth.csv", "--earth", "wgs84"], "nav.csv");
    assert_eq!(code, Some(0), "{err}");
    let nav = table_text(dir.join("nav.csv"));
    assert!(
        nav.lines()
            .next()
            .unwrap()
            .ends_with(",lat_rad,lon_rad,height_m")
    );
    let out = imukit()
        .current_dir(dir)
        .args(["compare", "truth.csv", "nav.csv"])
        .output()
        .unwrap();
    let report = String::from_utf8(out.stdout).unwrap();
    let max_position: f64 = report
        .lines()
        .find(|l| l.starts_with("position"))
        .and_then(|l| l.split_whitespace().nth(3))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    assert!(max_position < 1e-6, "{report}");
    // Described, the readings start at the scenario's origin without --init or --lat0-deg
    // (at rest and level there: far off for this flight, but on the WGS-84 Earth in NED).
    let (code, err) = integrate(&[], "origin.csv");
    assert_eq!(code, Some(0), "{err}");
    assert!(
        table_text(dir.join("origin.csv"))
            .lines()
            .next()
            .unwrap()
            .ends_with(",lat_rad,lon_rad,height_m")
    );
    // A file without a description (another program's) takes every setting from the flags.
    std::fs::write(dir.join("imu.csv"), table_text(dir.join("imu.csv"))).unwrap();
    // Without a geodetic start, with a flat-only flag, an unknown channel: named.
    for (extra, needle) in [
        (
            vec!["--earth", "wgs84"],
            "needs the starting latitude, longitude and height",
        ),
        (
            vec!["--vertical", "hold"],
            "--vertical: chooses the vertical channel of the WGS-84",
        ),
        (
            vec![
                "--earth",
                "wgs84",
                "--vertical",
                "sideways",
                "--init",
                "truth.csv",
            ],
            "invalid value 'sideways' for '--vertical <VERTICAL>'\n  [possible values: free, hold, baro]",
        ),
        (
            vec!["--earth", "wgs84", "--lat0-deg", "45"],
            "--lon0-deg: missing",
        ),
        (
            vec!["--earth", "globe"],
            "invalid value 'globe' for '--earth <EARTH>'\n  [possible values: flat, wgs84]",
        ),
        (
            vec![
                "--earth",
                "wgs84",
                "--vertical",
                "baro",
                "--init",
                "truth.csv",
            ],
            "needs a baro_height_m column",
        ),
    ] {
        let (code, err) = integrate(&extra, "bad.csv");
        // An unknown name is a usage error (2), listing the names; bad data is 65.
        let usage = needle.starts_with("invalid value");
        assert_eq!(code, Some(if usage { 2 } else { 65 }), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!dir.join("bad.csv").exists());
    }
}

#[test]
fn simulate_writes_the_same_bytes_on_one_two_or_three_threads_and_refuses_no_thread() {
    let dir = temp_dir("threads");
    let dir = dir.path();
    // Five streamed chunks of the figure-8, with sensor noise: the truth, the readings and the
    // writing cross between threads chunk by chunk while the noise is drawn in order.
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 2000.0\nduration_s = 10.0\n[trajectory]\ntype = \"builtin\"\n\
         name = \"figure8\"\n[imu]\nseed = 7\n[imu.accelerometer]\nNoiseDensity = 3e-3\n\
         BiasInstability = 2e-3\nRandomWalk = 1e-4\n[imu.gyroscope]\nNoiseDensity = 1e-4\n",
    )
    .unwrap();
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    // Text among the outputs (written on its own thread when there are two), binary alone (the
    // truth a chunk ahead instead), and both.
    for (imu_ext, truth_ext) in [
        ("npy", Some("csv")),
        ("csv", None),
        ("parquet", Some("npz")),
    ] {
        for (threads, tag) in [
            (None, "auto"),
            (Some("1"), "one"),
            (Some("2"), "two"),
            (Some("3"), "three"),
        ] {
            let imu = format!("imu_{tag}.{imu_ext}");
            let truth = truth_ext.map(|e| format!("truth_{tag}.{e}"));
            let mut args = vec!["simulate", "s.toml", "--out", &imu];
            args.extend(truth.iter().flat_map(|t| ["--truth", t.as_str()]));
            args.extend(threads.map(|n| ["--threads", n]).into_iter().flatten());
            let (code, err) = run_in(dir, &args);
            assert_eq!(code, Some(0), "{tag}: {err}");
        }
        if imu_ext == "npy" {
            // Every row: 20 001 samples of ten float64 columns after NumPy's header (< 1 KiB).
            let header = read("imu_one.npy").len() - 20_001 * 10 * 8;
            assert!((64..1024).contains(&header), "{header}");
        }
        for tag in ["auto", "two", "three"] {
            let same = |name: &str, ext: &str| {
                read(&format!("{name}_{tag}.{ext}")) == read(&format!("{name}_one.{ext}"))
            };
            assert!(same("imu", imu_ext), "{tag}: IMU .{imu_ext}");
            if let Some(e) = truth_ext {
                assert!(same("truth", e), "{tag}: truth .{e}");
            }
        }
    }
    // A run that breaks off after a few chunks: the same error on every split, and no file.
    std::fs::write(
        dir.join("breaks.toml"),
        "rate_hz = 2000.0\nduration_s = 10.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"t\", \"0\", \"sqrt(7 - t)\"]\nattitude = \"tangent\"\n",
    )
    .unwrap();
    let mut errors = Vec::new();
    for threads in ["1", "2", "3"] {
        let args = [
            "simulate",
            "breaks.toml",
            "--out",
            "b.csv",
            "--truth",
            "bt.npy",
            "--threads",
            threads,
        ];
        let (code, err) = run_in(dir, &args);
        assert_eq!(code, Some(65), "{threads}: {err}");
        assert!(
            !dir.join("b.csv").exists() && !dir.join("bt.npy").exists(),
            "{threads}"
        );
        errors.push(err);
    }
    assert!(errors[0].contains("t = 7"), "{}", errors[0]);
    assert!(errors.iter().all(|e| *e == errors[0]), "{errors:?}");
    // Monte Carlo runs at most --threads at a time, each run the same as with every core.
    for (threads, out) in [("1", "mc_one.csv"), ("8", "mc_many.csv")] {
        let args = [
            "simulate",
            "s.toml",
            "--out",
            out,
            "--runs",
            "2",
            "--threads",
            threads,
        ];
        assert_eq!(run_in(dir, &args).0, Some(0), "{threads}");
    }
    for r in ["0", "1"] {
        assert!(read(&format!("mc_one_run000{r}.csv")) == read(&format!("mc_many_run000{r}.csv")));
    }
    for bad in ["0", "-1"] {
        let (code, err) = run_in(
            dir,
            &["simulate", "s.toml", "--out", "bad.csv", "--threads", bad],
        );
        assert_eq!(code, Some(65), "{bad}: {err}");
        assert!(
            err.contains(&format!("--threads: must be ≥ 1 thread, got {bad}")),
            "{err}"
        );
        assert!(!dir.join("bad.csv").exists());
    }
}

#[test]
fn simulate_writes_gnss_fixes_beside_the_imu_per_run_and_refuses_collisions() {
    let dir = temp_dir("gnss-simulate");
    let dir = dir.path();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 50.0\nduration_s = 10.0\n[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\n\
         [gnss]\nrate_hz = 5.0\n[[gnss.outages]]\nstart_s = 2.0\nduration_s = 1.0\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate", "s.toml", "--out", "imu.csv", "--gnss", "gnss.csv", "--runs", "2",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    for r in 0..2 {
        let text = table_text(dir.join(format!("gnss_run{r:04}.csv")));
        // 51 epochs at 5 Hz, 5 in the outage [2, 3).
        assert_eq!(text.lines().count(), 1 + 51 - 5, "run {r}");
        assert!(text.starts_with("t_s,pos_x_m,pos_y_m,pos_z_m,vel_x_m_s,vel_y_m_s,vel_z_m_s\n"));
    }
    let (code, err) = run_in(
        dir,
        &[
            "simulate", "s.toml", "--out", "imu.csv", "--gnss", "imu.csv",
        ],
    );
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("--gnss") && err.contains("--out"), "{err}");
}

#[test]
fn fuse_follows_a_gnss_aided_car_and_names_bad_input() {
    let dir = temp_dir("fuse");
    let dir = dir.path();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 100.0\nduration_s = 60.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"60*sin(0.16*t)\", \"60*(1 - cos(0.16*t))\", \"0\"]\nattitude = \"tangent\"\n\
         [imu]\nkind = \"accel-gyro\"\npreset = \"stim300\"\n\
         [gnss]\nrate_hz = 5.0\ndecay_factor = 0.0\nhorizontal_accuracy_m = 1.0\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--gnss",
            "gnss.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let fuse_to = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "fuse",
            "imu.csv",
            "gnss.csv",
            "--init",
            "truth.csv",
            "--scenario",
            "s.toml",
            "--out",
            out,
        ];
        args.extend(extra);
        run_in(dir, &args)
    };
    let (code, err) = fuse_to("nav.csv", &[]);
    assert_eq!(code, Some(0), "{err}");
    // 301 fixes, applied or (rarely: the gate is the 99.9 % quantile) rejected.
    let numbers: Vec<usize> = err
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(err.contains("updates ("), "{err}");
    assert_eq!(numbers[1] + numbers[2], 301, "{err}");
    assert!(numbers[2] <= 2, "{err}");
    let header = table_text(dir.join("nav.csv"));
    assert!(header.starts_with(
        "t_s,pos_x_m,pos_y_m,pos_z_m,vel_x_m_s,vel_y_m_s,vel_z_m_s,q_w,q_x,q_y,q_z,yaw_rad,pitch_rad,roll_rad,pos_x_sigma_m,"
    ));
    let out = imukit()
        .current_dir(dir)
        .args(["compare", "truth.csv", "nav.csv"])
        .output()
        .unwrap();
    let report = String::from_utf8(out.stdout).unwrap();
    let rms: f64 = report
        .lines()
        .find(|l| l.starts_with("position"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    // Fixes of 1 m (1.4 m white, MATLAB's σ√2 at decay 0) at 5 Hz: the filter does better.
    assert!(rms < 1.0, "{report}");
    std::fs::remove_file(dir.join("nav.csv")).unwrap();
    for (out, extra, needle) in [
        ("nav.csv", vec!["--earth", "wgs84"], "which says flat"),
        ("imu.csv", vec![], "--out"),
    ] {
        let (code, err) = fuse_to(out, &extra);
        assert_eq!(code, Some(65), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
    assert!(!dir.join("nav.csv").exists());
}

#[test]
fn a_barometer_file_damps_the_vertical_channel_of_earth_navigation() {
    let dir = temp_dir("baro-integrate");
    let dir = dir.path();
    // At rest at 45° N for 20 minutes with a 1e-3 m/s² vertical accelerometer bias; a
    // barometer at 10 Hz with 0.5 m of noise.
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 10.0\nduration_s = 1200.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n[imu]\nkind = \"accel-gyro\"\n\
         [imu.accelerometer]\nConstantBias = [0.0, 0.0, 0.001]\n[baro]\nnoise_m = 0.5\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--baro",
            "baro.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let integrate = |extra: &[&str], out: &str| {
        let mut args = vec![
            "integrate",
            "imu.csv",
            "--init",
            "truth.csv",
            "--nav-frame",
            "NED",
            "--earth",
            "wgs84",
            "--out",
            out,
        ];
        args.extend(extra);
        run_in(dir, &args)
    };
    let last_height = |file: &str| -> f64 {
        let text = table_text(dir.join(file));
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let k = header.iter().position(|h| *h == "height_m").unwrap();
        text.lines()
            .last()
            .unwrap()
            .split(',')
            .nth(k)
            .unwrap()
            .parse()
            .unwrap()
    };
    let (code, err) = integrate(&["--vertical", "baro", "--baro", "baro.csv"], "damped.csv");
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = integrate(&["--vertical", "free"], "free.csv");
    assert_eq!(code, Some(0), "{err}");
    // Free: ½bt² alone is 720 m after 20 minutes, more with the instability; damped: the loop
    // holds the height to the barometer's noise.
    assert!((last_height("free.csv") - 300.0).abs() > 700.0);
    assert!(
        (last_height("damped.csv") - 300.0).abs() < 2.0,
        "{}",
        last_height("damped.csv")
    );
    let (code, err) = integrate(&["--baro", "baro.csv"], "x.csv");
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("--baro: barometer readings feed the baro-damped vertical channel"),
        "{err}"
    );
    std::fs::write(dir.join("bad.csv"), "t_s,baro_height_m\n0,300\n0,301\n").unwrap();
    let (code, err) = integrate(&["--vertical", "baro", "--baro", "bad.csv"], "y.csv");
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("bad.csv: row 3: times must be finite and increase"),
        "{err}"
    );
    // Readings 10⁴ s after the IMU's last sample: refused as the fusion refuses them.
    std::fs::write(
        dir.join("late.csv"),
        "t_s,baro_height_m
0,300
10000,301
",
    )
    .unwrap();
    let (code, err) = integrate(&["--vertical", "baro", "--baro", "late.csv"], "z.csv");
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("late.csv: row 3: time 10000 s is outside the IMU's span"),
        "{err}"
    );
    assert!(
        !dir.join("x.csv").exists() && !dir.join("y.csv").exists() && !dir.join("z.csv").exists()
    );
}

#[test]
fn study_compares_presets_through_the_tunnel_and_reports_a_filter_reset_to_the_fixes() {
    let dir = temp_dir("study");
    let dir = dir.path();
    let scenario =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    std::fs::write(
        dir.join("study.toml"),
        format!(
            "scenario = \"{}\"\npresets = [\"mpu-6050\", \"stim300\"]\nruns = 2\nsmooth = true\n\
             rest_s = 0.0\nsensor_errors = false\n",
            scenario.display()
        ),
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &["study", "study.toml", "--out", "t.csv", "--plot", "t.png"],
    );
    assert_eq!(code, Some(0), "{err}");
    // The MPU-6050's 2 % cross-axis sensitivity is beyond the 15-state filter (told of no rest
    // and no sensor errors): it loses the fixes, is reset to them and carries on, and that is
    // said, not hidden.
    assert!(
        err.contains("mpu-6050")
            && err.contains("was reset to them")
            && err.contains("in 2 of 2 runs"),
        "{err}"
    );
    assert!(
        !err.lines()
            .any(|l| l.trim_start().starts_with("stim300") && l.contains("reset to them")),
        "{err}"
    );
    // The MPU-6050 preset gives no bias drift, the STIM300 does: said before the runs.
    assert!(
        err.contains("not described alike: mpu-6050: no gyroscope bias drift"),
        "{err}"
    );
    let text = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    let mut lines = text.lines();
    assert!(
        lines.next().unwrap().contains("\"kind\": \"study\""),
        "{text}"
    );
    assert_eq!(
        lines.next().unwrap(),
        "t_s,mpu-6050_rms_error_m,mpu-6050_sigma_m,mpu-6050_smoothed_rms_error_m,\
         stim300_rms_error_m,stim300_sigma_m,stim300_smoothed_rms_error_m"
    );
    assert!(std::fs::metadata(dir.join("t.png")).unwrap().len() > 1000);
    // The table is drawn again by `imukit plot`, recognised as a study (smoothed curves too).
    let (code, err) = run_in(dir, &["plot", "t.csv", "--out", "again.svg"]);
    assert_eq!(code, Some(0), "{err}");
    let svg = std::fs::read_to_string(dir.join("again.svg")).unwrap();
    assert!(
        svg.contains("Horizontal position error through the GNSS outage")
            && svg.contains("dotted: smoothed")
            && svg.contains("stim300"),
        "{svg}"
    );
    // A bad figure name is refused before any run; an output over the study file is refused.
    let (code, err) = run_in(
        dir,
        &["study", "study.toml", "--out", "u.csv", "--plot", "u.gif"],
    );
    assert_ne!(code, Some(0));
    assert!(
        err.contains("u.gif") && !dir.join("u.csv").exists(),
        "{err}"
    );
    let (code, err) = run_in(dir, &["study", "study.toml", "--out", "study.toml"]);
    assert_ne!(code, Some(0));
    assert!(err.contains("study.toml"), "{err}");
    assert!(
        std::fs::read_to_string(dir.join("study.toml"))
            .unwrap()
            .contains("runs = 2")
    );
}

#[test]
fn fuse_takes_an_odometer_a_barometer_and_the_vehicle_constraints_and_names_bad_ones() {
    let dir = temp_dir("fuse-aids");
    let dir = dir.path();
    let scenario = "rate_hz = 100.0\nduration_s = 30.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"60*sin(0.16*t)\", \"60*(1 - cos(0.16*t))\", \"0\"]\nattitude = \"tangent\"\n\
         [imu]\nkind = \"accel-gyro\"\npreset = \"stim300\"\n\
         [gnss]\nrate_hz = 5.0\ndecay_factor = 0.0\n\
         [odometer]\nrate_hz = 10.0\n[baro]\nrate_hz = 10.0\n";
    std::fs::write(dir.join("s.toml"), scenario).unwrap();
    std::fs::write(
        dir.join("plain.toml"),
        scenario.split("[odometer]").next().unwrap(),
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--gnss",
            "gnss.csv",
            "--odometer",
            "odo.csv",
            "--baro",
            "baro.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    // Every file written is named.
    assert!(
        err.contains(
            "IMU readings in imu.csv, truth in truth.csv, GNSS fixes in gnss.csv, barometer \
             readings in baro.csv, odometer readings in odo.csv"
        ),
        "{err}"
    );
    let fuse = |scenario: &str, extra: &[&str]| {
        let mut args = vec![
            "fuse",
            "imu.csv",
            "gnss.csv",
            "--init",
            "truth.csv",
            "--scenario",
            scenario,
            "--out",
            "nav.csv",
        ];
        args.extend(extra);
        run_in(dir, &args)
    };
    let (code, err) = fuse(
        "s.toml",
        &["--odometer", "odo.csv", "--baro", "baro.csv", "--nhc"],
    );
    assert_eq!(code, Some(0), "{err}");
    // 151 fixes, 301 odometer readings with the constraints, 301 heights: one update each.
    let numbers: Vec<usize> = err
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    assert_eq!(numbers[1] + numbers[2], 151 + 301 + 301, "{err}");
    std::fs::remove_file(dir.join("nav.csv")).unwrap();
    // Bad aids are named by file, row or flag, and nothing is written.
    let odo = table_text(dir.join("odo.csv"));
    let mut lines: Vec<&str> = odo.lines().collect();
    lines.swap(5, 6);
    std::fs::write(dir.join("odo_back.csv"), lines.join("\n")).unwrap();
    for (scenario, extra, needles) in [
        (
            "plain.toml",
            vec!["--odometer", "odo.csv"],
            vec!["odo.csv", "no [odometer]"],
        ),
        (
            "s.toml",
            vec!["--odometer", "odo_back.csv"],
            vec!["odo_back.csv", "row 7"],
        ),
        ("s.toml", vec!["--nhc=-1"], vec!["--nhc", "> 0"]),
        (
            "s.toml",
            vec!["--covariance-interval-s=nan"],
            vec!["--covariance-interval-s", "≥ 0"],
        ),
        (
            "s.toml",
            vec!["--baro", "odo.csv"],
            vec!["odo.csv", "baro_height_m"],
        ),
    ] {
        let (code, err) = fuse(scenario, &extra);
        assert_eq!(code, Some(65), "{extra:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{extra:?}: {err}");
        }
        assert!(!dir.join("nav.csv").exists(), "{extra:?}");
    }
}

#[test]
fn fuse_aligns_from_gnss_without_truth_and_refuses_a_start_it_cannot_make() {
    let dir = temp_dir("fuse-align");
    let dir = dir.path();
    let scenario =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    let scenario = scenario.display().to_string();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            &scenario,
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--gnss",
            "gnss.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let fuse = |extra: &[&str]| {
        let mut args = vec![
            "fuse",
            "imu.csv",
            "gnss.csv",
            "--scenario",
            &scenario,
            "--out",
            "nav.csv",
        ];
        args.extend(extra);
        run_in(dir, &args)
    };
    let (code, err) = fuse(&["--align", "gnss"]);
    assert_eq!(code, Some(0), "{err}");
    // The estimate begins at the first fix at speed (the car waits 20 s, then drives), not at
    // t = 0.
    let nav = table_text(dir.join("nav.csv"));
    let t0: f64 = nav
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(t0 > 20.5 && t0 < 25.0, "{t0}");
    let out = imukit()
        .current_dir(dir)
        .args(["compare", "truth.csv", "nav.csv"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_file(dir.join("nav.csv")).unwrap();
    for (extra, needles) in [
        (vec!["--align", "static"], vec!["--align", "north", "gnss"]),
        (
            vec!["--align", "sideways"],
            vec![
                "invalid value 'sideways' for '--align <ALIGN>'",
                "gnss, static",
            ],
        ),
        (vec![], vec!["--init", "\"gnss\""]),
        (
            vec!["--init", "truth.csv", "--align", "gnss"],
            vec!["--init", "not both"],
        ),
        (
            vec!["--init", "truth.csv", "--rest-s=-1"],
            vec!["--rest-s", "≥ 0"],
        ),
    ] {
        let (code, err) = fuse(&extra);
        let usage = needles[0].starts_with("invalid value");
        assert_eq!(code, Some(if usage { 2 } else { 65 }), "{extra:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{extra:?}: {err}");
        }
        assert!(!dir.join("nav.csv").exists());
    }
    // Told of the wait and estimating the sensor errors: their columns follow the biases'.
    let (code, err) = fuse(&["--init", "truth.csv", "--rest-s", "20", "--sensor-errors"]);
    assert_eq!(code, Some(0), "{err}");
    let nav = table_text(dir.join("nav.csv"));
    let header: Vec<&str> = nav.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 35 + 42 + 1, "{header:?}");
    assert_eq!(header[35], "accel_scale_factor_x");
    assert_eq!(header[76], "gyro_g_sensitivity_z_sigma_rad_s_per_m_s2");
    assert_eq!(header[77], "gnss_resets");
}

#[test]
fn fuse_runs_on_the_wgs84_earth_with_geodetic_fixes() {
    let dir = temp_dir("fuse-earth");
    let dir = dir.path();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 100.0\nduration_s = 60.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n\
         [trajectory]\ntype = \"expression\"\n\
         position_m = [\"60*sin(0.16*t)\", \"60*(1 - cos(0.16*t))\", \"0\"]\nattitude = \"tangent\"\n\
         [imu]\nkind = \"accel-gyro\"\npreset = \"stim300\"\n\
         [gnss]\nrate_hz = 5.0\ndecay_factor = 0.0\nhorizontal_accuracy_m = 1.0\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--gnss",
            "gnss.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(
        dir,
        &[
            "fuse",
            "imu.csv",
            "gnss.csv",
            "--init",
            "truth.csv",
            "--scenario",
            "s.toml",
            "--out",
            "nav.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let header = table_text(dir.join("nav.csv"));
    assert!(
        header
            .lines()
            .next()
            .unwrap()
            .ends_with(",lat_rad,lon_rad,height_m,gnss_resets"),
        "{}",
        header.lines().next().unwrap()
    );
    let out = imukit()
        .current_dir(dir)
        .args(["compare", "truth.csv", "nav.csv"])
        .output()
        .unwrap();
    let report = String::from_utf8(out.stdout).unwrap();
    let rms: f64 = report
        .lines()
        .find(|l| l.starts_with("position"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    assert!(rms < 1.0, "{report}");
    // Flat fixes given for an Earth scenario are refused by column.
    std::fs::write(
        dir.join("flat.csv"),
        "t_s,pos_x_m,pos_y_m,pos_z_m,vel_x_m_s,vel_y_m_s,vel_z_m_s\n0,0,0,0,0,0,0\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "fuse",
            "imu.csv",
            "flat.csv",
            "--init",
            "truth.csv",
            "--scenario",
            "s.toml",
            "--out",
            "nav2.csv",
        ],
    );
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("flat.csv") && err.contains("lat_rad"), "{err}");
    assert!(!dir.join("nav2.csv").exists());
}

#[test]
fn orient_estimates_in_the_frame_the_readings_say_they_have() {
    let dir = temp_dir("orient-described");
    let dir = dir.path();
    // A level IMU at rest in NED: FRD body axes, specific force -g on z.
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 100.0\nduration_s = 1.0\nnav_frame = \"NED\"\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
    )
    .unwrap();
    let (code, err) = run_in(dir, &["simulate", "s.toml", "--out", "imu.csv"]);
    assert_eq!(code, Some(0), "{err}");
    let last_roll = |file: &str| -> f64 {
        let text = table_text(dir.join(file));
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let k = header.iter().position(|h| *h == "roll_rad").unwrap();
        text.lines()
            .last()
            .unwrap()
            .split(',')
            .nth(k)
            .unwrap()
            .parse()
            .unwrap()
    };
    // No flag: NED from the file, level (read as ENU's FLU axes it would be upside down).
    let (code, err) = run_in(
        dir,
        &[
            "orient", "imu.csv", "--filter", "ecompass", "--out", "o.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(last_roll("o.csv").abs() < 1e-9, "{}", last_roll("o.csv"));
    let o = std::fs::read_to_string(dir.join("o.csv")).unwrap();
    assert!(
        o.starts_with("# imukit: {\"kind\": \"orientation\", \"nav_frame\": \"NED\""),
        "{o}"
    );
    // MATLAB's conventions fill only what the file does not say: its sign is specific force.
    let (code, err) = run_in(
        dir,
        &[
            "orient",
            "imu.csv",
            "--filter",
            "ecompass",
            "--conventions",
            "matlab",
            "--out",
            "m.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(table_text(dir.join("m.csv")), table_text(dir.join("o.csv")));
    // A flag that contradicts the file is refused, naming both; nothing is written.
    for (flag, value, says) in [
        ("--nav-frame", "ENU", "says NED"),
        ("--accel-sign", "matlab", "says specific-force"),
    ] {
        let (code, err) = run_in(
            dir,
            &[
                "orient", "imu.csv", "--filter", "ecompass", flag, value, "--out", "x.csv",
            ],
        );
        assert_eq!(code, Some(65), "{err}");
        assert!(
            err.contains(&format!("{flag}: {value} contradicts imu.csv")) && err.contains(says),
            "{err}"
        );
        assert!(!dir.join("x.csv").exists());
    }
}

#[test]
fn compare_refuses_a_truth_and_an_estimate_in_different_frames() {
    let dir = temp_dir("compare-described");
    let dir = dir.path();
    std::fs::write(
        dir.join("s.toml"),
        "rate_hz = 100.0\nduration_s = 1.0\nnav_frame = \"NED\"\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
    )
    .unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "s.toml",
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
            "orient", "imu.csv", "--filter", "ecompass", "--out", "o.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(dir, &["compare", "truth.csv", "o.csv"]);
    assert_eq!(code, Some(0), "{err}");
    // The same estimate said to be in ENU: refused, both files named.
    let o = std::fs::read_to_string(dir.join("o.csv")).unwrap();
    std::fs::write(
        dir.join("enu.csv"),
        o.replace(
            "\"nav_frame\": \"NED\", \"body_frame\": \"FRD\"",
            "\"nav_frame\": \"ENU\", \"body_frame\": \"FLU\"",
        ),
    )
    .unwrap();
    let (code, err) = run_in(dir, &["compare", "truth.csv", "enu.csv"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("the inputs disagree: truth.csv says NED, enu.csv says ENU"),
        "{err}"
    );
}

/// A reader that goes away (`imukit … | head`) does not fail the command: it finishes and its
/// files are written.
#[test]
fn a_closed_standard_output_does_not_lose_the_files() {
    let dir = temp_dir("closed-stdout");
    let bin = env!("CARGO_BIN_EXE_imukit");
    let examples = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let script = format!(
        "set -o pipefail; \"{bin}\" simulate {examples}/static_log.toml --out still.csv \
         --quiet && \"{bin}\" identify still.csv --out curve.csv | true"
    );
    let status = Command::new("bash")
        .args(["-c", &script])
        .current_dir(dir.path())
        .status()
        .unwrap();
    assert!(status.success(), "{status}");
    assert!(dir.path().join("curve.csv").exists());
}

/// A walk navigated without any fix: the GNSS file left out, zero-velocity updates at the
/// stances bring the foot back within 1 % of the 754 m walked.
#[test]
fn fuse_without_fixes_navigates_a_walk_by_its_stances() {
    let dir = temp_dir("walk");
    let dir = dir.path();
    let walk = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/walk.toml");
    let (code, err) = run_in(
        dir,
        &["simulate", walk, "--out", "imu.csv", "--truth", "truth.csv"],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(
        dir,
        &[
            "fuse",
            "imu.csv",
            "--init",
            "truth.csv",
            "--scenario",
            walk,
            "--zupt",
            "--out",
            "nav.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("samples taken as stances"), "{err}");
    let last = |name: &str| -> Vec<f64> {
        let text = table_text(dir.join(name));
        let row = text.lines().last().unwrap().to_owned();
        row.split(',').take(4).map(|v| v.parse().unwrap()).collect()
    };
    let first_truth: Vec<f64> = table_text(dir.join("truth.csv"))
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .take(4)
        .map(|v| v.parse().unwrap())
        .collect();
    let end = last("nav.csv");
    let error = (1..4)
        .map(|k| (end[k] - first_truth[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(error < 7.54, "{error} m from the start after 754 m");
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

/// `--start-s` and `--end-s` cut every input of a command at the same instants, counted from
/// the first sample: a windowed integration starts from the reference's row where the window
/// starts and is the integration of those rows alone.
#[test]
fn a_time_window_cuts_every_input_at_the_same_instants() {
    let dir = temp_dir("window");
    let dir = dir.path();
    let toml = imukit()
        .current_dir(dir)
        .args(["scenario", "gnss-car"])
        .output()
        .unwrap();
    std::fs::write(dir.join("car.toml"), toml.stdout).unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "car.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
            "--gnss",
            "gnss.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(
        dir,
        &[
            "integrate",
            "imu.csv",
            "--init",
            "truth.csv",
            "--start-s",
            "30",
            "--end-s",
            "40",
            "--out",
            "nav.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let rows = |name: &str| -> Vec<Vec<f64>> {
        std::fs::read_to_string(dir.join(name))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("t_s"))
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (nav, truth) = (rows("nav.csv"), rows("truth.csv"));
    assert_eq!(nav.len(), 1001, "30 s to 40 s at 100 Hz");
    assert_eq!((nav[0][0], nav[1000][0]), (30.0, 40.0));
    // The start is the truth's row at 30 s: position, velocity and attitude as they are.
    let at30 = truth.iter().find(|r| r[0] == 30.0).unwrap();
    assert_eq!(nav[0][1..7], at30[1..7], "position and velocity");
    assert_eq!(nav[0][7..11], at30[10..14], "attitude");
    // Compared over the same window: the same 1001 rows, and a consumer part's drift in 10 s.
    let out = imukit()
        .current_dir(dir)
        .args([
            "compare",
            "truth.csv",
            "nav.csv",
            "--start-s",
            "30",
            "--end-s",
            "40",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("(1001 rows compared)"), "{text}");
    // Fused over a stretch: the fixes are cut there too, and the estimate starts at 25 s.
    let (code, err) = run_in(
        dir,
        &[
            "fuse",
            "imu.csv",
            "gnss.csv",
            "--init",
            "truth.csv",
            "--scenario",
            "car.toml",
            "--start-s",
            "25",
            "--end-s",
            "50",
            "--out",
            "fused.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    let fused = rows("fused.csv");
    assert_eq!((fused[0][0], fused[fused.len() - 1][0]), (25.0, 50.0));
    // The fixes of 25 s to 50 s at 5 Hz, both ends included.
    assert!(err.contains("2501 samples fused with 126 updates"), "{err}");
    // An empty window, and a window the wrong way round, are refused by name.
    for (args, needle) in [
        (
            &["integrate", "imu.csv", "--start-s", "500", "--out", "x.csv"][..],
            "no row lies in the window [500 s, the end]",
        ),
        (
            &["orient", "imu.csv", "--start-s", "500", "--out", "x.csv"][..],
            "no row lies in the window [500 s, the end]",
        ),
        (
            &["allan", "imu.csv", "--start-s", "500", "--out", "x.csv"][..],
            "0 row(s) lie in the window [500 s, the end]",
        ),
        (
            &[
                "integrate",
                "imu.csv",
                "--start-s",
                "5",
                "--end-s",
                "2",
                "--out",
                "x.csv",
            ][..],
            "--end-s: must be a finite number of seconds after the start (5 s)",
        ),
    ] {
        let (code, err) = run_in(dir, args);
        assert_eq!(code, Some(65), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!dir.join("x.csv").exists());
    }
}

/// A 9-axis file runs as 6D with `--no-mag` (the heading then comes from the gyroscopes alone);
/// a filter that ignores a magnetometer the file has says so; a filter that needs one says what
/// to use instead; an unknown setting is named before its value is read.
#[test]
fn orient_says_what_it_does_with_the_magnetometer() {
    let dir = temp_dir("orient-mag");
    let dir = dir.path();
    let scenario = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/matlab_orientation.toml");
    std::fs::copy(&scenario, dir.join("m.toml")).unwrap();
    let (code, err) = run_in(dir, &["simulate", "m.toml", "--out", "nine.csv"]);
    assert_eq!(code, Some(0), "{err}");
    let text = std::fs::read_to_string(dir.join("nine.csv")).unwrap();
    // The same readings without the magnetometer columns: a 6-axis file.
    let mut six = String::new();
    for line in text.lines() {
        if line.starts_with('#') {
            six += line;
        } else {
            six += &line.split(',').take(7).collect::<Vec<_>>().join(",");
        }
        six.push('\n');
    }
    std::fs::write(dir.join("six.csv"), six).unwrap();
    // The robust filter with --no-mag on the 9-axis file is the robust filter on the 6-axis one.
    let (code, err) = run_in(dir, &["orient", "nine.csv", "--no-mag", "--out", "a.csv"]);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = run_in(dir, &["orient", "six.csv", "--out", "b.csv"]);
    assert_eq!(code, Some(0), "{err}");
    let body = |name: &str| -> Vec<String> {
        std::fs::read_to_string(dir.join(name))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_owned)
            .collect()
    };
    assert_eq!(body("a.csv"), body("b.csv"));
    let (code, err) = run_in(dir, &["orient", "nine.csv", "--out", "c.csv"]);
    assert_eq!(code, Some(0), "{err}");
    assert_ne!(
        body("a.csv"),
        body("c.csv"),
        "without --no-mag the magnetometer is used"
    );
    for (args, code_wanted, needle) in [
        (
            &[
                "orient",
                "nine.csv",
                "--filter",
                "imufilter",
                "--out",
                "x.csv",
            ][..],
            0,
            "the imufilter filter uses no magnetometer: the file's mag_* columns are ignored",
        ),
        (
            &[
                "orient",
                "nine.csv",
                "--filter",
                "ahrsfilter",
                "--no-mag",
                "--out",
                "x.csv",
            ][..],
            65,
            "--no-mag: the ahrsfilter filter needs a magnetometer; for 6D use robust",
        ),
        (
            &[
                "orient", "six.csv", "--filter", "ecompass", "--out", "x.csv",
            ][..],
            65,
            "the ecompass filter needs a magnetometer and this file has none",
        ),
        (
            &[
                "orient",
                "six.csv",
                "--filter",
                "madgwick",
                "--param",
                "Bta=false",
                "--out",
                "x.csv",
            ][..],
            65,
            "Bta: unknown setting for madgwick; known: SampleRate, Beta",
        ),
    ] {
        let (code, err) = run_in(dir, args);
        assert_eq!(code, Some(code_wanted), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        let _ = std::fs::remove_file(dir.join("x.csv"));
    }
    // With --no-mag, imufilter on the 9-axis file says nothing: 6D is what was asked.
    let (code, err) = run_in(
        dir,
        &[
            "orient",
            "nine.csv",
            "--filter",
            "imufilter",
            "--no-mag",
            "--out",
            "x.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("warning"), "{err}");
}
