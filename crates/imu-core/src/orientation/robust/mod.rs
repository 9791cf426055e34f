//! imukit's own attitude and heading filter, made to survive real motion: the default of
//! `imukit orient`.
//!
//! The estimate is split in three, as in VQF (D. Laidig and T. Seel, "VQF: Highly accurate IMU
//! orientation estimation with bias estimation and magnetic disturbance rejection",
//! *Information Fusion* 91, 2023), whose ideas it builds on:
//! `q_nb = R_z(δ) ⊗ q_incl ⊗ q_gyro` — the gyroscope's integral `q_gyro` into an almost
//! inertial frame `I`, an inclination correction `q_incl` (about horizontal axes only) that
//! takes `I` to a level frame, and a heading offset `δ` about the vertical from the
//! magnetometer. Each part is corrected by its own sensor, so a disturbed magnetometer never
//! tilts the attitude and an accelerating body never turns the heading.
//!
//! - **Inclination.** The gravity reading is rotated into `I` and low-passed there (second-order
//!   Butterworth, time constant `tau_accel_s`; module `lowpass`). In `I`, motion that comes and goes —
//!   shaking, a circle, a hand's back and forth — averages out, while gravity stays put; the
//!   correction then turns `q_incl` so that the low-passed vector points down.
//! - **Sustained acceleration.** What does not average out within `tau_accel_s` — a long turn,
//!   minutes of vibration — would still tilt the estimate. The filter watches how far the
//!   specific force's magnitude is off gravity (`s`, RMS over `tau_accel_s`, in g); beyond
//!   `accel_threshold_g` it slows the correction by a further first-order lag of
//!   `tau_accel_s · ((s / accel_threshold_g)² − 1)`: the harder the body accelerates, the
//!   longer the gyroscope alone carries the tilt. It never stops listening (a filter that
//!   rejects the accelerometer for good and then trusts it again all at once is how tilt is
//!   lost), and it never learns bias from such readings. Flagged as `accel_rejected`.
//! - **Gyroscope bias** (module `bias`): a Kalman filter fed at rest by the low-passed rate and in
//!   motion by the inclination corrections (a bias shows as a steady correction).
//! - **Rest.** Gyroscope and accelerometer are low-passed over `rest_tau_s`; at rest when for
//!   `rest_min_s` every sample stays within `rest_gyro_rad_s` and `rest_accel_m_s2` of them
//!   (and the rate looks like a bias, below `bias_clip_rad_s`).
//! - **Heading** (module `magnetic`): `δ` follows the magnetometer's north in the level frame with
//!   time constant `tau_mag_s` (the mean of the readings so far during the first `tau_mag_s`),
//!   unless the field's magnitude or dip says a magnet is near.
//!
//! The state after each sample — bias estimate and flags — is [`RobustFilter::status`].
mod bias;
mod lowpass;
mod magnetic;
mod smooth;

pub use smooth::smooth;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::ecompass::{ecompass_ned, tilt};
use super::{
    Estimate, FilterInput, OrientError, OrientationFilter, check_finite, gravity_reading, positive,
    to_frame,
};
use crate::ideal::AccelSign;
use crate::math;
use crate::nav_frame::NavFrame;
use bias::{BiasEstimate, BiasEvidence};
use magnetic::MagneticTest;

const DEG: f64 = core::f64::consts::PI / 180.0;

