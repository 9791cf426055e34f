//! Tangent attitude: the body x axis along the velocity (the MATLAB trajectory tool's eqs. 10–13).
//!
//! `yaw = atan2(v_y, v_x)`, `pitch = −asin(v_z / |v|)` (written as `−atan2(v_z, |v_h|)`),
//! `roll = 0`; the same formula in ENU and NED (in NED a climb is nose-up). Where the speed falls
//! below a threshold the last valid attitude is held with zero rates; leading standstill samples
//! take the first valid attitude (batch functions backfill them). Yaw is unwrapped so it is
//! continuous. A vertical velocity (horizontal speed below the threshold while moving) is a
//! singularity and is refused.
use crate::kinematics::KinematicsError;
use crate::math;
use crate::rotation::EulerZyx;
use crate::trig;

/// Speeds below this (m/s) count as standstill for the tangent attitude, unless set otherwise.
pub const DEFAULT_MIN_SPEED_M_S: f64 = 1e-6;

/// Tangent Euler angles with their first and second time derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentAngles {
    /// Angles, rad (roll is 0).
    pub euler: EulerZyx,
    /// First derivatives, rad/s.
    pub rate: EulerZyx,
    /// Second derivatives, rad/s².
    pub accel: EulerZyx,
}

/// Tangent angles and their derivatives from velocity `v`, acceleration `a` and jerk `j`
/// (navigation frame, SI), in closed form. Requires a non-zero horizontal speed.
///
/// With `h = |v_h|`: `ẏ = (v_x a_y − v_y a_x)/h²`; `θ = atan2(v_z, h)` has
/// `θ̇ = (h a_z − v_z ḣ)/|v|²`; pitch = −θ. Second derivatives by the quotient rule.
#[must_use]
pub fn tangent_angles(v: [f64; 3], a: [f64; 3], j: [f64; 3]) -> TangentAngles {
    TangentSample::at(v, a, j).angles
}

/// One sample's tangent attitude before [`TangentTracker`]'s standstill hold and yaw unwrapping:
/// the speeds its checks need and [`tangent_angles`] (yaw in `[−π, π]`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentSample {
    /// `|v|`, m/s.
    pub speed_m_s: f64,
    /// `|v_h| = √(v_x² + v_y²)`, m/s.
    pub horizontal_m_s: f64,
    /// The angles and their derivatives (not finite where the horizontal speed is zero).
    pub angles: TangentAngles,
}

impl TangentSample {
    /// At velocity `v`, acceleration `a` and jerk `j` (navigation frame, SI), the arctangents
    /// from the library's `atan2`.
    #[must_use]
    pub fn at(v: [f64; 3], a: [f64; 3], j: [f64; 3]) -> Self {
        let (speed_m_s, h) = speeds(v);
        let arctangents = (math::atan2(v[1], v[0]), math::atan2(v[2], h));
        Self {
            speed_m_s,
            horizontal_m_s: h,
            angles: tangent_angles_at(v, a, j, h, arctangents),
        }
    }

    /// [`Self::at`] for each sample of the shortest of the four slices: the arctangents from
    /// the vector kernels of [`crate::trig`] (within [`trig::MAX_ULP`] of the correctly rounded
    /// values), the rest as [`Self::at`] computes it, in loops over the samples with no state
    /// between them (so the quotients and roots of neighbouring samples overlap).
    pub fn of_each(v: &[[f64; 3]], a: &[[f64; 3]], j: &[[f64; 3]], out: &mut [TangentSample]) {
        const BLOCK: usize = 16;
        let (mut vy, mut vx, mut vz) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        let (mut h, mut yaw, mut elevation) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        let n = v.len().min(a.len()).min(j.len()).min(out.len());
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let block = start..start + m;
            for (k, v) in v[block.clone()].iter().enumerate() {
                (vx[k], vy[k], vz[k]) = (v[0], v[1], v[2]);
                (out[start + k].speed_m_s, h[k]) = speeds(*v);
            }
            trig::atan2_into(&vy[..m], &vx[..m], &mut yaw[..m]);
            trig::atan2_into(&vz[..m], &h[..m], &mut elevation[..m]);
            for (k, ((v, a), j)) in v[block.clone()]
                .iter()
                .zip(&a[block.clone()])
                .zip(&j[block])
                .enumerate()
            {
                let o = &mut out[start + k];
                o.horizontal_m_s = h[k];
                o.angles = tangent_angles_at(*v, *a, *j, h[k], (yaw[k], elevation[k]));
            }
        }
    }
}

/// `(|v|, |v_h|)`.
#[inline]
fn speeds(v: [f64; 3]) -> (f64, f64) {
    (
        math::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]),
        math::sqrt(v[0] * v[0] + v[1] * v[1]),
    )
}

