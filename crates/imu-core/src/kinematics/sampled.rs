//! Truth kinematics from sampled positions and attitudes, by finite differences
//! ([`finite_diff`]), writing into a slice the caller owns.
//!
//! Attitude derivatives never difference raw wrapped angles: Euler angles are unwrapped locally
//! around each evaluation point, and quaternions are sign-aligned locally, then
//! `ω_b = 2·vec(q* ⊗ q̇)` and `α_b = 2·vec(q* ⊗ q̈)` (the `q̇*⊗q̇` term of the latter is a real
//! number and drops out of the vector part).
use nalgebra::Quaternion;

use crate::frame::Body;
use crate::kinematics::finite_diff::{self, Stencils};
use crate::kinematics::tangent::{DEFAULT_MIN_SPEED_M_S, TangentTracker};
use crate::kinematics::{KinematicsError, Truth, check_times};
use crate::math;
use crate::nav_frame::NavFrame;
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

/// Checks sampled inputs as [`truth_from_samples`] does, first problem first: lengths, order,
/// times, positions, then the attitude (finite values, gimbal lock, zero quaternions).
///
/// # Errors
/// As [`truth_from_samples`], except the checks on the results.
pub fn check_samples(
    t_s: &[f64],
    position_m: &[[f64; 3]],
    attitude: SampledAttitude<'_>,
    options: SampledOptions,
) -> Result<(), KinematicsError> {
    let n = t_s.len();
    check_len("position_m", n, position_m.len())?;
    check_times(t_s)?;
    finite_diff::check_order(options.order, n)?;
    if let Some(index) = position_m
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(KinematicsError::NotFinite {
            field: "position_m",
            index,
        });
    }
    match attitude {
        SampledAttitude::Euler(e) => {
            check_len("euler_rad", n, e.len())?;
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
        }
        SampledAttitude::Quaternion(q) => {
            check_len("quaternion", n, q.len())?;
            for (index, qi) in q.iter().enumerate() {
                unit_wxyz(*qi, index)?;
            }
        }
        SampledAttitude::Tangent => {}
    }
    Ok(())
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
    check_len("position_m", t_s.len(), position_m.len())?;
    check_len("output", t_s.len(), out.len())?;
    check_samples(t_s, position_m, attitude, options)?;
    match attitude {
        SampledAttitude::Tangent => {
            let mut stencils = Stencils::new();
            translation(t_s, position_m, options.order, 0, out, &mut stencils);
            tangent_path(t_s, options, out, &mut stencils)?;
            check_results(out, 0)
        }
        _ => fill_range(t_s, position_m, attitude, options.order, 0, None, out),
    }
}

/// [`truth_from_samples`] for the samples `start .. start + out.len()` only, so that a long
/// series can be turned into truth chunk by chunk with a fixed buffer (Euler or quaternion
/// attitude; the tangent attitude needs the whole series). The inputs must have passed
/// [`check_samples`]; `previous_yaw_rad` is the yaw written for sample `start − 1`, which the
/// yaw is unwrapped against (`None` for the first chunk). The numbers equal those of the whole
/// call.
///
/// # Errors
/// [`KinematicsError::NeedsWholeSeries`] for the tangent attitude, a range past the end, and
/// non-finite results.
pub fn truth_range<N: NavFrame>(
    t_s: &[f64],
    position_m: &[[f64; 3]],
    attitude: SampledAttitude<'_>,
    options: SampledOptions,
    start: usize,
    previous_yaw_rad: Option<f64>,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    if matches!(attitude, SampledAttitude::Tangent) {
        return Err(KinematicsError::NeedsWholeSeries);
    }
    let end = start.saturating_add(out.len());
    if end > t_s.len() || position_m.len() != t_s.len() {
        return Err(KinematicsError::LengthMismatch {
            field: "output range",
            expected: t_s.len(),
            got: end,
        });
    }
    fill_range(
        t_s,
        position_m,
        attitude,
        options.order,
        start,
        previous_yaw_rad,
        out,
    )
}

/// Position, velocity and acceleration of samples `start ..` into `out`.
fn translation<N: NavFrame>(
    t_s: &[f64],
    position_m: &[[f64; 3]],
    order: usize,
    start: usize,
    out: &mut [Truth<N>],
    stencils: &mut Stencils,
) {
    for (k, s) in out.iter_mut().enumerate() {
        let i = start + k;
        let (v, a) = stencils.derivatives_at(t_s, i, order, |j| position_m[j]);
        *s = Truth {
            t_s: t_s[i],
            position_m: Vec3::from_array(position_m[i]),
            velocity_m_s: Vec3::from_array(v),
            acceleration_m_s2: Vec3::from_array(a),
            ..Truth::default()
        };
    }
}