/// The filter's settings; [`Default`] gives the tuning it is tested with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustParams {
    /// Sample rate for samples without their own interval, Hz.
    pub sample_rate_hz: f64,
    /// Sign of the accelerometer readings.
    pub accel_sign: AccelSign,
    /// Whether the magnetometer is used.
    pub magnetometer: bool,
    /// Gravity, m/s² (for the acceleration test).
    pub gravity_m_s2: f64,
    /// Time constant of the inclination correction (the accelerometer's low-pass), s.
    pub tau_accel_s: f64,
    /// Time constant of the heading correction, s.
    pub tau_mag_s: f64,
    /// Deviation of the specific force's magnitude from gravity (fraction of g) that counts as
    /// acceleration.
    pub accel_threshold_g: f64,
    /// Time an acceleration must last before the accelerometer is left out, s.
    pub accel_sustained_s: f64,
    /// Low-pass time constant of the rest test, s.
    pub rest_tau_s: f64,
    /// Largest gyroscope deviation from its low-pass at rest, rad/s.
    pub rest_gyro_rad_s: f64,
    /// Largest accelerometer deviation from its low-pass at rest, m/s².
    pub rest_accel_m_s2: f64,
    /// Time the test must hold before the sensor counts as at rest, s.
    pub rest_min_s: f64,
    /// Standard deviation of the bias before any evidence, rad/s.
    pub bias_sigma_init_rad_s: f64,
    /// Time over which the bias may wander by 0.1 °/s, s.
    pub bias_forgetting_s: f64,
    /// Largest bias (and bias innovation) the filter believes, rad/s.
    pub bias_clip_rad_s: f64,
    /// Uncertainty of the bias learnt in motion, rad/s (0: no bias learnt in motion).
    pub bias_sigma_motion_rad_s: f64,
    /// Weight of the "no vertical bias change" pseudo-measurement in motion, relative to the
    /// horizontal ones.
    pub bias_vertical_forgetting: f64,
    /// Uncertainty of the bias learnt at rest, rad/s.
    pub bias_sigma_rest_rad_s: f64,
    /// Low-passed motion innovation above which the bias counts as stepping, rad/s (0: never).
    pub bias_step_rad_s: f64,
    /// Time over which the bias may wander by 0.1 °/s while it steps, s.
    pub bias_step_forgetting_s: f64,
    /// Largest relative magnetic magnitude error before the field counts as disturbed.
    pub mag_rejection: f64,
    /// Largest dip error before the field counts as disturbed, rad.
    pub dip_rejection_rad: f64,
    /// Low-pass time constant of the field's magnitude and dip, s.
    pub mag_current_tau_s: f64,
    /// Time constant with which the reference field follows an undisturbed field, s.
    pub mag_reference_tau_s: f64,
    /// Time the field must agree before a disturbance ends, s.
    pub mag_min_undisturbed_s: f64,
    /// Longest total time the heading goes uncorrected while disturbed, s.
    pub mag_max_rejection_s: f64,
    /// Gain divisor for corrections once that time is spent.
    pub mag_rejection_factor: f64,
    /// Time of rotation over which a steady new field becomes the reference, s.
    pub mag_new_time_s: f64,
    /// The same for the first reference, s.
    pub mag_new_first_time_s: f64,
    /// Rate the body must turn at for that time to count, rad/s.
    pub mag_new_min_rate_rad_s: f64,
}

impl Default for RobustParams {
    fn default() -> Self {
        Self {
            sample_rate_hz: 100.0,
            accel_sign: AccelSign::SpecificForce,
            magnetometer: false,
            gravity_m_s2: crate::DEFAULT_GRAVITY_M_S2,
            tau_accel_s: 3.0,
            tau_mag_s: 9.0,
            accel_threshold_g: 0.1,
            accel_sustained_s: 1.0,
            rest_tau_s: 0.5,
            rest_gyro_rad_s: 2.0 * DEG,
            rest_accel_m_s2: 0.5,
            rest_min_s: 1.5,
            bias_sigma_init_rad_s: 0.5 * DEG,
            bias_forgetting_s: 100.0,
            bias_clip_rad_s: 2.0 * DEG,
            bias_sigma_motion_rad_s: 0.1 * DEG,
            bias_vertical_forgetting: 1e-4,
            bias_sigma_rest_rad_s: 0.03 * DEG,
            bias_step_rad_s: 0.4 * DEG,
            bias_step_forgetting_s: 0.3,
            mag_rejection: 0.1,
            dip_rejection_rad: 10.0 * DEG,
            mag_current_tau_s: 0.05,
            mag_reference_tau_s: 20.0,
            mag_min_undisturbed_s: 0.5,
            mag_max_rejection_s: 60.0,
            mag_rejection_factor: 2.0,
            mag_new_time_s: 20.0,
            mag_new_first_time_s: 5.0,
            mag_new_min_rate_rad_s: 20.0 * DEG,
        }
    }
}

