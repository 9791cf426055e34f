//! The filter without fixes: Schuler's oscillation, heading drift, errors growing as the closed
//! forms say, zero-rate and zero-velocity updates, each preset's drift within its grade.
use std::path::Path;

use imu_core::fusion::InitialSigma;
use imukit::run::fuse::{FuseSetup, fuse};
use imukit::run::navigate::InitialState;
use imukit::{ScenarioSpec, Table};

use super::{col, rows3, simulate};

#[test]
fn without_fixes_an_accelerometer_bias_swings_with_schulers_period() {
    // At rest at 45° N, heading north, an accelerometer bias b on the forward (north) axis and
    // nothing else; one fix at the start, then none for 42 minutes (half a Schuler period).
    // Both the estimate's error (the Earth mechanization) and the filter's north one-sigma
    // (its error model, told σ_b = b) follow the closed form b/ω²·(1 − cos ωt), ω² = γ/(R_N + h):
    // 84.4 minutes per swing, not the 59.7 a doubled gravity gradient would give.
    let b = 1e-3;
    let text = format!(
        "rate_hz = 10.0\nduration_s = 2532.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = {{ latitude_deg = 45.0, longitude_deg = 7.0, height_m = 0.0 }}\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu]\nkind = \"accel-gyro\"\n[imu.accelerometer]\nconstant_bias_m_s2 = [{b}, 0.0, 0.0]\n\
         [gnss]\nrate_hz = 1.0\ndecay_factor = 0.0\n\
         [[gnss.outages]]\nstart_s = 0.5\nduration_s = 3000.0\n"
    );
    let sc = ScenarioSpec::from_toml(&text, "schuler.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    setup.initial_sigma = InitialSigma {
        position_m: 1e-6,
        velocity_m_s: 1e-9,
        attitude_rad: [1e-12; 3],
        accel_bias_m_s2: b,
        gyro_bias_rad_s: 1e-15,
    };
    let sim = simulate(&text, 0);
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
    let origin = imu_core::earth::Geodetic::from_degrees(45.0, 7.0, 0.0);
    let (r_n, _) = origin.radii_m();
    let omega = (imu_core::earth::normal_gravity_m_s2(&origin) / r_n).sqrt();
    let t = col(&nav, "t_s");
    let (err, sigma) = (
        col(&nav, "pos_x_m")
            .iter()
            .zip(col(&sim.truth, "pos_x_m"))
            .map(|(e, x)| e - x)
            .collect::<Vec<_>>(),
        col(&nav, "pos_x_sigma_m"),
    );
    for minutes in [10.0, 21.0, 30.0, 42.0] {
        let i = t.partition_point(|&x| x < minutes * 60.0);
        let want = b / (omega * omega) * (1.0 - (omega * t[i]).cos());
        eprintln!(
            "{minutes} min: error {:.2} m, σ {:.2} m, closed form {want:.2} m",
            err[i], sigma[i]
        );
        assert!(
            (err[i] - want).abs() < 0.02 * want,
            "error at {minutes} min: {} vs {want}",
            err[i]
        );
        assert!(
            (sigma[i] - want).abs() < 0.02 * want,
            "σ at {minutes} min: {} vs {want}",
            sigma[i]
        );
    }
}

