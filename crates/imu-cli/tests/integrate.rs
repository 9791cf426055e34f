//! `imukit integrate` and `compare`: the loop from a simulation back to its truth, flat and WGS-84.
use crate::common::{imukit, run_in, table_text, temp_dir};

/// A folder with a helix simulated in NED at 400 Hz: `helix.toml`, `imu.csv`, `truth.csv`.
fn helix(name: &str) -> tempfile::TempDir {
    let dir = temp_dir(name);
    std::fs::write(
        dir.path().join("helix.toml"),
        "rate_hz = 400.0\nduration_s = 10.0\nnav_frame = \"NED\"\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"5*cos(0.5*t)\", \"5*sin(0.5*t)\", \"-0.3*t\"]\nyaw_rad = \"0.5*t + pi/2\"\n\
         pitch_rad = \"0.05\"\nroll_rad = \"0.4*sin(1.7*t)\"\n",
    )
    .unwrap();
    ok(
        dir.path(),
        &[
            "simulate",
            "helix.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
        ],
    );
    dir
}

/// The largest position error `imukit compare TRUTH ESTIMATE` reports, m, and its report.
fn max_position_error(dir: &std::path::Path, truth: &str, estimate: &str) -> (f64, String) {
    let report = ok(dir, &["compare", truth, estimate]);
    let max = report
        .lines()
        .find(|l| l.starts_with("position"))
        .and_then(|l| l.split_whitespace().nth(3))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    (max, report)
}

/// A folder with the built-in `gnss-car` simulated: `car.toml`, `imu.csv`, `truth.csv`, `gnss.csv`.
fn gnss_car(name: &str) -> tempfile::TempDir {
    let dir = temp_dir(name);
    let toml = ok(dir.path(), &["scenario", "gnss-car"]);
    std::fs::write(dir.path().join("car.toml"), toml).unwrap();
    ok(
        dir.path(),
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
    dir
}

/// Runs `imukit` in `dir`, asserts it succeeds, and returns its standard output.
fn ok(dir: &std::path::Path, args: &[&str]) -> String {
    let out = imukit().current_dir(dir).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn simulate_integrate_compare_closes_the_loop() {
    let dir = helix("loop");
    let dir = dir.path();
    let run = |args: &[&str]| ok(dir, args);
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
}

/// The files say what they hold (NED, flat Earth, gravity, sign), so no flag is needed.
#[test]
fn integrate_takes_the_frame_from_the_files() {
    let dir = helix("described");
    let dir = dir.path();
    let run = |args: &[&str]| ok(dir, args);
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
    // The same numbers as with the flag, from CSV and from Parquet alike.
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
}

/// A flag or an input that contradicts what the files say is refused by name, and nothing is
/// written.
#[test]
fn integrate_refuses_a_flag_or_an_input_that_contradicts_the_files() {
    let dir = helix("contradicted");
    let dir = dir.path();
    ok(dir, &["simulate", "helix.toml", "--out", "imu.parquet"]);
    let readings = std::fs::read_to_string(dir.join("imu.csv")).unwrap();
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
    let (max_position, report) = max_position_error(dir, "truth.csv", "nav.csv");
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

/// `--start-s` and `--end-s` cut every input of a command at the same instants, counted from
/// the first sample: a windowed integration starts from the reference's row where the window
/// starts and is the integration of those rows alone.
#[test]
fn a_time_window_cuts_every_input_at_the_same_instants() {
    let dir = gnss_car("window");
    let dir = dir.path();
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
}

#[test]
fn a_window_without_rows_or_the_wrong_way_round_is_refused_by_name() {
    let dir = gnss_car("empty-window");
    let dir = dir.path();
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
