//! The loosely coupled INS/GNSS filter: with ideal sensors and exact fixes it reproduces the
//! truth; over 50 seeded Monte Carlo runs its stated uncertainty is honest (average NEES of
//! position, velocity and attitude, and average NIS of the fixes, inside the two-sided 95 %
//! chi-square bounds) and a filter told 100× too little process noise fails the same test;
//! heading is observable only when the vehicle accelerates horizontally.
use std::path::Path;

use imu_core::earth::FlatEarth;
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfNoise, EskfState, FULL_STATES, GnssFix, InitialSigma, SensorErrorSigma,
};
use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::strapdown::NavState;
use imu_core::{Body, Enu, Rotation, Vec3};
use imukit::io::conventions::NavFrameName;
use imukit::run::fuse::{FuseSetup, Gate, fuse};
use imukit::run::navigate::InitialState;
use imukit::{ScenarioSpec, Simulation, Table};

use crate::common::chi2_quantile;

/// A car-like manoeuvre: a 60 m circle at 8–12 m/s with a gentle hill, nose along the path.
fn scenario(imu: &str, gnss: &str) -> String {
    format!(
        "rate_hz = 50.0\nduration_s = 40.0\nnav_frame = \"ENU\"\n[trajectory]\ntype = \"expression\"\n\
         constants = {{ r = 60.0 }}\n\
         position_m = [\"r*sin(0.16*t + 0.02*sin(0.5*t))\", \"r*(1 - cos(0.16*t + 0.02*sin(0.5*t)))\", \"2*sin(0.1*t)\"]\n\
         attitude = \"tangent\"\n[imu]\nkind = \"accel-gyro\"\n{imu}\n[gnss]\nrate_hz = 5.0\n{gnss}\n"
    )
}

fn simulate(text: &str, run: u64) -> Simulation {
    ScenarioSpec::from_toml(text, "fusion.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate_run(run)
        .unwrap()
}

fn col(t: &Table, c: &str) -> Vec<f64> {
    t.column(c).unwrap()
}

fn rows3(t: &Table, names: [&str; 3]) -> Vec<[f64; 3]> {
    let c: Vec<Vec<f64>> = names.iter().map(|n| col(t, n)).collect();
    (0..t.rows()).map(|i| [c[0][i], c[1][i], c[2][i]]).collect()
}

#[test]
fn ideal_sensors_and_exact_fixes_reproduce_the_truth() {
    let text = scenario(
        "",
        "horizontal_accuracy_m = 0.0\nvertical_accuracy_m = 0.0\nvelocity_accuracy_m_s = 0.0",
    );
    let sim = simulate(&text, 0);
    let base = FuseSetup {
        nav_frame: NavFrameName::ENU,
        earth: None,
        accel_sign: imu_core::AccelSign::SpecificForce,
        gravity_m_s2: 9.81,
        noise: EskfNoise {
            accel_psd: 1e-3,
            gyro_psd: 1e-5,
            accel_bias_psd: 1e-6,
            gyro_bias_psd: 1e-8,
        },
        initial_sigma: InitialSigma {
            position_m: 0.01,
            velocity_m_s: 0.01,
            attitude_rad: [1e-4; 3],
            accel_bias_m_s2: 1e-3,
            gyro_bias_rad_s: 1e-5,
        },
        gnss_position_sigma_m: [1e-3; 3],
        gnss_position_noise: None,
        gnss_velocity_sigma_m_s: Some(1e-3),
        lever_arm_m: [0.0; 3],
        gnss_latency_s: 0.0,
        part_bias: [1e-3, 1e-5],
        gate: Gate::Off,
        aiding: Default::default(),
        covariance_interval_s: 0.0,
        max_fix_noise_scale: 1.0,
        estimate_sensor_errors: false,
        figures_known: true,
        sensor_error_sigma: SensorErrorSigma {
            accel_scale_factor: 1e-3,
            accel_misalignment: 1e-3,
            gyro_scale_factor: 1e-3,
            gyro_misalignment: 1e-3,
            gyro_g_sensitivity: 1e-5,
        },
        rest_s: 0.0,
        detect_rest: false,
        smooth: false,
        zupt: false,
    };
    // The 15-state filter and the one that also estimates the sensor matrices (which stay 0).
    for estimate_sensor_errors in [false, true] {
        let setup = FuseSetup {
            estimate_sensor_errors,
            ..base
        };
        reproduces_the_truth(&sim, &setup);
    }
}

fn reproduces_the_truth(sim: &Simulation, setup: &FuseSetup) {
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let (nav, summary) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, setup).unwrap();
    assert_eq!(summary.updates, 201);
    let (truth_p, est_p) = (
        rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]),
        rows3(&nav, ["pos_x_m", "pos_y_m", "pos_z_m"]),
    );
    let worst = truth_p
        .iter()
        .zip(&est_p)
        .map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    // The nominal propagation is second order (50 Hz on a 0.16 rad/s turn): millimetres
    // between fixes, pulled back at each fix.
    assert!(worst < 5e-3, "worst position error {worst:e} m");
    let bias = col(&nav, "accel_bias_x_m_s2");
    assert!(bias.iter().all(|b| b.abs() < 1e-3), "{:?}", bias.last());
    if setup.estimate_sensor_errors {
        for name in ["accel_scale_factor_x", "gyro_misalignment_zx"] {
            let m = col(&nav, name);
            assert!(m.iter().all(|v| v.abs() < 1e-4), "{name}: {:?}", m.last());
        }
    } else {
        assert!(nav.column("accel_scale_factor_x").is_none());
    }
}