/// A setting's range: `> 0`, `≥ 0`, or `≥ 1`.
#[derive(Clone, Copy)]
enum Range {
    Positive,
    NonNegative,
    AtLeastOne,
}

impl RobustParams {
    /// The numeric settings by name (the names `imukit orient --param` and Python's `settings`
    /// take; angles in rad, rates in rad/s, times in s), each with its field.
    pub fn settings_mut(&mut self) -> [(&'static str, &mut f64); 28] {
        [
            ("SampleRate", &mut self.sample_rate_hz),
            ("Gravity", &mut self.gravity_m_s2),
            ("AccelerometerTimeConstant", &mut self.tau_accel_s),
            ("MagnetometerTimeConstant", &mut self.tau_mag_s),
            ("AccelerationThreshold", &mut self.accel_threshold_g),
            ("AccelerationSustainedTime", &mut self.accel_sustained_s),
            ("RestTimeConstant", &mut self.rest_tau_s),
            ("RestGyroscopeThreshold", &mut self.rest_gyro_rad_s),
            ("RestAccelerometerThreshold", &mut self.rest_accel_m_s2),
            ("RestMinimumTime", &mut self.rest_min_s),
            ("BiasSigmaInit", &mut self.bias_sigma_init_rad_s),
            ("BiasForgettingTime", &mut self.bias_forgetting_s),
            ("BiasClip", &mut self.bias_clip_rad_s),
            ("BiasSigmaMotion", &mut self.bias_sigma_motion_rad_s),
            ("BiasVerticalForgetting", &mut self.bias_vertical_forgetting),
            ("BiasSigmaRest", &mut self.bias_sigma_rest_rad_s),
            ("BiasStepThreshold", &mut self.bias_step_rad_s),
            ("BiasStepForgettingTime", &mut self.bias_step_forgetting_s),
            ("MagneticRejection", &mut self.mag_rejection),
            ("DipRejection", &mut self.dip_rejection_rad),
            ("MagneticCurrentTimeConstant", &mut self.mag_current_tau_s),
            (
                "MagneticReferenceTimeConstant",
                &mut self.mag_reference_tau_s,
            ),
            (
                "MagneticMinUndisturbedTime",
                &mut self.mag_min_undisturbed_s,
            ),
            ("MagneticMaxRejectionTime", &mut self.mag_max_rejection_s),
            ("MagneticRejectionFactor", &mut self.mag_rejection_factor),
            ("MagneticNewFieldTime", &mut self.mag_new_time_s),
            ("MagneticNewFieldFirstTime", &mut self.mag_new_first_time_s),
            ("MagneticNewFieldMinRate", &mut self.mag_new_min_rate_rad_s),
        ]
    }

    /// The names [`RobustParams::settings_mut`] takes.
    #[must_use]
    pub fn setting_names() -> [&'static str; 28] {
        Self::default().settings_mut().map(|(name, _)| name)
    }

    fn check(&self) -> Result<(), OrientError> {
        let mut copy = *self;
        for (name, value) in copy.settings_mut() {
            let range = match name {
                "RestMinimumTime"
                | "AccelerationSustainedTime"
                | "BiasSigmaMotion"
                | "BiasStepThreshold"
                | "MagneticMinUndisturbedTime"
                | "MagneticMaxRejectionTime"
                | "MagneticNewFieldTime"
                | "MagneticNewFieldFirstTime"
                | "MagneticNewFieldMinRate"
                | "MagneticCurrentTimeConstant" => Range::NonNegative,
                "MagneticRejectionFactor" => Range::AtLeastOne,
                _ => Range::Positive,
            };
            match range {
                Range::Positive => {
                    positive(name, *value, false)?;
                }
                Range::NonNegative => {
                    positive(name, *value, true)?;
                }
                Range::AtLeastOne => {
                    if !(value.is_finite() && *value >= 1.0) {
                        return Err(OrientError::InvalidParameter {
                            field: name,
                            value: *value,
                            expected: "finite and ≥ 1",
                        });
                    }
                }
            }
        }
        Ok(())
    }
}

/// What the filter believes after a sample besides the attitude.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RobustStatus {
    /// Gyroscope bias estimate, rad/s (body axes).
    pub gyro_bias_rad_s: [f64; 3],
    /// The sensor was taken to be at rest (the bias was learnt from the rate).
    pub at_rest: bool,
    /// The specific force was far from gravity: the inclination correction was slowed.
    pub accel_rejected: bool,
    /// The magnetometer reading was rejected (magnetic disturbance).
    pub mag_disturbed: bool,
}

