//! Fixes whose errors last: the example road (`examples/car_tunnel.toml` without its outage
//! and odometer, its IMU one whose errors the filter models exactly) with MATLAB gpsSensor's
//! decay factor at 0.99 and 0.999, 50 seeded runs each, fused with the scenario's own model (the fixes' errors as filter states). The average NEES of
//! position and of velocity (per axis e²/σ² from the table's one-sigma columns, summed over the
//! three axes), over the runs and then over the drive (every 5 s from its start, 25 s, to
//! 165 s), lies inside the two-sided 95 % bounds of χ² with 3 × runs degrees of freedom over
//! runs, filtered and smoothed. (The epochs of one run are correlated: the bounds of the runs
//! alone are wider than those of the time average, so the test cannot fail for that.)
use std::path::Path;

use imukit::run::fuse::{FuseSetup, fuse};
use imukit::run::navigate::InitialState;
use imukit::{ScenarioSpec, Table};

use crate::common::nees_bounds_95;

fn rows3(t: &Table, names: [&str; 3]) -> Vec<[f64; 3]> {
    let c: Vec<Vec<f64>> = names.iter().map(|n| t.column(n).unwrap()).collect();
    (0..t.rows()).map(|i| [c[0][i], c[1][i], c[2][i]]).collect()
}

/// A part whose errors the filter models exactly (white noise and bias random walks), so that
/// what is tested is the fixes' model.
const PART: &str = "[imu.accelerometer]\nNoiseDensity = 0.003\nRandomWalk = 2e-4\n\
                    [imu.gyroscope]\nNoiseDensity = 2e-4\nRandomWalk = 2e-6";

/// The road without its outage and odometer, the receiver's decay factor `decay`, the IMU
/// [`PART`].
fn road(decay: f64) -> imukit::Scenario {
    road_with(decay, 1.0)
}

/// [`road`] with the receiver's accuracies (position and velocity) `worse` times the road's.
fn road_with(decay: f64, worse: f64) -> imukit::Scenario {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("car_tunnel.toml")).unwrap();
    let text = text
        .replace("decay_factor = 0.0", &format!("decay_factor = {decay}"))
        .replace("preset = \"stim300\"", "#")
        .replace("seed = 11\n", &format!("seed = 11\n{PART}\n"))
        .replace(
            "horizontal_accuracy_m = 1.5",
            &format!("horizontal_accuracy_m = {}", 1.5 * worse),
        )
        .replace(
            "vertical_accuracy_m = 3.0",
            &format!("vertical_accuracy_m = {}", 3.0 * worse),
        )
        .replace(
            "velocity_accuracy_m_s = 0.1",
            &format!("velocity_accuracy_m_s = {}", 0.1 * worse),
        );
    let cut = text.find("[[gnss.outages]]").unwrap();
    ScenarioSpec::from_toml(&text[..cut], "car_tunnel.toml")
        .unwrap()
        .resolve(&dir)
        .unwrap()
}

const RUNS: u64 = 50;
/// The epochs averaged: every 5 s of the drive.
const CHECKS_S: [f64; 29] = {
    let mut t = [0.0; 29];
    let mut k = 0;
    while k < 29 {
        t[k] = 25.0 + 5.0 * k as f64;
        k += 1;
    }
    t
};

/// Average NEES of position and velocity over [`RUNS`] runs and the epochs [`CHECKS_S`],
/// filtered and smoothed (`[filtered, smoothed][position, velocity]`).
fn average_nees(decay: f64) -> [[f64; 2]; 2] {
    let setup = FuseSetup::from_scenario(&road(decay)).unwrap();
    assert_eq!(setup.correlated_fixes(), decay > 0.0);
    average_nees_of(&road(decay), &setup)
}

