//! Scenario files end to end: parsing, built-ins, samples files, and the errors users meet.
use std::path::Path;

use imukit::io::columns::TRUTH_COLUMNS;
use imukit::io::read::read_columns;
use imukit::scenario::builtin;
use imukit::{Error, Scenario, ScenarioSpec, Table};

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-test-{name}-"))
        .tempdir()
        .unwrap()
}

fn run_toml(text: &str, dir: &Path) -> Result<imukit::Simulation, Error> {
    ScenarioSpec::from_toml(text, "test.toml")?
        .resolve(dir)?
        .simulate()
}

const ISSUE_EXAMPLE: &str = r#"
rate_hz = 200.0
duration_s = 1.0
nav_frame = "ENU"
gravity_m_s2 = 9.81
[trajectory]
type = "expression"
constants = { f = 1.0 }
position_m = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
attitude = "tangent"
[imu]
lever_arm_m = [-0.075, -0.075, 0.025]
accel_sign = "specific-force"
magnetic_field_ut = [-2.4169, 27.5550, 16.0849]
"#;

#[test]
fn the_documented_example_runs_with_the_documented_columns() {
    let sim = run_toml(ISSUE_EXAMPLE, Path::new(".")).unwrap();
    assert_eq!(sim.truth.rows(), 201);
    assert_eq!(sim.truth.columns, TRUTH_COLUMNS);
    assert_eq!(
        sim.imu.columns,
        [
            "t_s",
            "accel_x_m_s2",
            "accel_y_m_s2",
            "accel_z_m_s2",
            "gyro_x_rad_s",
            "gyro_y_rad_s",
            "gyro_z_rad_s",
            "mag_x_ut",
            "mag_y_ut",
            "mag_z_ut"
        ]
    );
    let t = sim.truth.column("t_s").unwrap();
    assert_eq!(t[200], 1.0);
    assert_eq!(t[1], 1.0 / 200.0);
    assert!(
        sim.truth
            .data
            .iter()
            .chain(&sim.imu.data)
            .all(|v| v.is_finite())
    );
}

#[test]
fn every_builtin_runs_and_gives_finite_values() {
    for name in builtin::NAMES {
        let spec = builtin::spec(name).unwrap();
        let sim = spec.resolve(Path::new(".")).unwrap().simulate().unwrap();
        assert!(sim.truth.rows() > 100, "{name}");
        assert!(
            sim.truth
                .data
                .iter()
                .chain(&sim.imu.data)
                .all(|v| v.is_finite()),
            "{name}"
        );
    }
}

#[test]
fn platform_turn_spins_at_a_quarter_then_a_half_turn_per_second_about_down() {
    let sim = builtin::spec("platform-turn")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    assert_eq!(sim.truth.rows(), 600);
    let wz = sim.imu.column("gyro_z_rad_s").unwrap();
    let tau = std::f64::consts::TAU;
    assert!((wz[100] - tau / 4.0).abs() < 1e-12 && (wz[500] - tau / 2.0).abs() < 1e-12);
    // NED, at rest: the accelerometer reads −g on z (specific force, z down).
    let az = sim.imu.column("accel_z_m_s2").unwrap();
    assert!(az.iter().all(|a| (a + 9.81).abs() < 1e-12));
}

#[test]
fn rounded_rectangle_lap_returns_to_its_start() {
    let sim = builtin::spec("rounded-rectangle")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    let (x, y) = (
        sim.truth.column("pos_x_m").unwrap(),
        sim.truth.column("pos_y_m").unwrap(),
    );
    let n = x.len() - 1;
    assert!(
        (x[n] - x[0]).abs() < 1e-3 && (y[n] - y[0]).abs() < 1e-3,
        "{} {}",
        x[n],
        y[n]
    );
    // On a straight the gyro is still, on an arc it reads −v/r (clockwise lap).
    let wz = sim.imu.column("gyro_z_rad_s").unwrap();
    assert!(wz[200].abs() < 1e-12);
    let arc_mid = ((0.8 + 0.05 * std::f64::consts::FRAC_PI_2) / 0.8 * 2000.0) as usize;
    assert!((wz[arc_mid] + 8.0).abs() < 1e-9, "{}", wz[arc_mid]);
}