#[test]
fn without_fixes_a_heading_error_drifts_as_the_filter_says() {
    // At rest at 45° N, ideal sensors, the start's heading off by ψ₀ = 1 mrad and the filter told
    // σ_ψ = ψ₀: the estimate's horizontal error (the mechanization) and the filter's one-sigma
    // (its error model: the Earth rate's horizontal part turning the heading error into tilt,
    // the Schuler loop, Coriolis) agree through 42 minutes.
    let psi0 = 1e-3;
    let text = "rate_hz = 10.0\nduration_s = 2532.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 0.0 }\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu]\nkind = \"accel-gyro\"\n\
         [gnss]\nrate_hz = 1.0\ndecay_factor = 0.0\n\
         [[gnss.outages]]\nstart_s = 0.5\nduration_s = 3000.0\n";
    let sc = ScenarioSpec::from_toml(text, "heading.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    setup.initial_sigma = InitialSigma {
        position_m: 1e-6,
        velocity_m_s: 1e-9,
        attitude_rad: [1e-12, 1e-12, psi0],
        accel_bias_m_s2: 1e-15,
        gyro_bias_rad_s: 1e-15,
    };
    let sim = simulate(text, 0);
    let mut initial = InitialState::from_table(&sim.truth).unwrap();
    // Ĉ = (I − [φ×]) C: the estimate's heading off by −ψ₀ about down.
    let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        initial.quaternion[0],
        initial.quaternion[1],
        initial.quaternion[2],
        initial.quaternion[3],
    ));
    let start =
        nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(0.0, 0.0, -psi0)) * q;
    initial.quaternion = [start.w, start.i, start.j, start.k];
    let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
    let t = col(&nav, "t_s");
    for minutes in [10.0, 21.0, 30.0, 42.0] {
        let i = t.partition_point(|&x| x < minutes * 60.0);
        let e = |c: &str| col(&nav, c)[i] - col(&sim.truth, c)[i];
        let err = e("pos_x_m").hypot(e("pos_y_m"));
        let sigma = col(&nav, "pos_x_sigma_m")[i].hypot(col(&nav, "pos_y_sigma_m")[i]);
        eprintln!("{minutes} min: horizontal error {err:.2} m, filter σ {sigma:.2} m");
        assert!(
            (err - sigma).abs() < 0.05 * sigma,
            "{minutes} min: {err} vs {sigma}"
        );
    }
}

