//! Rotations between frames, z-y-x Euler angles, quaternions and direction cosine matrices.
//!
//! `Rotation<Body, N>` is `C_nb` (body → navigation). Euler angles are intrinsic z-y-x:
//! `C_nb = Rz(yaw)·Ry(pitch)·Rx(roll)` with the elementary matrices of the MATLAB trajectory tool's eq. (2).
//! Quaternions are Hamilton, scalar first (`[w, x, y, z]`), `v_n = q ⊗ v_b ⊗ q*`; this `q_nb` equals
//! MATLAB's "frame rotation from navigation to body" orientation.
use core::marker::PhantomData;

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::frame::Frame;
use crate::math;
use crate::vector::Vec3;

/// The Hamilton product `a ⊗ b`, with nalgebra's operations in nalgebra's order (so bit for
/// bit its `a * b`), always inlined: the strapdown's recursion calls it every sample, and an
/// outlined call passes the quaternions through memory, where reloading them as vectors stalls
/// on store forwarding.
#[inline(always)]
pub(crate) fn quaternion_product(a: &Quaternion<f64>, b: &Quaternion<f64>) -> Quaternion<f64> {
    let (a, b) = (&a.coords, &b.coords); // [x, y, z, w]
    Quaternion::new(
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    )
}

/// The unit quaternion of the rotation vector `phi` (`exp(phi/2)`; the identity when
/// `|phi/2|² ≤ ε²`), nalgebra's `UnitQuaternion::from_scaled_axis` in nalgebra's order (so bit
/// for bit), always inlined as [`quaternion_product`].
#[inline(always)]
pub(crate) fn rotation_vector_quaternion(phi: &Vector3<f64>) -> Quaternion<f64> {
    let half = phi / 2.0;
    let nn = half.x * half.x + half.y * half.y + half.z * half.z;
    if nn <= f64::EPSILON * f64::EPSILON {
        return Quaternion::identity();
    }
    let n = math::sqrt(nn);
    Quaternion::from_parts(math::cos(n), half * (math::sin(n) / n))
}

/// `v` turned by the unit quaternion `q` (`q ⊗ v ⊗ q*`), nalgebra's formula in nalgebra's
/// order (`t = 2 q_v × v`, `v + q_w t + q_v × t`), always inlined as [`quaternion_product`].
#[inline(always)]
pub(crate) fn rotate(q: &Quaternion<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let u = q.vector();
    let t = u.cross(v) * 2.0;
    let cross = u.cross(&t);
    t * q.scalar() + cross + v
}

/// `(sin, cos)` of half of each z-y-x Euler angle: what the attitude's quaternion is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfAngleTrig {
    /// Of half the yaw.
    pub yaw: (f64, f64),
    /// Of half the pitch.
    pub pitch: (f64, f64),
    /// Of half the roll.
    pub roll: (f64, f64),
}

impl HalfAngleTrig {
    /// Of the half angles of `e`, from the library's `sin_cos` (a zero angle without the call).
    #[must_use]
    pub fn of(e: EulerZyx) -> Self {
        Self {
            roll: math::sin_cos(e.roll_rad * 0.5),
            pitch: math::sin_cos(e.pitch_rad * 0.5),
            yaw: math::sin_cos(e.yaw_rad * 0.5),
        }
    }
}

/// Intrinsic z-y-x Euler angles of a frame relative to another (body relative to navigation), rad.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EulerZyx {
    /// Rotation about z, applied first, rad.
    pub yaw_rad: f64,
    /// Rotation about the once-rotated y axis, rad.
    pub pitch_rad: f64,
    /// Rotation about the twice-rotated x axis, rad.
    pub roll_rad: f64,
}

