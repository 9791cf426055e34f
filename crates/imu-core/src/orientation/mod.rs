//! Orientation from IMU readings: the e-compass, Kalman filters equivalent in structure to
//! MATLAB's `imufilter` and `ahrsfilter`, the complementary, Madgwick and Mahony filters, and
//! imukit's own [`robust`] filter (inclination, heading and bias each from its own evidence,
//! with a smoother for whole logs), all behind one per-sample trait ([`OrientationFilter`]); and the quaternion distance that
//! judges them against truth ([`metrics`]).
//!
//! Conventions (docs/design.md §2): the estimate is `q_nb`, the rotation from the body to the
//! navigation frame `N` (ENU or NED) — MATLAB's "orientation" quaternion (its nav→body frame
//! rotation) has the same four numbers. Readings are body-frame: accelerometer in m/s² in the
//! [`AccelSign`] the filter is told (specific force, or MATLAB's gravity minus acceleration;
//! never guessed), gyroscope in rad/s, magnetometer in µT. Internally every filter works in NED
//! (down = +z, north = +x) on the down-pointing "gravity reading" `−f_b` and turns its result
//! into `N` by [`NavFrame::from_ned`].
//!
//! Nothing here allocates: filters are plain structs, stepped one sample at a time.
pub mod ecompass;
pub mod kalman;
pub mod metrics;
pub mod robust;
pub mod simple;

pub use ecompass::{Ecompass, ecompass};
pub use kalman::{KalmanFilter, KalmanParams};
pub use metrics::{DistanceStats, quaternion_distance};
pub use robust::{RobustFilter, RobustParams, RobustStatus};
pub use simple::{Complementary, Madgwick, Mahony};

use nalgebra::{UnitQuaternion, Vector3};

use crate::frame::{Body, Ned};
use crate::ideal::AccelSign;
use crate::nav_frame::NavFrame;
use crate::rotation::Rotation;

/// One sample for an orientation filter (body frame).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilterInput {
    /// Accelerometer, m/s², in the filter's [`AccelSign`].
    pub accel_m_s2: [f64; 3],
    /// Gyroscope, rad/s (ignored by [`ecompass()`]).
    pub gyro_rad_s: [f64; 3],
    /// Magnetometer, µT (ignored by filters without a magnetometer).
    pub mag_ut: [f64; 3],
    /// Time since the previous sample, s; `None`: the filter's sample period (`1/SampleRate`,
    /// MATLAB's fixed-rate behaviour). Readings with real time stamps carry it, so jitter and
    /// gaps are integrated over the time that passed (ignored on a filter's first sample, which
    /// only sets the start-up attitude, and by [`ecompass()`]).
    pub interval_s: Option<f64>,
}

impl FilterInput {
    /// The interval to integrate over: [`FilterInput::interval_s`], else `1/sample_rate_hz`.
    pub(crate) fn interval_or(&self, sample_rate_hz: f64) -> f64 {
        self.interval_s.unwrap_or(1.0 / sample_rate_hz)
    }
}

/// A filter's output for one sample (or one decimation block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<N: NavFrame> {
    /// Orientation `q_nb`.
    pub orientation: Rotation<Body, N>,
    /// Body rate with the estimated gyroscope bias removed, rad/s (the gyroscope reading for
    /// filters that do not estimate a bias).
    pub angular_velocity_rad_s: [f64; 3],
}

/// Why a reading cannot give an orientation, or a filter cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OrientError {
    /// A NaN or infinite reading (`field` names the sensor).
    NotFinite {
        /// `"accelerometer"`, `"gyroscope"` or `"magnetometer"`.
        field: &'static str,
    },
    /// A reading that does not fix the orientation: a zero accelerometer or magnetometer
    /// vector, or a magnetic field parallel to gravity.
    Degenerate {
        /// What is wrong.
        what: &'static str,
    },
    /// A parameter outside its range.
    InvalidParameter {
        /// The parameter's name (MATLAB's property name where there is one).
        field: &'static str,
        /// Its value.
        value: f64,
        /// The range it must be in.
        expected: &'static str,
    },
    /// The Kalman innovation covariance could not be inverted.
    Singular,
}

impl core::fmt::Display for OrientError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotFinite { field } => write!(f, "{field} reading is not a finite number"),
            Self::Degenerate { what } => write!(f, "{what}"),
            Self::InvalidParameter {
                field,
                value,
                expected,
            } => write!(f, "{field} = {value}: must be {expected}"),
            Self::Singular => write!(f, "the innovation covariance is singular"),
        }
    }
}

impl core::error::Error for OrientError {}

/// An orientation estimator stepped one sample at a time. Same inputs, same outputs: filters
/// are deterministic, and feeding a run in chunks equals feeding it whole.
pub trait OrientationFilter<N: NavFrame> {
    /// Takes one sample; returns the estimate it completes (`None` inside a decimation block).
    ///
    /// # Errors
    /// [`OrientError`] for non-finite or degenerate readings; the filter's state is unchanged.
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError>;

    /// Back to the state before the first sample.
    fn reset(&mut self);
}

/// Checks a sample's sensors (the magnetometer only when `mag` is set) and its interval.
pub(crate) fn check_finite(input: &FilterInput, gyro: bool, mag: bool) -> Result<(), OrientError> {
    if let Some(dt) = input.interval_s {
        positive("sample interval", dt, false)?;
    }
    let finite = |v: &[f64; 3]| v.iter().all(|c| c.is_finite());
    if !finite(&input.accel_m_s2) {
        return Err(OrientError::NotFinite {
            field: "accelerometer",
        });
    }
    if gyro && !finite(&input.gyro_rad_s) {
        return Err(OrientError::NotFinite { field: "gyroscope" });
    }
    if mag && !finite(&input.mag_ut) {
        return Err(OrientError::NotFinite {
            field: "magnetometer",
        });
    }
    Ok(())
}

/// The down-pointing gravity reading `−f_b` from an accelerometer reading in `sign`.
pub(crate) fn gravity_reading(accel_m_s2: [f64; 3], sign: AccelSign) -> Vector3<f64> {
    let a = Vector3::from(accel_m_s2);
    match sign {
        AccelSign::SpecificForce => -a,
        AccelSign::Matlab => a,
    }
}

/// A NED-internal `q_nb` as a rotation into `N`.
pub(crate) fn to_frame<N: NavFrame>(q_ned: &UnitQuaternion<f64>) -> Rotation<Body, N> {
    Rotation::<Body, Ned>::assume_from_quaternion(*q_ned).then(&N::from_ned())
}

/// Checks that `value` is finite and positive (or ≥ 0 with `zero_ok`).
pub(crate) fn positive(field: &'static str, value: f64, zero_ok: bool) -> Result<f64, OrientError> {
    let ok = value.is_finite() && (value > 0.0 || (zero_ok && value == 0.0));
    if ok {
        Ok(value)
    } else {
        Err(OrientError::InvalidParameter {
            field,
            value,
            expected: if zero_ok {
                "finite and ≥ 0"
            } else {
                "finite and > 0"
            },
        })
    }
}
