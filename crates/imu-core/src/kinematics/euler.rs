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

/// `(sin p, cos p, sin r, cos r)` of the pitch and roll of `e`.
fn pitch_roll_sin_cos(e: EulerZyx) -> [f64; 4] {
    [
        math::sin(e.pitch_rad),
        math::cos(e.pitch_rad),
        math::sin(e.roll_rad),
        math::cos(e.roll_rad),
    ]
}

/// `ω_b` from the rates `d` and the pitch's and roll's sines and cosines.
fn rate_from([sp, cp, sr, cr]: [f64; 4], d: EulerZyx) -> Vec3<Body> {
    let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
    Vec3::new(
        rd - yd * sp,
        pd * cr + yd * cp * sr,
        -pd * sr + yd * cp * cr,
    )
}

/// `α_b` from the rates `d`, second derivatives `dd` and the pitch's and roll's sines and
/// cosines.
fn acceleration_from([sp, cp, sr, cr]: [f64; 4], d: EulerZyx, dd: EulerZyx) -> Vec3<Body> {
    let (yd, pd, rd) = (d.yaw_rad, d.pitch_rad, d.roll_rad);
    let (ydd, pdd, rdd) = (dd.yaw_rad, dd.pitch_rad, dd.roll_rad);
    Vec3::new(
        rdd - ydd * sp - yd * pd * cp,
        pdd * cr - pd * rd * sr + ydd * cp * sr - yd * pd * sp * sr + yd * rd * cp * cr,
        -pdd * sr - pd * rd * cr + ydd * cp * cr - yd * pd * sp * cr - yd * rd * cp * sr,
    )
}

/// Body rate `ω_b` (rad/s) from Euler angles `e` and their rates `d` (rad/s, as `EulerZyx`).
#[must_use]
pub fn body_rate(e: EulerZyx, d: EulerZyx) -> Vec3<Body> {
    rate_from(pitch_roll_sin_cos(e), d)
}

/// Body angular acceleration `α_b = dω_b/dt` (rad/s²) from Euler angles `e`, their rates `d`
/// (rad/s) and second derivatives `dd` (rad/s²).
#[must_use]
pub fn body_angular_acceleration(e: EulerZyx, d: EulerZyx, dd: EulerZyx) -> Vec3<Body> {
    acceleration_from(pitch_roll_sin_cos(e), d, dd)
}

/// [`body_rate`] and [`body_angular_acceleration`] together, the same numbers with the
/// pitch's and roll's sines and cosines taken once.
#[must_use]
pub fn body_rate_and_acceleration(
    e: EulerZyx,
    d: EulerZyx,
    dd: EulerZyx,
) -> (Vec3<Body>, Vec3<Body>) {
    let sc = pitch_roll_sin_cos(e);
    (rate_from(sc, d), acceleration_from(sc, d, dd))
}

/// `angle` plus the multiple of 2π that brings it closest to `reference` (rad): yaw unwrapping
/// for callers that evaluate attitudes sample by sample.
#[must_use]
pub fn unwrap_near(angle: f64, reference: f64) -> f64 {
    math::unwrap_near(angle, reference)
}