/// Average NEES of position, velocity and attitude at `check_s` over `runs` runs, and the average
/// NIS of every fix with its count, with the filter's process noise scaled by `q_scale`; with
/// `wheels`, an odometer (10 Hz) and the non-holonomic constraints aid the filter too; the
/// covariance is stepped every `covariance_interval_s` (0: every sample). With `parts`, each run
/// is a different part whose scale factors, misalignment and g-sensitivity are drawn with these
/// one-sigmas; a filter of `S = 36` states is told them, one of 15 is not.
fn average_nees<const S: usize>(
    runs: u64,
    q_scale: f64,
    wheels: bool,
    covariance_interval_s: f64,
    parts: Option<SensorErrorSigma>,
) -> ([f64; 3], f64, usize) {
    // IMU: white noise and bias random walk (single-sided densities: the continuous PSD is N²,
    // so the filter's √q is N). GNSS: white (MATLAB decay factor 0: deviation σ√2).
    let (n_a, n_g, k_a, k_g) = (0.003, 2e-4, 2e-4, 2e-6);
    let (sigma_h, sigma_v, sigma_vel) = (0.8, 1.2, 0.05);
    let (sigma_odo, sigma_nhc) = (0.05, 0.02);
    let odometer = if wheels {
        format!("\n[odometer]\nrate_hz = 10.0\nnoise_m_s = {sigma_odo}")
    } else {
        String::new()
    };
    // A part's figures as the simulator takes them: 100 (I + M) in percent.
    let matrix = |scale: f64, cross: f64| {
        let (d, o) = (100.0 + 100.0 * scale, 100.0 * cross);
        format!("[[{d}, {o}, {o}], [{o}, {d}, {o}], [{o}, {o}, {d}]]")
    };
    let (accel_part, gyro_part) = parts.map_or_else(Default::default, |p| {
        (
            format!(
                "\naxes_misalignment_pct = {}",
                matrix(p.accel_scale_factor, p.accel_misalignment)
            ),
            format!(
                "\naxes_misalignment_pct = {}\nacceleration_bias_rad_s_per_m_s2 = {}",
                matrix(p.gyro_scale_factor, p.gyro_misalignment),
                p.gyro_g_sensitivity
            ),
        )
    });
    let text = scenario(
        &format!(
            "[imu.accelerometer]\nNoiseDensity = {n_a}\nRandomWalk = {k_a}{accel_part}\n\
             [imu.gyroscope]\nNoiseDensity = {n_g}\nRandomWalk = {k_g}{gyro_part}"
        ),
        &format!(
            "horizontal_accuracy_m = {sigma_h}\nvertical_accuracy_m = {sigma_v}\n\
             velocity_accuracy_m_s = {sigma_vel}\ndecay_factor = 0.0{odometer}"
        ),
    );
    let noise = EskfNoise {
        accel_psd: n_a * q_scale.sqrt(),
        gyro_psd: n_g * q_scale.sqrt(),
        accel_bias_psd: k_a * q_scale.sqrt(),
        gyro_bias_psd: k_g * q_scale.sqrt(),
    };
    let sigma0 = InitialSigma {
        position_m: 1.0,
        velocity_m_s: 0.1,
        attitude_rad: [0.005, 0.005, 0.02],
        accel_bias_m_s2: 0.01,
        gyro_bias_rad_s: 1e-4,
    };
    let check_s = 40.0;
    let mut sums = [0.0; 3];
    let (mut nis_sum, mut fixes) = (0.0, 0);
    let mut sc = ScenarioSpec::from_toml(&text, "fusion.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    sc.imu.sensors.draw_parts = parts.is_some();
    for run in 0..runs {
        let sim = sc.simulate_run(run).unwrap();
        let gnss = sim.gnss.as_ref().unwrap();
        // The start drawn from the initial uncertainty, every state: the true biases start at
        // 0 (the random walks' start), so the estimates start at a draw. (Drawing only position,
        // velocity and attitude left the filter pessimistic about the attitude: tilt and
        // accelerometer bias are told apart only slowly, and a bias uncertainty with no bias
        // error behind it keeps the tilt's covariance up.)
        let mut draw = SeededNormals::for_run(99, run);
        let mut d = |s: f64| s * draw.standard_normal();
        let t = col(&sim.truth, "t_s");
        let p_true = rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]);
        let v_true = rows3(&sim.truth, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]);
        let q_true: Vec<[f64; 4]> = (0..t.len())
            .map(|i| ["q_w", "q_x", "q_y", "q_z"].map(|c| col(&sim.truth, c)[i]))
            .collect();
        let tilt = [
            d(sigma0.attitude_rad[0]),
            d(sigma0.attitude_rad[1]),
            d(sigma0.attitude_rad[2]),
        ];
        let c0 = Rotation::<Body, Enu>::from_wxyz(q_true[0]).unwrap();
        let start_q = *c0.quaternion();
        let start = EskfState {
            nav: NavState {
                t_s: t[0],
                position: Vec3::<Enu>::from_array(p_true[0])
                    + Vec3::new(d(1.0), d(1.0), d(1.0)) * sigma0.position_m,
                velocity_m_s: Vec3::<Enu>::from_array(v_true[0])
                    + Vec3::new(d(1.0), d(1.0), d(1.0)) * sigma0.velocity_m_s,
                // Ĉ = (I − [φ×]) C_true: the estimate off by −φ.
                attitude: Rotation::assume_from_quaternion(
                    nalgebra::UnitQuaternion::from_scaled_axis(-nalgebra::Vector3::from(tilt))
                        * start_q,
                ),
            },
            accel_bias_m_s2: [0, 1, 2].map(|_| d(sigma0.accel_bias_m_s2)),
            gyro_bias_rad_s: [0, 1, 2].map(|_| d(sigma0.gyro_bias_rad_s)),
        };
        let mut f = Eskf::<_, S>::new(FlatEarth::<Enu>::new(9.81), &start, &sigma0, noise)
            .unwrap()
            .with_covariance_interval(covariance_interval_s)
            .unwrap();
        if S == FULL_STATES {
            f = f.with_sensor_error_sigma(&parts.unwrap()).unwrap();
        }
        let (w, a) = (
            rows3(&sim.imu, ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]),
            rows3(&sim.imu, ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]),
        );
        let (g_t, g_p, g_v) = (
            col(gnss, "t_s"),
            rows3(gnss, ["pos_x_m", "pos_y_m", "pos_z_m"]),
            rows3(gnss, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]),
        );
        let s2 = std::f64::consts::SQRT_2;
        let (odo_t, odo_v) = match &sim.odometer {
            Some(o) => (col(o, "t_s"), col(o, "speed_m_s")),
            None => (Vec::new(), Vec::new()),
        };
        let mut next_odo = 0;
        let mut next = 0;
        for i in 0..t.len() {
            f.propagate(t[i], w[i], a[i]).unwrap();
            while next < g_t.len() && g_t[next] <= t[i] {
                let fix = GnssFix {
                    position: Vec3::from_array(g_p[next]),
                    velocity_m_s: Some(Vec3::from_array(g_v[next])),
                    lever_arm_m: Vec3::zeros(),
                    position_sigma_m: [sigma_h * s2, sigma_h * s2, sigma_v * s2],
                    velocity_sigma_m_s: [sigma_vel; 3],
                    age_s: 0.0,
                };
                let outcome = f.update_gnss(&fix, f64::INFINITY).unwrap();
                nis_sum += outcome.nis;
                fixes += 1;
                next += 1;
            }
            while next_odo < odo_t.len() && odo_t[next_odo] <= t[i] {
                f.update_body_velocity(
                    [Some(odo_v[next_odo]), Some(0.0), Some(0.0)],
                    [sigma_odo, sigma_nhc, sigma_nhc],
                    f64::INFINITY,
                )
                .unwrap();
                next_odo += 1;
            }
            if (t[i] - check_s).abs() < 1e-9 {
                let s = f.state();
                let ep = nalgebra::Vector3::from(p_true[i]) - s.nav.position.as_nalgebra();
                let ev = nalgebra::Vector3::from(v_true[i]) - s.nav.velocity_m_s.as_nalgebra();
                let qt = *Rotation::<Body, Enu>::from_wxyz(q_true[i])
                    .unwrap()
                    .quaternion();
                let ea = (qt * s.nav.attitude.quaternion().inverse()).scaled_axis();
                for (k, e) in [ep, ev, ea].iter().enumerate() {
                    let block =
                        nalgebra::Matrix3::from_fn(|r, c| f.covariance(3 * k + r, 3 * k + c));
                    let inv = block.try_inverse().unwrap();
                    sums[k] += (e.transpose() * inv * e)[(0, 0)];
                }
            }
        }
    }
    (sums.map(|s| s / runs as f64), nis_sum / fixes as f64, fixes)
}

