//! imukit's own attitude and heading filter, made to survive real motion: a complementary
//! filter (gyroscope integration, the tilt pulled towards the accelerometer's gravity with time
//! constant `tau_accel_s`, the heading towards the magnetometer's north with `tau_mag_s`) that
//! learns its gyroscope bias **only at rest** and flags the readings it does not trust.
//!
//! What makes MATLAB's default filters and Mahony's integral gain go wrong on a handheld log —
//! a bias learnt from fast spins, a tilt pulled by linear acceleration, a heading pulled by a
//! magnet — is each handled by a test on the data, in the way of VQF (D. Laidig and T. Seel,
//! "VQF: Highly accurate IMU orientation estimation with bias estimation and magnetic
//! disturbance rejection", Information Fusion 91, 2023) and x-io's Fusion AHRS:
//!
//! - **Rest.** The readings are low-passed (time constant `rest_tau_s`); the sensor is at rest
//!   when, for at least `rest_min_s`, every gyroscope axis stays within `rest_gyro_rad_s` of its
//!   low-pass and every accelerometer axis within `rest_accel_m_s2` of its own. At rest the bias
//!   moves towards the low-passed rate — with a memory as long as the rest so far, up to
//!   `bias_tau_s` — and in motion it is held.
//! - **Acceleration rejection.** A reading whose magnitude is off gravity by more than
//!   `accel_rejection_g`·g, or whose direction is off the predicted one by more than
//!   `accel_rejection_rad`, does not correct the tilt (flagged). Rejected for longer than
//!   `recovery_s` in a row, the test is suspended until the tilt agrees again, so a wrong
//!   attitude is not kept for ever.
//! - **Magnetic disturbance.** The field's magnitude and dip are learnt from the first samples;
//!   a reading off by more than `mag_rejection` (fraction) in magnitude or `dip_rejection_rad`
//!   in dip does not correct the heading (flagged). Disturbed for longer than
//!   `mag_recovery_s`, the present field becomes the reference (the sensor has moved to a
//!   different place).
//!
//! The state after each sample — bias estimate and flags — is [`RobustFilter::status`].
use nalgebra::{UnitQuaternion, Vector3};

use super::ecompass::{ecompass_ned, tilt};
use super::{
    Estimate, FilterInput, OrientError, OrientationFilter, check_finite, gravity_reading, positive,
    to_frame,
};
use crate::frame::NavFrame;
use crate::ideal::AccelSign;
use crate::math;

/// The filter's settings; [`Default`] gives the tuning it is tested with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustParams {
    /// Sample rate for samples without their own interval, Hz.
    pub sample_rate_hz: f64,
    /// Sign of the accelerometer readings.
    pub accel_sign: AccelSign,
    /// Whether the magnetometer is used.
    pub magnetometer: bool,
    /// Gravity, m/s² (for the magnitude test).
    pub gravity_m_s2: f64,
    /// Time constant of the tilt correction, s.
    pub tau_accel_s: f64,
    /// Time constant of the heading correction, s.
    pub tau_mag_s: f64,
    /// Low-pass time constant of the rest test, s.
    pub rest_tau_s: f64,
    /// Largest gyroscope deviation from its low-pass at rest, rad/s.
    pub rest_gyro_rad_s: f64,
    /// Largest accelerometer deviation from its low-pass at rest, m/s².
    pub rest_accel_m_s2: f64,
    /// Time the test must hold before the sensor counts as at rest, s.
    pub rest_min_s: f64,
    /// Time constant of the bias learning at rest, s.
    pub bias_tau_s: f64,
    /// Largest accelerometer magnitude error before rejection, fraction of gravity.
    pub accel_rejection_g: f64,
    /// Largest angle between the measured and predicted gravity before rejection, rad.
    pub accel_rejection_rad: f64,
    /// Rejection for longer than this suspends the test, s.
    pub recovery_s: f64,
    /// Largest relative magnetic magnitude error before the field counts as disturbed.
    pub mag_rejection: f64,
    /// Largest dip error before the field counts as disturbed, rad.
    pub dip_rejection_rad: f64,
    /// A disturbance longer than this makes the present field the reference, s.
    pub mag_recovery_s: f64,
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
            rest_tau_s: 0.5,
            rest_gyro_rad_s: 2.0_f64.to_radians(),
            rest_accel_m_s2: 0.5,
            rest_min_s: 1.5,
            bias_tau_s: 3.0,
            accel_rejection_g: 0.1,
            accel_rejection_rad: 10.0_f64.to_radians(),
            recovery_s: 5.0,
            mag_rejection: 0.1,
            dip_rejection_rad: 10.0_f64.to_radians(),
            mag_recovery_s: 20.0,
        }
    }
}

