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
use num_dual::{Dual2, Dual3, DualNum, DualStruct};

use imu_core::kinematics::euler::{body_angular_acceleration, body_rate, unwrap_near};
use imu_core::kinematics::sampled::{GIMBAL_LOCK_COS_TOL, backfill_standstill};
use imu_core::kinematics::tangent::{DEFAULT_MIN_SPEED_M_S, TangentTracker};
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

/// An analytic motion: position of S (navigation frame, m) and optional Euler angles (rad).
pub trait Motion {
    /// Position `[x, y, z]` of the reference point S at time `t` (s), navigation frame, m.
    fn position<D: Scalar>(&self, t: D) -> [D; 3];
    /// z-y-x Euler angles `[yaw, pitch, roll]` (rad) at time `t`, or `None` for the tangent attitude.
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]>;
}

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
        }
    }

    /// Exact truth at time `t_s`. The second value is false for a tangent-attitude standstill
    /// before any motion (attitude then identity; batch callers backfill it).
    ///
    /// # Errors
    /// Non-finite results, gimbal lock in Euler angles, vertical tangent.
    pub fn step<N: NavFrame>(&mut self, t_s: f64) -> Result<(Truth<N>, bool), KinematicsError> {
        let index = self.index;
        self.index += 1;
        let p = self.motion.position(Dual3::new(t_s, 1.0, 0.0, 0.0));
        let part = |f: fn(&Dual3<f64>) -> f64| -> [f64; 3] { [f(&p[0]), f(&p[1]), f(&p[2])] };
        let (pos, vel, acc, jerk) = (
            part(|d| d.re()),
            part(|d| d.v1),
            part(|d| d.v2),
            part(|d| d.v3),
        );
        if !pos.iter().chain(&vel).chain(&acc).all(|c| c.is_finite()) {
            return Err(KinematicsError::NotFinite {
                field: "position_m",
                index,
            });
        }
        let mut truth = Truth::<N> {
            t_s,
            position_m: Vec3::from_array(pos),
            velocity_m_s: Vec3::from_array(vel),
            acceleration_m_s2: Vec3::from_array(acc),
            ..Truth::default()
        };
        let (euler, rate, accel) = match self.motion.euler(Dual2::new(t_s, 1.0, 0.0)) {
            Some(e) => {
                let ang = |f: fn(&Dual2<f64>) -> f64| EulerZyx::new(f(&e[0]), f(&e[1]), f(&e[2]));
                let mut euler = ang(|d| d.re());
                if !euler.to_array().iter().all(|c| c.is_finite()) {
                    return Err(KinematicsError::NotFinite {
                        field: "euler_rad",
                        index,
                    });
                }
                if euler.is_near_gimbal_lock(GIMBAL_LOCK_COS_TOL) {
                    return Err(KinematicsError::GimbalLock {
                        index,
                        pitch_rad: euler.pitch_rad,
                    });
                }
                if let Some(last) = self.last_yaw {
                    euler.yaw_rad = unwrap_near(euler.yaw_rad, last);
                }
                self.last_yaw = Some(euler.yaw_rad);
                (euler, ang(|d| d.v1), ang(|d| d.v2))
            }
            None => match self.tracker.update(index, vel, acc, jerk)? {
                Some(a) => (a.euler, a.rate, a.accel),
                None => return Ok((truth, false)),
            },
        };
        truth.euler = euler;
        truth.attitude = Rotation::from_euler(euler);
        truth.omega_b_rad_s = body_rate(euler, rate);
        truth.alpha_b_rad_s2 = body_angular_acceleration(euler, rate, accel);
        if !truth.is_finite() {
            return Err(KinematicsError::NotFinite {
                field: "truth",
                index,
            });
        }
        Ok((truth, true))
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
    for (i, (&t, slot)) in t_s.iter().zip(out.iter_mut()).enumerate() {
        let (truth, valid) = stepper.step(t)?;
        *slot = truth;
        if valid {
            first_valid.get_or_insert(i);
        }
    }
    backfill_standstill(out, first_valid);
    Ok(())
}