#[test]
fn the_filter_is_consistent_over_50_runs_and_a_mistuned_one_is_not() {
    let runs = 50;
    let dof = 3.0 * runs as f64;
    let (lo, hi) = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    let (nees, nis, fixes) = average_nees::<BASE_STATES>(runs, 1.0, false, 0.0, None);
    eprintln!("average NEES {nees:?}, 95 % bounds [{lo:.3}, {hi:.3}]");
    for (name, v) in ["position", "velocity", "attitude"].iter().zip(nees) {
        assert!(
            lo <= v && v <= hi,
            "{name}: average NEES {v} outside [{lo}, {hi}]"
        );
    }
    // The innovations: each fix's NIS is χ² with 6 degrees of freedom, independent from fix to
    // fix for a consistent filter; their average over all fixes within the 95 % bounds of
    // χ²(6·fixes)/fixes.
    let k = 6.0 * fixes as f64;
    let (nis_lo, nis_hi) = (
        chi2_quantile(k, -1.959_964) / fixes as f64,
        chi2_quantile(k, 1.959_964) / fixes as f64,
    );
    eprintln!("average NIS {nis} over {fixes} fixes, 95 % bounds [{nis_lo:.3}, {nis_hi:.3}]");
    assert!(nis_lo <= nis && nis <= nis_hi, "NIS {nis}");
    // Told 100 times too little process noise, the filter is overconfident.
    let (mistuned, mistuned_nis, _) = average_nees::<BASE_STATES>(runs, 0.01, false, 0.0, None);
    eprintln!("mistuned (process noise × 0.01): average NEES {mistuned:?}, NIS {mistuned_nis}");
    assert!(
        mistuned.iter().any(|&v| v > hi),
        "a mistuned filter passed: {mistuned:?}"
    );
    assert!(mistuned_nis > nis_hi, "{mistuned_nis}");
}