/// What the filter believes after a sample besides the attitude.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RobustStatus {
    /// Gyroscope bias estimate, rad/s (body axes).
    pub gyro_bias_rad_s: [f64; 3],
    /// The sensor was taken to be at rest (the bias was learnt).
    pub at_rest: bool,
    /// The accelerometer reading was rejected (linear acceleration).
    pub accel_rejected: bool,
    /// The magnetometer reading was rejected (magnetic disturbance).
    pub mag_disturbed: bool,
}

/// The filter (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustFilter {
    params: RobustParams,
    q: Option<UnitQuaternion<f64>>,
    bias: Vector3<f64>,
    gyro_lp: Vector3<f64>,
    accel_lp: Vector3<f64>,
    rest_time_s: f64,
    rejected_time_s: f64,
    recovering: bool,
    mag_reference: Option<(f64, f64)>,
    disturbed_time_s: f64,
    status: RobustStatus,
}

impl RobustFilter {
    /// A filter with `params`.
    ///
    /// # Errors
    /// A rate, time constant or threshold that is not finite and positive.
    pub fn new(params: RobustParams) -> Result<Self, OrientError> {
        for (name, v) in [
            ("SampleRate", params.sample_rate_hz),
            ("Gravity", params.gravity_m_s2),
            ("AccelerometerTimeConstant", params.tau_accel_s),
            ("MagnetometerTimeConstant", params.tau_mag_s),
            ("RestTimeConstant", params.rest_tau_s),
            ("RestGyroscopeThreshold", params.rest_gyro_rad_s),
            ("RestAccelerometerThreshold", params.rest_accel_m_s2),
            ("BiasTimeConstant", params.bias_tau_s),
            ("AccelerationRejection", params.accel_rejection_g),
            ("AccelerationRejectionAngle", params.accel_rejection_rad),
            ("MagneticRejection", params.mag_rejection),
            ("DipRejection", params.dip_rejection_rad),
        ] {
            positive(name, v, false)?;
        }
        for (name, v) in [
            ("RestMinimumTime", params.rest_min_s),
            ("RecoveryTime", params.recovery_s),
            ("MagneticRecoveryTime", params.mag_recovery_s),
        ] {
            positive(name, v, true)?;
        }
        Ok(Self {
            params,
            q: None,
            bias: Vector3::zeros(),
            gyro_lp: Vector3::zeros(),
            accel_lp: Vector3::zeros(),
            rest_time_s: 0.0,
            rejected_time_s: 0.0,
            recovering: false,
            mag_reference: None,
            disturbed_time_s: 0.0,
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

    /// Magnitude and dip of the field `m` (body) seen through `q`.
    fn field(q: &UnitQuaternion<f64>, m: &Vector3<f64>) -> (f64, f64) {
        let n = q * m;
        (m.norm(), math::atan2(n.z, math::hypot(n.x, n.y)))
    }

    fn advance(
        &mut self,
        q: UnitQuaternion<f64>,
        down: &Vector3<f64>,
        w: &Vector3<f64>,
        m: &Vector3<f64>,
        dt: f64,
    ) -> UnitQuaternion<f64> {
        let p = self.params;
        let mut status = RobustStatus::default();
        // Rest: both sensors close to their low-pass for long enough.
        let alpha = dt / (p.rest_tau_s + dt);
        self.gyro_lp += (w - self.gyro_lp) * alpha;
        self.accel_lp += (down - self.accel_lp) * alpha;
        let steady = (w - self.gyro_lp).amax() <= p.rest_gyro_rad_s
            && (down - self.accel_lp).amax() <= p.rest_accel_m_s2;
        self.rest_time_s = if steady { self.rest_time_s + dt } else { 0.0 };
        if self.rest_time_s >= p.rest_min_s {
            status.at_rest = true;
            // Early in a rest the mean of the rest so far (the low-pass's own memory is
            // `rest_tau_s`), later an exponential average over `bias_tau_s`.
            let memory = p
                .bias_tau_s
                .min(self.rest_time_s - p.rest_min_s + p.rest_tau_s);
            self.bias += (self.gyro_lp - self.bias) * (dt / (memory + dt));
        }
        // Gyroscope integration.
        let rate = w - self.bias;
        let mut q = q * UnitQuaternion::from_scaled_axis(rate * dt);
        // Tilt towards the measured gravity, unless it is not gravity.
        let g_norm = down.norm();
        if g_norm > 0.0 {
            let measured = down / g_norm;
            let predicted = q.inverse() * Vector3::z();
            let axis = measured.cross(&predicted);
            let angle = math::atan2(axis.norm(), measured.dot(&predicted));
            let off_gravity =
                math::abs(g_norm - p.gravity_m_s2) > p.accel_rejection_g * p.gravity_m_s2;
            let reject = off_gravity || angle > p.accel_rejection_rad;
            if reject && !self.recovering {
                status.accel_rejected = true;
                self.rejected_time_s += dt;
                if self.rejected_time_s > p.recovery_s {
                    self.recovering = true;
                }
            } else {
                if !reject {
                    self.recovering = false;
                    self.rejected_time_s = 0.0;
                }
                let k = dt / (p.tau_accel_s + dt);
                let correction = if angle > 0.0 {
                    axis * (angle / axis.norm().max(f64::MIN_POSITIVE))
                } else {
                    Vector3::zeros()
                };
                q *= UnitQuaternion::from_scaled_axis(correction * k);
            }
        }
        // Heading towards magnetic north, unless the field is disturbed.
        if p.magnetometer && m.norm() > 0.0 {
            let (norm, dip) = Self::field(&q, m);
            let reference = *self.mag_reference.get_or_insert((norm, dip));
            let disturbed = math::abs(norm - reference.0) > p.mag_rejection * reference.0
                || math::abs(dip - reference.1) > p.dip_rejection_rad;
            if disturbed {
                status.mag_disturbed = true;
                self.disturbed_time_s += dt;
                if self.disturbed_time_s > p.mag_recovery_s {
                    self.mag_reference = Some((norm, dip));
                    self.disturbed_time_s = 0.0;
                }
            } else {
                self.disturbed_time_s = 0.0;
                let n = q * m;
                if math::hypot(n.x, n.y) > 0.0 {
                    let heading_error = math::atan2(n.y, n.x);
                    let k = dt / (p.tau_mag_s + dt);
                    q = UnitQuaternion::from_scaled_axis(Vector3::z() * (-k * heading_error)) * q;
                }
            }
        }
        status.gyro_bias_rad_s = self.bias.into();
        self.status = status;
        q
    }
}

impl<N: NavFrame> OrientationFilter<N> for RobustFilter {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        let p = self.params;
        check_finite(input, true, p.magnetometer)?;
        let down = gravity_reading(input.accel_m_s2, p.accel_sign);
        let m = Vector3::from(input.mag_ut);
        let w = Vector3::from(input.gyro_rad_s);
        let q = match self.q {
            Some(q) => self.advance(q, &down, &w, &m, input.interval_or(p.sample_rate_hz)),
            None => {
                let q = if p.magnetometer {
                    ecompass_ned(&down, &m)?
                } else {
                    tilt::<N>(&down)?
                };
                self.gyro_lp = w;
                self.accel_lp = down;
                if p.magnetometer {
                    self.mag_reference = Some(Self::field(&q, &m));
                }
                q
            }
        };
        self.q = Some(q);
        Ok(Some(Estimate {
            orientation: to_frame(&q),
            angular_velocity_rad_s: (w - self.bias).into(),
        }))
    }

    fn reset(&mut self) {
        if let Ok(fresh) = Self::new(self.params) {
            *self = fresh;
        }
    }
}
