//! Truth kinematics per sample: position, velocity, acceleration (navigation frame), attitude,
//! body rate and body angular acceleration.
//!
//! Sources: [`sampled`] (finite differences on caller-owned slices) and [`body_rates`]
//! (integration of body-frame rates). Exact truth over dual numbers is `imukit::motion::analytic`
//! (dual numbers need the standard library); it uses [`euler`] (Euler rates → body rate),
//! [`tangent`] (attitude aligned with the velocity) and [`sampled::backfill_standstill`] from here.
pub mod body_rates;
mod error;
pub mod euler;
pub mod finite_diff;
pub mod sampled;
pub mod tangent;

pub use error::KinematicsError;

use crate::frame::Body;
use crate::nav_frame::NavFrame;
use crate::rotation::{EulerZyx, Rotation};
use crate::vector::Vec3;

/// The true motion of the reference point S and the attitude of the rigid body at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth<N> {
    /// Time, s.
    pub t_s: f64,
    /// Position of S in the navigation frame, m.
    pub position_m: Vec3<N>,
    /// Velocity of S in the navigation frame, m/s.
    pub velocity_m_s: Vec3<N>,
    /// Kinematic acceleration of S in the navigation frame (no gravity), m/s².
    pub acceleration_m_s2: Vec3<N>,
    /// Attitude `C_nb`.
    pub attitude: Rotation<Body, N>,
    /// The same attitude as z-y-x Euler angles; yaw is unwrapped (continuous) along a path.
    pub euler: EulerZyx,
    /// Body rate `ω_b`, rad/s.
    pub omega_b_rad_s: Vec3<Body>,
    /// Body angular acceleration `α_b = dω_b/dt`, rad/s².
    pub alpha_b_rad_s2: Vec3<Body>,
}

impl<N: NavFrame> Default for Truth<N> {
    fn default() -> Self {
        Self {
            t_s: 0.0,
            position_m: Vec3::zeros(),
            velocity_m_s: Vec3::zeros(),
            acceleration_m_s2: Vec3::zeros(),
            attitude: Rotation::identity(),
            euler: EulerZyx::default(),
            omega_b_rad_s: Vec3::zeros(),
            alpha_b_rad_s2: Vec3::zeros(),
        }
    }
}

impl<N: NavFrame> Truth<N> {
    /// True when every field is finite.
    #[must_use]
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.t_s.is_finite()
            && self.position_m.is_finite()
            && self.velocity_m_s.is_finite()
            && self.acceleration_m_s2.is_finite()
            && self.euler.to_array().iter().all(|a| a.is_finite())
            && self.omega_b_rad_s.is_finite()
            && self.alpha_b_rad_s2.is_finite()
    }

    /// Sets the attitude from z-y-x Euler angles `euler` (rad), and the body rate and body
    /// angular acceleration from the angles' first and second time derivatives `rate` (rad/s)
    /// and `accel` (rad/s²) (see [`euler::body_rate_and_acceleration`]).
    pub fn set_euler_motion(&mut self, euler: EulerZyx, rate: EulerZyx, accel: EulerZyx) {
        self.set_euler_motion_with(euler, &euler::EulerTrig::of(euler), rate, accel);
    }

    /// [`Self::set_euler_motion`] with the sines and cosines `trig` of `euler` already taken
    /// (many at once, by [`euler::EulerTrig::of_each`]).
    pub fn set_euler_motion_with(
        &mut self,
        euler: EulerZyx,
        trig: &euler::EulerTrig,
        rate: EulerZyx,
        accel: EulerZyx,
    ) {
        self.euler = euler;
        self.attitude = Rotation::from_half_angle_trig(&trig.half);
        (self.omega_b_rad_s, self.alpha_b_rad_s2) =
            euler::body_rate_and_acceleration(&trig.pitch_roll, rate, accel);
    }
}

/// Checks that sample times are finite and strictly increasing.
///
/// # Errors
/// [`KinematicsError::NotFinite`] or [`KinematicsError::TimeNotIncreasing`] with the index.
pub fn check_times(t_s: &[f64]) -> Result<(), KinematicsError> {
    for (i, &t) in t_s.iter().enumerate() {
        if !t.is_finite() {
            return Err(KinematicsError::NotFinite {
                field: "t_s",
                index: i,
            });
        }
        if i > 0 && t <= t_s[i - 1] {
            return Err(KinematicsError::TimeNotIncreasing {
                index: i,
                previous_s: t_s[i - 1],
                t_s: t,
            });
        }
    }
    Ok(())
}
