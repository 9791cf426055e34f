//! Coning: angular vibration about two axes in quadrature, `ω = θΩ·(0, cos Ωt, sin Ωt)`, turns
//! the body about the third axis at `θ²Ω/2` although each rate averages to zero. The attitude
//! has a closed form — `ω(t) = R_x(Ωt)·w₀` with `w₀ = (0, θΩ, 0)` gives
//! `q(t) = exp((w₀ + Ω x̂) t) ⊗ exp(−Ω t x̂)` — so the strapdown's attitude on the exact angle
//! increments is checked against it: a one-sample update (each increment taken as a rotation
//! vector) drifts at `θ²Ω/2 · (1 − sin(Ωh)/(Ωh))` about x (Titterton & Weston, §11.2.2), the
//! closed form of what it misses within an interval; the two-sample coning correction leaves
//! at least 100× less.
use core::f64::consts::PI;

use imu_core::earth::FlatEarth;
use imu_core::strapdown::{
    Increments, NavState, StrapdownOptions, VerticalChannel, strapdown_increments,
};
use imu_core::{Ned, Rotation};
use nalgebra::{UnitQuaternion, Vector3};

/// Half-angle amplitude θ of the vibration about y and z, rad; its frequency, Hz.
const THETA: f64 = 0.01;
const F_HZ: f64 = 10.0;
/// Strapdown rate, Hz, and duration, s (a whole number of the vibration's periods).
const RATE_HZ: f64 = 400.0;
const SECONDS: f64 = 60.0;

/// The exact attitude (body → navigation) at `t`.
fn truth(t: f64) -> UnitQuaternion<f64> {
    let omega = 2.0 * PI * F_HZ;
    let w0 = Vector3::new(omega, THETA * omega, 0.0);
    UnitQuaternion::from_scaled_axis(w0 * t)
        * UnitQuaternion::from_scaled_axis(Vector3::new(-omega * t, 0.0, 0.0))
}

/// The exact angle increments `∫ω dt` over each interval (the first row zero).
fn increments(t: &[f64]) -> Vec<[f64; 3]> {
    let omega = 2.0 * PI * F_HZ;
    let angle = |t: f64| [0.0, THETA * (omega * t).sin(), -THETA * (omega * t).cos()];
    (0..t.len())
        .map(|k| match k {
            0 => [0.0; 3],
            _ => {
                let (a, b) = (angle(t[k - 1]), angle(t[k]));
                [0.0, b[1] - a[1], b[2] - a[2]]
            }
        })
        .collect()
}

/// The attitude error after the run, as a rotation vector in body axes (rad): estimate against
/// truth, `q_true⁻¹ ⊗ q_est`.
fn final_error(coning: bool) -> Vector3<f64> {
    let n = (SECONDS * RATE_HZ) as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / RATE_HZ).collect();
    let options = StrapdownOptions {
        coning,
        sculling: false,
        vertical: VerticalChannel::Free,
    };
    let mut out = vec![NavState::default(); n];
    strapdown_increments(
        FlatEarth::<Ned>::default(),
        &t,
        &increments(&t),
        &vec![[0.0; 3]; n],
        None,
        NavState {
            attitude: Rotation::identity(),
            ..NavState::default()
        },
        options,
        &mut out,
    )
    .unwrap();
    let estimate = *out[n - 1].attitude.quaternion();
    (truth(t[n - 1]).inverse() * estimate).scaled_axis()
}

#[test]
fn the_motion_cones_at_theta_squared_omega_over_two() {
    // The closed form itself: over one period the first factor turns 2π√(1 + θ²) about
    // (1, θ, 0)/√(1 + θ²) and the second −2π about x, a net 2π(√(1 + θ²) − 1) about that axis:
    // the coning rate θ²Ω/2 to first order.
    let period = 1.0 / F_HZ;
    let turn = truth(period).scaled_axis();
    let root = (1.0 + THETA * THETA).sqrt();
    let expected = Vector3::new(1.0, THETA, 0.0) * (2.0 * PI * (root - 1.0) / root);
    assert!((turn - expected).norm() < 1e-12, "{turn:?} vs {expected:?}");
    let rate = turn.x / period;
    let omega = 2.0 * PI * F_HZ;
    assert!((rate / (0.5 * THETA * THETA * omega) - 1.0).abs() < THETA * THETA);
    // The closed form obeys q̇ = ½ q ⊗ ω: a central difference at an arbitrary instant.
    let (t, h) = (0.123, 1e-6);
    let rate = (truth(t).inverse() * truth(t + h)).scaled_axis() / h;
    let w = Vector3::new(
        0.0,
        THETA * omega * (omega * (t + h / 2.0)).cos(),
        THETA * omega * (omega * (t + h / 2.0)).sin(),
    );
    assert!((rate - w).norm() < 1e-7 * w.norm(), "{rate:?} vs {w:?}");
}

#[test]
fn a_one_sample_update_drifts_by_the_closed_form_and_the_coning_correction_removes_it() {
    let omega = 2.0 * PI * F_HZ;
    let x = omega / RATE_HZ;
    let one_sample = final_error(false);
    let drift = 0.5 * THETA * THETA * omega * (1.0 - x.sin() / x) * SECONDS;
    // The estimate turns less than the truth about x (the error's sign) by the closed form.
    assert!(
        (one_sample.x / -drift - 1.0).abs() < 0.01,
        "one-sample error {:.6e} rad about x, closed form −{drift:.6e}",
        one_sample.x
    );
    // Seen from the coning body the drift leans by up to θ towards y and z.
    assert!(one_sample.y.abs() < 2.0 * THETA * drift && one_sample.z.abs() < 2.0 * THETA * drift);
    let corrected = final_error(true);
    let rest = THETA
        * THETA
        * RATE_HZ
        * (0.5 * (x - x.sin()) - (0.5 * x).sin().powi(2) * x.sin() / 3.0)
        * SECONDS;
    assert!(
        (corrected.x / -rest - 1.0).abs() < 0.02,
        "two-sample error {:.6e} rad about x, closed form −{rest:.6e}",
        corrected.x
    );
    assert!(
        corrected.norm() * 100.0 <= one_sample.norm(),
        "with the coning correction {:.3e} rad against {:.3e} rad",
        corrected.norm(),
        one_sample.norm()
    );
    // Per sample the same as the batch call.
    let mut per_sample = Increments::new(
        FlatEarth::<Ned>::default(),
        &NavState::default(),
        StrapdownOptions::default(),
    )
    .unwrap();
    let t: Vec<f64> = (0..=800).map(|k| f64::from(k) / RATE_HZ).collect();
    let d = increments(&t);
    let mut last = NavState::default();
    for k in 1..t.len() {
        last = per_sample.step(t[k], d[k], [0.0; 3]).unwrap();
    }
    let expected = truth(t[800]);
    // Two seconds at the two-sample rest rate (6e-8 rad/s): well under a microradian.
    assert!(last.attitude.quaternion().angle_to(&expected) < 1e-6);
}