/// [`average_nees`] of the data of `sc` fused with `setup`.
fn average_nees_of(sc: &imukit::Scenario, setup: &FuseSetup) -> [[f64; 2]; 2] {
    let setup = *setup;
    let mut sums = [[0.0; 2]; 2];
    for run in 0..RUNS {
        let sim = sc.simulate_run(run).unwrap();
        let initial = InitialState::from_table(&sim.truth).unwrap();
        let gnss = sim.gnss.as_ref().unwrap();
        let t = sim.truth.column("t_s").unwrap();
        let truth = [
            rows3(&sim.truth, ["pos_x_m", "pos_y_m", "pos_z_m"]),
            rows3(&sim.truth, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]),
        ];
        for (s, smooth) in [false, true].into_iter().enumerate() {
            let (nav, _) = fuse(&sim.imu, gnss, &initial, &FuseSetup { smooth, ..setup }).unwrap();
            let estimate = [
                rows3(&nav, ["pos_x_m", "pos_y_m", "pos_z_m"]),
                rows3(&nav, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]),
            ];
            let sigma = [
                rows3(&nav, ["pos_x_sigma_m", "pos_y_sigma_m", "pos_z_sigma_m"]),
                rows3(
                    &nav,
                    ["vel_x_sigma_m_s", "vel_y_sigma_m_s", "vel_z_sigma_m_s"],
                ),
            ];
            for check in CHECKS_S {
                let i = t.iter().position(|x| (x - check).abs() < 1e-6).unwrap();
                for q in 0..2 {
                    sums[s][q] += (0..3)
                        .map(|k| ((estimate[q][i][k] - truth[q][i][k]) / sigma[q][i][k]).powi(2))
                        .sum::<f64>();
                }
            }
        }
    }
    let count = (RUNS as usize * CHECKS_S.len()) as f64;
    sums.map(|s| s.map(|v| v / count))
}

#[test]
fn fixes_with_a_decay_factor_of_0_99_and_0_999_leave_the_uncertainty_honest() {
    let (lo, hi) = nees_bounds_95(RUNS);
    for decay in [0.99, 0.999] {
        let nees = average_nees(decay);
        for (s, name) in ["filtered", "smoothed"].iter().enumerate() {
            eprintln!(
                "decay {decay}, {name}: NEES (position, velocity) {:?}, bounds [{lo:.3}, {hi:.3}]",
                nees[s]
            );
            for (q, what) in ["position", "velocity"].iter().enumerate() {
                let v = nees[s][q];
                assert!(
                    (lo..=hi).contains(&v),
                    "decay {decay}, {name} {what}: NEES {v} outside [{lo}, {hi}]"
                );
            }
        }
    }
}

#[test]
fn a_receiver_whose_process_is_not_stated_is_taken_as_white() {
    // The road's receiver without its decay factor: the simulator draws MATLAB's default
    // (0.999), the filter takes the fixes as white; a correlation time makes them states, in
    // their stationary state from the start.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("car_tunnel.toml")).unwrap();
    let setup = |replacement: &str| {
        let text = text.replace("decay_factor = 0.0", replacement);
        let sc = ScenarioSpec::from_toml(&text, "car_tunnel.toml")
            .unwrap()
            .resolve(&dir)
            .unwrap();
        FuseSetup::from_scenario(&sc).unwrap()
    };
    assert!(!setup("").correlated_fixes());
    assert!(!setup("decay_factor = 0.0").correlated_fixes());
    let markov = setup("correlation_time_s = 30.0");
    let model = markov.fix_error_model(0.2).unwrap();
    assert_eq!(model.correlation_time_s, 30.0);
    assert_eq!(model.initial_sigma_m, markov.gnss_position_sigma_m);
    assert_eq!(model.sigma_m, [1.5, 1.5, 3.0]);
}

#[test]
fn a_receiver_three_times_worse_than_stated_is_found_out_by_its_innovations() {
    // White fixes three times worse (position and velocity) than the filter is told: taken as
    // stated, they are lost; with the fixes' noise scaled from their
    // innovations (up to 25× in variance) it is inside them, filtered and smoothed.
    let (lo, hi) = nees_bounds_95(RUNS);
    let data = road_with(0.0, 3.0);
    let told = FuseSetup::from_scenario(&road(0.0)).unwrap();
    // Taken as stated, the filter rejects the fixes, is reset to them and gives up.
    let sim = data.simulate_run(0).unwrap();
    let initial = InitialState::from_table(&sim.truth).unwrap();
    match fuse(&sim.imu, sim.gnss.as_ref().unwrap(), &initial, &told) {
        Ok((_, summary)) => assert!(summary.resets > 0, "{summary:?}"),
        Err(e) => assert!(matches!(e, imukit::Error::Diverged { .. }), "{e}"),
    }
    let adaptive = FuseSetup {
        max_fix_noise_scale: imukit::run::fuse::DEFAULT_MAX_FIX_NOISE_SCALE,
        ..told
    };
    let nees = average_nees_of(&data, &adaptive);
    eprintln!("scaled from the innovations: NEES {nees:?}, bounds [{lo:.3}, {hi:.3}]");
    for (s, name) in ["filtered", "smoothed"].iter().enumerate() {
        for (q, what) in ["position", "velocity"].iter().enumerate() {
            let v = nees[s][q];
            assert!(
                (lo..=hi).contains(&v),
                "{name} {what}: NEES {v} outside [{lo}, {hi}]"
            );
        }
    }
}