/// The first-order gains of an interval: `1 − e^(−Δt/τ)` for the heading and the magnetic
/// reference, kept while the interval stays (the exponential is the costliest step).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Gains {
    dt_s: f64,
    heading: f64,
    mag_reference: f64,
}

impl Gains {
    fn new(p: &RobustParams, dt_s: f64) -> Self {
        Self {
            dt_s,
            heading: 1.0 - math::exp(-dt_s / p.tau_mag_s),
            mag_reference: 1.0 - math::exp(-dt_s / p.mag_reference_tau_s),
        }
    }

    /// The gains for `dt_s` (recomputed when it changes by more than 1e-6 of itself).
    fn at(&mut self, p: &RobustParams, dt_s: f64) -> Self {
        if math::abs(dt_s - self.dt_s) > 1e-6 * self.dt_s {
            *self = Self::new(p, dt_s);
        }
        *self
    }
}

/// A stretch of readings whose magnitude is off gravity.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Excursion {
    duration_s: f64,
    /// Count, sum and sum of squares of the relative deviation from gravity.
    samples: f64,
    sum: f64,
    sum2: f64,
    /// Inclination, its low-pass and the bias from before it began.
    before: (UnitQuaternion<f64>, lowpass::LowPass<3>, BiasEstimate),
    sustained: bool,
}

/// The filter's state once it has its first sample.
#[derive(Clone, Copy, Debug, PartialEq)]
struct State {
    q_gyro: UnitQuaternion<f64>,
    q_incl: UnitQuaternion<f64>,
    /// The heading as a rotation about the vertical (turned by each correction, so that no
    /// angle is turned back into a rotation every sample).
    heading: UnitQuaternion<f64>,
    accel_lp: lowpass::LowPass<3>,
    rest_gyro_lp: lowpass::LowPass<3>,
    rest_accel_lp: lowpass::LowPass<3>,
    rest_s: f64,
    gravity_m_s2: f64,
    excursion: Option<Excursion>,
    waited: bool,
    gains: Gains,
    bias: BiasEstimate,
    magnetic: MagneticTest,
    mag_samples: f64,
    elapsed_s: f64,
}

/// The filter (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustFilter {
    params: RobustParams,
    state: Option<State>,
    status: RobustStatus,
}

impl RobustFilter {
    /// A filter with `params`.
    ///
    /// # Errors
    /// A rate, time constant or threshold outside its range (named as
    /// [`RobustParams::settings_mut`] names it).
    pub fn new(params: RobustParams) -> Result<Self, OrientError> {
        params.check()?;
        Ok(Self {
            params,
            state: None,
            status: RobustStatus::default(),
        })
    }

    /// The settings.
    #[must_use]
    pub fn params(&self) -> &RobustParams {
        &self.params
    }