/// Translation and pointwise attitude (Euler or quaternion) of samples `start ..`.
fn fill_range<N: NavFrame>(
    t_s: &[f64],
    position_m: &[[f64; 3]],
    attitude: SampledAttitude<'_>,
    order: usize,
    start: usize,
    previous_yaw_rad: Option<f64>,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    let mut stencils = Stencils::new();
    translation(t_s, position_m, order, start, out, &mut stencils);
    let mut previous = previous_yaw_rad;
    for (k, s) in out.iter_mut().enumerate() {
        let i = start + k;
        match attitude {
            SampledAttitude::Euler(e) => euler_at(t_s, e, order, i, previous, s, &mut stencils),
            SampledAttitude::Quaternion(q) => {
                quaternion_at(t_s, q, order, i, previous, s, &mut stencils);
            }
            SampledAttitude::Tangent => return Err(KinematicsError::NeedsWholeSeries),
        }
        previous = Some(s.euler.yaw_rad);
    }
    check_results(out, start)
}

/// Refuses non-finite results, naming the sample.
fn check_results<N: NavFrame>(out: &[Truth<N>], start: usize) -> Result<(), KinematicsError> {
    match out.iter().position(|s| !s.is_finite()) {
        Some(k) => Err(KinematicsError::NotFinite {
            field: "truth",
            index: start + k,
        }),
        None => Ok(()),
    }
}

/// Attitude, body rate and angular acceleration of sample `i` of an Euler path (checked).
fn euler_at<N: NavFrame>(
    t_s: &[f64],
    e: &[EulerZyx],
    order: usize,
    i: usize,
    previous_yaw: Option<f64>,
    s: &mut Truth<N>,
    stencils: &mut Stencils,
) {
    let centre = e[i].to_array();
    let local = |j: usize| {
        let ej = e[j].to_array();
        core::array::from_fn(|k| math::unwrap_near(ej[k], centre[k]))
    };
    let (d, dd) = stencils.derivatives_at(t_s, i, order, local);
    let mut euler = e[i];
    if let Some(y) = previous_yaw {
        euler.yaw_rad = math::unwrap_near(euler.yaw_rad, y);
    }
    let (d, dd) = (EulerZyx::from_array(d), EulerZyx::from_array(dd));
    s.set_euler_motion(euler, d, dd);
}

/// Attitude, body rate and angular acceleration of sample `i` of a quaternion path (checked).
fn quaternion_at<N: NavFrame>(
    t_s: &[f64],
    q: &[[f64; 4]],
    order: usize,
    i: usize,
    previous_yaw: Option<f64>,
    s: &mut Truth<N>,
    stencils: &mut Stencils,
) {
    let unit = |j: usize| unit_wxyz(q[j], j).unwrap_or([1.0, 0.0, 0.0, 0.0]);
    let qi = unit(i);
    let aligned = |j: usize| {
        let qj = unit(j);
        let dot: f64 = (0..4).map(|k| qj[k] * qi[k]).sum();
        if dot < 0.0 { qj.map(|c| -c) } else { qj }
    };
    let (d, dd) = stencils.derivatives_at(t_s, i, order, aligned);
    let conj = Quaternion::new(qi[0], -qi[1], -qi[2], -qi[3]);
    let w = conj * Quaternion::new(d[0], d[1], d[2], d[3]);
    let a = conj * Quaternion::new(dd[0], dd[1], dd[2], dd[3]);
    let attitude = Rotation::<Body, N>::from_wxyz(qi).unwrap_or_default();
    let mut euler = attitude.to_euler();
    if let Some(y) = previous_yaw {
        euler.yaw_rad = math::unwrap_near(euler.yaw_rad, y);
    }
    s.attitude = attitude;
    s.euler = euler;
    s.omega_b_rad_s = Vec3::new(2.0 * w.i, 2.0 * w.j, 2.0 * w.k);
    s.alpha_b_rad_s2 = Vec3::new(2.0 * a.i, 2.0 * a.j, 2.0 * a.k);
}

fn tangent_path<N: NavFrame>(
    t_s: &[f64],
    options: SampledOptions,
    out: &mut [Truth<N>],
    stencils: &mut Stencils,
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
        let (d, dd) = stencils.derivatives_at(t_s, i, options.order, |j| out[j].euler.to_array());
        let (d, dd) = (EulerZyx::from_array(d), EulerZyx::from_array(dd));
        let s = &mut out[i];
        s.set_euler_motion(s.euler, d, dd);
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
