//! A log with no data sheet: a walking foot whose IMU is three times noisier than any preset
//! (and whose accelerometer reads 0.03 g off, as a phone's does), fused with zero-velocity
//! updates from nothing but its readings — the noise learnt from its quiet stretches, levelled
//! over the rest at the start, heading zero, at the origin. The stance detector finds the
//! stances and calls no swing still; the walk closes its loop; the learnt noise is the part's.
use std::path::Path;

use imukit::run::fuse::{
    AidTables, FuseRequest, MAX_STANCE_GAP_S, Part, PartModel, Start, fuse_with, learnt_noise,
    longest_without_stance, stance_gap_message, stance_samples,
};
use imukit::run::navigate::NavRequest;
use imukit::{ScenarioSpec, Simulation, Table};

/// Ten seconds standing, then 270 strides (six laps of a 10 m circle, 377 m) at 0.9 strides a
/// second, back to the start. The IMU: the ICM-42688-P's ranges (a heel strike fits), white
/// noise three times the noisiest preset's (the MPU-6050's accelerometer, the MTi-1's
/// gyroscope), constant biases of 0.03 g and about 1 °/s.
const NOISY_WALK: &str = r#"
rate_hz = 100.0
duration_s = 310.0
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

[imu.accelerometer]
noise_density_m_s2_per_rt_hz = 0.0117680
constant_bias_m_s2 = [0.3, -0.2, 0.25]

[imu.gyroscope]
noise_density_rad_s_per_rt_hz = 0.00036652
constant_bias_rad_s = [0.02, -0.015, 0.01]
"#;

fn simulate(run: u64) -> Simulation {
    ScenarioSpec::from_toml(NOISY_WALK, "noisy_walk.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate_run(run)
        .unwrap()
}

fn rows3(t: &Table, names: [&str; 3]) -> Vec<[f64; 3]> {
    let c: Vec<Vec<f64>> = names.iter().map(|n| t.column(n).unwrap()).collect();
    (0..t.rows()).map(|i| [c[0][i], c[1][i], c[2][i]]).collect()
}

#[test]
fn a_noisy_walk_with_no_data_sheet_closes_its_loop_from_its_readings_alone() {
    for run in 0..3 {
        let sim = simulate(run);
        let nav = NavRequest::default().setup().unwrap();
        let model = PartModel {
            imu: Part::Learnt,
            ..PartModel::default()
        };
        let learnt = model.setup_for(&nav, None, &sim.imu).unwrap();
        // The noise learnt is the part's density (here single-sided and two-sided alike: the
        // preset's noise per sample is density × √(rate)).
        for (learnt, stated) in [
            (learnt.noise.accel_psd, 0.0117680),
            (learnt.noise.gyro_psd, 0.00036652),
        ] {
            assert!(
                (learnt / stated - 1.0).abs() < 0.05,
                "run {run}: learnt {learnt:e}, stated {stated:e}"
            );
        }
        assert!(
            !learnt.warrants_sensor_errors(),
            "the part's matrices are unknown"
        );
        let request = FuseRequest {
            start: Start::when_not_given(false),
            zupt: true,
            ..FuseRequest::default()
        };
        let (setup, start) = request.apply(learnt).unwrap();
        let (est, summary) = fuse_with(
            &sim.imu,
            &Table::default(),
            AidTables::default(),
            start,
            &setup,
        )
        .unwrap();
        // The foot stands 10 s, then through its first stride's stance (0.6 of a stride at
        // 0.9 strides a second): the rest found ends by then, and not much before.
        let moves = 10.0 + 0.6 / 0.9;
        assert!(
            summary.rest_s <= moves && summary.rest_s > moves - 0.6,
            "run {run}: rest {} s, the foot moves at {moves} s",
            summary.rest_s
        );
        let detection = summary.detection.unwrap();
        assert!(detection.learnt);
        // The foot stands at every stride (1.1 s apart): nothing to warn about.
        let (_, gap) = summary.stance_gap.unwrap();
        assert!(
            gap < MAX_STANCE_GAP_S,
            "run {run}: {gap} s without a stance"
        );
        assert_eq!(stance_gap_message("imu", summary.stance_gap), None);
        // Gravity as this accelerometer reads it: |g + bias| (the bias is 0.03 g).
        let reading = (0.3_f64.powi(2) + 0.2_f64.powi(2) + (9.81_f64 + 0.25).powi(2)).sqrt();
        assert!(
            (detection.gravity_m_s2 - reading).abs() < 5e-3,
            "run {run}: {} against {reading}",
            detection.gravity_m_s2
        );

        // The stances against the truth's speed: found inside the stances, none in a swing.
        let t = sim.imu.column("t_s").unwrap();
        let f = rows3(&sim.imu, ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]);
        let w = rows3(&sim.imu, ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]);
        let stance = stance_samples(&t, &f, &w, &setup_with_rest(&setup, summary.rest_s));
        let ((found, stances), (called_still, swings)) = stance_scores(&sim.truth, &stance);
        eprintln!(
            "run {run}: stances found {found} of {stances}, swing samples called still \
             {called_still} of {swings}"
        );
        assert!(
            found * 100 >= 95 * stances,
            "run {run}: {found} of {stances}"
        );
        assert!(
            called_still * 100 <= swings,
            "run {run}: {called_still} of {swings}"
        );

        // The loop closes: the walk ends where it began (the truth's 377 m).
        let (walked, closure) = walked_and_closure(&sim.truth, &est);
        eprintln!(
            "run {run}: {walked:.1} m walked, loop closed within {closure:.3} m ({:.3} %)",
            100.0 * closure / walked
        );
        assert!(
            closure <= 0.005 * walked,
            "run {run}: {closure} m after {walked} m"
        );
    }
}

