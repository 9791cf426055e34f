//! Three light orientation filters behind the same trait as the Kalman filters:
//!
//! * [`Complementary`] (MATLAB `complementaryFilter`): gyroscope integration, then a fraction
//!   `AccelerometerGain` of the tilt error and `MagnetometerGain` of the heading error removed
//!   per sample;
//! * [`Madgwick`] (S. Madgwick, "An efficient orientation filter for inertial and
//!   inertial/magnetic sensor arrays", 2010): `q̇ = ½ q ⊗ ω − β ∇f/|∇f|`, the gradient of the
//!   misfit of the predicted gravity (and field) directions;
//! * [`Mahony`] (R. Mahony et al., "Nonlinear complementary filters on the special orthogonal
//!   group", IEEE TAC 53(5), 2008): `ω ← ω + k_P e + k_I ∫e` with `e = a × v̂ (+ m × ŵ)`.
//!
//! Written here rather than taken from the `ahrs` crate: that crate pins an older nalgebra
//! (0.34; imukit uses 0.35, so two copies), fixes the sample period at construction, has no
//! complementary filter, and would need its own frame and sign conversions; these share
//! imukit's frames, accelerometer sign handling, start-up and trait with the Kalman filters.
//!
//! All three start from the first sample's e-compass (or tilt, without a magnetometer) and
//! work in NED on the normalised down-pointing gravity reading `−f_b`; the Earth-field
//! reference is the measured field turned to north, `b = (|h_xy|, 0, h_z)`.
use nalgebra::{Quaternion, UnitQuaternion, Vector3, Vector4};

use super::ecompass::{ecompass_ned, tilt};
use super::{
    Estimate, FilterInput, OrientError, OrientationFilter, check_finite, gravity_reading, positive,
    to_frame,
};
use crate::ideal::AccelSign;
use crate::math;
use crate::nav_frame::NavFrame;

/// What the three filters share: rate, sensors, sign, and the running quaternion. Each sample
/// is integrated over its own interval when it has one ([`FilterInput::interval_s`]), else over
/// `1/sample_rate_hz`; the complementary filter's gains stay fractions per sample, as MATLAB's.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Core {
    sample_rate_hz: f64,
    magnetometer: bool,
    accel_sign: AccelSign,
    q: Option<UnitQuaternion<f64>>,
}

impl Core {
    fn new(
        sample_rate_hz: f64,
        magnetometer: bool,
        accel_sign: AccelSign,
    ) -> Result<Self, OrientError> {
        positive("SampleRate", sample_rate_hz, false)?;
        Ok(Self {
            sample_rate_hz,
            magnetometer,
            accel_sign,
            q: None,
        })
    }

    /// One sample through a filter: the readings are checked, the first sample only sets the
    /// start-up attitude, and later ones go to `advance`, which returns the new quaternion and
    /// the body rate to report.
    fn step<N: NavFrame>(
        &mut self,
        input: &FilterInput,
        advance: impl FnOnce(&Step, f64) -> (UnitQuaternion<f64>, Vector3<f64>),
    ) -> Result<Option<Estimate<N>>, OrientError> {
        check_finite(input, true, self.magnetometer)?;
        let a = gravity_reading(input.accel_m_s2, self.accel_sign);
        let m = Vector3::from(input.mag_ut);
        let w = Vector3::from(input.gyro_rad_s);
        let (q, w) = match self.q {
            Some(q) => advance(&Step { a, m, w, q }, input.interval_or(self.sample_rate_hz)),
            None if self.magnetometer => (ecompass_ned(&a, &m)?, w),
            None => (tilt::<N>(&a)?, w),
        };
        self.q = Some(q);
        Ok(Some(Estimate {
            orientation: to_frame(&q),
            angular_velocity_rad_s: w.into(),
        }))
    }
}