#[test]
fn csv_written_tables_read_back_bit_for_bit_and_feed_a_samples_scenario() {
    let dir = temp_dir("samples");
    let dir = dir.path();
    let exact = builtin::spec("tilted-circle")
        .unwrap()
        .resolve(dir)
        .unwrap()
        .simulate()
        .unwrap();
    let path = dir.join("truth.csv");
    exact.truth.write_csv(&path).unwrap();
    let back = read_columns(&path, &TRUTH_COLUMNS, "").unwrap();
    for c in TRUTH_COLUMNS {
        assert_eq!(
            back.get(c),
            exact.truth.column(c).unwrap().as_slice(),
            "{c}"
        );
    }
    // No partial file is left behind.
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
    let scenario = "[trajectory]\ntype = \"samples\"\nfile = \"truth.csv\"\n";
    let sampled = run_toml(scenario, dir).unwrap();
    for c in ["vel_x_m_s", "acc_z_m_s2", "omega_y_rad_s", "alpha_x_rad_s2"] {
        let (a, b) = (
            sampled.truth.column(c).unwrap(),
            exact.truth.column(c).unwrap(),
        );
        let scale = b.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        let err = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / scale;
        assert!(err < 1e-8, "{c}: {err:e}");
    }
}

fn err_text(r: Result<impl std::fmt::Debug, Error>) -> String {
    r.expect_err("should fail").to_string()
}

#[test]
fn errors_in_a_scenario_name_its_key_and_column() {
    let dir = temp_dir("errors");
    let dir = dir.path();
    // Unknown function, with key and column.
    let bad = ISSUE_EXAMPLE.replace("0.8*sin(2*pi*f*t)", "0.8*sine(2*pi*f*t)");
    let e = err_text(run_toml(&bad, dir));
    assert!(
        e.contains("trajectory.position_m[1]")
            && e.contains("unknown function 'sine'")
            && e.contains("column 5"),
        "{e}"
    );
    // Unknown variable.
    let bad = ISSUE_EXAMPLE.replace("0.3*cos(2*pi*f*t)", "0.3*cos(2*pi*g*t)");
    let e = err_text(run_toml(&bad, dir));
    assert!(
        e.contains("unknown variable 'g'") && e.contains("position_m[2]"),
        "{e}"
    );
    // Unknown key.
    let e = err_text(run_toml(
        &ISSUE_EXAMPLE.replace("gravity_m_s2", "gravity"),
        dir,
    ));
    assert!(
        e.contains("test.toml") && e.contains("unknown field `gravity`"),
        "{e}"
    );
    // Unknown built-in.
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"builtin\"\nname = \"figure9\"\n",
        dir,
    ));
    assert!(e.contains("figure9") && e.contains("figure8"), "{e}");
    // Gimbal lock in an Euler path, with the time.
    let lock = "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\npitch_rad = \"pi/2*t/0.5\"\n";
    let e = err_text(run_toml(lock, dir));
    assert!(e.contains("gimbal lock") && e.contains("t = 0.5 s"), "{e}");
    // Missing rate for an expression.
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\n",
        dir,
    ));
    assert!(e.contains("rate_hz: missing"), "{e}");
    // An attitude mode is one of two names, refused at its line with both.
    let e = err_text(run_toml(
        "rate_hz = 10.0\n[trajectory]\ntype = \"expression\"\nposition_m = [\"t\", 0, 0]\nattitude = \"along\"\n",
        dir,
    ));
    assert!(
        e.contains("line 5")
            && e.contains("unknown variant `along`, expected `tangent` or `level`"),
        "{e}"
    );
}

