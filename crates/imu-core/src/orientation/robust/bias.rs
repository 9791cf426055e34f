//! The robust filter's gyroscope bias estimate: a three-state Kalman filter fed at rest by the
//! low-passed gyroscope and in motion by the inclination corrections the accelerometer makes
//! (the idea of VQF's motion bias estimation, Laidig & Seel, *Information Fusion* 91, 2023).
//!
//! In motion, a bias error `b − b̂` turns the gyroscope-integrated attitude at `R (b − b̂)` in
//! the Earth frame (`R`: body to Earth); the accelerometer's correction `c` per step `Δt`
//! undoes the horizontal part of it, so `−c/Δt + R b̂ ≈ R b` is a measurement of the bias
//! through `R`. Because the correction comes from the low-passed accelerometer, `R` and
//! `R b̂` are low-passed alike. The vertical row is a weak pseudo-measurement `0` (the
//! accelerometer says nothing about rotation about the vertical; it only keeps that part of
//! the bias from wandering). At rest the measurement is the low-passed rate itself (`H = I`).
//!
//! The noise is set by standard deviations a user can read: the bias may wander by
//! `FORGETTING_SIGMA` over `forgetting_s` (process noise `V = FORGETTING_SIGMA² Δt /
//! forgetting_s`); a measurement's variance `W = p²/V + p` with `p = σ²` makes the steady
//! uncertainty under continual updates about `σ` (`sigma_motion`, `sigma_rest`).
//!
//! A slow forgetting time serves a stable bias (the heading of a 6D estimate drifts with what is
//! left of it), but a bias that steps in motion (a temperature jump, a shock) would then take
//! minutes to learn, its inclination error meanwhile `δb τ`. A step shows as a motion innovation
//! that keeps one sign: its low-pass over [`STEP_TAU_S`] is near zero while the bias is right
//! (the innovation's noise is fast; a steady acceleration is left out before it reaches the
//! estimate) and the step itself once the bias is off. While that low-pass is above
//! `bias_step_rad_s`, the bias may wander as over `bias_step_forgetting_s` instead; the
//! measurement's weight stays what the slow forgetting time sets, so the estimate follows the
//! step at the rate its evidence allows and settles as before once the innovation falls back.
use nalgebra::{Matrix3, Vector3};

use super::RobustParams;
use super::lowpass::LowPass;

/// How far the bias may wander over the forgetting time, rad/s (0.1 °/s).
const FORGETTING_SIGMA_RAD_S: f64 = 0.1 * core::f64::consts::PI / 180.0;

/// Time constant of the low-pass that watches the motion innovation for a step, s.
const STEP_TAU_S: f64 = 10.0;

/// The bias, its covariance, the low-passes of the motion measurement and the step watch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BiasEstimate {
    bias: Vector3<f64>,
    p: Matrix3<f64>,
    r_lp: LowPass<9>,
    rb_lp: LowPass<2>,
    step_lp: LowPass<2>,
}

/// What the accelerometer or the rest says about the bias this sample.
pub(crate) enum BiasEvidence {
    /// At rest: the low-passed gyroscope reading, rad/s.
    Rest(Vector3<f64>),
    /// In motion: the inclination correction applied this step (rotation vector in the Earth
    /// frame, rad; horizontal).
    Motion(Vector3<f64>),
    /// Nothing (the accelerometer is not trusted).
    None,
}

impl BiasEstimate {
    pub(crate) fn new(p: &RobustParams, dt_s: f64) -> Self {
        Self {
            bias: Vector3::zeros(),
            p: Matrix3::identity() * (p.bias_sigma_init_rad_s * p.bias_sigma_init_rad_s),
            r_lp: LowPass::new(p.tau_accel_s, dt_s),
            rb_lp: LowPass::new(p.tau_accel_s, dt_s),
            step_lp: LowPass::new(STEP_TAU_S, dt_s),
        }
    }

    /// The estimate for the gyroscope read backwards in time (readings negated).
    pub(crate) fn negated(self) -> Self {
        Self {
            bias: -self.bias,
            rb_lp: self.rb_lp.negated(),
            step_lp: self.step_lp.negated(),
            ..self
        }
    }

    pub(crate) fn bias(&self) -> Vector3<f64> {
        self.bias
    }

    /// One sample: `r` rotates body to Earth after this step's correction, `dt_s` the step.
    pub(crate) fn update(
        &mut self,
        p: &RobustParams,
        r: &Matrix3<f64>,
        evidence: BiasEvidence,
        dt_s: f64,
    ) {
        // The low-passes run every sample, so they are ready when motion evidence comes.
        let rb = r * self.bias;
        let r_lp = Matrix3::from_column_slice(&self.r_lp.step(
            {
                let mut a = [0.0; 9];
                a.copy_from_slice(r.as_slice());
                a
            },
            dt_s,
        ));
        let rb_lp = self.rb_lp.step([rb.x, rb.y], dt_s);
        let forgetting =
            |time_s: f64| FORGETTING_SIGMA_RAD_S * FORGETTING_SIGMA_RAD_S * dt_s / time_s;
        let v = forgetting(p.bias_forgetting_s);
        let weight = |sigma: f64| {
            let s2 = sigma * sigma;
            s2 * s2 / v + s2
        };
        let (update, stepped) = match evidence {
            BiasEvidence::Rest(rate) => (
                Some((
                    Matrix3::identity(),
                    rate - self.bias,
                    Vector3::repeat(weight(p.bias_sigma_rest_rad_s)),
                )),
                false,
            ),
            BiasEvidence::Motion(correction) => {
                let hb = r_lp * self.bias;
                let e = Vector3::new(
                    -correction.x / dt_s + rb_lp[0] - hb.x,
                    -correction.y / dt_s + rb_lp[1] - hb.y,
                    -hb.z,
                );
                let [x, y] = self.step_lp.step([e.x, e.y], dt_s);
                let wm = weight(p.bias_sigma_motion_rad_s);
                let w = Vector3::new(wm, wm, wm / p.bias_vertical_forgetting.max(1e-10));
                let step = p.bias_step_rad_s;
                (
                    Some((r_lp, e, w)),
                    step > 0.0 && x * x + y * y > step * step,
                )
            }
            BiasEvidence::None => (None, false),
        };
        // Prediction: the bias may wander (up to the initial uncertainty), faster while it steps.
        let v = if stepped {
            forgetting(p.bias_step_forgetting_s)
        } else {
            v
        };
        let p0 = p.bias_sigma_init_rad_s * p.bias_sigma_init_rad_s;
        for i in 0..3 {
            if self.p[(i, i)] < p0 {
                self.p[(i, i)] += v;
            }
        }
        let Some((h, e, w)) = update else {
            return;
        };
        let clip = p.bias_clip_rad_s;
        let e = e.map(|x| x.clamp(-clip, clip));
        // P is symmetric, so H P is (P Hᵀ)ᵀ: four 3×3 products instead of six.
        let pht = self.p * h.transpose();
        let s = h * pht + Matrix3::from_diagonal(&w);
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = pht * s_inv;
        let bias = (self.bias + k * e).map(|x| x.clamp(-clip, clip));
        let cov = self.p - k * pht.transpose();
        // Settings at the edge of their range (a forgetting time of 1e308 s makes the process
        // noise underflow) must not turn the estimate into NaN: such an update is left out.
        if bias.iter().chain(cov.iter()).all(|v| v.is_finite()) {
            self.bias = bias;
            self.p = cov;
        }
    }
}
