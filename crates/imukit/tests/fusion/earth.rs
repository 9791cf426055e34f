//! The filter on the WGS-84 Earth: the truth reproduced, consistency over seeded runs, a long
//! outage, gyrocompassing at rest and the refusal of a gyroscope that cannot.
use std::path::Path;

use imu_core::sensor::{NoiseSource, SeededNormals};
use imukit::ScenarioSpec;
use imukit::run::fuse::{FuseSetup, Gate, fuse};
use imukit::run::navigate::InitialState;

use super::{col, scenario, simulate};
use crate::common::chi2_quantile;

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
            start,
            source:
                AlignError::NoNorth {
                    horizontal_rate_rad_s,
                    ..
                },
        } => {
            assert_eq!(*start, "static");
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