#[test]
fn errors_in_a_samples_file_name_the_file_row_and_column() {
    let dir = temp_dir("sample-errors");
    let dir = dir.path();
    // Missing columns in a samples file.
    std::fs::write(dir.join("nocols.csv"), "t_s,pos_x_m,pos_y_m\n0,0,0\n").unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"nocols.csv\"\n",
        dir,
    ));
    assert!(
        e.contains("nocols.csv") && e.contains("pos_z_m") && e.contains("yaw_rad"),
        "{e}"
    );
    // NaN with row and column.
    let mut text = String::from("t_s,pos_x_m,pos_y_m,pos_z_m\n");
    for k in 0..20 {
        text += &format!(
            "{},{},0,{}\n",
            k as f64 * 0.1,
            k,
            if k == 4 { "nan" } else { "0" }
        );
    }
    std::fs::write(dir.join("nan.csv"), text).unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"nan.csv\"\nattitude = \"tangent\"\n",
        dir,
    ));
    assert!(
        e.contains("nan.csv, row 6, column pos_z_m") && e.contains("not a finite number"),
        "{e}"
    );
    // Repeated time, with the file row.
    let mut text = String::from("t_s,pos_x_m,pos_y_m,pos_z_m\n");
    for k in 0..20 {
        let t = if k == 9 { 0.8 } else { k as f64 * 0.1 };
        text += &format!("{t},{k},0,0\n");
    }
    std::fs::write(dir.join("rep.csv"), text).unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"rep.csv\"\nattitude = \"tangent\"\n",
        dir,
    ));
    assert!(
        e.contains("rep.csv, row 11") && e.contains("does not increase"),
        "{e}"
    );
    // Too few samples for the stencil.
    std::fs::write(
        dir.join("few.csv"),
        "t_s,pos_x_m,pos_y_m,pos_z_m\n0,0,0,0\n1,1,0,0\n2,2,0,0\n",
    )
    .unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"few.csv\"\nattitude = \"tangent\"\n",
        dir,
    ));
    assert!(
        e.contains("too few samples") && e.contains("need at least 10"),
        "{e}"
    );
    // Truncated row.
    std::fs::write(
        dir.join("trunc.csv"),
        "t_s,pos_x_m,pos_y_m,pos_z_m\n0,0,0,0\n1,1,0\n",
    )
    .unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"trunc.csv\"\nattitude = \"tangent\"\n",
        dir,
    ));
    assert!(e.contains("trunc.csv") && e.contains("row 3"), "{e}");
    // Missing file.
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"absent.csv\"\n",
        dir,
    ));
    assert!(e.contains("absent.csv"), "{e}");
    // Empty file.
    std::fs::write(dir.join("empty.csv"), "").unwrap();
    let e = err_text(run_toml(
        "[trajectory]\ntype = \"samples\"\nfile = \"empty.csv\"\n",
        dir,
    ));
    assert!(e.contains("empty.csv") && e.contains("empty"), "{e}");
}

