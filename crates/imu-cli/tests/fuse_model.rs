//! One meaning per number: the filter's model stated as options (`--imu` and the `--gnss-*`
//! figures) is the scenario's `[imu]` and `[gnss]` with the same figures, to the byte.
use std::path::Path;
use std::process::Command;

fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

/// `example` simulated into `dir`: `imu.csv`, and with `fixes` also `truth.csv` and `gnss.csv`.
fn simulate_drive(example: &Path, dir: &Path, fixes: bool) {
    let mut c = imukit();
    c.arg("simulate")
        .arg(example)
        .arg("--out")
        .arg(dir.join("imu.csv"));
    if fixes {
        c.arg("--truth")
            .arg(dir.join("truth.csv"))
            .arg("--gnss")
            .arg(dir.join("gnss.csv"));
    }
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `imukit fuse` of the drive simulated into `dir`: its `imu.csv`, the fixes `gnss`, from the
/// first row of `truth.csv`, with `extra` arguments, the estimate to `dir/out`.
fn fuse_drive(dir: &Path, gnss: &str, extra: &[&str], out: &str) -> std::process::Output {
    imukit()
        .arg("fuse")
        .arg(dir.join("imu.csv"))
        .arg(dir.join(gnss))
        .arg("--init")
        .arg(dir.join("truth.csv"))
        .args(extra)
        .arg("--out")
        .arg(dir.join(out))
        .output()
        .unwrap()
}

#[test]
fn a_part_and_receiver_stated_as_options_fuse_as_the_scenario_does() {
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    let file = |name: &str| dir.path().join(name);
    simulate_drive(&example, dir.path(), true);
    let fuse = |extra: &[&str], to: &str| {
        let out = fuse_drive(dir.path(), "gnss.csv", extra, to);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read(file(to)).unwrap()
    };
    let by_scenario = fuse(&["--scenario", example.to_str().unwrap()], "s.csv");
    // car_tunnel.toml: stim300, 1.5 m / 3 m / 0.1 m/s, decay factor 0.
    let stated = [
        "--imu",
        "stim300",
        "--gnss-horizontal-accuracy-m",
        "1.5",
        "--gnss-vertical-accuracy-m",
        "3",
        "--gnss-velocity-accuracy-m-s",
        "0.1",
    ];
    let by_options = fuse(
        &[&stated[..], &["--gnss-decay-factor", "0"]].concat(),
        "p.csv",
    );
    assert!(by_scenario == by_options, "the two estimates differ");
    // Left out, the decay factor is MATLAB's 0.999, as in a scenario without the key: another
    // receiver, another estimate.
    let matlab = fuse(&stated, "m.csv");
    assert!(matlab != by_scenario);
    // A latency that is not one is refused by its option.
    let out = fuse_drive(
        dir.path(),
        "gnss.csv",
        &[&stated[..], &["--gnss-latency-s", "-1"]].concat(),
        "x.csv",
    );
    let log = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(65), "{log}");
    assert!(log.contains("--gnss-latency-s"), "{log}");
}

#[test]
fn geodetic_fixes_read_on_the_flat_earth_point_at_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    let file = |name: &str| dir.path().join(name);
    simulate_drive(&example, dir.path(), false);
    // A receiver's log as users have it: geodetic, without imukit's description.
    let mut fixes = String::from("t_s,lat_rad,lon_rad,height_m,vel_x_m_s,vel_y_m_s,vel_z_m_s\n");
    for k in 1..20 {
        fixes += &format!("{k}.0,0.8,0.2,100.0,5.0,0.0,0.0\n");
    }
    std::fs::write(file("fixes.csv"), fixes).unwrap();
    let out = imukit()
        .arg("fuse")
        .arg(file("imu.csv"))
        .arg(file("fixes.csv"))
        .args(["--imu", "stim300", "--align", "gnss", "--out"])
        .arg(file("nav.csv"))
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(65), "{log}");
    assert!(
        log.contains("fixes.csv") && log.contains("--earth wgs84"),
        "{log}"
    );
}

#[test]
fn a_receivers_per_axis_sigmas_are_read_as_its_horizontal_and_vertical_accuracy_are() {
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    let file = |name: &str| dir.path().join(name);
    simulate_drive(&example, dir.path(), true);
    // The same fixes with their own accuracy, stated two ways (1.2 m across, 2.5 m up).
    let with = |name: &str, header: &str, values: &str| {
        let text = std::fs::read_to_string(file("gnss.csv")).unwrap();
        let mut seen_header = false;
        let body: String = text
            .lines()
            .map(|l| {
                if l.starts_with('#') {
                    format!("{l}\n")
                } else if !seen_header {
                    seen_header = true;
                    format!("{l},{header}\n")
                } else {
                    format!("{l},{values}\n")
                }
            })
            .collect();
        std::fs::write(file(name), body).unwrap();
    };
    with(
        "split.csv",
        "horizontal_accuracy_m,vertical_accuracy_m",
        "1.2,2.5",
    );
    with(
        "axes.csv",
        "pos_x_sigma_m,pos_y_sigma_m,pos_z_sigma_m",
        "1.2,1.2,2.5",
    );
    with("partial.csv", "pos_x_sigma_m,pos_y_sigma_m", "1.2,1.2");
    let scenario = ["--scenario", example.to_str().unwrap()];
    let fuse = |fixes: &str, to: &str| fuse_drive(dir.path(), fixes, &scenario, to);
    for (fixes, to) in [("split.csv", "a.csv"), ("axes.csv", "b.csv")] {
        let out = fuse(fixes, to);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert!(std::fs::read(file("a.csv")).unwrap() == std::fs::read(file("b.csv")).unwrap());
    let out = fuse("partial.csv", "c.csv");
    let log = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(65), "{log}");
    assert!(
        log.contains("partial.csv") && log.contains("missing pos_z_sigma_m"),
        "{log}"
    );
}

