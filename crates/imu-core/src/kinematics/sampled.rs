//! Truth kinematics from sampled positions and attitudes, by finite differences
//! ([`finite_diff`](super::finite_diff)), writing into a slice the caller owns.
//!
//! Attitude derivatives never difference raw wrapped angles: Euler angles are unwrapped locally
//! around each evaluation point, and quaternions are sign-aligned locally, then
//! `ω_b = 2·vec(q* ⊗ q̇)` and `α_b = 2·vec(q* ⊗ q̈)` (the `q̇*⊗q̇` term of the latter is a real
//! number and drops out of the vector part).
use nalgebra::Quaternion;

use crate::frame::{Body, NavFrame};
use crate::kinematics::euler::{body_angular_acceleration, body_rate};
use crate::kinematics::finite_diff::{self, derivatives_at};
use crate::kinematics::tangent::{DEFAULT_MIN_SPEED_M_S, TangentTracker};
use crate::kinematics::{KinematicsError, Truth, check_times};
use crate::math;
use crate::rotation::{EulerZyx, Rotation};
use crate::vector::Vec3;

/// Below this `|cos(pitch)|` an Euler-angle path is refused as gimbal-locked.
pub const GIMBAL_LOCK_COS_TOL: f64 = 1e-6;

/// How the attitude of a sampled path is given.
#[derive(Clone, Copy, Debug)]
pub enum SampledAttitude<'a> {
    /// z-y-x Euler angles per sample (wrapped or not).
    Euler(&'a [EulerZyx]),
    /// Quaternions `q_nb` as `[w, x, y, z]` per sample (normalised here; either sign).
    Quaternion(&'a [[f64; 4]]),
    /// Body x axis along the velocity ([`tangent`](super::tangent)).
    Tangent,
}

/// Options of [`truth_from_samples`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledOptions {
    /// Finite-difference order: 2 (MATLAB `gradient`), 4, 6 (default) or 8.
    pub order: usize,
    /// Standstill threshold for the tangent attitude, m/s.
    pub min_speed_m_s: f64,
}

impl Default for SampledOptions {
    fn default() -> Self {
        Self {
            order: finite_diff::DEFAULT_ORDER,
            min_speed_m_s: DEFAULT_MIN_SPEED_M_S,
        }
    }
}

fn check_len(field: &'static str, expected: usize, got: usize) -> Result<(), KinematicsError> {
    if expected == got {
        Ok(())
    } else {
        Err(KinematicsError::LengthMismatch {
            field,
            expected,
            got,
        })
    }
}

fn unit_wxyz(q: [f64; 4], index: usize) -> Result<[f64; 4], KinematicsError> {
    if !q.iter().all(|c| c.is_finite()) {
        return Err(KinematicsError::NotFinite {
            field: "quaternion",
            index,
        });
    }
    let n = math::sqrt(q.iter().map(|c| c * c).sum());
    if n == 0.0 {
        return Err(KinematicsError::ZeroQuaternion { index });
    }
    Ok(q.map(|c| c / n))
}

/// Truth at every sample time `t_s` from positions `position_m` (navigation frame, m) and the
/// attitude, written into `out` (same length).
///
/// # Errors
/// Non-finite inputs, times that do not increase strictly, too few samples for the order,
/// mismatched lengths, pitch at ±90° in an Euler path, zero quaternions, vertical tangent.
pub fn truth_from_samples<N: NavFrame>(
    t_s: &[f64],
    position_m: &[[f64; 3]],
    attitude: SampledAttitude<'_>,
    options: SampledOptions,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    let n = t_s.len();
    let order = options.order;
    check_len("position_m", n, position_m.len())?;
    check_len("output", n, out.len())?;
    check_times(t_s)?;
    finite_diff::check_order(order, n)?;
    if let Some(index) = position_m
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(KinematicsError::NotFinite {
            field: "position_m",
            index,
        });
    }

    for i in 0..n {
        let (v, a) = derivatives_at(t_s, i, order, |j| position_m[j]);
        out[i] = Truth {
            t_s: t_s[i],
            position_m: Vec3::from_array(position_m[i]),
            velocity_m_s: Vec3::from_array(v),
            acceleration_m_s2: Vec3::from_array(a),
            ..Truth::default()
        };
    }

    match attitude {
        SampledAttitude::Euler(e) => euler_path(t_s, e, order, out)?,
        SampledAttitude::Quaternion(q) => quaternion_path(t_s, q, order, out)?,
        SampledAttitude::Tangent => tangent_path(t_s, options, out)?,
    }
    if let Some(index) = out.iter().position(|s| !s.is_finite()) {
        return Err(KinematicsError::NotFinite {
            field: "truth",
            index,
        });
    }
    Ok(())
}