/// Flat Earth, a car at 10 m/s on a straight road with ideal sensors but for `imu` (a constant
/// bias), no fix after the first, the filter told only `sigma` (a one-sigma of the bias): the
/// horizontal position errors and one-sigmas (x along the road, y across) at 10, 20 and 30 s.
fn drift_without_fixes(imu: &str, sigma: InitialSigma) -> Vec<(f64, [f64; 2], [f64; 2])> {
    let text = format!(
        "rate_hz = 100.0\nduration_s = 31.0\nnav_frame = \"ENU\"\n[trajectory]\n\
         type = \"expression\"\nposition_m = [\"10*t\", \"0\", \"0\"]\nattitude = \"tangent\"\n\
         [imu]\nkind = \"accel-gyro\"\n{imu}\n\
         [gnss]\nrate_hz = 1.0\ndecay_factor = 0.0\n\
         [[gnss.outages]]\nstart_s = 0.5\nduration_s = 100.0\n"
    );
    let sc = ScenarioSpec::from_toml(&text, "drift.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    setup.initial_sigma = sigma;
    setup.covariance_interval_s = 0.0;
    let sim = simulate(&text, 0);
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
    let t = col(&nav, "t_s");
    [10.0, 20.0, 30.0]
        .iter()
        .map(|&ts| {
            let i = t.partition_point(|&x| x < ts - 1e-9);
            let e = |c: &str| col(&nav, c)[i] - col(&sim.truth, c)[i];
            let s = |c: &str| col(&nav, c)[i];
            (
                t[i],
                [e("pos_x_m"), e("pos_y_m")],
                [s("pos_x_sigma_m"), s("pos_y_sigma_m")],
            )
        })
        .collect()
}

#[test]
fn without_fixes_the_error_grows_as_half_b_t_squared_and_as_g_b_t_cubed_over_six() {
    // The terms an outage's drift is made of, each alone and in closed form: an accelerometer
    // bias b along the road moves the estimate by ½ b t²; a gyroscope bias b_g about the
    // road's axis tilts the estimate by b_g t, which turns gravity into a cross-road error
    // g b_g t³/6. The filter's one-sigma follows the same laws with σ for b.
    let tiny = InitialSigma {
        position_m: 1e-9,
        velocity_m_s: 1e-9,
        attitude_rad: [1e-9; 3],
        accel_bias_m_s2: 1e-12,
        gyro_bias_rad_s: 1e-12,
    };
    let (b, sigma_b) = (0.01, 0.02);
    let accel = drift_without_fixes(
        &format!("[imu.accelerometer]\nconstant_bias_m_s2 = [{b}, 0.0, 0.0]"),
        InitialSigma {
            accel_bias_m_s2: sigma_b,
            ..tiny
        },
    );
    for (t, err, sigma) in accel {
        let (law, law_sigma) = (0.5 * b * t * t, 0.5 * sigma_b * t * t);
        eprintln!(
            "accelerometer bias, {t:.2} s: error {:.4} m (½bt² {law:.4}), σ {:.4} m (½σt² {law_sigma:.4})",
            err[0], sigma[0]
        );
        assert!(
            (err[0] - law).abs() < 1e-3 * law,
            "{t}: {} vs {law}",
            err[0]
        );
        assert!(err[1].abs() < 1e-6, "{t}: across {}", err[1]);
        assert!(
            (sigma[0] - law_sigma).abs() < 1e-3 * law_sigma,
            "{t}: σ {} vs {law_sigma}",
            sigma[0]
        );
    }
    let (bg, sigma_bg, g) = (1e-4, 2e-4, 9.81);
    let gyro = drift_without_fixes(
        &format!("[imu.gyroscope]\nconstant_bias_rad_s = [{bg}, 0.0, 0.0]"),
        InitialSigma {
            gyro_bias_rad_s: sigma_bg,
            ..tiny
        },
    );
    for (t, err, sigma) in gyro {
        let (law, law_sigma) = (g * bg * t.powi(3) / 6.0, g * sigma_bg * t.powi(3) / 6.0);
        eprintln!(
            "gyroscope bias, {t:.2} s: error {:.4} m (g b t³/6 {law:.4}), σ {:.4} m (g σ t³/6 {law_sigma:.4})",
            err[1], sigma[1]
        );
        assert!(
            (err[1].abs() - law).abs() < 0.01 * law,
            "{t}: {} vs {law}",
            err[1]
        );
        assert!(
            (sigma[1] - law_sigma).abs() < 0.01 * law_sigma,
            "{t}: σ {} vs {law_sigma}",
            sigma[1]
        );
    }
}

#[test]
fn at_rest_the_zero_rate_updates_calibrate_the_gyroscopes_as_least_squares_says() {
    // An MPU-6050 (±20 °/s turn-on bias, no drift) standing still for 30 s, the filter told
    // the first 20 s are a rest: each sample's zero-rate update is one more reading of the
    // bias, so the heading axis (which nothing else sees at rest) ends the rest with
    // 1/σ² = 1/σ₀² + N/σ_s² (N samples of one-sigma σ_s), and the estimate within 3σ of the part.
    let text = "rate_hz = 100.0\nduration_s = 30.0\nnav_frame = \"ENU\"\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu]\nkind = \"accel-gyro\"\npreset = \"mpu-6050\"\n\
         [imu.gyroscope]\nacceleration_bias_rad_s_per_m_s2 = 0.0\naxes_misalignment_pct = 0.0\n\
         [imu.accelerometer]\naxes_misalignment_pct = 0.0\n\
         [gnss]\nrate_hz = 5.0\nhorizontal_accuracy_m = 1.5\nvertical_accuracy_m = 3.0\n\
         velocity_accuracy_m_s = 0.1\ndecay_factor = 0.0\n";
    let sc = ScenarioSpec::from_toml(text, "rest.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    setup.rest_s = 20.0;
    let bias = sc.imu.sensors.params.gyroscope.constant_bias;
    let sigma_sample = setup.noise.gyro_psd / 0.01_f64.sqrt();
    let sigma0 = setup.initial_sigma.gyro_bias_rad_s;
    for run in 0..3 {
        let sim = sc.simulate_run(run).unwrap();
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
        let t = col(&nav, "t_s");
        let i = t.partition_point(|&x| x < 20.0) - 1;
        let n = (i + 1) as f64;
        let expected = (1.0 / (sigma0 * sigma0) + n / (sigma_sample * sigma_sample)).powf(-0.5);
        let sigma = col(&nav, "gyro_bias_z_sigma_rad_s")[i];
        eprintln!(
            "run {run}: after {n} samples at rest σ_bz = {sigma:.4e} rad/s (least squares {expected:.4e})"
        );
        assert!(
            (sigma / expected - 1.0).abs() < 0.01,
            "{sigma} vs {expected}"
        );
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let est = col(&nav, &format!("gyro_bias_{axis}_rad_s"))[i];
            let s = col(&nav, &format!("gyro_bias_{axis}_sigma_rad_s"))[i];
            assert!(
                (est - bias[k]).abs() < 3.0 * s,
                "{axis}: {est} vs {} (σ {s})",
                bias[k]
            );
            assert!(s < 1e-3 * sigma0, "{axis}: σ {s}");
        }
    }
}

#[test]
fn a_consumer_imu_needs_the_rest_and_the_sensor_error_states_and_learns_them_on_the_road() {
    // The MPU-6050 on the tunnel road: its ±20 °/s turn-on bias and 2 % cross-axis
    // sensitivity make the 15-state filter lose the fixes; with the rest before the drive
    // and the 36 states it follows the road, and by the tunnel every sensor error it estimates
    // is within 3σ of the part's; those the turns and speed changes show — the yaw rate leaking
    // into the roll and pitch gyroscopes, the horizontal accelerations into the vertical
    // accelerometer — known to better than half their start.
    use imukit::Error;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("car_tunnel.toml"))
        .unwrap()
        .replace("preset = \"stim300\"", "preset = \"mpu-6050\"");
    let sc = ScenarioSpec::from_toml(&text, "car_tunnel.toml")
        .unwrap()
        .resolve(&dir)
        .unwrap();
    let plain = FuseSetup::from_scenario(&sc).unwrap();
    let full = FuseSetup {
        rest_s: 20.0,
        estimate_sensor_errors: true,
        ..plain
    };
    let p = &sc.imu.sensors.params;
    let m =
        |a: &[[f64; 3]; 3], r: usize, c: usize| a[r][c] / 100.0 - if r == c { 1.0 } else { 0.0 };
    let columns = imukit::run::fuse::sensor_error_columns();
    let truth: Vec<f64> = (0..9)
        .map(|k| m(&p.accelerometer.axes_misalignment_pct, k / 3, k % 3))
        .chain((0..9).map(|k| m(&p.gyroscope.axes_misalignment_pct, k / 3, k % 3)))
        .chain(p.gyroscope.acceleration_bias)
        .collect();
    for run in 0..3 {
        let sim = sc.simulate_run(run).unwrap();
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let gnss = sim.gnss.as_ref().unwrap();
        for setup in [
            plain,
            FuseSetup {
                rest_s: 20.0,
                ..plain
            },
            FuseSetup {
                estimate_sensor_errors: true,
                ..plain
            },
        ] {
            // Without both, the filter loses the fixes: it is reset to them (or, when the
            // resets do not bring it back, diverges), said either way.
            match fuse(&sim.imu, gnss, &initial, &setup) {
                Ok((_, summary)) => assert!(summary.resets > 0, "run {run}: {summary:?}"),
                Err(e) => assert!(matches!(e, Error::Diverged { .. }), "run {run}: {e}"),
            }
        }
        let (nav, summary) = fuse(&sim.imu, gnss, &initial, &full).unwrap();
        assert_eq!(summary.resets, 0, "run {run}");
        let i = col(&nav, "t_s").partition_point(|&x| x < 119.9);
        let mut learned = Vec::new();
        for (k, truth) in truth.iter().enumerate() {
            let (est, sigma) = (col(&nav, &columns[k]), col(&nav, &columns[k + 21]));
            assert!(
                (est[i] - truth).abs() < 3.0 * sigma[i],
                "run {run}, {}: {} vs {truth} (σ {})",
                columns[k],
                est[i],
                sigma[i]
            );
            if sigma[i] < 0.5 * sigma[0] {
                learned.push(columns[k].as_str());
            }
        }
        eprintln!("run {run}: learned to better than half their start: {learned:?}");
        for name in [
            "accel_misalignment_zx",
            "accel_misalignment_zy",
            "gyro_misalignment_xz",
            "gyro_misalignment_yz",
        ] {
            assert!(learned.contains(&name), "run {run}: {learned:?}");
        }
    }
}

