//! `imukit orient` as a user runs it: smoothing a whole log after the fact.
use crate::common::{imukit, table_text, temp_dir};
use std::path::Path;
use std::process::Command;

fn run_in(dir: &Path, args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_imukit"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// The RMS attitude error (degrees) `imukit compare` prints for an estimate against the truth.
fn rms_attitude_error(dir: &Path, estimate: &str) -> f64 {
    let out = Command::new(env!("CARGO_BIN_EXE_imukit"))
        .args(["compare", "truth.csv", estimate])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with("attitude"))
        .unwrap_or_else(|| panic!("{text}"));
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

/// `--smooth` runs the robust filter forward and backward over the whole file: as many rows as
/// samples, with the status columns, closer to the truth than the forward pass alone on MATLAB's
/// turning platform; another filter with `--smooth` is refused naming the flag.
#[test]
fn orient_smooth_smooths_the_whole_run() {
    let dir = tempfile::Builder::new()
        .prefix("imukit-cli-orient-smooth-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let scenario =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/matlab_orientation.toml");
    std::fs::copy(&scenario, dir.join("m.toml")).unwrap();
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "m.toml",
            "--out",
            "imu.csv",
            "--truth",
            "truth.csv",
        ],
    );
    assert_eq!(code, Some(0), "{err}");
    for (out, extra) in [("forward.csv", None), ("smooth.csv", Some("--smooth"))] {
        let mut args = vec!["orient", "imu.csv", "--out", out];
        args.extend(extra);
        let (code, err) = run_in(dir, &args);
        assert_eq!(code, Some(0), "{err}");
        if extra.is_some() {
            assert!(err.contains("(smoothed)"), "{err}");
        }
    }
    let rows = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .count()
    };
    assert_eq!(rows("smooth.csv"), rows("forward.csv"));
    let header = std::fs::read_to_string(dir.join("smooth.csv")).unwrap();
    assert!(header.contains("accel_rejected"), "status columns");
    let (forward, smooth) = (
        rms_attitude_error(dir, "forward.csv"),
        rms_attitude_error(dir, "smooth.csv"),
    );
    assert!(
        smooth < forward,
        "smoothed {smooth}°, forward {forward}° RMS"
    );
    let (code, err) = run_in(
        dir,
        &[
            "orient", "imu.csv", "--filter", "madgwick", "--smooth", "--out", "x.csv",
        ],
    );
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("--smooth: only the robust filter smooths a run, not madgwick"),
        "{err}"
    );
    assert!(!dir.join("x.csv").exists());
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