    /// The bias estimate and flags after the last sample.
    #[must_use]
    pub fn status(&self) -> RobustStatus {
        self.status
    }

    /// The filter for the same run read backwards from here: gyroscope readings negated (the
    /// bias estimate and the rate low-passes with them), attitude, low-passes of gravity and the
    /// magnetic reference kept. `None` before the first sample.
    pub(crate) fn reversed(&self) -> Option<Self> {
        let s = self.state?;
        Some(Self {
            state: Some(State {
                bias: s.bias.negated(),
                rest_gyro_lp: s.rest_gyro_lp.negated(),
                excursion: None,
                waited: false,
                ..s
            }),
            ..*self
        })
    }

    fn start<N: NavFrame>(
        &self,
        down: &Vector3<f64>,
        w: &Vector3<f64>,
        m: &Vector3<f64>,
        dt: f64,
    ) -> Result<State, OrientError> {
        let p = &self.params;
        let (q_incl, heading) = if p.magnetometer {
            // Level from gravity, heading from the field: split the e-compass into the two.
            let q = ecompass_ned(down, m)?;
            let yaw = yaw_of(&q);
            (rotate_z(-yaw) * q, rotate_z(yaw))
        } else {
            (tilt::<N>(down)?, UnitQuaternion::identity())
        };
        let mut accel_lp = lowpass::LowPass::new(p.tau_accel_s, dt);
        accel_lp.step((*down).into(), dt);
        let mut rest_gyro_lp = lowpass::LowPass::new(p.rest_tau_s, dt);
        rest_gyro_lp.step((*w).into(), dt);
        let mut rest_accel_lp = lowpass::LowPass::new(p.rest_tau_s, dt);
        rest_accel_lp.step((*down).into(), dt);
        Ok(State {
            q_gyro: UnitQuaternion::identity(),
            q_incl,
            heading,
            accel_lp,
            rest_gyro_lp,
            rest_accel_lp,
            rest_s: 0.0,
            gravity_m_s2: p.gravity_m_s2,
            excursion: None,
            waited: false,
            gains: Gains::new(p, dt),
            bias: BiasEstimate::new(p, dt),
            magnetic: MagneticTest::new(p, dt),
            mag_samples: 1.0,
            elapsed_s: 0.0,
        })
    }