#[test]
fn a_receiver_worse_than_stated_is_scaled_with_gnss_adaptive_and_said_so() {
    // The tunnel road's fixes drawn three times worse than the receiver the filter is told of
    // (white, 4.5 m / 9 m / 0.3 m/s against 1.5 m / 3 m / 0.1 m/s): taken as stated the filter
    // loses them; with --gnss-adaptive it scales their noise, is never reset and says by how much.
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    let text = std::fs::read_to_string(&example)
        .unwrap()
        .replace("horizontal_accuracy_m = 1.5", "horizontal_accuracy_m = 4.5")
        .replace("vertical_accuracy_m = 3.0", "vertical_accuracy_m = 9.0")
        .replace("velocity_accuracy_m_s = 0.1", "velocity_accuracy_m_s = 0.3");
    let worse = dir.path().join("worse.toml");
    std::fs::write(&worse, text).unwrap();
    simulate_drive(&worse, dir.path(), true);
    let scenario = ["--scenario", example.to_str().unwrap()];
    let fuse = |extra: &[&str], to: &str| {
        fuse_drive(dir.path(), "gnss.csv", &[&scenario[..], extra].concat(), to)
    };
    let stated = fuse(&[], "stated.csv");
    let log = String::from_utf8_lossy(&stated.stderr).to_string();
    assert!(
        !stated.status.success() || log.contains("reset to them"),
        "{log}"
    );
    let adaptive = fuse(&["--gnss-adaptive"], "adaptive.csv");
    let log = String::from_utf8_lossy(&adaptive.stderr).to_string();
    assert!(adaptive.status.success(), "{log}");
    assert!(!log.contains("reset to them"), "{log}");
    let note = log
        .lines()
        .find(|l| l.contains("noisier than stated"))
        .unwrap_or_else(|| panic!("{log}"));
    // The one-sigmas scaled by about the factor the fixes are worse (3), within the bound (5).
    let factor: f64 = note
        .split("were ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap();
    assert!((2.0..=5.0).contains(&factor), "{note}");
}

#[test]
fn a_receivers_own_column_names_and_accuracies_are_read_through_gnss_map() {
    // The tunnel road's fixes under a vendor's names, each with per-axis standard deviations
    // (`pos_std_1..3`): through `--gnss-map` they fuse as the same file under imukit's names.
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/car_tunnel.toml");
    simulate_drive(&example, dir.path(), true);
    let file = |name: &str| dir.path().join(name);
    let text = std::fs::read_to_string(file("gnss.csv")).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    let sigma = |k: usize| format!("{}", 1.0 + 0.5 * (k % 3) as f64);
    let (mut ours, mut theirs) = (
        String::from(
            "t_s,pos_x_m,pos_y_m,pos_z_m,vel_x_m_s,vel_y_m_s,vel_z_m_s,pos_x_sigma_m,pos_y_sigma_m,pos_z_sigma_m\n",
        ),
        String::from("gps_time,e,n,u,ve,vn,vu,pos_std_1,pos_std_2,pos_std_3\n"),
    );
    for (k, r) in rows.iter().enumerate() {
        let line = format!("{r},{},{},{}\n", sigma(k), sigma(k + 1), sigma(k + 2));
        ours.push_str(&line);
        theirs.push_str(&line);
    }
    std::fs::write(file("ours.csv"), ours).unwrap();
    std::fs::write(file("theirs.csv"), theirs).unwrap();
    std::fs::write(
        file("receiver.map.toml"),
        "time = { column = \"gps_time\", unit = \"s\" }\n[columns]\n\
         pos_x_m = \"e\"\npos_y_m = \"n\"\npos_z_m = \"u\"\n\
         vel_x_m_s = \"ve\"\nvel_y_m_s = \"vn\"\nvel_z_m_s = \"vu\"\n\
         pos_x_sigma_m = \"pos_std_1\"\npos_y_sigma_m = \"pos_std_2\"\npos_z_sigma_m = \"pos_std_3\"\n",
    )
    .unwrap();
    let scenario = ["--scenario", example.to_str().unwrap()];
    let fuse = |gnss: &str, extra: &[&str], to: &str| {
        let out = fuse_drive(dir.path(), gnss, &[&scenario[..], extra].concat(), to);
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (ok, log) = fuse("ours.csv", &[], "ours_nav.csv");
    assert!(ok, "{log}");
    let map = file("receiver.map.toml");
    let (ok, log) = fuse(
        "theirs.csv",
        &["--gnss-map", map.to_str().unwrap()],
        "theirs_nav.csv",
    );
    assert!(ok, "{log}");
    assert_eq!(
        std::fs::read(file("ours_nav.csv")).unwrap(),
        std::fs::read(file("theirs_nav.csv")).unwrap()
    );
    // Without the map the vendor's file is refused, its missing columns named; a map naming a
    // column imukit does not read is refused by map and key.
    let (ok, log) = fuse("theirs.csv", &[], "never.csv");
    assert!(!ok && log.contains("pos_x_m"), "{log}");
    std::fs::write(
        file("typo.map.toml"),
        "time = { column = \"gps_time\", unit = \"s\" }\n[columns]\npos_x_sigma = \"pos_std_1\"\n",
    )
    .unwrap();
    let typo = file("typo.map.toml");
    let (ok, log) = fuse(
        "theirs.csv",
        &["--gnss-map", typo.to_str().unwrap()],
        "never.csv",
    );
    assert!(
        !ok && log.contains("columns.pos_x_sigma") && log.contains("typo.map.toml"),
        "{log}"
    );
    assert!(!file("never.csv").exists());
}
