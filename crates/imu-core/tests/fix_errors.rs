//! The fixes' correlated errors as filter states (`imu_core::fusion::fix_errors`): on fixes
//! made by MATLAB gpsSensor's own process (`imu_core::aiding::GnssModel`, decay factors 0.99 and
//! 0.999 at 1 Hz), a filter with the fix-error states is consistent — the average NEES of
//! position and velocity over 100 seeded runs inside the two-sided 95 % chi-square bounds after
//! five minutes — and a filter that takes the same fixes as white (their stationary deviation
//! as the fix's sigma) is not: its position NEES lies far above the bounds, because it
//! believes every fix anew while their error lasts hundreds of fixes.
use imu_core::aiding::{GnssModel, GnssParams, GnssState, PositionNoise};
use imu_core::earth::FlatEarth;
use imu_core::fusion::gate::Gate;
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfState, FIX_ERROR_STATES, FULL_STATES, FixErrorModel, GnssFix,
    SensorErrorSigma,
};
use imu_core::sensor::SeededNormals;
use imu_core::strapdown::NavState;
use imu_core::{Enu, Rotation, Vec3};

// The filter's noise and start, and the helpers, of the consistency tests beside.
use crate::eskf::{NOISE, SIGMA, chi2_quantile, draw3};

const RATE_HZ: f64 = 100.0;
const HORIZONTAL_M: f64 = 1.5;
const VERTICAL_M: f64 = 3.0;
const VELOCITY_M_S: f64 = 0.1;
/// The white part the filter is told a fix has when the receiver's process has none (MATLAB's).
const WHITE_FLOOR_M: f64 = 1e-3;

const FIX_STATES: usize = BASE_STATES + FIX_ERROR_STATES;
const FULL_FIX_STATES: usize = FULL_STATES + FIX_ERROR_STATES;

/// Driving north-east at a constant 11 m/s, level, on the flat ENU Earth.
fn truth(t_s: f64) -> (Vec3<Enu>, Vec3<Enu>) {
    let v = Vec3::new(10.0, 5.0, 0.0);
    (Vec3::new(3.0, -2.0, 1.0) + v * t_s, v)
}

/// How the filter takes the fixes.
#[derive(Clone, Copy, PartialEq)]
enum Model {
    /// White, with the process's stationary deviation.
    White,
    /// The fix-error states.
    States,
}