#[test]
fn builtin_defaults_can_be_overridden_by_the_file() {
    let text = "rate_hz = 100.0\nnav_frame = \"NED\"\n[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\n[imu]\nkind = \"accel-gyro\"\n";
    let sc: Scenario = ScenarioSpec::from_toml(text, "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    assert_eq!(sc.t_s.len(), 101);
    assert_eq!(sc.imu.lever_arm_m, [-0.075, -0.075, 0.025]);
    let sim = sc.simulate().unwrap();
    assert_eq!(sim.imu.columns.len(), 7);
    let _: &Table = &sim.truth;
}

#[test]
fn body_rate_scenarios_reproduce_matlabs_platform_from_formulas_and_files() {
    let dir = temp_dir("bodyrates");
    let dir = dir.path();
    let text = "rate_hz = 100.0\nduration_s = 5.99\nnav_frame = \"NED\"\n[trajectory]\ntype = \"body-rates\"\n\
                angular_velocity_body_rad_s = [0, 0, \"piecewise(t < 3.995, pi/2, pi)\"]\n";
    let formulas = run_toml(text, dir).unwrap();
    let builtin = builtin::spec("platform-turn")
        .unwrap()
        .resolve(dir)
        .unwrap()
        .simulate()
        .unwrap();
    let (a, b) = (
        formulas.truth.column("yaw_rad").unwrap(),
        builtin.truth.column("yaw_rad").unwrap(),
    );
    assert_eq!(a.len(), 600);
    for k in 0..600 {
        assert!((a[k] - b[k]).abs() < 1e-11, "k = {k}: {} vs {}", a[k], b[k]);
    }
    assert_eq!(
        formulas.imu.column("gyro_z_rad_s"),
        builtin.imu.column("gyro_z_rad_s")
    );
    // The same rates from a CSV file.
    let mut csv = String::from(
        "t_s,acc_body_x_m_s2,acc_body_y_m_s2,acc_body_z_m_s2,omega_x_rad_s,omega_y_rad_s,omega_z_rad_s\n",
    );
    for k in 0..600 {
        let w = if k < 400 {
            std::f64::consts::FRAC_PI_2
        } else {
            std::f64::consts::PI
        };
        csv += &format!("{},0,0,0,0,0,{}\n", k as f64 / 100.0, w);
    }
    std::fs::write(dir.join("rates.csv"), csv).unwrap();
    let file = run_toml(
        "nav_frame = \"NED\"\n[trajectory]\ntype = \"body-rates\"\nfile = \"rates.csv\"\n",
        dir,
    )
    .unwrap();
    let c = file.truth.column("yaw_rad").unwrap();
    for k in 0..600 {
        assert!((c[k] - b[k]).abs() < 1e-11, "k = {k}");
    }
    let e = err_text(run_toml(
        "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"body-rates\"\nangular_velocity_body_rad_s = [0, 0, \"w*t\"]\n",
        dir,
    ));
    assert!(
        e.contains("angular_velocity_body_rad_s[2]") && e.contains("unknown variable 'w'"),
        "{e}"
    );
}

/// The built-in with GNSS: the car stands 20 s (a rest a filter can use), drives its loop back
/// to the start, and its receiver gives 5 Hz fixes except in the 15 s outage.
#[test]
fn gnss_car_stands_drives_its_loop_and_loses_its_fixes() {
    let sim = builtin::spec("gnss-car")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    let t = sim.truth.column("t_s").unwrap();
    let (x, y) = (
        sim.truth.column("pos_x_m").unwrap(),
        sim.truth.column("pos_y_m").unwrap(),
    );
    let vx = sim.truth.column("vel_x_m_s").unwrap();
    let n = t.len() - 1;
    // 789 m of track: 20 s standing, two 10 s ramps at 1 m/s², the rest at 10 m/s.
    let length = 600.0 + 60.0 * std::f64::consts::PI;
    let duration = 20.0 + 20.0 + (length - 100.0) / 10.0;
    assert!(
        (t[n] - duration).abs() <= 0.01,
        "within a sample: {} vs {duration}",
        t[n]
    );
    assert!(
        x[n].hypot(y[n]) < 1e-6,
        "the loop closes: {} {}",
        x[n],
        y[n]
    );
    for k in 0..2000 {
        assert!(x[k] == 0.0 && y[k] == 0.0 && vx[k] == 0.0, "row {k}");
    }
    assert!(vx[2100] > 0.9, "moving after the wait: {}", vx[2100]);
    let gnss = sim.gnss.as_ref().expect("the receiver's fixes");
    let tg = gnss.column("t_s").unwrap();
    assert!(
        tg.iter().all(|&s| !(60.0..75.0).contains(&s)),
        "no fix in the outage"
    );
    let before = tg.iter().filter(|&&s| s < 60.0).count();
    assert_eq!(before, 300, "5 Hz from t = 0");
}
