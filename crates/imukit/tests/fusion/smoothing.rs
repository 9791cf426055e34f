//! The Rauch–Tung–Striebel pass over the filter: consistent, better than the filter in every outage,
//! and the same from one pass as from two.
use std::path::Path;

use imukit::run::fuse::{FuseSetup, fuse};
use imukit::run::navigate::InitialState;
use imukit::{ScenarioSpec, Table};

use super::{col, rows3};
use crate::common::chi2_quantile;

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