impl EulerZyx {
    /// Angles from yaw, pitch and roll in radians.
    #[must_use]
    pub const fn new(yaw_rad: f64, pitch_rad: f64, roll_rad: f64) -> Self {
        Self {
            yaw_rad,
            pitch_rad,
            roll_rad,
        }
    }
    /// `[yaw, pitch, roll]`.
    #[must_use]
    pub const fn to_array(self) -> [f64; 3] {
        [self.yaw_rad, self.pitch_rad, self.roll_rad]
    }
    /// From `[yaw, pitch, roll]`.
    #[must_use]
    pub const fn from_array(a: [f64; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }
    /// The direction cosine matrix `Rz(yaw)·Ry(pitch)·Rx(roll)`, row-major.
    #[must_use]
    pub fn to_dcm(self) -> [[f64; 3]; 3] {
        let (sy, cy) = (math::sin(self.yaw_rad), math::cos(self.yaw_rad));
        let (sp, cp) = (math::sin(self.pitch_rad), math::cos(self.pitch_rad));
        let (sr, cr) = (math::sin(self.roll_rad), math::cos(self.roll_rad));
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    }
    /// Angles of a direction cosine matrix (row-major), with pitch in [−π/2, π/2] and yaw, roll in
    /// (−π, π]. At gimbal lock (|pitch| = π/2) roll is set to 0 and yaw absorbs the rotation.
    #[must_use]
    pub fn from_dcm(c: &[[f64; 3]; 3]) -> Self {
        let horiz = math::sqrt(c[2][1] * c[2][1] + c[2][2] * c[2][2]);
        let pitch = math::atan2(-c[2][0], horiz);
        if horiz < 1e-12 {
            // Gimbal lock: only yaw − roll (pitch = +90°) or yaw + roll (−90°) is defined.
            let yaw = math::atan2(-c[0][1], c[1][1]);
            Self::new(yaw, pitch, 0.0)
        } else {
            Self::new(
                math::atan2(c[1][0], c[0][0]),
                pitch,
                math::atan2(c[2][1], c[2][2]),
            )
        }
    }
    /// True when `cos(pitch)` is below `tol`, where z-y-x Euler rates are singular.
    #[must_use]
    pub fn is_near_gimbal_lock(self, tol: f64) -> bool {
        math::abs(math::cos(self.pitch_rad)) < tol
    }
}

/// Re-resolves vectors from `From` axes into `To` axes.
///
/// `Rotation<Body, N>` is `C_nb`: `body_to_nav.apply(f_b)` is `f` in navigation axes. Rotations
/// compose only when their frames match:
///
/// ```compile_fail
/// use imu_core::{Body, Enu, Ned, Rotation, EulerZyx};
/// let a = Rotation::<Body, Enu>::from_euler(EulerZyx::default());
/// let b = Rotation::<Body, Ned>::from_euler(EulerZyx::default());
/// let _ = a.then(&b); // Enu ≠ Body
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation<From, To> {
    q: UnitQuaternion<f64>,
    frames: PhantomData<(From, To)>,
}

impl<From: Frame, To: Frame> Default for Rotation<From, To> {
    fn default() -> Self {
        Self::identity()
    }
}

impl<From: Frame, To: Frame> Rotation<From, To> {
    /// The identity (the two frames coincide).
    #[must_use]
    pub fn identity() -> Self {
        Self::assume_from_quaternion(UnitQuaternion::identity())
    }
    /// Wraps a unit quaternion you know maps `From` onto `To`; the name marks the claim for review.
    #[must_use]
    pub fn assume_from_quaternion(q: UnitQuaternion<f64>) -> Self {
        Self {
            q,
            frames: PhantomData,
        }
    }
    /// From `[w, x, y, z]`, normalised; `None` when the norm is zero or not finite.
    #[must_use]
    pub fn from_wxyz(q: [f64; 4]) -> Option<Self> {
        let raw = Quaternion::new(q[0], q[1], q[2], q[3]);
        let n = raw.norm();
        if !(n.is_finite() && n > 0.0) {
            return None;
        }
        Some(Self::assume_from_quaternion(UnitQuaternion::new_unchecked(
            raw / n,
        )))
    }
    /// The rotation with z-y-x Euler angles `e` of `From` relative to `To`.
    ///
    /// `q = q_z(yaw) ⊗ q_y(pitch) ⊗ q_x(roll)` from the half angles' sines and cosines: the
    /// products of nalgebra's `UnitQuaternion::from_euler_angles(roll, pitch, yaw)` in its order,
    /// so the same numbers bit for bit, with the sine and cosine of a zero angle taken without a
    /// library call (`math::sin_cos`).
    #[must_use]
    pub fn from_euler(e: EulerZyx) -> Self {
        Self::from_half_angle_trig(&HalfAngleTrig::of(e))
    }
    /// [`Self::from_euler`] from the sines and cosines of the half angles, taken elsewhere (by
    /// [`crate::kinematics::euler::EulerTrig::of_each`], many at once).
    #[must_use]
    pub fn from_half_angle_trig(half: &HalfAngleTrig) -> Self {
        let ((sr, cr), (sp, cp), (sy, cy)) = (half.roll, half.pitch, half.yaw);
        Self::assume_from_quaternion(UnitQuaternion::new_unchecked(Quaternion::new(
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        )))
    }
    /// From a direction cosine matrix (row-major) assumed orthonormal.
    #[must_use]
    pub fn from_dcm(c: &[[f64; 3]; 3]) -> Self {
        let m = Matrix3::new(
            c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2],
        );
        let r = nalgebra::Rotation3::from_matrix_unchecked(m);
        Self::assume_from_quaternion(UnitQuaternion::from_rotation_matrix(&r))
    }
    /// The quaternion as `[w, x, y, z]` (Hamilton, scalar first).
    #[must_use]
    pub fn to_wxyz(&self) -> [f64; 4] {
        [self.q.w, self.q.i, self.q.j, self.q.k]
    }
    /// The underlying unit quaternion.
    #[must_use]
    pub fn quaternion(&self) -> &UnitQuaternion<f64> {
        &self.q
    }
    /// The direction cosine matrix, row-major.
    #[must_use]
    pub fn to_dcm(&self) -> [[f64; 3]; 3] {
        let m = self.q.to_rotation_matrix();
        let m = m.matrix();
        [
            [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
            [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
            [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
        ]
    }
    /// z-y-x Euler angles (yaw, roll in (−π, π], pitch in [−π/2, π/2]).
    #[must_use]
    pub fn to_euler(&self) -> EulerZyx {
        EulerZyx::from_dcm(&self.to_dcm())
    }
    /// Re-resolves `v` from `From` axes into `To` axes.
    #[must_use]
    pub fn apply(&self, v: Vec3<From>) -> Vec3<To> {
        Vec3::from_nalgebra(rotate(&self.q, v.as_nalgebra()))
    }
    /// The inverse rotation (`C_nbᵀ` for `C_nb`).
    #[must_use]
    pub fn inverse(&self) -> Rotation<To, From> {
        Rotation::assume_from_quaternion(self.q.inverse())
    }
    /// `self` first, then `next`.
    #[must_use]
    pub fn then<Next: Frame>(&self, next: &Rotation<To, Next>) -> Rotation<From, Next> {
        Rotation::assume_from_quaternion(UnitQuaternion::new_unchecked(quaternion_product(
            &next.q, &self.q,
        )))
    }
}

impl Rotation<crate::frame::Ned, crate::frame::Enu> {
    /// The change of axes NED → ENU: `(e, n, u) = (y, x, −z)` of the NED vector (a rotation by
    /// π about the horizontal axis halfway between north and east).
    #[must_use]
    pub fn ned_to_enu() -> Self {
        let h = core::f64::consts::FRAC_1_SQRT_2;
        Self::assume_from_quaternion(UnitQuaternion::new_unchecked(Quaternion::new(
            0.0, h, h, 0.0,
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::{Rng, SeedableRng};

    /// A value in (−scale, scale), or an exact zero one time in eight (a zero angle is common).
    fn value(rng: &mut rand_xoshiro::Xoshiro256PlusPlus, scale: f64) -> f64 {
        let u = rng.next_u64();
        if u.is_multiple_of(8) {
            0.0
        } else {
            ((u >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
        }
    }

    fn vector(rng: &mut rand_xoshiro::Xoshiro256PlusPlus, scale: f64) -> Vector3<f64> {
        Vector3::new(value(rng, scale), value(rng, scale), value(rng, scale))
    }

    fn bits<const N: usize>(a: impl IntoIterator<Item = f64>) -> [u64; N] {
        let mut out = [0; N];
        for (o, x) in out.iter_mut().zip(a) {
            *o = x.to_bits();
        }
        out
    }

    /// The inlined kernels give nalgebra's results bit for bit, over angles from 1e-9 rad (below
    /// nalgebra's identity threshold for some) to several turns.
    #[test]
    fn kernels_equal_nalgebra_bit_for_bit() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        for k in 0..20_000 {
            let scale = [1e-9, 1e-4, 0.1, 3.0, 20.0][k % 5];
            let phi = vector(&mut rng, scale);
            let q = rotation_vector_quaternion(&phi);
            let want = UnitQuaternion::from_scaled_axis(phi);
            assert_eq!(
                bits::<4>(q.coords.iter().copied()),
                bits::<4>(want.coords.iter().copied()),
                "exp of {phi:?}"
            );
            let other = UnitQuaternion::from_scaled_axis(vector(&mut rng, 2.0));
            let product = quaternion_product(&q, other.quaternion());
            assert_eq!(
                bits::<4>(product.coords.iter().copied()),
                bits::<4>((want * other).coords.iter().copied())
            );
            let v = vector(&mut rng, 50.0);
            assert_eq!(
                bits::<3>(rotate(&q, &v).iter().copied()),
                bits::<3>((want * v).iter().copied())
            );
        }
    }
}