/// The walking foot of `examples/walk.toml` (a consumer IMU, ten minutes, 754 m around a circle
/// and back to the start, GNSS only while standing): with zero-velocity updates at the
/// detected stances the walk ends within 1 % of the distance walked of where it began; the
/// detector misses few stance samples and takes no moving sample (faster than 0.05 m/s) for one.
#[test]
fn a_walk_navigated_by_zero_velocity_updates_returns_to_its_start() {
    use imukit::run::fuse::stance_samples;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let sc = imukit::Scenario::from_file(&dir.join("walk.toml")).unwrap();
    let sim = sc.simulate_run(0).unwrap();
    let setup = FuseSetup {
        rest_s: 10.0,
        zupt: true,
        ..FuseSetup::from_scenario(&sc).unwrap()
    };
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let (nav, summary) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
    let truth = rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]);
    let est = rows3(&nav, ["pos_x_m", "pos_y_m", "pos_z_m"]);
    let walked = 540.0 * 2.0 * std::f64::consts::PI * 10.0 / 45.0;
    let last = truth.len() - 1;
    let start_to_end = (0..3)
        .map(|k| (truth[last][k] - truth[0][k]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        start_to_end < 1e-6,
        "the walk ends where it began: {start_to_end} m"
    );
    let error = (0..3)
        .map(|k| (est[last][k] - truth[0][k]).powi(2))
        .sum::<f64>()
        .sqrt();
    // Stances against the truth's speed.
    let t = col(&sim.imu, "t_s");
    let f = rows3(&sim.imu, ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]);
    let w = rows3(&sim.imu, ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]);
    let stance = stance_samples(&t, &f, &w, &setup);
    let speed: Vec<f64> = rows3(&sim.truth, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"])
        .iter()
        .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
        .collect();
    let still: Vec<bool> = speed.iter().map(|s| *s == 0.0).collect();
    let inner = |i: usize| (i.saturating_sub(5)..(i + 5).min(still.len())).all(|j| still[j]);
    let (stance_inner, missed) = (0..still.len())
        .filter(|&i| inner(i))
        .fold((0, 0), |(s, m), i| (s + 1, m + usize::from(!stance[i])));
    let false_stance = (0..still.len())
        .filter(|&i| stance[i] && speed[i] > 0.05)
        .count();
    eprintln!(
        "walk: {walked:.1} m walked, back {error:.3} m from the start ({:.3} %); stances: \
         {} samples, missed {missed} of {stance_inner}, {false_stance} false",
        100.0 * error / walked,
        summary.stance_samples
    );
    assert!(error < 0.01 * walked, "{error} m after {walked} m");
    assert!(
        missed * 50 <= stance_inner,
        "missed {missed} of {stance_inner}"
    );
    assert_eq!(false_stance, 0);
}

