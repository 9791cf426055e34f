//! `imukit fuse` and `study` as a user runs them: fixes, aids, starts, the WGS-84 Earth, a walk.
use crate::common::{imukit, run_in, table_text, temp_dir};

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

/// A levelling over a "rest" whose specific force is twice gravity is refused by the start that
/// was asked for, and nothing is written.
#[test]
fn fuse_refuses_a_levelling_over_a_rest_that_is_not_one() {
    let tmp = temp_dir("level");
    let dir = tmp.path();
    let mut accelerating = String::from(
        "t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2\n",
    );
    for i in 0..300 {
        accelerating.push_str(&format!("{},0,0,0,0,0,19.6\n", f64::from(i) / 100.0));
    }
    std::fs::write(dir.join("pushed.csv"), accelerating).unwrap();
    let args = [
        "fuse",
        "pushed.csv",
        "--imu",
        "stim300",
        "--align",
        "level",
        "--rest-s",
        "1",
        "--out",
        "level.csv",
    ];
    let (code, err) = run_in(dir, &args);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("--align: \"level\": the mean specific force is 19.600"),
        "{err}"
    );
    assert!(!dir.join("level.csv").exists());
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
