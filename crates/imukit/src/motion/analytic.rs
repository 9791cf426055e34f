//! Exact truth from analytic motions evaluated over dual numbers.
//!
//! This lives in the std layer, not in `imu-core`: `num-dual` needs the standard library, and
//! the core builds and runs without it (and without a heap). The stepper feeds the core's
//! heap-free pieces (body rate from Euler rates, the tangent-attitude tracker, the standstill
//! backfill) with exact derivatives.
//!
//! A [`Motion`] gives the position of the reference point S and, optionally, z-y-x Euler angles as
//! functions of time, generic over the scalar (any [`num_dual::DualNum`] with `f64` primitive, and
//! `f64` itself). Position is evaluated once over a third-order dual number (p, v, a and the jerk
//! that the tangent attitude's angular acceleration needs) and the angles over a second-order dual
//! number, so every derivative is exact to rounding: the counterpart of the MATLAB trajectory tool's `'sym'` option.
//!
//! ```
//! use imukit::motion::analytic::{truth_from_motion, AnalyticOptions, Motion, Scalar};
//! use imu_core::{Enu, Truth};
//!
//! /// A level circle of radius 2 m at 0.5 rad/s, nose along the path.
//! struct Circle;
//! impl Motion for Circle {
//!     fn position<D: Scalar>(&self, t: D) -> [D; 3] {
//!         let w = t * 0.5;
//!         [w.cos() * 2.0, w.sin() * 2.0, D::from(0.0)]
//!     }
//!     fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
//!         None // tangent attitude
//!     }
//! }
//! let t = [0.0, 0.1, 0.2];
//! let mut out = [Truth::<Enu>::default(); 3];
//! truth_from_motion(&Circle, &t, AnalyticOptions::default(), &mut out).unwrap();
//! assert!((out[1].omega_b_rad_s.z() - 0.5).abs() < 1e-12);
//! ```
use num_dual::{Dual2, Dual3, DualNum};

use imu_core::kinematics::euler::{EulerTrig, unwrap_near};
use imu_core::kinematics::sampled::{GIMBAL_LOCK_COS_TOL, backfill_standstill};
use imu_core::kinematics::tangent::{DEFAULT_MIN_SPEED_M_S, TangentSample, TangentTracker};
use imu_core::kinematics::{KinematicsError, Truth, check_times};
use imu_core::{EulerZyx, NavFrame, Rotation, Vec3};

/// The scalar a [`Motion`] is evaluated over: `f64` or a dual number with `f64` parts.
pub trait Scalar: DualNum<Primitive = f64> + Copy {}
impl<D: DualNum<Primitive = f64> + Copy> Scalar for D {}

/// `atan2(y, x)` over duals with derivatives that stay finite wherever the angle is defined:
/// num-dual's differentiates `atan(y/x)`, which is infinite at `x = 0` (a heading of exactly
/// 90°); this takes `atan(y/x)` or `−atan(x/y)`, whichever divides by the larger, and sets the
/// value from `f64::atan2`.
#[must_use]
pub fn atan2<D: Scalar>(y: D, x: D) -> D {
    let (yr, xr) = (y.re(), x.re());
    let branch = if xr.abs() >= yr.abs() {
        (y / x).atan()
    } else {
        -(x / y).atan()
    };
    // The value exactly `f64::atan2` (the branch's own value cancels exactly), the derivatives
    // the branch's.
    D::from(yr.atan2(xr)) + (branch - D::from(branch.re()))
}

/// A motion's exact derivatives at one time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionPoint {
    /// Per axis of the position (navigation frame): position, velocity, acceleration and jerk
    /// (m, m/s, m/s², m/s³).
    pub position: [[f64; 4]; 3],
    /// Per z-y-x Euler angle (yaw, pitch, roll): angle, rate and angular acceleration (rad,
    /// rad/s, rad/s²); `None` for the tangent attitude.
    pub euler: Option<[[f64; 3]; 3]>,
}

