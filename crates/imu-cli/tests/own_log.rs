//! A user's own log with nothing else: `imukit fuse walk.csv --zupt --out nav.csv` learns the
//! sensor's noise from the log, levels over the rest at the start and closes a walk's loop; a
//! part whose figures the log contradicts, and a log with no stances, are said so.
use std::path::Path;
use std::process::Command;

fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

/// Ten seconds standing, then 45 strides around a 10 m circle (one lap, 62.8 m) with an IMU
/// three times noisier than any preset and a 0.03 g accelerometer bias.
const WALK: &str = r#"
rate_hz = 100.0
duration_s = 60.0
nav_frame = "ENU"
[trajectory]
type = "walk"
cadence_hz = 0.9
stride_m = 1.3962634015954636
radius_m = 10.0
start_s = 10.0
[imu]
kind = "accel-gyro"
preset = "icm-42688-p"
seed = 5
[imu.accelerometer]
noise_density_m_s2_per_rt_hz = 0.0117680
constant_bias_m_s2 = [0.3, -0.2, 0.25]
[imu.gyroscope]
noise_density_rad_s_per_rt_hz = 0.00036652
"#;

fn last_position(path: &Path) -> [f64; 3] {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let last: Vec<f64> = lines
        .next_back()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    [
        last[at("pos_x_m")],
        last[at("pos_y_m")],
        last[at("pos_z_m")],
    ]
}

#[test]
fn a_walk_is_fused_from_its_readings_alone() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("walk.toml");
    std::fs::write(&scenario, WALK).unwrap();
    let walk = dir.path().join("walk.csv");
    let out = imukit()
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&walk)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let nav = dir.path().join("nav.csv");
    let out = imukit()
        .arg("fuse")
        .arg(&walk)
        .arg("--zupt")
        .arg("--out")
        .arg(&nav)
        .output()
        .unwrap();
    let log = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{log}");
    assert!(log.contains("white noise learnt from the log"), "{log}");
    assert!(log.contains("15 states"), "{log}");
    assert!(!log.contains("warning"), "{log}");
    // Levelled at the end of the rest, at the origin; one lap later back there, within
    // 0.5 % of the 62.8 m walked.
    let end = last_position(&nav);
    let off = end.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(off < 0.005 * 62.83, "ended {off} m from the start: {end:?}");

    // The part named is quieter than the log: said, and the detectors still find the stances.
    let out = imukit()
        .arg("fuse")
        .arg(&walk)
        .args(["--zupt", "--imu", "icm-42688-p", "--out"])
        .arg(&nav)
        .output()
        .unwrap();
    let log = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("warning") && log.contains("× (accelerometer)"),
        "{log}"
    );
    assert!(!log.contains("--zupt found"), "{log}");

    // A hand-held log with a rest and no steps: --zupt finds almost no stances and says so.
    let still = dir.path().join("still.toml");
    std::fs::write(
        &still,
        "rate_hz = 100.0\nduration_s = 30.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"0.3*(1 - cos(2*max(t - 5, 0)))\", \"0\", \"0\"]\nattitude = \"level\"\n\
         [imu]\npreset = \"icm-42688-p\"\nseed = 1\n",
    )
    .unwrap();
    let hand = dir.path().join("hand.csv");
    let out = imukit()
        .arg("simulate")
        .arg(&still)
        .arg("--out")
        .arg(&hand)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = imukit()
        .arg("fuse")
        .arg(&hand)
        .args(["--zupt", "--out"])
        .arg(&nav)
        .output()
        .unwrap();
    let log = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{log}");
    assert!(log.contains("--zupt found"), "{log}");
}

/// A logger's exact copies of its last sample (x-io's NGIMU writes them) are dropped and said
/// by every job that reads readings, with the same numbers as the log without them; a repeated
/// time with other readings is refused, naming the file and the row.
#[test]
fn every_job_drops_a_loggers_repeated_rows_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let header =
        "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s";
    let row = |k: u32| {
        let x = f64::from(k);
        format!(
            "{},{},{},{},{},{},{}",
            x * 0.01,
            0.01 * (0.7 * x).sin(),
            0.01 * (1.3 * x).cos(),
            9.81 + 0.01 * (0.9 * x).sin(),
            1e-3 * (1.1 * x).sin(),
            1e-3 * (0.5 * x).cos(),
            1e-3 * (0.3 * x).sin()
        )
    };
    let rows: Vec<String> = (0..2000).map(row).collect();
    let mut repeated = rows.clone();
    // File rows 12 and 503 (header 1) copy the row before.
    repeated.insert(10, rows[9].clone());
    repeated.insert(501, rows[499].clone());
    std::fs::write(
        dir.join("clean.csv"),
        format!("{header}\n{}\n", rows.join("\n")),
    )
    .unwrap();
    std::fs::write(
        dir.join("copies.csv"),
        format!("{header}\n{}\n", repeated.join("\n")),
    )
    .unwrap();
    for job in [
        vec!["orient", "--out"],
        vec!["integrate", "--out"],
        vec!["allan", "--out"],
    ] {
        let run = |input: &str, out: &str| {
            imukit()
                .current_dir(dir)
                .args([job[0], input, job[1], out])
                .output()
                .unwrap()
        };
        let out = run("copies.csv", "copies_out.csv");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{job:?}: {err}");
        assert!(
            err.contains("copies.csv: 2 rows repeat the row before exactly")
                && err.contains("the first at row 12"),
            "{job:?}: {err}"
        );
        assert!(run("clean.csv", "clean_out.csv").status.success());
        let body = |name: &str| {
            let text = std::fs::read_to_string(dir.join(name)).unwrap();
            text.lines()
                .filter(|l| !l.starts_with('#'))
                .map(str::to_owned)
                .collect::<Vec<_>>()
        };
        assert_eq!(body("copies_out.csv"), body("clean_out.csv"), "{job:?}");
    }
    // The same time with other readings is no copy.
    let mut other = rows.clone();
    other.insert(10, rows[9].replace(",9.81", ",9.7"));
    std::fs::write(
        dir.join("other.csv"),
        format!("{header}\n{}\n", other.join("\n")),
    )
    .unwrap();
    let out = imukit()
        .current_dir(dir)
        .args(["orient", "other.csv", "--out", "o.csv"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(65), "{err}");
    assert!(
        err.contains("other.csv: time at row 12 does not increase"),
        "{err}"
    );
    assert!(!dir.join("o.csv").exists());
}