/// Each preset in free inertial on the example road after a 20 s alignment at rest (the filter
/// told of the rest, then no fix at all): its horizontal position error when the car stops at
/// 170 s, against a navigation engineer's bounds for its grade — a navigation-grade part drifts
/// metres, a tactical one tens of metres, an industrial one hundreds, a consumer one up to
/// kilometres, none more. The table in the README is this test's output.
#[test]
fn each_presets_free_inertial_drift_is_within_its_grades_bounds() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("car_tunnel.toml")).unwrap();
    eprintln!(
        "| preset | grade | drift after 170 s | not given by its data sheet |\n|---|---|---|---|"
    );
    for name in imukit::io::presets::names() {
        let grade = imukit::io::presets::load(name)
            .unwrap()
            .info
            .get("grade")
            .cloned()
            .unwrap_or_default();
        let bound_m = match grade.as_str() {
            "ideal" | "navigation" => 10.0,
            "tactical" => 100.0,
            "industrial" => 1000.0,
            _ => 3000.0,
        };
        let sc = ScenarioSpec::from_toml(
            &text.replace("preset = \"stim300\"", &format!("preset = \"{name}\"")),
            "car_tunnel.toml",
        )
        .unwrap()
        .resolve(&dir)
        .unwrap();
        let sim = sc.simulate().unwrap();
        let setup = FuseSetup {
            rest_s: 20.0,
            ..FuseSetup::from_scenario(&sc).unwrap()
        };
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let no_fixes = Table::default();
        let (nav, _) = fuse(&sim.imu, &no_fixes, &initial, &setup).unwrap();
        let (p, q) = (
            rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]),
            rows3(&nav, ["pos_x_m", "pos_y_m", "pos_z_m"]),
        );
        let last = p.len() - 1;
        let drift = (p[last][0] - q[last][0]).hypot(p[last][1] - q[last][1]);
        let missing = imukit::io::presets::load(name)
            .unwrap()
            .datasheet
            .map(|d| d.missing_error_terms())
            .unwrap_or_default();
        eprintln!("| {name} | {grade} | {drift:.1} m | {missing} |");
        assert!(
            drift < bound_m,
            "{name} ({grade}): {drift} m, bound {bound_m} m"
        );
    }
}