/// An analytic motion: position of S (navigation frame, m) and optional Euler angles (rad).
pub trait Motion {
    /// Position `[x, y, z]` of the reference point S at time `t` (s), navigation frame, m.
    fn position<D: Scalar>(&self, t: D) -> [D; 3];
    /// z-y-x Euler angles `[yaw, pitch, roll]` (rad) at time `t`, or `None` for the tangent attitude.
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]>;
    /// The derivatives at each time of `t_s` into `out` (resized to fit): by default
    /// [`dual_derivatives`], the position over a third-order and the angles over a
    /// second-order dual number, one time after another. A motion may compute the same numbers
    /// faster over the whole slice (formulas do, compiled).
    fn derivatives(&self, t_s: &[f64], out: &mut Vec<MotionPoint>)
    where
        Self: Sized,
    {
        dual_derivatives(self, t_s, out);
    }
}

/// [`Motion::derivatives`] over dual numbers, one time after another.
pub fn dual_derivatives<M: Motion>(motion: &M, t_s: &[f64], out: &mut Vec<MotionPoint>) {
    out.clear();
    out.extend(t_s.iter().map(|&t| {
        let p = motion.position(Dual3::new(t, 1.0, 0.0, 0.0));
        let euler = motion
            .euler(Dual2::new(t, 1.0, 0.0))
            .map(|e| e.map(|d| [d.re, d.v1, d.v2]));
        MotionPoint {
            position: p.map(|d| [d.re, d.v1, d.v2, d.v3]),
            euler,
        }
    }));
}

/// Times whose derivatives [`truth_from_motion`] and the streamed simulation ask a motion for
/// at once.
pub const DERIVATIVE_CHUNK: usize = 256;

/// Options of [`truth_from_motion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyticOptions {
    /// Standstill threshold for the tangent attitude, m/s.
    pub min_speed_m_s: f64,
}

impl Default for AnalyticOptions {
    fn default() -> Self {
        Self {
            min_speed_m_s: DEFAULT_MIN_SPEED_M_S,
        }
    }
}

/// Per-sample evaluation of a [`Motion`], keeping the tangent-attitude state.
#[derive(Debug)]
pub struct AnalyticStepper<'m, M> {
    motion: &'m M,
    tracker: TangentTracker,
    index: usize,
    last_yaw: Option<f64>,
    point: Vec<MotionPoint>,
    block: Block,
}

/// What [`AnalyticStepper::step_block`] keeps of each sample of a block between its passes.
#[derive(Debug, Default)]
struct Block {
    /// The tangent attitude's motion (velocity, acceleration, jerk) and its samples.
    motion: [Vec<[f64; 3]>; 3],
    tangent: Vec<TangentSample>,
    /// Angles, rates and angular accelerations (a standstill before any motion: zeros).
    euler: Vec<EulerZyx>,
    rate: Vec<EulerZyx>,
    accel: Vec<EulerZyx>,
    /// Whether the attitude is valid (false: a standstill before any motion).
    valid: Vec<bool>,
    trig: Vec<EulerTrig>,
}

impl<'m, M: Motion> AnalyticStepper<'m, M> {
    /// A stepper over `motion`.
    #[must_use]
    pub fn new(motion: &'m M, options: AnalyticOptions) -> Self {
        Self {
            motion,
            tracker: TangentTracker::new(options.min_speed_m_s),
            index: 0,
            last_yaw: None,
            point: Vec::with_capacity(1),
            block: Block::default(),
        }
    }

    /// Exact truth at time `t_s`. The second value is false for a tangent-attitude standstill
    /// before any motion (attitude then identity; batch callers backfill it).
    ///
    /// # Errors
    /// Non-finite results, gimbal lock in Euler angles, vertical tangent.
    pub fn step<N: NavFrame>(&mut self, t_s: f64) -> Result<(Truth<N>, bool), KinematicsError> {
        self.motion.derivatives(&[t_s], &mut self.point);
        let point = self.point[0];
        self.step_at(t_s, &point)
    }

