//! Body rate and body angular acceleration from z-y-x Euler angles and their time derivatives.
//!
//! `ω_b = [ṙ − ẏ sin p, ṗ cos r + ẏ cos p sin r, −ṗ sin r + ẏ cos p cos r]` (y = yaw, p = pitch,
//! r = roll), from `[ω_b×] = C_nbᵀ dC_nb/dt` with `C_nb = Rz(y)·Ry(p)·Rx(r)`
//! (Titterton & Weston, *Strapdown Inertial Navigation Technology*, 2nd ed., eq. 3.52).
//! `α_b` is its exact time derivative. The MATLAB trajectory tool's eq. (7) forms `dR/dt·R⁻¹`, the rate in the
//! navigation frame `ω_n = C_nb ω_b`, which equals `ω_b` only for rotation about one fixed axis.
use crate::frame::Body;
use crate::math;
use crate::rotation::EulerZyx;
use crate::vector::Vec3;

/// The sines and cosines of an attitude's pitch and roll: what the body rate and its derivative
/// need of the angles themselves (and `cos p` tells gimbal lock).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PitchRollTrig {
    /// `sin(pitch)`.
    pub sin_pitch: f64,
    /// `cos(pitch)`.
    pub cos_pitch: f64,
    /// `sin(roll)`.
    pub sin_roll: f64,
    /// `cos(roll)`.
    pub cos_roll: f64,
}

impl PitchRollTrig {
    /// The sines and cosines of the pitch and roll of `e`.
    #[must_use]
    pub fn of(e: EulerZyx) -> Self {
        let (sin_pitch, cos_pitch) = math::sin_cos(e.pitch_rad);
        let (sin_roll, cos_roll) = math::sin_cos(e.roll_rad);
        Self {
            sin_pitch,
            cos_pitch,
            sin_roll,
            cos_roll,
        }
    }

    /// True when `|cos(pitch)|` is below `tol`, where z-y-x Euler rates are singular (as
    /// [`EulerZyx::is_near_gimbal_lock`]).
    #[must_use]
    pub fn is_near_gimbal_lock(&self, tol: f64) -> bool {
        math::abs(self.cos_pitch) < tol
    }

    /// `ω_b` from the rates `d`.
    fn rate(&self, d: EulerZyx) -> Vec3<Body> {
        let (sp, cp, sr, cr) = (self.sin_pitch, self.cos_pitch, self.sin_roll, self.cos_roll);
        let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
        Vec3::new(
            rd - yd * sp,
            pd * cr + yd * cp * sr,
            -pd * sr + yd * cp * cr,
        )
    }

    /// `α_b` from the rates `d` and second derivatives `dd`.
    fn acceleration(&self, d: EulerZyx, dd: EulerZyx) -> Vec3<Body> {
        let (sp, cp, sr, cr) = (self.sin_pitch, self.cos_pitch, self.sin_roll, self.cos_roll);
        let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
        let (ydd, pdd, rdd) = (dd.yaw_rad, dd.pitch_rad, dd.roll_rad);
        Vec3::new(
            rdd - ydd * sp - yd * pd * cp,
            pdd * cr - pd * rd * sr + ydd * cp * sr - yd * pd * sp * sr + yd * rd * cp * cr,
            -pdd * sr - pd * rd * cr + ydd * cp * cr - yd * pd * sp * cr - yd * rd * cp * sr,
        )
    }
}

/// Body rate `ω_b` (rad/s) from Euler angles `e` and their rates `d` (rad/s, as `EulerZyx`).
#[must_use]
pub fn body_rate(e: EulerZyx, d: EulerZyx) -> Vec3<Body> {
    PitchRollTrig::of(e).rate(d)
}

/// Body angular acceleration `α_b = dω_b/dt` (rad/s²) from Euler angles `e`, their rates `d`
/// (rad/s) and second derivatives `dd` (rad/s²).
#[must_use]
pub fn body_angular_acceleration(e: EulerZyx, d: EulerZyx, dd: EulerZyx) -> Vec3<Body> {
    PitchRollTrig::of(e).acceleration(d, dd)
}

/// [`body_rate`] and [`body_angular_acceleration`] together, from the sines and cosines `trig`
/// of the angles' pitch and roll (taken once for both).
#[must_use]
pub fn body_rate_and_acceleration(
    trig: &PitchRollTrig,
    d: EulerZyx,
    dd: EulerZyx,
) -> (Vec3<Body>, Vec3<Body>) {
    (trig.rate(d), trig.acceleration(d, dd))
}

/// `angle` plus the multiple of 2π that brings it closest to `reference` (rad): yaw unwrapping
/// for callers that evaluate attitudes sample by sample.
#[must_use]
pub fn unwrap_near(angle: f64, reference: f64) -> f64 {
    math::unwrap_near(angle, reference)
}
