//! Outputs under faults, as a user meets them: a real process interrupted by a real signal, two
//! real processes writing one name, links planted beside an output, and a command whose last
//! output fails. Never a partial file, a mixed file, a write through a link, or half of a
//! command's outputs.
use crate::common::run_in;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-outputs-{name}-"))
        .tempdir()
        .unwrap()
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// A scenario of `seconds` at 1 kHz: long enough to be interrupted while it writes.
fn scenario(dir: &Path, name: &str, seconds: f64, builtin: &str) -> String {
    std::fs::write(
        dir.join(name),
        format!(
            "rate_hz = 1000.0\nduration_s = {seconds}\n[trajectory]\ntype = \"builtin\"\nname = \"{builtin}\"\n"
        ),
    )
    .unwrap();
    name.to_string()
}

/// Sends `signal` (a name `kill` takes) to the process.
fn send(signal: &str, pid: u32) {
    let status = Command::new("kill")
        .args([format!("-{signal}"), pid.to_string()])
        .status()
        .unwrap();
    assert!(status.success(), "kill -{signal} {pid}");
}

#[test]
fn a_signal_removes_every_output_begun_and_exits_with_the_conventional_status() {
    let dir = temp_dir("signals");
    let dir = dir.path();
    let long = scenario(dir, "long.toml", 3000.0, "figure8");
    for (signal, status) in [("INT", 130), ("TERM", 143), ("HUP", 129)] {
        for outputs in [
            vec!["--out", "o.csv", "--truth", "t.parquet"],
            vec!["--out", "o.npy", "--truth", "t.npz"],
            vec!["--out", "o.parquet", "--runs", "3"],
        ] {
            let mut child = imukit()
                .current_dir(dir)
                .arg("simulate")
                .arg(&long)
                .args(&outputs)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap();
            // Interrupted once it has written for a while (the files grow meanwhile).
            std::thread::sleep(Duration::from_millis(700));
            send(signal, child.id());
            let waited = Instant::now();
            let code = child.wait().unwrap().code();
            assert_eq!(code, Some(status), "{signal} {outputs:?}");
            assert!(waited.elapsed() < Duration::from_secs(10));
            assert_eq!(names(dir), ["long.toml"], "{signal} {outputs:?}");
        }
    }
}