    /// [`Self::step`] with the motion's derivatives at `t_s` already evaluated (by
    /// [`Motion::derivatives`], many times at once).
    ///
    /// # Errors
    /// As [`Self::step`].
    pub fn step_at<N: NavFrame>(
        &mut self,
        t_s: f64,
        point: &MotionPoint,
    ) -> Result<(Truth<N>, bool), KinematicsError> {
        let mut truth = Truth::default();
        let valid = self.step_into(t_s, point, &mut truth)?;
        Ok((truth, valid))
    }

    /// [`Self::step_at`] written into `truth` (every field set; returns whether the attitude is
    /// valid, see [`Self::step`]).
    ///
    /// # Errors
    /// As [`Self::step`].
    pub fn step_into<N: NavFrame>(
        &mut self,
        t_s: f64,
        point: &MotionPoint,
        truth: &mut Truth<N>,
    ) -> Result<bool, KinematicsError> {
        let first = self.step_block(
            &[t_s],
            core::slice::from_ref(point),
            core::slice::from_mut(truth),
        )?;
        Ok(first.is_some())
    }

    /// [`Self::step_into`] for the samples at the times `t_s` in order, with their derivatives
    /// `points`, written into `out` (the shortest of the three): returns the first sample whose
    /// attitude is valid (`None` while a tangent attitude has not yet moved; from that sample
    /// on, every attitude is valid).
    ///
    /// The angles' sines and cosines and the tangent attitude's arctangents are taken for many
    /// samples at once by the vector kernels of [`imu_core::trig`] (within
    /// [`imu_core::trig::MAX_ULP`] of the correctly rounded values); the numbers are the same
    /// however the samples are split into calls.
    ///
    /// # Errors
    /// As [`Self::step`], for the first sample in order that fails.
    pub fn step_block<N: NavFrame>(
        &mut self,
        t_s: &[f64],
        points: &[MotionPoint],
        out: &mut [Truth<N>],
    ) -> Result<Option<usize>, KinematicsError> {
        let n = t_s.len().min(points.len()).min(out.len());
        let mut first_valid = None;
        for start in (0..n).step_by(DERIVATIVE_CHUNK) {
            let end = n.min(start + DERIVATIVE_CHUNK);
            let first =
                self.step_chunk(&t_s[start..end], &points[start..end], &mut out[start..end])?;
            if first_valid.is_none() {
                first_valid = first.map(|k| start + k);
            }
        }
        Ok(first_valid)
    }