/// One run: the truth's biases and the filter's start drawn from the initial one-sigmas,
/// white noise on every reading, fixes at 1 Hz from the receiver's process with `decay`.
/// Returns the NEES of position and velocity at each of `at_s`.
fn run<const S: usize>(decay: f64, model: Model, run: u64, at_s: &[f64]) -> Vec<[f64; 2]> {
    let earth = FlatEarth::<Enu>::new(9.81);
    let mut n = SeededNormals::for_run(11, run);
    let mut receiver_noise = SeededNormals::for_run(12, run);
    let bias_a = draw3(&mut n, [SIGMA.accel_bias_m_s2; 3]);
    let bias_g = draw3(&mut n, [SIGMA.gyro_bias_rad_s; 3]);
    let (p0, v0) = truth(0.0);
    let dp = draw3(&mut n, [SIGMA.position_m; 3]);
    let dv = draw3(&mut n, [SIGMA.velocity_m_s; 3]);
    let tilt = draw3(&mut n, SIGMA.attitude_rad);
    let start = EskfState::<FlatEarth<Enu>> {
        nav: NavState {
            t_s: 0.0,
            position: p0 - Vec3::from_array(dp),
            velocity_m_s: v0 - Vec3::from_array(dv),
            attitude: Rotation::assume_from_quaternion(nalgebra::UnitQuaternion::from_scaled_axis(
                -nalgebra::Vector3::from(tilt),
            )),
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let receiver = GnssModel::new(&GnssParams {
        rate_hz: 1.0,
        horizontal_accuracy_m: HORIZONTAL_M,
        vertical_accuracy_m: VERTICAL_M,
        velocity_accuracy_m_s: VELOCITY_M_S,
        position_noise: PositionNoise::DecayFactor(decay),
    })
    .unwrap();
    let mut receiver_state = GnssState::default();
    let mut f = Eskf::<FlatEarth<Enu>, S>::new(earth, &start, &SIGMA, NOISE)
        .unwrap()
        .with_covariance_interval(0.05)
        .unwrap();
    if S >= FULL_STATES {
        // Sensor errors the truth does not have, known to be small.
        let tight = SensorErrorSigma {
            accel_scale_factor: 1e-4,
            accel_misalignment: 1e-4,
            gyro_scale_factor: 1e-4,
            gyro_misalignment: 1e-4,
            gyro_g_sensitivity: 1e-6,
        };
        f = f.with_sensor_error_sigma(&tight).unwrap();
    }
    let stationary = FixErrorModel::decay_factor_sigma_ratio(decay);
    let fix_sigma = match model {
        Model::White => [HORIZONTAL_M, HORIZONTAL_M, VERTICAL_M].map(|s| s * stationary),
        Model::States => {
            let accuracy = [HORIZONTAL_M, HORIZONTAL_M, VERTICAL_M];
            let ratio = FixErrorModel::decay_factor_sigma_ratio(decay);
            let m =
                FixErrorModel::from_decay_factor(decay, 1.0, accuracy.map(|s| s * ratio)).unwrap();
            f = f.with_fix_errors(m).unwrap();
            [WHITE_FLOOR_M; 3]
        }
    };
    let (sigma_w, sigma_a) = (
        NOISE.gyro_psd * RATE_HZ.sqrt(),
        NOISE.accel_psd * RATE_HZ.sqrt(),
    );
    let end = at_s.iter().copied().fold(0.0, f64::max);
    let samples = (end * RATE_HZ).round() as usize;
    let mut out = Vec::new();
    for k in 0..=samples {
        let t = k as f64 / RATE_HZ;
        let w = draw3(&mut n, [sigma_w; 3]);
        let a = draw3(&mut n, [sigma_a; 3]);
        f.propagate(
            t,
            std::array::from_fn(|i| bias_g[i] + w[i]),
            std::array::from_fn(|i| [0.0, 0.0, 9.81][i] + bias_a[i] + a[i]),
        )
        .unwrap();
        if k > 0 && k % (RATE_HZ as usize) == 0 {
            let (p, v) = truth(t);
            let (e_ned, ev) = receiver.step(&mut receiver_state, &mut receiver_noise);
            let e_enu = Vec3::new(e_ned[1], e_ned[0], -e_ned[2]);
            let fix = GnssFix::<FlatEarth<Enu>> {
                position: p + e_enu,
                velocity_m_s: Some(v + Vec3::new(ev[1], ev[0], -ev[2])),
                lever_arm_m: Vec3::zeros(),
                position_sigma_m: fix_sigma,
                velocity_sigma_m_s: [VELOCITY_M_S; 3],
                age_s: 0.0,
            };
            f.update(&fix, Gate::Off).unwrap();
        }
        if at_s.iter().any(|a| (a * RATE_HZ).round() as usize == k) {
            let (p, v) = truth(t);
            let nav = f.state().nav;
            let e = [
                *(p - nav.position).as_nalgebra(),
                *(v - nav.velocity_m_s).as_nalgebra(),
            ];
            out.push(std::array::from_fn(|j| {
                let block = nalgebra::Matrix3::from_fn(|r, c| f.covariance(3 * j + r, 3 * j + c));
                (e[j].transpose() * block.try_inverse().unwrap() * e[j])[(0, 0)]
            }));
        }
    }
    out
}

const RUNS: u64 = 100;
const AT_S: [f64; 1] = [300.0];

/// Average NEES of position and velocity over [`RUNS`] runs at each of [`AT_S`], and the 95 %
/// bounds of an average of [`RUNS`] χ²(3) draws.
fn average_nees<const S: usize>(decay: f64, model: Model) -> (Vec<[f64; 2]>, (f64, f64)) {
    let mut sums = vec![[0.0; 2]; AT_S.len()];
    for r in 0..RUNS {
        for (sum, nees) in sums.iter_mut().zip(run::<S>(decay, model, r, &AT_S)) {
            sum[0] += nees[0];
            sum[1] += nees[1];
        }
    }
    let runs = RUNS as f64;
    let bounds = (
        chi2_quantile(3.0 * runs, -1.959_964) / runs,
        chi2_quantile(3.0 * runs, 1.959_964) / runs,
    );
    (sums.iter().map(|s| s.map(|x| x / runs)).collect(), bounds)
}

fn consistent<const S: usize>(decay: f64) {
    let (nees, (lo, hi)) = average_nees::<S>(decay, Model::States);
    eprintln!(
        "{S} states, decay {decay}: average NEES (position, velocity) at {AT_S:?} s: {nees:?}, 95 % bounds [{lo:.3}, {hi:.3}]"
    );
    for (at, pv) in AT_S.iter().zip(&nees) {
        for (what, v) in ["position", "velocity"].iter().zip(pv) {
            assert!(
                (lo..=hi).contains(v),
                "{S} states, decay {decay}, {what} at {at} s: average NEES {v} outside [{lo}, {hi}]"
            );
        }
    }
}

#[test]
fn with_the_fix_error_states_the_filter_is_consistent_on_correlated_fixes() {
    for decay in [0.99, 0.999] {
        consistent::<FIX_STATES>(decay);
    }
    consistent::<FULL_FIX_STATES>(0.99);
}

#[test]
fn a_filter_that_takes_correlated_fixes_as_white_is_not() {
    for decay in [0.99, 0.999] {
        let (nees, (_, hi)) = average_nees::<BASE_STATES>(decay, Model::White);
        eprintln!("white fixes, decay {decay}: average NEES (position, velocity) {nees:?}");
        assert!(
            nees.iter().all(|pv| pv[0] > 2.0 * hi),
            "decay {decay}: the white model passed ({nees:?})"
        );
    }
}

#[test]
fn the_decay_factor_is_the_gauss_markov_process_sampled_at_the_fixes() {
    // τ = −Δt/ln k: over one fix interval the decay is k itself, and the stationary variance
    // σ² 2/(1 + k) is what MATLAB's drive σ² 2(1 − k) sums to, 2(1 − k)/(1 − k²).
    for k in [0.5, 0.99, 0.999] {
        let ratio = FixErrorModel::decay_factor_sigma_ratio(k);
        let m =
            FixErrorModel::from_decay_factor(k, 0.2, [1.5, 1.5, 3.0].map(|s| s * ratio)).unwrap();
        let (phi, q) = m.step(0.2);
        assert!((phi - k).abs() < 1e-14, "decay {phi} against {k}");
        // MATLAB's drive, σ² 2(1 − k), per fix.
        let drive = 2.0 * (1.0 - k) * 1.5 * 1.5;
        assert!((q[0] - drive).abs() < 1e-12 * drive.max(1.0), "{q:?}");
        assert!((m.sigma_m[2] - 3.0 * (2.0 / (1.0 + k)).sqrt()).abs() < 1e-14);
        // The start: the first fix's error, MATLAB's drive.
        assert!((m.initial_sigma_m[0] * m.initial_sigma_m[0] - drive).abs() < 1e-12);
        // Two half steps are one step.
        let (half, q_half) = m.step(0.1);
        assert!((half * half - phi).abs() < 1e-14);
        assert!((q_half[0] * half * half + q_half[0] - q[0]).abs() < 1e-12);
    }
    assert!(FixErrorModel::from_decay_factor(0.0, 1.0, [1.0; 3]).is_none());
    assert!(FixErrorModel::from_decay_factor(1.0, 1.0, [1.0; 3]).is_none());
    assert!(FixErrorModel::stationary(0.0, [1.0; 3]).is_none());
    // A filter without the states refuses the model.
    let earth = FlatEarth::<Enu>::new(9.81);
    let start = EskfState::<FlatEarth<Enu>> {
        nav: NavState {
            t_s: 0.0,
            position: Vec3::zeros(),
            velocity_m_s: Vec3::zeros(),
            attitude: Rotation::identity(),
        },
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let m = FixErrorModel::stationary(60.0, [1.0, 1.0, 2.0]).unwrap();
    let plain = Eskf::<FlatEarth<Enu>, BASE_STATES>::new(earth, &start, &SIGMA, NOISE).unwrap();
    assert!(plain.with_fix_errors(m).is_err());
    let with = Eskf::<FlatEarth<Enu>, FIX_STATES>::new(earth, &start, &SIGMA, NOISE)
        .unwrap()
        .with_fix_errors(m)
        .unwrap();
    assert_eq!(with.sigmas()[15..], [1.0, 1.0, 2.0]);
}