/// The stance samples `stance` found against the truth's speed: (found, of the stance samples
/// whose neighbours (±5 samples, the detector's window and more) are all still), and (called
/// still, of the swing samples moving faster than 0.05 m/s).
fn stance_scores(truth: &Table, stance: &[bool]) -> ((usize, usize), (usize, usize)) {
    let speed: Vec<f64> = rows3(truth, ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"])
        .iter()
        .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
        .collect();
    let still: Vec<bool> = speed.iter().map(|s| *s == 0.0).collect();
    let inner = |i: usize| (i.saturating_sub(5)..(i + 6).min(still.len())).all(|j| still[j]);
    let (stances, found) = (0..still.len())
        .filter(|&i| inner(i))
        .fold((0, 0), |(s, k), i| (s + 1, k + usize::from(stance[i])));
    let (swings, called_still) = (0..still.len())
        .filter(|&i| speed[i] > 0.05)
        .fold((0, 0), |(s, k), i| (s + 1, k + usize::from(stance[i])));
    ((found, stances), (called_still, swings))
}

/// The distance the truth walked and how far the estimate's end is from its start, m.
fn walked_and_closure(truth: &Table, est: &Table) -> (f64, f64) {
    let truth = rows3(truth, ["pos_x_m", "pos_y_m", "pos_z_m"]);
    let walked: f64 = truth
        .windows(2)
        .map(|p| {
            (0..3)
                .map(|k| (p[1][k] - p[0][k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
    let pos = rows3(est, ["pos_x_m", "pos_y_m", "pos_z_m"]);
    let (first, last) = (pos[0], pos[pos.len() - 1]);
    let closure = (0..3)
        .map(|k| (last[k] - first[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    (walked, closure)
}

/// `setup` with the rest the fusion found (the stance detector takes the gyroscope's mean over
/// it off).
fn setup_with_rest(
    setup: &imukit::run::fuse::FuseSetup,
    rest_s: f64,
) -> imukit::run::fuse::FuseSetup {
    imukit::run::fuse::FuseSetup { rest_s, ..*setup }
}

#[test]
fn a_log_that_never_rests_is_refused_with_what_to_give_instead() {
    // The same walk from its first stride: no rest at the start to level over.
    let sim = simulate(0);
    let t = sim.imu.column("t_s").unwrap();
    let from = t.partition_point(|&x| x < 10.5);
    let width = sim.imu.columns.len();
    let moving = Table {
        columns: sim.imu.columns.clone(),
        data: sim.imu.data[from * width..].to_vec(),
    };
    let nav = NavRequest::default().setup().unwrap();
    let model = PartModel {
        imu: Part::Learnt,
        ..PartModel::default()
    };
    let learnt = model.setup_for(&nav, None, &moving).unwrap();
    let request = FuseRequest {
        start: Start::when_not_given(false),
        zupt: true,
        ..FuseRequest::default()
    };
    let (setup, start) = request.apply(learnt).unwrap();
    let err = fuse_with(
        &moving,
        &Table::default(),
        AidTables::default(),
        start,
        &setup,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("\"level\"") && err.contains("rest"), "{err}");
    // The quiet stretches alone (no rest) still give the noise.
    let f = rows3(&moving, ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]);
    let w = rows3(&moving, ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]);
    let q = learnt_noise(&f, &w, 0.01, 9.81).unwrap();
    assert!(
        (q.noise.accel / 0.117680 - 1.0).abs() < 0.05,
        "{}",
        q.noise.accel
    );
}

/// A car standing 30 s with its engine running, then driving: at rest the readings carry the
/// engine's vibration (0.3 m/s² at 31 Hz on the accelerometers, 0.01 rad/s on the gyroscopes,
/// sampled at 100 Hz), far above the part's white noise. Readings only, in ENU/FLU.
fn idling_then_driving(seed: u64) -> Table {
    let rate = 100.0;
    let n = 90 * 100;
    let mut rng = <rand_xoshiro::Xoshiro256PlusPlus as rand_core::SeedableRng>::seed_from_u64(seed);
    let mut z =
        || -> f64 { rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng) };
    let mut table = Table::new(&[
        "t_s",
        "accel_x_m_s2",
        "accel_y_m_s2",
        "accel_z_m_s2",
        "gyro_x_rad_s",
        "gyro_y_rad_s",
        "gyro_z_rad_s",
    ]);
    for i in 0..n {
        let t = i as f64 / rate;
        let engine = (2.0 * std::f64::consts::PI * 31.0 * t).sin();
        // Driving from 30 s: accelerating, braking and turning by a second or two.
        let (push, turn) = if t < 30.0 {
            (0.0, 0.0)
        } else {
            (1.5 * (0.7 * t).sin(), 0.2 * (0.4 * t).sin())
        };
        table.push_row(&[
            t,
            0.3 * engine + push + 0.001 * z(),
            0.2 * engine + turn * 8.0 + 0.001 * z(),
            9.81 + 0.3 * engine + 0.001 * z(),
            0.01 * engine + 1e-4 * z(),
            0.01 * engine + 1e-4 * z(),
            0.002 + turn + 1e-4 * z(),
        ]);
    }
    table
}

#[test]
fn a_car_idling_is_at_rest_although_its_engine_shakes_the_sensor() {
    for seed in 0..3 {
        let imu = idling_then_driving(seed);
        let nav = NavRequest::default().setup().unwrap();
        // A quiet part is named (the STIM300's white noise is 1e-3 m/s² per sample at 100 Hz):
        // the detectors take the log's noise, the engine's, and find the rest.
        for imu_part in [Part::Learnt, Part::Preset("stim300".into())] {
            let model = PartModel {
                imu: imu_part.clone(),
                ..PartModel::default()
            };
            let setup = model.setup_for(&nav, None, &imu).unwrap();
            let request = FuseRequest {
                start: Start::when_not_given(false),
                ..FuseRequest::default()
            };
            let (setup, start) = request.apply(setup).unwrap();
            let (_, summary) =
                fuse_with(&imu, &Table::default(), AidTables::default(), start, &setup).unwrap();
            assert!(
                (28.5..=30.0).contains(&summary.rest_s),
                "seed {seed}, {imu_part:?}: rest {} s",
                summary.rest_s
            );
            let d = summary.detection.unwrap();
            assert!(d.learnt && d.noise.accel > 0.1, "{d:?}");
        }
        // The part's noise alone would call the idling car moving from its first block.
        let f = rows3(&imu, ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]);
        let w = rows3(&imu, ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]);
        let part = imu_core::stillness::ReadingNoise {
            accel: 1e-3,
            gyro: 4.4e-4,
        };
        assert_eq!(imu_core::stillness::initial_rest(&f, &w, part, 50), 0);
    }
}

#[test]
fn a_stretch_without_stances_is_found_and_warned_about() {
    // 10 Hz: stances at 0–1 s (the rest), 2 s, 2.5 s, then none until 6 s.
    let t: Vec<f64> = (0..80).map(|i| f64::from(i) * 0.1).collect();
    let stance: Vec<bool> = t
        .iter()
        .map(|x| *x < 1.0 || (*x - 2.0).abs() < 1e-9 || (*x - 2.5).abs() < 1e-9 || *x >= 6.0)
        .collect();
    let gap = longest_without_stance(&t, &stance, 1.0).unwrap();
    assert!(
        (gap.0 - 2.5).abs() < 1e-9 && (gap.1 - 3.5).abs() < 1e-9,
        "{gap:?}"
    );
    let message = stance_gap_message("walk.csv", Some(gap)).unwrap();
    assert!(
        message.contains("no stance for 3.5 s (from t = 2.5 s"),
        "{message}"
    );
    // The rest itself is not a stretch without stances; one stance after it is no stretch.
    assert_eq!(longest_without_stance(&t[..25], &stance[..25], 1.0), None);
    assert_eq!(stance_gap_message("walk.csv", Some((1.0, 1.9))), None);
}