    /// [`Self::step_block`] for at most [`DERIVATIVE_CHUNK`] samples: the motion's values and
    /// angles sample by sample (checks, tangent tracker, yaw unwrapping), then the sines and
    /// cosines of every angle at once, then the attitudes, body rates and accelerations.
    fn step_chunk<N: NavFrame>(
        &mut self,
        t_s: &[f64],
        points: &[MotionPoint],
        out: &mut [Truth<N>],
    ) -> Result<Option<usize>, KinematicsError> {
        let n = t_s.len();
        let base = self.index;
        self.index += n;
        let b = &mut self.block;
        let tangent = points.first().is_some_and(|p| p.euler.is_none());
        b.euler.clear();
        b.rate.clear();
        b.accel.clear();
        b.valid.clear();
        if tangent {
            for (k, series) in b.motion.iter_mut().enumerate() {
                series.clear();
                series.extend(points.iter().map(|p| p.position.map(|axis| axis[k + 1])));
            }
            b.tangent.resize(n, TangentSample::default());
            let [v, a, j] = &b.motion;
            TangentSample::of_each(v, a, j, &mut b.tangent);
        }
        // First pass: in order, up to the first sample that fails here.
        let mut failed = None;
        for (k, (point, truth)) in points.iter().zip(out.iter_mut()).enumerate() {
            let index = base + k;
            let part = |k: usize| -> [f64; 3] { point.position.map(|axis| axis[k]) };
            let (pos, vel, acc) = (part(0), part(1), part(2));
            if !pos.iter().chain(&vel).chain(&acc).all(|c| c.is_finite()) {
                failed = Some(KinematicsError::NotFinite {
                    field: "position_m",
                    index,
                });
                break;
            }
            truth.t_s = t_s[k];
            truth.position_m = Vec3::from_array(pos);
            truth.velocity_m_s = Vec3::from_array(vel);
            truth.acceleration_m_s2 = Vec3::from_array(acc);
            let angles = match point.euler {
                Some(e) => {
                    let ang = |k: usize| EulerZyx::new(e[0][k], e[1][k], e[2][k]);
                    let mut euler = ang(0);
                    if !euler.to_array().iter().all(|c| c.is_finite()) {
                        failed = Some(KinematicsError::NotFinite {
                            field: "euler_rad",
                            index,
                        });
                        break;
                    }
                    if let Some(last) = self.last_yaw {
                        euler.yaw_rad = unwrap_near(euler.yaw_rad, last);
                    }
                    self.last_yaw = Some(euler.yaw_rad);
                    Some((euler, ang(1), ang(2)))
                }
                None => match self.tracker.update_sample(index, &b.tangent[k]) {
                    Ok(a) => a.map(|a| (a.euler, a.rate, a.accel)),
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                },
            };
            let (euler, rate, accel) = angles.unwrap_or_default();
            b.euler.push(euler);
            b.rate.push(rate);
            b.accel.push(accel);
            b.valid.push(angles.is_some());
        }
        // The sines and cosines of every angle, at once.
        let done = b.euler.len();
        b.trig.resize(done, EulerTrig::of(EulerZyx::default()));
        EulerTrig::of_each(&b.euler, &mut b.trig);
        let mut first_valid = None;
        for (k, truth) in out[..done].iter_mut().enumerate() {
            let index = base + k;
            if !b.valid[k] {
                truth.euler = EulerZyx::default();
                truth.attitude = Rotation::identity();
                truth.omega_b_rad_s = Vec3::zeros();
                truth.alpha_b_rad_s2 = Vec3::zeros();
                continue;
            }
            first_valid.get_or_insert(k);
            let trig = &b.trig[k];
            // Euler angles given by the motion may reach gimbal lock; the tangent attitude's
            // pitch is an arctangent of a nonzero horizontal speed, never ±90°.
            if !tangent && trig.pitch_roll.is_near_gimbal_lock(GIMBAL_LOCK_COS_TOL) {
                return Err(KinematicsError::GimbalLock {
                    index,
                    pitch_rad: b.euler[k].pitch_rad,
                });
            }
            truth.set_euler_motion_with(b.euler[k], trig, b.rate[k], b.accel[k]);
            if !truth.is_finite() {
                return Err(KinematicsError::NotFinite {
                    field: "truth",
                    index,
                });
            }
        }
        match failed {
            Some(e) => Err(e),
            None => Ok(first_valid),
        }
    }
}

/// Exact truth of `motion` at each of the times `t_s` (strictly increasing), written into `out`.
///
/// # Errors
/// As [`AnalyticStepper::step`], plus non-increasing times and a length mismatch.
pub fn truth_from_motion<M: Motion, N: NavFrame>(
    motion: &M,
    t_s: &[f64],
    options: AnalyticOptions,
    out: &mut [Truth<N>],
) -> Result<(), KinematicsError> {
    if out.len() != t_s.len() {
        return Err(KinematicsError::LengthMismatch {
            field: "output",
            expected: t_s.len(),
            got: out.len(),
        });
    }
    check_times(t_s)?;
    let mut stepper = AnalyticStepper::new(motion, options);
    let mut first_valid = None;
    let mut points = Vec::with_capacity(DERIVATIVE_CHUNK);
    for (c, (times, slots)) in t_s
        .chunks(DERIVATIVE_CHUNK)
        .zip(out.chunks_mut(DERIVATIVE_CHUNK))
        .enumerate()
    {
        motion.derivatives(times, &mut points);
        if let Some(k) = stepper.step_block(times, &points, slots)? {
            first_valid.get_or_insert(c * DERIVATIVE_CHUNK + k);
        }
    }
    backfill_standstill(out, first_valid);
    Ok(())
}
