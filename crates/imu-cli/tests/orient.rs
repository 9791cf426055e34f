//! `imukit orient` as a user runs it: smoothing a whole log after the fact.
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