#[test]
fn with_an_odometer_and_the_vehicle_constraints_the_filter_stays_consistent() {
    // The same 50 runs with a 10 Hz odometer (σ 0.05 m/s) and the non-holonomic constraints
    // (the car neither slips sideways nor leaves the road; σ 0.02 m/s): the average NEES stays
    // inside the 95 % bounds.
    let runs = 50;
    let dof = 3.0 * runs as f64;
    let (lo, hi) = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    let (nees, _, _) = average_nees::<BASE_STATES>(runs, 1.0, true, 0.0, None);
    eprintln!(
        "with odometer and constraints: average NEES {nees:?}, 95 % bounds [{lo:.3}, {hi:.3}]"
    );
    for (name, v) in ["position", "velocity", "attitude"].iter().zip(nees) {
        assert!(
            lo <= v && v <= hi,
            "{name}: average NEES {v} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn with_the_covariance_stepped_at_10_hz_the_filter_stays_consistent() {
    // The IMU at 50 Hz, the covariance every 0.1 s (5 samples, and at each fix): the same
    // 50 runs, the same bounds.
    let runs = 50;
    let dof = 3.0 * runs as f64;
    let (lo, hi) = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    let (nees, nis, fixes) = average_nees::<BASE_STATES>(runs, 1.0, false, 0.1, None);
    eprintln!("covariance at 10 Hz: average NEES {nees:?}, NIS {nis} over {fixes} fixes");
    for (name, v) in ["position", "velocity", "attitude"].iter().zip(nees) {
        assert!(
            lo <= v && v <= hi,
            "{name}: average NEES {v} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn with_the_sensor_error_states_the_filter_stays_consistent_over_50_parts() {
    // Each of the 50 runs a different part: scale factors and misalignment of 0.5 % one-sigma,
    // g-sensitivity 1e-4 (rad/s)/(m/s²). The 36-state filter, told those one-sigmas, keeps the
    // average NEES inside the 95 % bounds; the 15-state filter, blind to them, does not.
    let parts = SensorErrorSigma {
        accel_scale_factor: 0.005,
        accel_misalignment: 0.005,
        gyro_scale_factor: 0.005,
        gyro_misalignment: 0.005,
        gyro_g_sensitivity: 1e-4,
    };
    let runs = 50;
    let dof = 3.0 * runs as f64;
    let (lo, hi) = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    let (nees, nis, fixes) = average_nees::<FULL_STATES>(runs, 1.0, false, 0.0, Some(parts));
    eprintln!(
        "36 states, drawn parts: average NEES {nees:?}, NIS {nis} over {fixes} fixes, 95 % bounds [{lo:.3}, {hi:.3}]"
    );
    for (name, v) in ["position", "velocity", "attitude"].iter().zip(nees) {
        assert!(
            lo <= v && v <= hi,
            "{name}: average NEES {v} outside [{lo}, {hi}]"
        );
    }
    let k = 6.0 * fixes as f64;
    let (nis_lo, nis_hi) = (
        chi2_quantile(k, -1.959_964) / fixes as f64,
        chi2_quantile(k, 1.959_964) / fixes as f64,
    );
    assert!(
        nis_lo <= nis && nis <= nis_hi,
        "NIS {nis} outside [{nis_lo}, {nis_hi}]"
    );
    let (blind, _, _) = average_nees::<BASE_STATES>(runs, 1.0, false, 0.0, Some(parts));
    eprintln!("15 states, the same parts: average NEES {blind:?}");
    assert!(blind.iter().any(|&v| v > hi), "{blind:?}");
}

#[test]
fn fixes_stamped_late_are_compared_with_the_state_back_then() {
    // A receiver 0.2 s late on a car at 9.6 m/s turning at 1.5 m/s²: its fixes lie 1.9 m behind
    // the car and their velocities 0.3 m/s off. Told the latency (the scenario's `latency_s`),
    // the filter predicts its state back and follows the truth; not told, it is dragged behind.
    let text = scenario(
        "",
        "horizontal_accuracy_m = 0.05\nvertical_accuracy_m = 0.05\nvelocity_accuracy_m_s = 0.01\n\
         decay_factor = 0.0\nlatency_s = 0.2",
    );
    let sim = simulate(&text, 0);
    let sc = ScenarioSpec::from_toml(&text, "fusion.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    assert_eq!(setup.gnss_latency_s, 0.2);
    setup.gate = Gate::Off;
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let rms_horizontal = |setup: &FuseSetup| {
        let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, setup).unwrap();
        let (t, e) = (
            rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]),
            rows3(&nav, ["pos_x_m", "pos_y_m", "pos_z_m"]),
        );
        let half = t.len() / 2;
        let sum: f64 = (half..t.len())
            .map(|i| (t[i][0] - e[i][0]).powi(2) + (t[i][1] - e[i][1]).powi(2))
            .sum();
        (sum / (t.len() - half) as f64).sqrt()
    };
    let told = rms_horizontal(&setup);
    setup.gnss_latency_s = 0.0;
    let untold = rms_horizontal(&setup);
    eprintln!("latency 0.2 s: RMS horizontal error {told:.4} m compensated, {untold:.4} m not");
    assert!(told < 0.05, "{told}");
    assert!(untold > 1.0, "{untold}");
}

#[test]
fn fixes_that_jump_are_rejected_and_after_ten_in_a_row_the_filter_is_reset_to_them() {
    let text = scenario("", "decay_factor = 0.0");
    let sim = simulate(&text, 0);
    let sc = ScenarioSpec::from_toml(&text, "fusion.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let mut gnss = sim.gnss.clone().unwrap();
    let width = gnss.columns.len();
    // One fix 200 m off: rejected, the rest applied.
    gnss.data[50 * width + 1] += 200.0;
    let (_, summary) = fuse(&sim.imu, &gnss, &initial, &setup).unwrap();
    assert_eq!((summary.updates, summary.rejected), (200, 1));
    assert_eq!(summary.resets, 0);
    // From fix 100 on, every fix 200 m off: the tenth rejected in a row resets the filter to
    // it, and it follows the fixes from there, its reset counted and in the column.
    for k in 100..gnss.rows() {
        gnss.data[k * width + 1] += 200.0;
    }
    let (nav, summary) = fuse(&sim.imu, &gnss, &initial, &setup).unwrap();
    assert_eq!(summary.resets, 1);
    assert_eq!(summary.rejected, 1 + 10);
    let t_fix = gnss.data[109 * width];
    let (t, resets) = (col(&nav, "t_s"), col(&nav, "gnss_resets"));
    let first = resets.iter().position(|&r| r == 1.0).unwrap();
    assert!(
        t[first] >= t_fix && t[first - 1] < t_fix,
        "{} {t_fix}",
        t[first]
    );
    assert_eq!(resets.last(), Some(&1.0));
    // At the end, where the jumped fixes put it (200 m along x), within three of its sigmas.
    let (x, sx) = (col(&nav, "pos_x_m"), col(&nav, "pos_x_sigma_m"));
    let truth_x = col(&sim.truth, "pos_x_m");
    let end = x.len() - 1;
    let off = x[end] - (truth_x[end] + 200.0);
    assert!(off.abs() < 3.0 * sx[end], "{off} m (σ {})", sx[end]);
    // Fixes that jump again and again after each reset are a divergence, reported by row.
    for k in 100..gnss.rows() {
        let jump = 200.0 * ((k - 100) / 10) as f64;
        gnss.data[k * width + 1] += jump;
    }
    let e = match fuse(&sim.imu, &gnss, &initial, &setup) {
        Ok((_, summary)) => panic!("no divergence reported: {summary:?}"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("fixes in a row rejected by the innovation gate")
            && e.contains("after 3 resets to the fixes"),
        "{e}"
    );
}

#[test]
fn heading_is_observable_in_a_turn_and_not_on_a_straight_line_at_constant_speed() {
    // GNSS position only; the heading's one-sigma after 40 s: in the circle (horizontal
    // acceleration 1.5 m/s²) it falls far below its 0.05 rad start, on the straight line it
    // stays near it (only the gyro's noise and the tilt coupling touch it).
    let run = |path: &str| {
        let text = scenario("", "decay_factor = 0.0")
            .replace(
                "position_m = [\"r*sin(0.16*t + 0.02*sin(0.5*t))\", \"r*(1 - cos(0.16*t + 0.02*sin(0.5*t)))\", \"2*sin(0.1*t)\"]",
                path,
            );
        let sim = simulate(&text, 0);
        let sc = ScenarioSpec::from_toml(&text, "fusion.toml")
            .unwrap()
            .resolve(Path::new("."))
            .unwrap();
        let mut setup = FuseSetup::from_scenario(&sc).unwrap();
        setup.gnss_velocity_sigma_m_s = None;
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
        *col(&nav, "att_z_sigma_rad").last().unwrap()
    };
    let turning = run("position_m = [\"60*sin(0.16*t)\", \"60*(1 - cos(0.16*t))\", \"0\"]");
    let straight = run("position_m = [\"10*t\", \"0\", \"0\"]");
    eprintln!("heading one-sigma after 40 s: turning {turning}, straight {straight}");
    assert!(turning < 0.25 * 0.05, "turning: {turning}");
    assert!(straight > 0.8 * 0.05, "straight: {straight}");
}

#[test]
fn the_biases_of_a_tactical_imu_converge_on_the_road_before_the_tunnel() {
    // STIM300 on the tunnel road, GNSS only: by 115 s each accelerometer and gyroscope bias
    // estimate is within 3σ of the part's constant bias and its one-sigma is below 0.6 of its
    // start (the turns and speed changes make them observable; the vertical gyroscope's, seen
    // only through heading in the turns, comes down least, to about half), over five runs. The part's
    // scale-factor and cross-axis errors are set perfect here: acting on gravity and the turns
    // they would add a bias the 15-state filter folds into its estimate (1 mrad of cross-axis
    // error reads as 10 mg on a level road).
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("car_tunnel.toml")).unwrap()
        + "[imu.accelerometer]\naxes_misalignment_pct = 0.0\n\
           [imu.gyroscope]\naxes_misalignment_pct = 0.0\nacceleration_bias_rad_s_per_m_s2 = 0.0\n";
    let sc = ScenarioSpec::from_toml(&text, "car_tunnel.toml")
        .unwrap()
        .resolve(&dir)
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let p = &sc.imu.sensors.params;
    let truth = [
        ("accel", "m_s2", p.accelerometer.constant_bias),
        ("gyro", "rad_s", p.gyroscope.constant_bias),
    ];
    for run in 0..5 {
        let sim = sc.simulate_run(run).unwrap();
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
        let i = col(&nav, "t_s").partition_point(|&x| x < 115.0);
        for (sensor, unit, bias) in truth {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                let est = col(&nav, &format!("{sensor}_bias_{axis}_{unit}"))[i];
                let sigma = col(&nav, &format!("{sensor}_bias_{axis}_sigma_{unit}"));
                assert!(
                    (est - bias[k]).abs() < 3.0 * sigma[i],
                    "run {run}, {sensor} {axis}: {est} vs {} (σ {})",
                    bias[k],
                    sigma[i]
                );
                assert!(
                    sigma[i] < 0.6 * sigma[0],
                    "run {run}, {sensor} {axis}: σ {} from {}",
                    sigma[i],
                    sigma[0]
                );
            }
        }
    }
}

#[test]
fn aligned_from_gnss_the_filter_starts_without_truth_and_converges() {
    // The tunnel road from rest, STIM300, fixes of 1.5 m and 0.1 m/s: the filter starts at the
    // first fix at 3 m/s or more with heading and pitch along its velocity, and its stated
    // uncertainty holds the error it starts with and the one it converges to.
    use imukit::run::fuse::{ALIGN_MIN_SPEED_M_S, AidTables, Start, fuse_with};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let sc = imukit::Scenario::from_file(&dir.join("car_tunnel.toml")).unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    for run in 0..5 {
        let sim = sc.simulate_run(run).unwrap();
        let gnss = sim.gnss.as_ref().unwrap();
        let (nav, _) = fuse_with(
            &sim.imu,
            gnss,
            AidTables::default(),
            Start::AlignGnss,
            &setup,
        )
        .unwrap();
        // It begins at the first fix at speed.
        let (g_t, g_vx, g_vy) = (
            col(gnss, "t_s"),
            col(gnss, "vel_x_m_s"),
            col(gnss, "vel_y_m_s"),
        );
        let k = (0..g_t.len())
            .find(|&k| g_vx[k].hypot(g_vy[k]) >= ALIGN_MIN_SPEED_M_S)
            .unwrap();
        let t_nav = col(&nav, "t_s");
        assert!(
            (t_nav[0] - g_t[k]).abs() < 1e-9,
            "{} vs {}",
            t_nav[0],
            g_t[k]
        );
        let truth_t = col(&sim.truth, "t_s");
        let at = |t: f64| truth_t.partition_point(|&x| x < t - 1e-9);
        let yaw_error = |i_nav: usize| {
            let e = col(&nav, "yaw_rad")[i_nav] - col(&sim.truth, "yaw_rad")[at(t_nav[i_nav])];
            (e + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        };
        let yaw_sigma = |i_nav: usize| col(&nav, "att_z_sigma_rad")[i_nav];
        // The start within 3σ of its stated heading uncertainty; at 115 s (before the
        // tunnel), heading and position within 3σ, the heading known to better than 0.5°.
        assert!(
            yaw_error(0).abs() < 3.0 * yaw_sigma(0),
            "run {run}: {}",
            yaw_error(0)
        );
        let i = t_nav.partition_point(|&x| x < 115.0);
        eprintln!(
            "run {run}: aligned at {:.2} s, heading error {:.4} rad (σ {:.4}); at 115 s {:.5} rad (σ {:.5})",
            t_nav[0],
            yaw_error(0),
            yaw_sigma(0),
            yaw_error(i),
            yaw_sigma(i)
        );
        assert!(yaw_error(i).abs() < 3.0 * yaw_sigma(i), "run {run}");
        assert!(
            yaw_sigma(i) < 0.5_f64.to_radians(),
            "run {run}: {}",
            yaw_sigma(i)
        );
        for axis in ["x", "y"] {
            let e = col(&nav, &format!("pos_{axis}_m"))[i]
                - col(&sim.truth, &format!("pos_{axis}_m"))[at(t_nav[i])];
            let s = col(&nav, &format!("pos_{axis}_sigma_m"))[i];
            assert!(e.abs() < 3.0 * s, "run {run}, {axis}: {e} vs σ {s}");
        }
    }
}

/// The car of [`scenario`] on the WGS-84 Earth at 45° N (its circle in the tangent plane), in
/// frame `frame`.
fn earth_scenario(frame: &str, imu: &str, gnss: &str) -> String {
    scenario(imu, gnss)
        .replace(
            "nav_frame = \"ENU\"\n",
            &format!(
                "nav_frame = \"{frame}\"\nearth = \"wgs84\"\n\
                 origin = {{ latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }}\n"
            ),
        )
        .replace(
            "2*sin(0.1*t)",
            if frame == "NED" {
                "-2*sin(0.1*t)"
            } else {
                "2*sin(0.1*t)"
            },
        )
}

#[test]
fn on_the_earth_ideal_sensors_and_exact_fixes_reproduce_the_truth() {
    // The Earth filter (Earth rate, transport rate, Coriolis, normal gravity) on the car at
    // 45° N, both frames: with ideal readings and exact fixes it stays on the truth.
    for frame in ["ENU", "NED"] {
        let text = earth_scenario(
            frame,
            "",
            "horizontal_accuracy_m = 0.0\nvertical_accuracy_m = 0.0\nvelocity_accuracy_m_s = 0.0",
        );
        let sim = simulate(&text, 0);
        let sc = ScenarioSpec::from_toml(&text, "earth.toml")
            .unwrap()
            .resolve(Path::new("."))
            .unwrap();
        let mut setup = FuseSetup::from_scenario(&sc).unwrap();
        assert!(setup.earth.is_some());
        setup.gate = Gate::Off;
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let (nav, summary) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
        assert_eq!(summary.updates, 201);
        assert_eq!(nav.columns.len(), 39); // FUSE_COLUMNS, the geodetic position, gnss_resets
        let worst = |a: &str, b: &str| {
            col(&sim.truth, a)
                .iter()
                .zip(col(&nav, b))
                .map(|(x, y)| (x - y).abs())
                .fold(0.0_f64, f64::max)
        };
        let pos = ["pos_x_m", "pos_y_m", "pos_z_m"].map(|c| worst(c, c));
        let lat = worst("lat_rad", "lat_rad") * 6.4e6;
        eprintln!("{frame}: worst position error {pos:?} m, latitude {lat:e} m");
        assert!(pos.iter().all(|e| *e < 5e-3), "{frame}: {pos:?}");
        assert!(lat < 5e-3, "{frame}: {lat}");
        assert!(worst("yaw_rad", "yaw_rad") < 1e-4, "{frame}");
    }
}

/// The normalised squared position and velocity errors at 40 s, averaged over 50 runs of the
/// noisy car at 45° N (IMU white noise and bias random walk, white fixes), with the 95 % bounds
/// of χ²(3·50)/(3·50); `wheels` adds an odometer, the constraints and a barometer.
fn earth_consistency(wheels: bool) -> ([f64; 2], (f64, f64)) {
    let (n_a, n_g, k_a, k_g) = (0.003, 2e-4, 2e-4, 2e-6);
    let aids = if wheels {
        "\n[odometer]\nrate_hz = 10.0\nnoise_m_s = 0.05\n[baro]\nrate_hz = 10.0\nnoise_m = 0.5"
    } else {
        ""
    };
    let text = earth_scenario(
        "ENU",
        &format!(
            "[imu.accelerometer]\nNoiseDensity = {n_a}\nRandomWalk = {k_a}\n\
             [imu.gyroscope]\nNoiseDensity = {n_g}\nRandomWalk = {k_g}"
        ),
        &format!(
            "horizontal_accuracy_m = 0.8\nvertical_accuracy_m = 1.2\nvelocity_accuracy_m_s = 0.05\n\
             decay_factor = 0.0{aids}"
        ),
    );
    let sc = ScenarioSpec::from_toml(&text, "earth.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let mut setup = FuseSetup::from_scenario(&sc).unwrap();
    if wheels {
        setup.aiding.nhc_sigma_m_s = Some(0.02);
    }
    let runs = 50;
    let mut sums = [0.0; 2];
    for run in 0..runs {
        let sim = sc.simulate_run(run).unwrap();
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let aid_tables = imukit::run::fuse::AidTables {
            odometer: sim.odometer.as_ref(),
            baro: sim.baro.as_ref(),
        };
        let (nav, _) = imukit::run::fuse::fuse_with(
            &sim.imu,
            sim.gnss.as_ref().unwrap(),
            aid_tables,
            imukit::run::fuse::Start::State(&initial),
            &setup,
        )
        .unwrap();
        let last = nav.rows() - 1;
        for (k, (quantity, unit)) in [("pos", "m"), ("vel", "m_s")].iter().enumerate() {
            for axis in ["x", "y", "z"] {
                let c = format!("{quantity}_{axis}_{unit}");
                let e = col(&nav, &c)[last] - col(&sim.truth, &c)[last];
                let s = col(&nav, &format!("{quantity}_{axis}_sigma_{unit}"))[last];
                sums[k] += (e / s).powi(2);
            }
        }
    }
    let dof = 3.0 * runs as f64;
    (
        sums.map(|s| s / dof),
        (
            chi2_quantile(dof, -1.959_964) / dof,
            chi2_quantile(dof, 1.959_964) / dof,
        ),
    )
}

#[test]
fn on_the_earth_the_errors_match_the_stated_uncertainty_over_50_runs() {
    // GNSS alone, and with odometer, constraints and barometer: the position and velocity
    // errors normalised by the filter's one-sigma average 1 within the 95 % bounds.
    for wheels in [false, true] {
        let (averages, (lo, hi)) = earth_consistency(wheels);
        eprintln!(
            "on the Earth (aids: {wheels}): normalised squared errors {averages:?}, 95 % bounds [{lo:.3}, {hi:.3}]"
        );
        for (name, v) in ["position", "velocity"].iter().zip(averages) {
            assert!(
                lo <= v && v <= hi,
                "aids {wheels}, {name}: {v} outside [{lo}, {hi}]"
            );
        }
    }
}

#[test]
fn through_a_20_minute_outage_on_the_earth_the_filter_knows_its_drift() {
    // A navigation-grade IMU (HG9900) at rest at 45° N: GNSS for 2 minutes, then none for 20.
    // The Earth filter's error model carries the Schuler feedback (gravity gradient, Earth rate),
    // and over 30 runs, each starting from an attitude drawn from the filter's initial
    // uncertainty (0.01 rad of tilt, 0.05 rad of heading), the RMS horizontal error at the
    // outage's end is not above the filter's one-sigma, nor far below: between 0.6 and 1.1 of it.
    // (The filter is conservative here: it models the part's flicker bias instability as a random
    // walk, whose spread keeps growing where flicker's does not. The error is kilometres: at rest
    // the heading is barely observed in 2 minutes, and a heading error ψ tilts the frame at
    // Ω cos φ · ψ, here like a 0.5 °/h gyroscope bias; a gyrocompass alignment removes it.)
    let text = "rate_hz = 10.0\nduration_s = 1320.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
                origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n\
                [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
                [imu]\nkind = \"accel-gyro\"\npreset = \"hg9900\"\nseed = 5\n\
                [gnss]\nrate_hz = 1.0\ndecay_factor = 0.0\nhorizontal_accuracy_m = 1.0\n\
                [[gnss.outages]]\nstart_s = 120.0\nduration_s = 1200.0\n";
    let sc = ScenarioSpec::from_toml(text, "schuler.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let runs = 30;
    let (mut e2, mut s2) = (0.0, 0.0);
    for run in 0..runs {
        let sim = sc.simulate_run(run).unwrap();
        let mut initial = InitialState::from_table(&sim.truth).unwrap();
        let mut draw = SeededNormals::for_run(77, run);
        let sigma = setup.initial_sigma.attitude_rad;
        let phi = nalgebra::Vector3::from_fn(|i, _| sigma[i] * draw.standard_normal());
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            initial.quaternion[0],
            initial.quaternion[1],
            initial.quaternion[2],
            initial.quaternion[3],
        ));
        let start = nalgebra::UnitQuaternion::from_scaled_axis(-phi) * q;
        initial.quaternion = [start.w, start.i, start.j, start.k];
        let (nav, _) = fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &setup).unwrap();
        let last = nav.rows() - 2; // the last sample before the fix at 1320 s
        for axis in ["x", "y"] {
            let c = format!("pos_{axis}_m");
            e2 += (col(&nav, &c)[last] - col(&sim.truth, &c)[last]).powi(2);
            s2 += col(&nav, &format!("pos_{axis}_sigma_m"))[last].powi(2);
        }
    }
    let (rms, sigma) = ((e2 / runs as f64).sqrt(), (s2 / runs as f64).sqrt());
    eprintln!(
        "HG9900 after 20 min without GNSS: RMS horizontal error {rms:.2} m, filter {sigma:.2} m"
    );
    assert!((0.6..=1.1).contains(&(rms / sigma)), "{rms} vs {sigma}");
}

#[test]
fn an_imu_slower_than_its_gnss_is_refused() {
    // Every other IMU sample of the car (25 Hz) against its 5 Hz fixes is fine; every 20th
    // (2.5 Hz) is slower than the fixes and refused, naming both rates.
    let text = scenario("", "decay_factor = 0.0");
    let sim = simulate(&text, 0);
    let sc = ScenarioSpec::from_toml(&text, "fusion.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let every = |k: usize| {
        let mut t = Table::new(
            &sim.imu
                .columns
                .iter()
                .map(String::as_str)
                .collect::<Vec<_>>(),
        );
        for row in sim.imu.data.chunks(sim.imu.columns.len()).step_by(k) {
            t.push_row(row);
        }
        t
    };
    let gnss = sim.gnss.as_ref().unwrap();
    assert!(fuse(&every(2), gnss, &initial, &setup).is_ok());
    let e = fuse(&every(20), gnss, &initial, &setup)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("GNSS data") && e.contains("more often than the IMU"),
        "{e}"
    );
}

#[test]
fn a_navigation_grade_imu_at_rest_finds_north_and_then_holds_it_through_the_outage() {
    // The HG9900 at rest at 45° N again, now aligned without truth: 60 s of levelling and
    // gyrocompassing, then the filter. Its heading error after the alignment lies within 3σ of
    // what it states (1.5 mrad: the gyroscope's white noise averaged over 60 s, over the Earth
    // rate's horizontal part), and 20 minutes without GNSS now cost a few hundred metres instead
    // of the 5 km of a 0.05 rad heading, the error between 0.6 and 1.1 of the filter's sigma (as
    // in the test above, the flicker model makes it conservative).
    use imukit::run::fuse::{AidTables, Start, fuse_with};
    let text = "rate_hz = 10.0\nduration_s = 1320.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
                origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n\
                [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
                [imu]\nkind = \"accel-gyro\"\npreset = \"hg9900\"\nseed = 5\n\
                [gnss]\nrate_hz = 1.0\ndecay_factor = 0.0\nhorizontal_accuracy_m = 1.0\n\
                [[gnss.outages]]\nstart_s = 120.0\nduration_s = 1200.0\n";
    let sc = ScenarioSpec::from_toml(text, "gyrocompass.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let runs = 30;
    let (mut e2, mut s2) = (0.0, 0.0);
    for run in 0..runs {
        let sim = sc.simulate_run(run).unwrap();
        let gnss = sim.gnss.as_ref().unwrap();
        let start = Start::from(imukit::run::fuse::AlignName::Static);
        let (nav, _) = fuse_with(&sim.imu, gnss, AidTables::default(), start, &setup).unwrap();
        let yaw_error = col(&nav, "yaw_rad")[0] - col(&sim.truth, "yaw_rad")[0];
        let yaw_sigma = col(&nav, "att_z_sigma_rad")[0];
        if run < 3 {
            eprintln!(
                "run {run}: heading after the alignment off by {yaw_error:.2e} rad (σ {yaw_sigma:.2e})"
            );
        }
        assert!(
            yaw_error.abs() < 3.0 * yaw_sigma,
            "run {run}: {yaw_error} vs σ {yaw_sigma}"
        );
        assert!(yaw_sigma < 0.01, "{yaw_sigma}");
        let last = nav.rows() - 2;
        let truth_last = sim.truth.rows() - 2;
        for axis in ["x", "y"] {
            let c = format!("pos_{axis}_m");
            e2 += (col(&nav, &c)[last] - col(&sim.truth, &c)[truth_last]).powi(2);
            s2 += col(&nav, &format!("pos_{axis}_sigma_m"))[last].powi(2);
        }
    }
    let (rms, sigma) = ((e2 / runs as f64).sqrt(), (s2 / runs as f64).sqrt());
    eprintln!(
        "HG9900 gyrocompassed, 20 min without GNSS: RMS horizontal error {rms:.2} m, filter {sigma:.2} m"
    );
    assert!(rms < 500.0, "{rms}");
    assert!((0.6..=1.1).contains(&(rms / sigma)), "{rms} vs {sigma}");
}

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

#[test]
fn a_consumer_gyroscope_cannot_gyrocompass_and_says_why_as_a_typed_source() {
    use imu_core::fusion::align::AlignError;
    use imukit::run::fuse::{AidTables, AlignName, Start, fuse_with};
    let text = "rate_hz = 10.0\nduration_s = 70.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
                origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n\
                [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
                [imu]\nkind = \"accel-gyro\"\npreset = \"icm-42688-p\"\nseed = 5\n\
                [gnss]\nrate_hz = 1.0\n";
    let sc = ScenarioSpec::from_toml(text, "consumer.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let sim = sc.simulate().unwrap();
    let gnss = sim.gnss.as_ref().unwrap();
    let e = fuse_with(
        &sim.imu,
        gnss,
        AidTables::default(),
        Start::from(AlignName::Static),
        &setup,
    )
    .unwrap_err();
    // The core's error is the source, not text: a program can tell why.
    match &e {
        imukit::Error::Align {
            field,
            source:
                AlignError::NoNorth {
                    horizontal_rate_rad_s,
                    ..
                },
        } => {
            assert_eq!(field, "align");
            // Ω cos 45°: the horizontal Earth rate the part's bias drowns.
            let omega_h = 7.292_115e-5 * std::f64::consts::FRAC_1_SQRT_2;
            assert!((horizontal_rate_rad_s - omega_h).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(e.location().field.as_deref(), Some("align"));
    assert!(
        e.to_string()
            .contains("use \"gnss\" or give the initial state"),
        "{e}"
    );
    assert!(std::error::Error::source(&e).is_some());
}

/// The forward–backward smoother on the example road, 30 seeded runs of a STIM300 (15 states)
/// and of an MPU-6050 (36 states, the rest at the start): its position NEES averaged over the
/// runs (per axis, e²/σ², summed over the three axes) stays inside the 95 % bounds of χ² with
/// 3 × runs degrees of freedom in the middle of the tunnel and between fixes; its RMS position
/// error through the tunnel over the runs is below half the filter's, and below the filter's in
/// at least 9 runs in 10 (a filter can be lucky in one run).
#[test]
fn the_smoother_is_consistent_and_beats_the_filter_in_every_outage() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let runs = 30;
    let dof = 3.0 * runs as f64;
    let (lo, hi) = (
        chi2_quantile(dof, -1.959_964) / runs as f64,
        chi2_quantile(dof, 1.959_964) / runs as f64,
    );
    for (preset, sensor_errors, rest_s) in [("stim300", false, 0.0), ("mpu-6050", true, 20.0)] {
        let text = std::fs::read_to_string(dir.join("car_tunnel.toml"))
            .unwrap()
            .replace("preset = \"stim300\"", &format!("preset = \"{preset}\""));
        let sc = ScenarioSpec::from_toml(&text, "car_tunnel.toml")
            .unwrap()
            .resolve(&dir)
            .unwrap();
        let filter_setup = FuseSetup {
            estimate_sensor_errors: sensor_errors,
            rest_s,
            ..FuseSetup::from_scenario(&sc).unwrap()
        };
        let smoother_setup = FuseSetup {
            smooth: true,
            ..filter_setup
        };
        let checks = [60.0, 135.0];
        let mut nees = [0.0; 2];
        let mut mean_square = [0.0; 2];
        let mut better = 0;
        for run in 0..runs {
            let sim = sc.simulate_run(run).unwrap();
            let initial = InitialState::from_table(&sim.truth).unwrap();
            let gnss = sim.gnss.as_ref().unwrap();
            let (filtered, _) = fuse(&sim.imu, gnss, &initial, &filter_setup).unwrap();
            let (smoothed, _) = fuse(&sim.imu, gnss, &initial, &smoother_setup).unwrap();
            let t = col(&sim.truth, "t_s");
            let truth = rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]);
            let error = |nav: &Table| -> Vec<[f64; 3]> {
                rows3(nav, ["pos_x_m", "pos_y_m", "pos_z_m"])
                    .iter()
                    .zip(&truth)
                    .map(|(e, p)| [0, 1, 2].map(|k| e[k] - p[k]))
                    .collect()
            };
            let (ef, es) = (error(&filtered), error(&smoothed));
            let sigma = rows3(
                &smoothed,
                ["pos_x_sigma_m", "pos_y_sigma_m", "pos_z_sigma_m"],
            );
            for (c, check) in checks.iter().enumerate() {
                let i = t.iter().position(|x| (x - check).abs() < 1e-6).unwrap();
                nees[c] += (0..3)
                    .map(|k| (es[i][k] / sigma[i][k]).powi(2))
                    .sum::<f64>();
            }
            let tunnel = |e: &[[f64; 3]]| {
                let inside: Vec<f64> = t
                    .iter()
                    .zip(e)
                    .filter(|(x, _)| (120.0..150.0).contains(*x))
                    .map(|(_, v)| v.iter().map(|c| c * c).sum::<f64>())
                    .collect();
                (inside.iter().sum::<f64>() / inside.len() as f64).sqrt()
            };
            let (rf, rs) = (tunnel(&ef), tunnel(&es));
            mean_square[0] += rf * rf / runs as f64;
            mean_square[1] += rs * rs / runs as f64;
            better += usize::from(rs < rf);
        }
        let [rms_filtered, rms_smoothed] = mean_square.map(f64::sqrt);
        eprintln!(
            "{preset}: tunnel RMS over {runs} runs filtered {rms_filtered:.3} m, smoothed \
             {rms_smoothed:.3} m; smoother better in {better} runs"
        );
        assert!(
            rms_smoothed < 0.5 * rms_filtered,
            "{rms_smoothed} vs {rms_filtered}"
        );
        assert!(
            better * 10 >= runs as usize * 9,
            "better in {better} of {runs}"
        );
        let nees = nees.map(|s| s / runs as f64);
        eprintln!(
            "{preset}: smoothed position NEES at {checks:?} s: {nees:?}, bounds [{lo:.3}, {hi:.3}]"
        );
        for (check, v) in checks.iter().zip(nees) {
            assert!(
                lo <= v && v <= hi,
                "{preset}: NEES {v} at {check} s outside [{lo}, {hi}]"
            );
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

/// One pass gives both tables: the filtered one is `fuse`'s and the smoothed one `fuse` with
/// `smooth`'s, value for value (the study compares them without running the filter twice).
#[test]
fn the_filtered_and_smoothed_tables_of_one_pass_are_those_of_two() {
    use imukit::run::fuse::{AidTables, Start, fuse_filtered_and_smoothed, fuse_with};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let sc = imukit::Scenario::from_file(&dir.join("car_tunnel.toml")).unwrap();
    let setup = FuseSetup::from_scenario(&sc).unwrap();
    let sim = sc.simulate_run(0).unwrap();
    let initial = InitialState::from_table(&sim.truth).unwrap();
    let gnss = sim.gnss.as_ref().unwrap();
    let run = |setup: &FuseSetup| {
        fuse_with(
            &sim.imu,
            gnss,
            AidTables::default(),
            Start::State(&initial),
            setup,
        )
        .unwrap()
        .0
    };
    let filtered = run(&setup);
    let smoothed = run(&FuseSetup {
        smooth: true,
        ..setup
    });
    let (f, s, _) = fuse_filtered_and_smoothed(
        &sim.imu,
        gnss,
        AidTables::default(),
        Start::State(&initial),
        &setup,
    )
    .unwrap();
    assert_eq!(f, filtered);
    assert_eq!(s, smoothed);
    assert_ne!(f, s);
}
