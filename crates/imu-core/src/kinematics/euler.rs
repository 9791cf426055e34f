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

/// Body rate `ω_b` (rad/s) from Euler angles `e` and their rates `d` (rad/s, as `EulerZyx`).
#[must_use]
pub fn body_rate(e: EulerZyx, d: EulerZyx) -> Vec3<Body> {
    let (sp, cp) = (math::sin(e.pitch_rad), math::cos(e.pitch_rad));
    let (sr, cr) = (math::sin(e.roll_rad), math::cos(e.roll_rad));
    let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
    Vec3::new(
        rd - yd * sp,
        pd * cr + yd * cp * sr,
        -pd * sr + yd * cp * cr,
    )
}

/// Body angular acceleration `α_b = dω_b/dt` (rad/s²) from Euler angles `e`, their rates `d`
/// (rad/s) and second derivatives `dd` (rad/s²).
#[must_use]
pub fn body_angular_acceleration(e: EulerZyx, d: EulerZyx, dd: EulerZyx) -> Vec3<Body> {
    let (sp, cp) = (math::sin(e.pitch_rad), math::cos(e.pitch_rad));
    let (sr, cr) = (math::sin(e.roll_rad), math::cos(e.roll_rad));
    let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
    let (ydd, pdd, rdd) = (dd.yaw_rad, dd.pitch_rad, dd.roll_rad);
    Vec3::new(
        rdd - ydd * sp - yd * pd * cp,
        pdd * cr - pd * rd * sr + ydd * cp * sr - yd * pd * sp * sr + yd * rd * cp * cr,
        -pdd * sr - pd * rd * cr + ydd * cp * cr - yd * pd * sp * cr - yd * rd * cp * sr,
    )
}

/// `angle` plus the multiple of 2π that brings it closest to `reference` (rad): yaw unwrapping
/// for callers that evaluate attitudes sample by sample.
#[must_use]
pub fn unwrap_near(angle: f64, reference: f64) -> f64 {
    math::unwrap_near(angle, reference)
}