fn euler_path<N: NavFrame>(
    t_s: &[f64],
    e: &[EulerZyx],
    order: usize,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    check_len("euler_rad", t_s.len(), e.len())?;
    for (index, ei) in e.iter().enumerate() {
        if !ei.to_array().iter().all(|c| c.is_finite()) {
            return Err(KinematicsError::NotFinite {
                field: "euler_rad",
                index,
            });
        }
        if ei.is_near_gimbal_lock(GIMBAL_LOCK_COS_TOL) {
            return Err(KinematicsError::GimbalLock {
                index,
                pitch_rad: ei.pitch_rad,
            });
        }
    }
    for i in 0..t_s.len() {
        let centre = e[i].to_array();
        let local = |j: usize| {
            let ej = e[j].to_array();
            core::array::from_fn(|k| math::unwrap_near(ej[k], centre[k]))
        };
        let (d, dd) = derivatives_at(t_s, i, order, local);
        let mut euler = e[i];
        if i > 0 {
            euler.yaw_rad = math::unwrap_near(euler.yaw_rad, out[i - 1].euler.yaw_rad);
        }
        let (d, dd) = (EulerZyx::from_array(d), EulerZyx::from_array(dd));
        let s = &mut out[i];
        s.euler = euler;
        s.attitude = Rotation::from_euler(euler);
        s.omega_b_rad_s = body_rate(euler, d);
        s.alpha_b_rad_s2 = body_angular_acceleration(euler, d, dd);
    }
    Ok(())
}

fn quaternion_path<N: NavFrame>(
    t_s: &[f64],
    q: &[[f64; 4]],
    order: usize,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    check_len("quaternion", t_s.len(), q.len())?;
    for (index, qi) in q.iter().enumerate() {
        unit_wxyz(*qi, index)?;
    }
    let unit = |j: usize| unit_wxyz(q[j], j).unwrap_or([1.0, 0.0, 0.0, 0.0]);
    for i in 0..t_s.len() {
        let qi = unit(i);
        let aligned = |j: usize| {
            let qj = unit(j);
            let dot: f64 = (0..4).map(|k| qj[k] * qi[k]).sum();
            if dot < 0.0 { qj.map(|c| -c) } else { qj }
        };
        let (d, dd) = derivatives_at(t_s, i, order, aligned);
        let conj = Quaternion::new(qi[0], -qi[1], -qi[2], -qi[3]);
        let w = conj * Quaternion::new(d[0], d[1], d[2], d[3]);
        let a = conj * Quaternion::new(dd[0], dd[1], dd[2], dd[3]);
        let attitude = Rotation::<Body, N>::from_wxyz(qi).unwrap_or_default();
        let mut euler = attitude.to_euler();
        if i > 0 {
            euler.yaw_rad = math::unwrap_near(euler.yaw_rad, out[i - 1].euler.yaw_rad);
        }
        let s = &mut out[i];
        s.attitude = attitude;
        s.euler = euler;
        s.omega_b_rad_s = Vec3::new(2.0 * w.i, 2.0 * w.j, 2.0 * w.k);
        s.alpha_b_rad_s2 = Vec3::new(2.0 * a.i, 2.0 * a.j, 2.0 * a.k);
    }
    Ok(())
}

fn tangent_path<N: NavFrame>(
    t_s: &[f64],
    options: SampledOptions,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    let mut tracker = TangentTracker::new(options.min_speed_m_s);
    let mut first_valid = None;
    for (i, s) in out.iter_mut().enumerate() {
        if let Some(angles) = tracker.update(i, s.velocity_m_s.to_array(), [0.0; 3], [0.0; 3])? {
            s.euler = angles.euler;
            first_valid.get_or_insert(i);
        }
    }
    backfill_standstill(out, first_valid);
    for i in 0..t_s.len() {
        let (d, dd) = derivatives_at(t_s, i, options.order, |j| out[j].euler.to_array());
        let (d, dd) = (EulerZyx::from_array(d), EulerZyx::from_array(dd));
        let s = &mut out[i];
        s.attitude = Rotation::from_euler(s.euler);
        s.omega_b_rad_s = body_rate(s.euler, d);
        s.alpha_b_rad_s2 = body_angular_acceleration(s.euler, d, dd);
    }
    Ok(())
}

/// Gives leading standstill samples (before `first_valid`) the first valid tangent attitude.
pub fn backfill_standstill<N: NavFrame>(out: &mut [Truth<N>], first_valid: Option<usize>) {
    if let Some(first) = first_valid {
        let euler = out[first].euler;
        for s in &mut out[..first] {
            s.euler = euler;
            s.attitude = Rotation::from_euler(euler);
        }
    }
}