/// [`tangent_angles`] given the horizontal speed `h = √(v_x² + v_y²)` (m/s) and the arctangents
/// `atan2(v_y, v_x)` and `atan2(v_z, h)` already taken.
#[inline]
fn tangent_angles_at(
    v: [f64; 3],
    a: [f64; 3],
    j: [f64; 3],
    h: f64,
    (yaw, elevation): (f64, f64),
) -> TangentAngles {
    let [vx, vy, vz] = v;
    let [ax, ay, az] = a;
    let [jx, jy, jz] = j;
    // Yaw.
    let d = vx * vx + vy * vy;
    let n = vx * ay - vy * ax;
    let n_dot = vx * jy - vy * jx;
    let d_dot = 2.0 * (vx * ax + vy * ay);
    let yaw_rate = n / d;
    let yaw_acc = (n_dot * d - n * d_dot) / (d * d);
    // Pitch.
    let h_dot = (vx * ax + vy * ay) / h;
    let h_ddot = (ax * ax + ay * ay + vx * jx + vy * jy - h_dot * h_dot) / h;
    let d2 = d + vz * vz;
    let n2 = h * az - vz * h_dot;
    let n2_dot = h * jz - vz * h_ddot;
    let d2_dot = 2.0 * (vx * ax + vy * ay + vz * az);
    let theta_rate = n2 / d2;
    let theta_acc = (n2_dot * d2 - n2 * d2_dot) / (d2 * d2);
    TangentAngles {
        euler: EulerZyx::new(yaw, -elevation, 0.0),
        rate: EulerZyx::new(yaw_rate, -theta_rate, 0.0),
        accel: EulerZyx::new(yaw_acc, -theta_acc, 0.0),
    }
}

/// Per-sample tangent attitude with standstill hold and yaw unwrapping.
#[derive(Clone, Copy, Debug)]
pub struct TangentTracker {
    min_speed_m_s: f64,
    last: Option<EulerZyx>,
}

impl TangentTracker {
    /// A tracker that treats speeds below `min_speed_m_s` as standstill.
    #[must_use]
    pub const fn new(min_speed_m_s: f64) -> Self {
        Self {
            min_speed_m_s,
            last: None,
        }
    }

    /// The tangent attitude at sample `index` from velocity, acceleration and jerk.
    ///
    /// Returns `Ok(None)` at a standstill before any valid attitude (the caller backfills), the
    /// held attitude with zero rates at a later standstill, otherwise the unwrapped angles.
    ///
    /// # Errors
    /// [`KinematicsError::VerticalTangent`] when the velocity is vertical.
    pub fn update(
        &mut self,
        index: usize,
        v: [f64; 3],
        a: [f64; 3],
        j: [f64; 3],
    ) -> Result<Option<TangentAngles>, KinematicsError> {
        self.update_sample(index, &TangentSample::at(v, a, j))
    }

    /// [`Self::update`] from the sample's speeds and angles taken already ([`TangentSample`],
    /// many samples at once by [`TangentSample::of_each`]).
    ///
    /// # Errors
    /// As [`Self::update`].
    #[inline]
    pub fn update_sample(
        &mut self,
        index: usize,
        sample: &TangentSample,
    ) -> Result<Option<TangentAngles>, KinematicsError> {
        if sample.speed_m_s < self.min_speed_m_s {
            return Ok(self.last.map(|euler| TangentAngles {
                euler,
                ..TangentAngles::default()
            }));
        }
        if sample.horizontal_m_s < self.min_speed_m_s {
            return Err(KinematicsError::VerticalTangent { index });
        }
        let mut angles = sample.angles;
        if let Some(last) = self.last {
            angles.euler.yaw_rad = math::unwrap_near(angles.euler.yaw_rad, last.yaw_rad);
        }
        self.last = Some(angles.euler);
        Ok(Some(angles))
    }
}

/// Tangent Euler angles for a series of velocities (navigation frame, m/s), written into `out`:
/// standstill samples hold the last valid attitude, leading ones take the first valid attitude,
/// and yaw is unwrapped. All zero when the body never moves.
///
/// # Errors
/// [`KinematicsError::VerticalTangent`], [`KinematicsError::NotFinite`],
/// [`KinematicsError::LengthMismatch`].
pub fn tangent_series(
    velocity_m_s: &[[f64; 3]],
    min_speed_m_s: f64,
    out: &mut [EulerZyx],
) -> Result<(), KinematicsError> {
    if out.len() != velocity_m_s.len() {
        return Err(KinematicsError::LengthMismatch {
            field: "output",
            expected: velocity_m_s.len(),
            got: out.len(),
        });
    }
    let mut tracker = TangentTracker::new(min_speed_m_s);
    let mut first_valid = None;
    for (i, (v, e)) in velocity_m_s.iter().zip(out.iter_mut()).enumerate() {
        if !v.iter().all(|c| c.is_finite()) {
            return Err(KinematicsError::NotFinite {
                field: "velocity_m_s",
                index: i,
            });
        }
        *e = match tracker.update(i, *v, [0.0; 3], [0.0; 3])? {
            Some(a) => {
                first_valid.get_or_insert(i);
                a.euler
            }
            None => EulerZyx::default(),
        };
    }
    if let Some(first) = first_valid {
        let e = out[first];
        out[..first].fill(e);
    }
    Ok(())
}