    fn advance(
        p: &RobustParams,
        s: &mut State,
        down: &Vector3<f64>,
        w: &Vector3<f64>,
        m: &Vector3<f64>,
        dt: f64,
    ) -> RobustStatus {
        let mut status = RobustStatus::default();
        s.elapsed_s += dt;
        // Rest: both sensors close to their low-pass for long enough.
        let gyro_lp = Vector3::from(s.rest_gyro_lp.step((*w).into(), dt));
        let accel_lp = Vector3::from(s.rest_accel_lp.step((*down).into(), dt));
        let steady = (w - gyro_lp).norm_squared() < p.rest_gyro_rad_s * p.rest_gyro_rad_s
            && (down - accel_lp).norm_squared() < p.rest_accel_m_s2 * p.rest_accel_m_s2
            && gyro_lp.amax() <= p.bias_clip_rad_s;
        s.rest_s = if steady { s.rest_s + dt } else { 0.0 };
        status.at_rest = s.rest_s >= p.rest_min_s;
        // Gyroscope integration.
        s.q_gyro = renormalized((s.q_gyro * rotation(&((w - s.bias.bias()) * dt))).into_inner());
        // How much this reading is gravity: its magnitude against gravity's (learnt at rest).
        // (Only near the nominal value: a steady push also looks like rest.)
        let at_rest_norm = accel_lp.norm();
        if status.at_rest
            && math::abs(at_rest_norm - p.gravity_m_s2) < p.accel_threshold_g * p.gravity_m_s2
        {
            let k = dt / (p.rest_tau_s + dt);
            s.gravity_m_s2 += k * (at_rest_norm - s.gravity_m_s2);
        }
        let (rejected, waiting) = Self::watch_acceleration(p, s, down, dt);
        status.accel_rejected = rejected;
        // Inclination: the gravity reading low-passed in the almost inertial frame (while
        // rejected, the gravity the estimate already has, which moves nothing).
        let input = if rejected {
            (s.q_incl.inverse() * Vector3::z()) * s.gravity_m_s2
        } else {
            s.q_gyro * down
        };
        let lp = Vector3::from(s.accel_lp.step(input.into(), dt));
        let in_level = s.q_incl * lp;
        let rotation = toward_down(&in_level);
        // Its rotation vector, to second order (what the bias estimate reads as a rate).
        let correction = Vector3::new(2.0 * rotation.i, 2.0 * rotation.j, 0.0);
        let catching_up = s.waited;
        s.waited = waiting;
        if !waiting {
            // Renormalised, so that rounding never accumulates over a long run.
            s.q_incl = renormalized((rotation * s.q_incl).into_inner());
        }
        // Bias: from the rest, or from the corrections while the accelerometer is trusted.
        let q6 = s.q_incl * s.q_gyro;
        let evidence = if status.at_rest {
            BiasEvidence::Rest(gyro_lp)
        } else if rejected || waiting || catching_up || p.bias_sigma_motion_rad_s == 0.0 {
            BiasEvidence::None
        } else {
            BiasEvidence::Motion(correction)
        };
        let r6 = q6.to_rotation_matrix().into_inner();
        s.bias.update(p, &r6, evidence, dt);
        // Heading from magnetic north.
        if p.magnetometer && (m.x != 0.0 || m.y != 0.0 || m.z != 0.0) {
            status.mag_disturbed = Self::correct_heading(p, s, &r6, m, gyro_lp.norm(), dt);
        }
        status.gyro_bias_rad_s = s.bias.bias().into();
        status
    }

    /// The acceleration test (see the module documentation): a sustained excursion of the
    /// magnitude off gravity (a turn, a long push), once it has lasted `accel_sustained_s` and
    /// held steady, has what it did to the inclination and bias undone, and the accelerometer is
    /// left out until the magnitude is back. Returns (rejected, waiting).
    fn watch_acceleration(
        p: &RobustParams,
        s: &mut State,
        down: &Vector3<f64>,
        dt: f64,
    ) -> (bool, bool) {
        let deviation = down.norm() / s.gravity_m_s2 - 1.0;
        let off = math::abs(deviation) > p.accel_threshold_g;
        match (&mut s.excursion, off) {
            (None, true) => {
                s.excursion = Some(Excursion {
                    duration_s: dt,
                    samples: 1.0,
                    sum: deviation,
                    sum2: deviation * deviation,
                    before: (s.q_incl, s.accel_lp, s.bias),
                    sustained: false,
                });
            }
            (Some(e), true) => {
                e.duration_s += dt;
                e.samples += 1.0;
                e.sum += deviation;
                e.sum2 += deviation * deviation;
                // Steady: the magnitude stays within a quarter of its offset (a turn), unlike
                // the swings of a hand's back and forth, which the low-pass averages out.
                let mean = e.sum / e.samples;
                let var = (e.sum2 / e.samples - mean * mean).max(0.0);
                if !e.sustained && e.duration_s >= p.accel_sustained_s && 16.0 * var <= mean * mean
                {
                    e.sustained = true;
                    (s.q_incl, s.accel_lp, s.bias) = e.before;
                }
            }
            (_, false) => s.excursion = None,
        }
        let rejected = s.excursion.is_some_and(|e| e.sustained);
        // While an excursion is young the correction waits: if it turns out sustained it is
        // undone anyway, and if it ends (or swings like a hand's) the low-pass, which kept
        // every reading, catches up at once.
        let waiting = s
            .excursion
            .is_some_and(|e| !e.sustained && e.duration_s < p.accel_sustained_s);
        (rejected, waiting)
    }

