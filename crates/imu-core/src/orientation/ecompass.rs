//! The electronic compass (MATLAB `ecompass`): orientation from one accelerometer and one
//! magnetometer reading of a body at rest or moving steadily.
//!
//! With `d = −f_b/|f_b|` the down direction and `m` the magnetic field, both in body coordinates,
//! east is `e = d × m/|d × m|` and north `n = e × d`; the rows of `C_nb` are the navigation
//! axes in body coordinates, `(n, e, d)` in NED and `(e, n, −d)` in ENU. The yaw is therefore
//! measured from **magnetic** north (as MATLAB's), and any linear acceleration tilts the result.
//! Degenerate readings are refused: a zero accelerometer or magnetometer vector, and a field
//! within 1e-9 rad of the vertical (no horizontal component to point north).
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::{
    Estimate, FilterInput, OrientError, OrientationFilter, check_finite, gravity_reading, to_frame,
};
use crate::frame::{Body, Ned};
use crate::ideal::AccelSign;
use crate::math;
use crate::nav_frame::NavFrame;
use crate::rotation::{EulerZyx, Rotation};

/// Orientation `q_nb` from an accelerometer reading (m/s², in `sign`) and a magnetometer
/// reading (µT), both body frame.
///
/// # Errors
/// [`OrientError::NotFinite`] or [`OrientError::Degenerate`] (zero vectors, field along
/// gravity).
pub fn ecompass<N: NavFrame>(
    accel_m_s2: [f64; 3],
    mag_ut: [f64; 3],
    sign: AccelSign,
) -> Result<Rotation<Body, N>, OrientError> {
    let input = FilterInput {
        accel_m_s2,
        mag_ut,
        ..FilterInput::default()
    };
    check_finite(&input, false, true)?;
    let q = ecompass_ned(&gravity_reading(accel_m_s2, sign), &Vector3::from(mag_ut))?;
    Ok(to_frame(&q))
}

/// The e-compass as a filter: each sample's orientation from its own accelerometer and
/// magnetometer readings alone (no memory; the gyroscope is passed through).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ecompass {
    /// Sign of the accelerometer readings fed in.
    pub accel_sign: AccelSign,
}

impl<N: NavFrame> OrientationFilter<N> for Ecompass {
    fn update(&mut self, input: &FilterInput) -> Result<Option<Estimate<N>>, OrientError> {
        check_finite(input, true, true)?;
        Ok(Some(Estimate {
            orientation: ecompass(input.accel_m_s2, input.mag_ut, self.accel_sign)?,
            angular_velocity_rad_s: input.gyro_rad_s,
        }))
    }

    fn reset(&mut self) {}
}

/// [`ecompass`] on the gravity reading `−f_b`, as the NED-internal quaternion.
pub(crate) fn ecompass_ned(
    down: &Vector3<f64>,
    mag: &Vector3<f64>,
) -> Result<UnitQuaternion<f64>, OrientError> {
    let (gn, mn) = (down.norm(), mag.norm());
    if gn <= 0.0 {
        return Err(OrientError::Degenerate {
            what: "the accelerometer reading is zero: no gravity direction",
        });
    }
    if mn <= 0.0 {
        return Err(OrientError::Degenerate {
            what: "the magnetometer reading is zero: no north direction",
        });
    }
    let d = down / gn;
    let east = d.cross(mag);
    let en = east.norm();
    if en <= 1e-9 * mn {
        return Err(OrientError::Degenerate {
            what: "the magnetic field is parallel to gravity: no north direction",
        });
    }
    let e = east / en;
    let n = e.cross(&d);
    let c_nb = Matrix3::from_rows(&[n.transpose(), e.transpose(), d.transpose()]);
    Ok(UnitQuaternion::from_rotation_matrix(
        &Rotation3::from_matrix_unchecked(c_nb),
    ))
}

/// Roll and pitch from the gravity reading with zero yaw in `N` (the initial attitude of
/// filters without a magnetometer), as the NED-internal quaternion.
pub(crate) fn tilt<N: NavFrame>(down: &Vector3<f64>) -> Result<UnitQuaternion<f64>, OrientError> {
    let level_in_ned = tilt_ned(down)?;
    let e = to_frame::<N>(&level_in_ned).to_euler();
    let level = Rotation::<Body, N>::from_euler(EulerZyx::new(0.0, e.pitch_rad, e.roll_rad));
    Ok(*level.then(&N::from_ned().inverse()).quaternion())
}

/// Roll and pitch from the gravity reading, zero NED yaw.
fn tilt_ned(down: &Vector3<f64>) -> Result<UnitQuaternion<f64>, OrientError> {
    let gn = down.norm();
    if gn <= 0.0 {
        return Err(OrientError::Degenerate {
            what: "the accelerometer reading is zero: no gravity direction",
        });
    }
    let d = down / gn;
    // Gravity reading in body axes at roll φ, pitch θ: (−sin θ, sin φ cos θ, cos φ cos θ).
    let pitch = math::atan2(-d.x, math::sqrt(d.y * d.y + d.z * d.z));
    let roll = math::atan2(d.y, d.z);
    Ok(*Rotation::<Body, Ned>::from_euler(EulerZyx::new(0.0, pitch, roll)).quaternion())
}