#[test]
fn an_interrupted_navigation_leaves_no_output_and_its_inputs_as_they_were() {
    let dir = temp_dir("signals-integrate");
    let dir = dir.path();
    let s = scenario(dir, "s.toml", 200.0, "figure8");
    let made = imukit()
        .current_dir(dir)
        .args(["simulate", &s, "--out", "imu.csv", "--truth", "truth.csv"])
        .output()
        .unwrap();
    assert!(made.status.success());
    let before = std::fs::read(dir.join("imu.csv")).unwrap();
    let mut child = imukit()
        .current_dir(dir)
        .args([
            "integrate",
            "imu.csv",
            "--init",
            "truth.csv",
            "--scheme",
            "rk4",
            "--substeps",
            "1000",
            "--out",
            "nav.parquet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    send("INT", child.id());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert_eq!(names(dir), ["imu.csv", "s.toml", "truth.csv"]);
    assert_eq!(std::fs::read(dir.join("imu.csv")).unwrap(), before);
}

#[test]
fn two_processes_writing_one_name_leave_one_whole_file_of_one_of_them() {
    let dir = temp_dir("two-writers");
    let dir = dir.path();
    let a = scenario(dir, "a.toml", 20.0, "figure8");
    let b = scenario(dir, "b.toml", 30.0, "tilted-circle");
    for (s, out) in [
        (&a, "a.csv"),
        (&b, "b.csv"),
        (&a, "a.parquet"),
        (&b, "b.parquet"),
    ] {
        let ok = imukit()
            .current_dir(dir)
            .args(["simulate", s, "--out", out])
            .output()
            .unwrap();
        assert!(ok.status.success());
    }
    let whole = |ext: &str| {
        (
            std::fs::read(dir.join(format!("a.{ext}"))).unwrap(),
            std::fs::read(dir.join(format!("b.{ext}"))).unwrap(),
        )
    };
    let mut winners = [0, 0];
    for k in 0..20 {
        let ext = if k % 2 == 0 { "csv" } else { "parquet" };
        let same = format!("same.{ext}");
        let spawn = |s: &str| {
            imukit()
                .current_dir(dir)
                .args(["simulate", s, "--out", &same])
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (first, second) = (spawn(&a), spawn(&b));
        for child in [first, second] {
            let out = child.wait_with_output().unwrap();
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let got = std::fs::read(dir.join(&same)).unwrap();
        let (wa, wb) = whole(ext);
        if got == wa {
            winners[0] += 1;
        } else if got == wb {
            winners[1] += 1;
        } else {
            panic!(
                "try {k}: {same} is neither run's file ({} bytes)",
                got.len()
            );
        }
        assert!(!names(dir).iter().any(|n| n.contains("imukit-partial")));
    }
    assert_eq!(winners[0] + winners[1], 20);
}

#[cfg(unix)]
#[test]
fn links_planted_beside_an_output_are_never_written_through() {
    let dir = temp_dir("links");
    let dir = dir.path();
    let s = scenario(dir, "s.toml", 1.0, "figure8");
    std::fs::write(dir.join("victim.txt"), "keep me").unwrap();
    // At the name the temporary file once had, and at the output itself.
    std::os::unix::fs::symlink("victim.txt", dir.join("o.csv.imukit-partial")).unwrap();
    std::os::unix::fs::symlink("s.toml", dir.join("t.csv.imukit-partial")).unwrap();
    std::os::unix::fs::symlink("victim.txt", dir.join("p.csv")).unwrap();
    // A link to a device is replaced too (only the system's own, /dev/stdout, are written
    // through): run as root, a link to a disk would otherwise be a write to the disk.
    std::os::unix::fs::symlink("/dev/null", dir.join("q.csv")).unwrap();
    let before = std::fs::read(dir.join("s.toml")).unwrap();
    for out in ["o.csv", "p.csv", "q.csv"] {
        let run = imukit()
            .current_dir(dir)
            .args(["simulate", &s, "--out", out, "--truth", "t.csv"])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let meta = std::fs::symlink_metadata(dir.join(out)).unwrap();
        assert!(meta.file_type().is_file(), "{out} is a file, not a link");
        assert!(
            std::fs::read_to_string(dir.join(out))
                .unwrap()
                .contains("}\nt_s,")
        );
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("victim.txt")).unwrap(),
        "keep me"
    );
    assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
    // The system's own links are written through: the table goes to standard output.
    let out = imukit()
        .current_dir(dir)
        .args(["simulate", &s, "--out", "/dev/stdout"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with("# imukit: {\"kind\": \"readings\""));
    assert_eq!(
        stdout.lines().nth(1),
        Some(
            "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,mag_x_ut,mag_y_ut,mag_z_ut"
        )
    );
    assert_eq!(std::fs::read(dir.join("s.toml")).unwrap(), before);
}

#[test]
fn a_command_whose_last_output_fails_puts_none_of_them_in_place() {
    let dir = temp_dir("all-or-none");
    let dir = dir.path();
    let s = scenario(dir, "s.toml", 1.0, "figure8");
    std::fs::write(dir.join("o.csv"), "an older file").unwrap();
    // The truth's folder does not exist: the readings must not be written either, and the
    // older file stays as it was.
    let run = imukit()
        .current_dir(dir)
        .args(["simulate", &s, "--out", "o.csv", "--truth", "nope/t.csv"])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(74));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("nope/t.csv"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.join("o.csv")).unwrap(),
        "an older file"
    );
    assert_eq!(names(dir), ["o.csv", "s.toml"]);
    // A study whose figure cannot be written leaves no table.
    let study = dir.join("st.toml");
    let tunnel = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    std::fs::write(
        &study,
        format!(
            "scenario = {:?}\npresets = [\"ideal\"]\nruns = 2\n",
            tunnel.display().to_string()
        ),
    )
    .unwrap();
    let run = imukit()
        .current_dir(dir)
        .args([
            "study",
            "st.toml",
            "--out",
            "st.csv",
            "--plot",
            "nope/st.png",
        ])
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(74),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(names(dir), ["o.csv", "s.toml", "st.toml"]);
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
