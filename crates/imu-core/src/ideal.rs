//! Ideal IMU readings from truth: specific force at a lever arm, body rate, magnetic field.
//!
//! `f_b = C_nbᵀ (a_n − g_n) + ω_b × (ω_b × r) + α_b × r` (rigid-body kinematics, eq. 9 of the MATLAB trajectory tool,
//! with gravity taken out as a real accelerometer senses it), `ω_b` unchanged (the same at every
//! point of a rigid body), `m_b = C_nbᵀ m_n`.
use crate::frame::{Body, Frame};
use crate::kinematics::Truth;
use crate::nav_frame::NavFrame;
use crate::vector::Vec3;

/// Sign convention of accelerometer output.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AccelSign {
    /// Specific force `f_b` (a level IMU at rest reads `+g` on its up axis), as real sensors,
    /// ROS, gnss-ins-sim and Kalibr report.
    #[default]
    SpecificForce,
    /// `−f_b`, gravity minus acceleration, as MATLAB's `imuSensor` outputs.
    Matlab,
}

/// Where and how the IMU sits on the body, and the environment it senses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuMount<N> {
    /// Lever arm `r` from the reference point S to the IMU point I, body frame, m.
    pub lever_arm_m: Vec3<Body>,
    /// Accelerometer sign convention.
    pub accel_sign: AccelSign,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// Earth magnetic field in the navigation frame, µT.
    pub magnetic_field_ut: Vec3<N>,
}

impl<N: NavFrame> Default for ImuMount<N> {
    fn default() -> Self {
        Self {
            lever_arm_m: Vec3::zeros(),
            accel_sign: AccelSign::SpecificForce,
            gravity_m_s2: crate::frame::DEFAULT_GRAVITY_M_S2,
            magnetic_field_ut: N::default_magnetic_field_ut(),
        }
    }
}

/// One ideal reading in body axes `B` (the navigation frame's convention unless told, [`Frd`]
/// from the Earth's kinematics).
///
/// [`Frd`]: crate::frame::Frd
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IdealReading<B: Frame = Body> {
    /// Accelerometer, m/s² (sign per [`AccelSign`]).
    pub accel_m_s2: Vec3<B>,
    /// Gyroscope, rad/s.
    pub gyro_rad_s: Vec3<B>,
    /// Magnetometer, µT.
    pub mag_ut: Vec3<B>,
}

impl IdealReading<crate::frame::Frd> {
    /// The reading in the body axes of `N`'s convention (turned by [`NavFrame::frd_to_body`]).
    #[must_use]
    pub fn to_body<N: NavFrame>(&self) -> IdealReading<Body> {
        let turn = N::frd_to_body();
        IdealReading {
            accel_m_s2: turn.apply(self.accel_m_s2),
            gyro_rad_s: turn.apply(self.gyro_rad_s),
            mag_ut: turn.apply(self.mag_ut),
        }
    }
}

/// Acceleration-like quantity carried from the reference point S to a point at lever arm `r`
/// (body frame, m) of a rigid body turning at `ω_b` with `α_b`:
/// `a_I = a_S + ω_b × (ω_b × r) + α_b × r` (the MATLAB trajectory tool's eq. 9; centripetal and Euler terms).
#[must_use]
#[inline]
pub fn at_lever_arm<B: Frame>(
    a_s: Vec3<B>,
    omega_b: Vec3<B>,
    alpha_b: Vec3<B>,
    r: Vec3<B>,
) -> Vec3<B> {
    a_s + omega_b.cross(&omega_b.cross(&r)) + alpha_b.cross(&r)
}

impl<N: NavFrame> ImuMount<N> {
    /// Specific force at the IMU point, body frame, m/s² (always the physical sign).
    #[must_use]
    pub fn specific_force(&self, truth: &Truth<N>) -> Vec3<Body> {
        let f_s = truth
            .attitude
            .inverse()
            .apply(truth.acceleration_m_s2 - N::gravity(self.gravity_m_s2));
        at_lever_arm(
            f_s,
            truth.omega_b_rad_s,
            truth.alpha_b_rad_s2,
            self.lever_arm_m,
        )
    }

    /// The ideal reading of all three sensors for one truth sample.
    #[must_use]
    pub fn read(&self, truth: &Truth<N>) -> IdealReading {
        let f = self.specific_force(truth);
        IdealReading {
            accel_m_s2: match self.accel_sign {
                AccelSign::SpecificForce => f,
                AccelSign::Matlab => -f,
            },
            gyro_rad_s: truth.omega_b_rad_s,
            mag_ut: truth.attitude.inverse().apply(self.magnetic_field_ut),
        }
    }

    /// Ideal readings for a slice of truth samples, written into `out` (same length; extra
    /// output slots are left untouched).
    pub fn read_into(&self, truth: &[Truth<N>], out: &mut [IdealReading]) {
        for (s, o) in truth.iter().zip(out.iter_mut()) {
            *o = self.read(s);
        }
    }
}
