//! Body rate and body angular acceleration from z-y-x Euler angles and their time derivatives.
//!
//! `ω_b = [ṙ − ẏ sin p, ṗ cos r + ẏ cos p sin r, −ṗ sin r + ẏ cos p cos r]` (y = yaw, p = pitch,
//! r = roll), from `[ω_b×] = C_nbᵀ dC_nb/dt` with `C_nb = Rz(y)·Ry(p)·Rx(r)`
//! (Titterton & Weston, *Strapdown Inertial Navigation Technology*, 2nd ed., eq. 3.52).
//! `α_b` is its exact time derivative. The MATLAB trajectory tool's eq. (7) forms `dR/dt·R⁻¹`, the rate in the
//! navigation frame `ω_n = C_nb ω_b`, which equals `ω_b` only for rotation about one fixed axis.
use crate::frame::Body;
use crate::math;
use crate::rotation::{EulerZyx, HalfAngleTrig};
use crate::trig;
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

/// Every sine and cosine an attitude from z-y-x Euler angles needs: the pitch's and roll's (body
/// rate and angular acceleration, gimbal lock) and the half angles' (the quaternion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EulerTrig {
    /// Of the pitch and roll.
    pub pitch_roll: PitchRollTrig,
    /// Of half the yaw, pitch and roll.
    pub half: HalfAngleTrig,
}

/// Attitudes whose sines and cosines [`EulerTrig::of_each`] takes in one pass of the kernels.
const TRIG_BLOCK: usize = 16;

impl EulerTrig {
    /// The sines and cosines of `e`, from the library's `sin_cos` (see [`EulerTrig::of_each`]
    /// for many attitudes at once).
    #[must_use]
    pub fn of(e: EulerZyx) -> Self {
        Self {
            pitch_roll: PitchRollTrig::of(e),
            half: HalfAngleTrig::of(e),
        }
    }

    /// The sines and cosines of each attitude of `euler` into `out` (the shorter of the two),
    /// from the vector kernels of [`crate::trig`] for the half angles (each within
    /// [`trig::MAX_ULP`] of the correctly rounded value, each attitude's independent of the
    /// others), and the pitch's and roll's from theirs by the double-angle formulas
    /// `sin θ = 2 sin(θ/2) cos(θ/2)`, `cos θ = (cos(θ/2) − sin(θ/2))(cos(θ/2) + sin(θ/2))`: within
    /// [`DOUBLE_ANGLE_ULP`] ulp of the correctly rounded sine, and of the cosine within that many
    /// ulp of 1 (an absolute bound: near ±π/2 the cosine is small and its relative error is not).
    /// Three kernel values per attitude, or two for a block whose rolls are all zero (the tangent
    /// attitude's); a zero roll's sine and cosine are `(roll, 1)` exactly either way.
    pub fn of_each(euler: &[EulerZyx], out: &mut [EulerTrig]) {
        const MOST: usize = 3 * TRIG_BLOCK;
        let (mut x, mut sin, mut cos) = ([0.0; MOST], [0.0; MOST], [0.0; MOST]);
        for (euler, out) in euler.chunks(TRIG_BLOCK).zip(out.chunks_mut(TRIG_BLOCK)) {
            let n = euler.len().min(out.len());
            let rolls = euler.iter().any(|e| e.roll_rad != 0.0);
            let per = if rolls { 3 } else { 2 };
            for (k, e) in euler[..n].iter().enumerate() {
                let a = &mut x[per * k..per * (k + 1)];
                a[..2].copy_from_slice(&[e.yaw_rad * 0.5, e.pitch_rad * 0.5]);
                if rolls {
                    a[2] = e.roll_rad * 0.5;
                }
            }
            trig::sin_cos_into(&x[..per * n], &mut sin[..per * n], &mut cos[..per * n]);
            for (k, (e, o)) in euler[..n].iter().zip(out.iter_mut()).enumerate() {
                let at = |j: usize| (sin[per * k + j], cos[per * k + j]);
                let half_pitch = at(1);
                let half_roll = if rolls {
                    at(2)
                } else {
                    (e.roll_rad * 0.5, 1.0)
                };
                // A zero roll's `(±0, 1)` halves give `(±0, 1)` exactly.
                let (sin_pitch, cos_pitch) = double_angle(half_pitch);
                let (sin_roll, cos_roll) = double_angle(half_roll);
                *o = Self {
                    pitch_roll: PitchRollTrig {
                        sin_pitch,
                        cos_pitch,
                        sin_roll,
                        cos_roll,
                    },
                    half: HalfAngleTrig {
                        yaw: at(0),
                        pitch: half_pitch,
                        roll: half_roll,
                    },
                };
            }
        }
    }
}

/// The largest error of the sines and cosines [`EulerTrig::of_each`] forms by the double-angle
/// formulas, in ulp of the correctly rounded sine and in ulp of 1 (ε) for the cosine. From the
/// half angle's kernel values (each within [`trig::MAX_ULP`], so within 2·2⁻⁵² relative) and the
/// roundings: the sine's relative error is at most 4.5·2⁻⁵², which is 9 ulp where the result
/// sits at the top of its binade; the cosine's absolute error at most about 6.3 ε.
/// `tests/trig.rs` checks the bound against correctly rounded values on 40 000 attitudes (3 ulp
/// and 1.75 ε the largest seen).
pub const DOUBLE_ANGLE_ULP: u32 = 9;

/// `(sin θ, cos θ)` from `(sin(θ/2), cos(θ/2))`.
#[inline]
fn double_angle((s, c): (f64, f64)) -> (f64, f64) {
    (2.0 * s * c, (c - s) * (c + s))
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
#[inline]
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
#[inline]
pub fn unwrap_near(angle: f64, reference: f64) -> f64 {
    math::unwrap_near(angle, reference)
}
