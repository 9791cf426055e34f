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
use nalgebra::{Matrix3, Vector3};

use super::RobustParams;
use super::lowpass::LowPass;

/// How far the bias may wander over the forgetting time, rad/s (0.1 °/s).
const FORGETTING_SIGMA_RAD_S: f64 = 0.1 * core::f64::consts::PI / 180.0;

/// The bias, its covariance and the low-passes of the motion measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BiasEstimate {
    bias: Vector3<f64>,
    p: Matrix3<f64>,
    r_lp: LowPass<9>,
    rb_lp: LowPass<2>,
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
        }
    }

    /// The estimate for the gyroscope read backwards in time (readings negated).
    pub(crate) fn negated(self) -> Self {
        Self {
            bias: -self.bias,
            rb_lp: self.rb_lp.negated(),
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
        // Prediction: the bias may wander (up to the initial uncertainty).
        let v = FORGETTING_SIGMA_RAD_S * FORGETTING_SIGMA_RAD_S * dt_s / p.bias_forgetting_s;
        let p0 = p.bias_sigma_init_rad_s * p.bias_sigma_init_rad_s;
        for i in 0..3 {
            if self.p[(i, i)] < p0 {
                self.p[(i, i)] += v;
            }
        }
        let weight = |sigma: f64| {
            let s2 = sigma * sigma;
            s2 * s2 / v + s2
        };
        let (h, e, w) = match evidence {
            BiasEvidence::Rest(rate) => (
                Matrix3::identity(),
                rate - self.bias,
                Vector3::repeat(weight(p.bias_sigma_rest_rad_s)),
            ),
            BiasEvidence::Motion(correction) => {
                let hb = r_lp * self.bias;
                let measured = Vector3::new(
                    -correction.x / dt_s + rb_lp[0],
                    -correction.y / dt_s + rb_lp[1],
                    0.0,
                );
                let wm = weight(p.bias_sigma_motion_rad_s);
                (
                    r_lp,
                    measured - hb,
                    Vector3::new(wm, wm, wm / p.bias_vertical_forgetting.max(1e-10)),
                )
            }
            BiasEvidence::None => return,
        };
        let clip = p.bias_clip_rad_s;
        let e = e.map(|x| x.clamp(-clip, clip));
        let s = h * self.p * h.transpose() + Matrix3::from_diagonal(&w);
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = self.p * h.transpose() * s_inv;
        let bias = (self.bias + k * e).map(|x| x.clamp(-clip, clip));
        let cov = self.p - k * h * self.p;
        // Settings at the edge of their range (a forgetting time of 1e308 s makes the process
        // noise underflow) must not turn the estimate into NaN: such an update is left out.
        if bias.iter().chain(cov.iter()).all(|v| v.is_finite()) {
            self.bias = bias;
            self.p = cov;
        }
    }
}