    /// Turns the heading towards magnetic north seen in the level frame (`r6`: body to level);
    /// returns whether the field is disturbed.
    fn correct_heading(
        p: &RobustParams,
        s: &mut State,
        r6: &Matrix3<f64>,
        m: &Vector3<f64>,
        rate_rad_s: f64,
        dt: f64,
    ) -> bool {
        let level = r6 * m;
        // µT readings: no overflow to guard against with `hypot` (a non-finite one is refused).
        let horizontal = math::sqrt(level.x * level.x + level.y * level.y);
        let gains = s.gains.at(p, dt);
        let factor = s.magnetic.step(
            p,
            level.norm(),
            math::atan2(level.z, horizontal),
            rate_rad_s,
            gains.mag_reference,
            dt,
        );
        if horizontal > 0.0 {
            // The angle from the heading to north seen in the level frame (at `−atan2(y, x)`),
            // from the heading's half-angle cosine and sine without turning either into angles.
            let (c, h) = (s.heading.w, s.heading.k);
            let (cos_psi, sin_psi) = (c * c - h * h, 2.0 * c * h);
            let (cos_t, sin_t) = (level.x, -level.y);
            let error = math::atan2(
                sin_t * cos_psi - cos_t * sin_psi,
                cos_t * cos_psi + sin_t * sin_psi,
            );
            let mut k = gains.heading * factor;
            // The mean of the readings so far while that is faster than the time constant.
            if s.elapsed_s < p.tau_mag_s {
                s.mag_samples += 1.0;
                k = k.max(1.0 / s.mag_samples);
            }
            s.heading = renormalized((s.heading * rotate_z(k * error)).into_inner());
        }
        s.magnetic.disturbed()
    }
}

/// The rotation taking the direction of `v` to down (NED +z), from the direction alone (no
/// trigonometry): `w = cos(θ/2) = √((1 + d_z)/2)`, vector `(d_y, −d_x, 0)/(2w)`; half a turn
/// about x for `v` pointing up, none for a zero `v`.
fn toward_down(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let norm = v.norm();
    if norm <= 0.0 {
        return UnitQuaternion::identity();
    }
    let dz = v.z / norm;
    let w = math::sqrt(0.5 * (1.0 + dz));
    let q = if w > 1e-6 {
        // One division for both horizontal parts: (d_y, −d_x)/(2w) = (v_y, −v_x)/(2w‖v‖).
        let scale = 0.5 / (w * norm);
        nalgebra::Quaternion::new(w, v.y * scale, -v.x * scale, 0.0)
    } else {
        nalgebra::Quaternion::new(0.0, 1.0, 0.0, 0.0)
    };
    UnitQuaternion::new_unchecked(q)
}

/// `q`, within rounding of unit length (a product of unit quaternions), back to unit length by
/// one Newton step of `1/√(q·q)` about 1: `q (3 − q·q)/2`, whose error is of the order of the
/// square of `q`'s, so rounding never accumulates (no square root or division).
fn renormalized(q: nalgebra::Quaternion<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(q * (1.5 - 0.5 * q.norm_squared()))
}

/// The NED yaw of a NED-internal `q_nb`.
fn yaw_of(q: &UnitQuaternion<f64>) -> f64 {
    let x = q * Vector3::x();
    math::atan2(x.y, x.x)
}

/// A rotation by `angle` about the NED vertical (down).
fn rotate_z(angle: f64) -> UnitQuaternion<f64> {
    rotation(&Vector3::new(0.0, 0.0, angle))
}

