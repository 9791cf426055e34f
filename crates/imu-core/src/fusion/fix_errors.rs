//! A GNSS receiver's position errors as filter states: a first-order Gauss–Markov process per
//! navigation axis, `ḃ = −b/τ + w`, of stationary deviation σ (horizontal on the two horizontal
//! axes, vertical on the third) and correlation time `τ`. A fix then reads
//! `p_fix = p_antenna + b + v`, `v` its white part (the fix's own one-sigma), and the filter
//! learns `b` instead of taking a slowly wandering error for the truth. A filter that takes
//! fixes whose errors last tens of seconds as white believes every fix anew, and its one-sigma
//! shrinks far below the error it carries (Groves 2nd ed. §14.3.3; Brown & Hwang §9.3).
//!
//! The states come after the others: a filter of [`BASE_STATES`] + [`FIX_ERROR_STATES`] (18) or
//! [`FULL_STATES`] + [`FIX_ERROR_STATES`] (39) states. Over a step `Δt`, `φ = e^{−Δt/τ}`:
//! `b ← φ b`, its covariance rows and columns scale by `φ` and its variance gains
//! `σ² (1 − φ²)` — exact for any step, so the covariance interval does not change the model.
//! The estimate `b̂` is kept in the filter's nominal state (closed loop, like the biases) and
//! decays with `φ`.
//!
//! MATLAB gpsSensor's `DecayFactor` `k` per fix of interval `Δt_f` is the same process sampled
//! at the fixes: `τ = −Δt_f / ln k`, stationary deviation `σ √(2/(1 + k))`, started from zero
//! (the filter's start at the first fix's error, [`FixErrorModel::from_decay_factor`]); a receiver that has run for a while starts in its
//! stationary state ([`FixErrorModel::stationary`]).
use nalgebra::SMatrix;

use super::sensor_errors::{BASE_STATES, FULL_STATES};
use crate::math;

/// Number of fix-error states: one per navigation axis.
pub const FIX_ERROR_STATES: usize = 3;

/// Whether a filter of `states` error states estimates the sensor errors (36 or 39).
#[must_use]
pub const fn has_sensor_errors(states: usize) -> bool {
    states == FULL_STATES || states == FULL_STATES + FIX_ERROR_STATES
}

/// Whether a filter of `states` error states carries the fixes' errors (18 or 39).
#[must_use]
pub const fn has_fix_errors(states: usize) -> bool {
    states == BASE_STATES + FIX_ERROR_STATES || states == FULL_STATES + FIX_ERROR_STATES
}

/// Whether `states` is a filter's state count: 15, 18, 36 or 39.
#[must_use]
pub const fn is_state_count(states: usize) -> bool {
    states == BASE_STATES || states == FULL_STATES || has_fix_errors(states)
}

/// The fixes' correlated position error as the filter models it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixErrorModel {
    /// Stationary one-sigma per navigation axis (x, y, z of the frame), m.
    pub sigma_m: [f64; 3],
    /// Correlation time `τ`, s (> 0, finite).
    pub correlation_time_s: f64,
    /// One-sigma per axis of the error at the filter's start, m: `sigma_m` for a receiver
    /// that has run for a while, one step's for MATLAB's process, which starts from zero.
    pub initial_sigma_m: [f64; 3],
}

impl FixErrorModel {
    /// MATLAB gpsSensor's position error, `x_k = k x_{k−1} + σ √(2(1 − k)) w_k` from zero, for
    /// fixes every `fix_interval_s`, given its stationary one-sigma per axis
    /// (`σ ×` [`Self::decay_factor_sigma_ratio`], the receiver's accuracy σ): `τ = −Δt_f / ln k`;
    /// at the start the first fix's error, one step of the process from zero (one-sigma
    /// `σ √(2(1 − k))`, the stationary one times `√(1 − k²)`), so that a fix at the filter's
    /// first sample is not taken for exact. `None` for a factor outside (0, 1) — 0 is white noise and 1 an error
    /// that stays zero, neither a correlated process — or an interval that is not positive.
    #[must_use]
    pub fn from_decay_factor(
        decay_factor: f64,
        fix_interval_s: f64,
        stationary_sigma_m: [f64; 3],
    ) -> Option<Self> {
        let k = decay_factor;
        if !(k > 0.0 && k < 1.0 && fix_interval_s.is_finite() && fix_interval_s > 0.0) {
            return None;
        }
        let first_fix = math::sqrt(1.0 - k * k);
        let model = Self {
            sigma_m: stationary_sigma_m,
            correlation_time_s: -fix_interval_s / math::ln(k),
            initial_sigma_m: stationary_sigma_m.map(|s| s * first_fix),
        };
        model.is_valid().then_some(model)
    }

    /// The stationary one-sigma of MATLAB's process over its accuracy σ: `√(2/(1 + k))` (1 for
    /// `k = 1`, √2 for white fixes, `k = 0`).
    #[must_use]
    pub fn decay_factor_sigma_ratio(decay_factor: f64) -> f64 {
        math::sqrt(2.0 / (1.0 + decay_factor))
    }

    /// A first-order Gauss–Markov error of correlation time `correlation_time_s` and
    /// stationary one-sigma `sigma_m` per axis, in its stationary state at the start (a
    /// receiver that has run for a while). `None` for a time that is not positive or sigmas
    /// that are negative.
    #[must_use]
    pub fn stationary(correlation_time_s: f64, sigma_m: [f64; 3]) -> Option<Self> {
        let model = Self {
            sigma_m,
            correlation_time_s,
            initial_sigma_m: sigma_m,
        };
        model.is_valid().then_some(model)
    }

    /// Finite, non-negative sigmas and a finite positive correlation time.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let ok = |s: &f64| s.is_finite() && *s >= 0.0;
        self.sigma_m.iter().all(ok)
            && self.initial_sigma_m.iter().all(ok)
            && self.correlation_time_s.is_finite()
            && self.correlation_time_s > 0.0
    }

    /// The decay over `dt_s` and the variance each axis gains: `(φ, σ² (1 − φ²))`.
    #[must_use]
    pub fn step(&self, dt_s: f64) -> (f64, [f64; 3]) {
        let phi = math::exp(-dt_s / self.correlation_time_s);
        let gain = 1.0 - phi * phi;
        (phi, self.sigma_m.map(|s| s * s * gain))
    }
}

/// The first fix-error state of a filter of `S` states.
pub(crate) const fn first<const S: usize>() -> usize {
    S - FIX_ERROR_STATES
}

/// One covariance step of the fix errors, after the other states' (which leave their rows and
/// columns as they were): rows and columns scaled by `φ`, variances plus `q`; `phi`, the step's
/// transition for the smoother, gets `φ` on their diagonal.
pub(crate) fn decay_covariance<const S: usize>(
    cov: &mut SMatrix<f64, S, S>,
    phi_matrix: Option<&mut SMatrix<f64, S, S>>,
    phi: f64,
    q: &[f64; 3],
) {
    let b = first::<S>();
    for k in b..S {
        cov.row_mut(k).scale_mut(phi);
        cov.column_mut(k).scale_mut(phi);
        cov[(k, k)] += q[k - b];
    }
    if let Some(m) = phi_matrix {
        for k in b..S {
            m[(k, k)] = phi;
        }
    }
}