/// One sample as the filters see it.
struct Step {
    /// Gravity reading `−f_b`, m/s².
    a: Vector3<f64>,
    /// Magnetometer, µT.
    m: Vector3<f64>,
    /// Gyroscope, rad/s.
    w: Vector3<f64>,
    /// The quaternion before this sample.
    q: UnitQuaternion<f64>,
}

/// `v` normalised, or `None` for a zero vector.
fn unit(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n > 0.0).then(|| v / n)
}

/// The Earth-field reference in NED from the body-frame field `m` and the orientation `q`.
fn field_reference(q: &UnitQuaternion<f64>, m: &Vector3<f64>) -> Vector3<f64> {
    let h = q * m;
    Vector3::new(math::sqrt(h.x * h.x + h.y * h.y), 0.0, h.z)
}

/// `q` advanced by the body rate `w` over `dt` (first-order quaternion kinematics, then
/// normalised, as both papers do).
fn integrate(q: &UnitQuaternion<f64>, q_dot: &Quaternion<f64>, dt: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(q.quaternion() + q_dot * dt)
}

fn rate_quaternion(q: &UnitQuaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q.quaternion() * Quaternion::from_imag(*w) * 0.5
}

/// MATLAB's `complementaryFilter`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Complementary {
    core: Core,
    accelerometer_gain: f64,
    magnetometer_gain: f64,
}

impl Complementary {
    /// A filter at `sample_rate_hz`; gains in [0, 1] (MATLAB's defaults are 0.01 and 0.01).
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`] naming the field.
    pub fn new(
        sample_rate_hz: f64,
        accelerometer_gain: f64,
        magnetometer_gain: f64,
        magnetometer: bool,
        accel_sign: AccelSign,
    ) -> Result<Self, OrientError> {
        for (field, v) in [
            ("AccelerometerGain", accelerometer_gain),
            ("MagnetometerGain", magnetometer_gain),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(OrientError::InvalidParameter {
                    field,
                    value: v,
                    expected: "in [0, 1]",
                });
            }
        }
        Ok(Self {
            core: Core::new(sample_rate_hz, magnetometer, accel_sign)?,
            accelerometer_gain,
            magnetometer_gain,
        })
    }
}

impl<N: NavFrame> OrientationFilter<N> for Complementary {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        let magnetometer = self.core.magnetometer;
        self.core.step(input, |&Step { a, m, w, q: q0 }, dt| {
            let mut q = q0 * UnitQuaternion::from_scaled_axis(w * dt);
            // Tilt: turn the predicted down direction a fraction of the way to the measured one.
            if let Some(a) = unit(&a) {
                let v = q.inverse() * Vector3::z();
                let axis = a.cross(&v);
                let angle = math::atan2(axis.norm(), a.dot(&v));
                if let Some(axis) = unit(&axis) {
                    q *= UnitQuaternion::from_scaled_axis(axis * (self.accelerometer_gain * angle));
                }
            }
            // Heading: remove a fraction of the measured field's east component (about nav z).
            if magnetometer {
                let h = q * m;
                if h.x != 0.0 || h.y != 0.0 {
                    let error = math::atan2(h.y, h.x);
                    q = UnitQuaternion::from_scaled_axis(
                        Vector3::z() * (-self.magnetometer_gain * error),
                    ) * q;
                }
            }
            (q, w)
        })
    }

    fn reset(&mut self) {
        self.core.q = None;
    }
}

/// Madgwick's gradient-descent filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Madgwick {
    core: Core,
    beta: f64,
}

impl Madgwick {
    /// A filter at `sample_rate_hz` with gain `beta` (rad/s; 0.033 without and 0.041 with a
    /// magnetometer are the defaults of the Python `ahrs` package, from Madgwick's paper).
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`] naming the field.
    pub fn new(
        sample_rate_hz: f64,
        beta: f64,
        magnetometer: bool,
        accel_sign: AccelSign,
    ) -> Result<Self, OrientError> {
        positive("beta", beta, true)?;
        Ok(Self {
            core: Core::new(sample_rate_hz, magnetometer, accel_sign)?,
            beta,
        })
    }
}

