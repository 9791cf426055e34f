//! `imukit demo`, `simulate` and `exercise` as a user runs them: outputs, threads, built-ins.
use crate::common::{imukit, run_in, table_text, temp_dir};

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
fn a_random_vibration_writes_the_truth_per_run_and_sines_once() {
    let dir = temp_dir("vibration-runs");
    let dir = dir.path();
    let scenario = |vibration: &str| {
        format!(
            "rate_hz = 100.0\nduration_s = 1.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
             [imu]\nkind = \"accel-gyro\"\n[imu.vibration]\n{vibration}\n"
        )
    };
    std::fs::write(
        dir.join("random.toml"),
        scenario(
            "random = [{ kind = \"angular-rate\", axis = \"x\", psd = [[5, 1e-4], [40, 1e-4]] }]",
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("sine.toml"),
        scenario("sines = [{ kind = \"angular-rate\", axis = \"x\", frequency_hz = 7, amplitude = 0.2 }]"),
    )
    .unwrap();
    let args = |s: &'static str, out: &'static str, truth: &'static str| {
        ["simulate", s, "--out", out, "--truth", truth, "--runs", "2"]
    };
    let (code, err) = run_in(dir, &args("random.toml", "r.csv", "rt.csv"));
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("rt_run0000.csv … rt_run0001.csv"), "{err}");
    assert!(!dir.join("rt.csv").exists());
    let column = |file: &str, name: &str| {
        let t = ::imukit::io::read::read_table(dir.join(file)).unwrap();
        t.column(name).unwrap()
    };
    // Each run's truth says what its own vibration did: the gyroscope (ideal, at rest) reads it.
    for r in 0..2 {
        let (reading, shaken) = (
            column(&format!("r_run000{r}.csv"), "gyro_x_rad_s"),
            column(&format!("rt_run000{r}.csv"), "vib_gyro_x_rad_s"),
        );
        assert!(
            reading
                .iter()
                .zip(&shaken)
                .all(|(a, b)| (a - b).abs() < 1e-9),
            "run {r}"
        );
    }
    assert!(
        column("rt_run0000.csv", "vib_gyro_x_rad_s")
            != column("rt_run0001.csv", "vib_gyro_x_rad_s")
    );
    // Sines are the same in every run: one truth file.
    let (code, err) = run_in(dir, &args("sine.toml", "s.csv", "st.csv"));
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.join("st.csv").exists() && !dir.join("st_run0000.csv").exists());
    // A truth per run may not overwrite another output.
    let (code, err) = run_in(
        dir,
        &[
            "simulate",
            "random.toml",
            "--out",
            "x.csv",
            "--truth",
            "x.csv",
            "--runs",
            "2",
        ],
    );
    assert_eq!(code, Some(65), "{err}");
}