/// The rotation by the rotation vector `v` (rad). A sample's turn is a few milliradians: there
/// the half angle's cosine and `sin(x)/x` come from their Taylor series in `x²` (no square root,
/// division or library call), whose first left-out terms (`x⁸/9!`, `x¹⁰/10!`) are below 1e-23
/// of the result, so it is exact to rounding; larger turns take the library's sine and cosine.
fn rotation(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let x2 = 0.25 * v.norm_squared();
    if x2 < 2.5e-5 {
        // Horner's scheme with the coefficients 1/n! (constants: no division at run time).
        const C: [f64; 4] = [1.0 / 2.0, 1.0 / 24.0, 1.0 / 720.0, 1.0 / 40320.0];
        const S: [f64; 3] = [1.0 / 6.0, 1.0 / 120.0, 1.0 / 5040.0];
        let cos = 1.0 - x2 * (C[0] - x2 * (C[1] - x2 * (C[2] - x2 * C[3])));
        let sinc = 1.0 - x2 * (S[0] - x2 * (S[1] - x2 * S[2]));
        let u = v * (0.5 * sinc);
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(cos, u.x, u.y, u.z))
    } else {
        UnitQuaternion::from_scaled_axis(*v)
    }
}

impl<N: NavFrame> OrientationFilter<N> for RobustFilter {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        let p = self.params;
        check_finite(input, true, p.magnetometer)?;
        let down = gravity_reading(input.accel_m_s2, p.accel_sign);
        let m = Vector3::from(input.mag_ut);
        let w = Vector3::from(input.gyro_rad_s);
        let dt = input.interval_or(p.sample_rate_hz);
        let state = match self.state.as_mut() {
            Some(s) => {
                self.status = Self::advance(&p, s, &down, &w, &m, dt);
                s
            }
            None => {
                let s = self.start::<N>(&down, &w, &m, dt)?;
                self.status = RobustStatus::default();
                self.state.insert(s)
            }
        };
        let q = state.heading * state.q_incl * state.q_gyro;
        Ok(Some(Estimate {
            orientation: to_frame(&q),
            angular_velocity_rad_s: (w - state.bias.bias()).into(),
        }))
    }

    fn reset(&mut self) {
        self.state = None;
        self.status = RobustStatus::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_rotation_from_its_series_is_the_library_rotation_to_rounding() {
        // Turns on both sides of the series' bound (a half angle of 5e-3 rad), about skew axes.
        for angle in [1e-12, 1e-6, 1e-3, 4e-3, 9.99e-3, 1.001e-2, 0.3, 3.0] {
            for axis in [
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.3, -0.5, 0.8).normalize(),
                Vector3::new(-0.1, 0.2, -0.97).normalize(),
            ] {
                let v = axis * angle;
                let ours = rotation(&v);
                let library = UnitQuaternion::from_scaled_axis(v);
                let off = (ours.into_inner() - library.into_inner()).coords.amax();
                assert!(off <= 4.0 * f64::EPSILON, "{angle} rad: off by {off:e}");
                // Unit length to rounding, so renormalising moves nothing measurable.
                assert!((ours.norm() - 1.0).abs() <= 2.0 * f64::EPSILON);
            }
        }
        assert_eq!(rotate_z(0.0), UnitQuaternion::identity());
    }

    #[test]
    fn renormalising_by_a_newton_step_keeps_a_long_product_at_unit_length() {
        // A million turns of a few milliradians about changing axes, renormalised each step:
        // the length stays within rounding of 1, and the product within rounding of the
        // library's normalised one.
        let mut ours = UnitQuaternion::identity();
        let mut library = UnitQuaternion::identity();
        let mut worst = 0.0_f64;
        for k in 0..1_000_000 {
            let t = f64::from(k) * 1e-3;
            let v = Vector3::new(3e-3 * t.sin(), 2e-3 * (0.7 * t).cos(), 1e-3);
            ours = renormalized((ours * rotation(&v)).into_inner());
            library = UnitQuaternion::new_normalize((library * rotation(&v)).into_inner());
            worst = worst.max((ours.norm() - 1.0).abs());
        }
        assert!(worst <= 4.0 * f64::EPSILON, "length off by {worst:e}");
        assert!(
            ours.angle_to(&library) < 1e-9,
            "{}",
            ours.angle_to(&library)
        );
    }
}