/// `∇ = Jᵀ f` of `f(q) = q* ⊗ r ⊗ q − s` (the nav-frame reference `r` seen in the body, minus
/// the measured unit vector `s`), over the four quaternion components.
fn misfit_gradient(q: &Quaternion<f64>, r: &Vector3<f64>, s: &Vector3<f64>) -> Vector4<f64> {
    let rq = Quaternion::from_imag(*r);
    let f = (q.conjugate() * rq * q).imag() - s;
    let basis = [
        Quaternion::new(1.0, 0.0, 0.0, 0.0),
        Quaternion::new(0.0, 1.0, 0.0, 0.0),
        Quaternion::new(0.0, 0.0, 1.0, 0.0),
        Quaternion::new(0.0, 0.0, 0.0, 1.0),
    ];
    Vector4::from_fn(|i, _| {
        let e = basis[i];
        let column = (e.conjugate() * rq * q + q.conjugate() * rq * e).imag();
        column.dot(&f)
    })
}

impl<N: NavFrame> OrientationFilter<N> for Madgwick {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        let magnetometer = self.core.magnetometer;
        self.core.step(input, |&Step { a, m, w, q: q0 }, dt| {
            let mut q_dot = rate_quaternion(&q0, &w);
            if let Some(a) = unit(&a) {
                let q = q0.quaternion();
                let mut grad = misfit_gradient(q, &Vector3::z(), &a);
                if magnetometer && let Some(m) = unit(&m) {
                    grad += misfit_gradient(q, &field_reference(&q0, &m), &m);
                }
                // A gradient at rounding level has no direction: normalising it would turn
                // rounding noise into a full step of β.
                let n = grad.norm();
                if n > 1e-12 {
                    let g = grad * (self.beta / n);
                    q_dot -= Quaternion::new(g[0], g[1], g[2], g[3]);
                }
            }
            let q = integrate(&q0, &q_dot, dt);
            (q, w)
        })
    }

    fn reset(&mut self) {
        self.core.q = None;
    }
}

/// Mahony's explicit complementary filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mahony {
    core: Core,
    kp: f64,
    ki: f64,
    integral: Vector3<f64>,
}

impl Mahony {
    /// A filter at `sample_rate_hz` with proportional and integral gains (the Python `ahrs`
    /// package's defaults are `k_P = 1`, `k_I = 0.3`).
    ///
    /// # Errors
    /// [`OrientError::InvalidParameter`] naming the field.
    pub fn new(
        sample_rate_hz: f64,
        kp: f64,
        ki: f64,
        magnetometer: bool,
        accel_sign: AccelSign,
    ) -> Result<Self, OrientError> {
        positive("k_P", kp, true)?;
        positive("k_I", ki, true)?;
        Ok(Self {
            core: Core::new(sample_rate_hz, magnetometer, accel_sign)?,
            kp,
            ki,
            integral: Vector3::zeros(),
        })
    }

    /// The integral of the error, which settles at minus the gyroscope bias, rad/s.
    #[must_use]
    pub fn integral(&self) -> [f64; 3] {
        (self.integral * self.ki).into()
    }
}

impl<N: NavFrame> OrientationFilter<N> for Mahony {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        let magnetometer = self.core.magnetometer;
        self.core.step(input, |&Step { a, m, w, q: q0 }, dt| {
            let mut e = Vector3::zeros();
            if let Some(a) = unit(&a) {
                let body = q0.inverse();
                e += a.cross(&(body * Vector3::z()));
                if magnetometer && let Some(m) = unit(&m) {
                    e += m.cross(&(body * field_reference(&q0, &m)));
                }
            }
            let integral = self.integral + e * dt;
            let corrected = w + e * self.kp + integral * self.ki;
            let q = integrate(&q0, &rate_quaternion(&q0, &corrected), dt);
            self.integral = integral;
            (q, corrected)
        })
    }

    fn reset(&mut self) {
        self.core.q = None;
        self.integral = Vector3::zeros();
    }
}
