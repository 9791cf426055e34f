//! A fourth-order strapdown for rate samples: classical Runge–Kutta on the navigation equations
//! `q̇ = ½ q ⊗ (0, ω_b)`, `v̇ = C_nb f_b + g_n`, `ṗ = v` (flat Earth), with `substeps` RK4 steps
//! per sample interval and the rates between samples taken from the quintic Lagrange polynomial
//! through the six samples around the interval (one-sided near the ends, so the interpolation
//! error, O(Δt⁶), stays below the integration error, O(Δt⁴/substeps⁴)). Errors fall as Δt⁴ on
//! smooth motion, where the coning/sculling scheme of [`step`](super::step) falls as Δt². The
//! quaternion is renormalised after every substep.
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::frame::NavFrame;
use crate::rotation::Rotation;
use crate::strapdown::step::{NavState, StrapdownError, check_lengths};
use crate::vector::Vec3;

type State = (Quaternion<f64>, Vector3<f64>, Vector3<f64>);

fn derivative(
    q: &Quaternion<f64>,
    v: &Vector3<f64>,
    w: [f64; 3],
    f: [f64; 3],
    g: &Vector3<f64>,
) -> State {
    let qdot = q * Quaternion::new(0.0, w[0], w[1], w[2]) * 0.5;
    let unit = UnitQuaternion::from_quaternion(*q);
    let vdot = unit * Vector3::from(f) + g;
    (qdot, vdot, *v)
}

/// Interpolation nodes per interval: the six samples around it.
pub const NODES: usize = 6;

/// Lagrange weights at `x` for the nodes `xs`.
pub(crate) fn lagrange(xs: &[f64; NODES], x: f64) -> [f64; NODES] {
    core::array::from_fn(|i| {
        (0..NODES)
            .filter(|&j| j != i)
            .fold(1.0, |acc, j| acc * (x - xs[j]) / (xs[i] - xs[j]))
    })
}

/// The first of the six samples whose quintic carries the interval from sample `k` to `k + 1`
/// in a series of `n ≥ 6` samples: two before `k`, three after `k + 1`, shifted inwards at the
/// ends.
#[must_use]
pub fn window_start(k: usize, n: usize) -> usize {
    k.saturating_sub(NODES / 2 - 1).min(n - NODES)
}

/// Six consecutive rate samples: times (s, increasing), gyroscope (rad/s) and specific force
/// (m/s², body frame).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RateWindow {
    /// Sample times, s.
    pub t_s: [f64; NODES],
    /// Body rates, rad/s.
    pub gyro_rad_s: [[f64; 3]; NODES],
    /// Specific force, m/s².
    pub accel_m_s2: [[f64; 3]; NODES],
}

/// The RK4 integrator one interval at a time (per-sample stepper; no heap): the caller hands it
/// each interval's six-sample window ([`window_start`]), so a stream needs to hold only six
/// samples. [`strapdown_rates_rk4`] is this stepper over a whole series.
#[derive(Clone, Copy, Debug)]
pub struct Rk4Strapdown<N: NavFrame> {
    q: Quaternion<f64>,
    v: Vector3<f64>,
    p: Vector3<f64>,
    g: Vector3<f64>,
    substeps: usize,
    frame: core::marker::PhantomData<N>,
}

impl<N: NavFrame> Rk4Strapdown<N> {
    /// Starts from `initial`, with `substeps` (≥ 1; 0 counts as 1) RK4 steps per interval.
    #[must_use]
    pub fn new(initial: NavState<N>, gravity_m_s2: f64, substeps: usize) -> Self {
        Self {
            q: *initial.attitude.quaternion().quaternion(),
            v: *initial.velocity_m_s.as_nalgebra(),
            p: *initial.position_m.as_nalgebra(),
            g: *N::gravity(gravity_m_s2).as_nalgebra(),
            substeps: substeps.max(1),
            frame: core::marker::PhantomData,
        }
    }

    /// Integrates from `w.t_s[j]` to `w.t_s[j + 1]` (`j < 5`) and returns the state there. The
    /// window's values must be finite and its times increasing (checked by the callers).
    pub fn interval(&mut self, w: &RateWindow, j: usize) -> NavState<N> {
        let (q, v, p, g) = (&mut self.q, &mut self.v, &mut self.p, &self.g);
        let m = self.substeps;
        let h = (w.t_s[j + 1] - w.t_s[j]) / m as f64;
        let at = |x: f64| -> ([f64; 3], [f64; 3]) {
            let l = lagrange(&w.t_s, x);
            let sum = |s: &[[f64; 3]; NODES]| -> [f64; 3] {
                core::array::from_fn(|i| (0..NODES).map(|k| l[k] * s[k][i]).sum())
            };
            (sum(&w.gyro_rad_s), sum(&w.accel_m_s2))
        };
        for step in 0..m {
            let t0 = w.t_s[j] + step as f64 * h;
            let (w0, f0) = if step == 0 {
                (w.gyro_rad_s[j], w.accel_m_s2[j])
            } else {
                at(t0)
            };
            let (wm, fm) = at(t0 + 0.5 * h);
            let (w1, f1) = if step + 1 == m {
                (w.gyro_rad_s[j + 1], w.accel_m_s2[j + 1])
            } else {
                at(t0 + h)
            };
            let k1 = derivative(q, v, w0, f0, g);
            let k2 = derivative(
                &(*q + k1.0 * (0.5 * h)),
                &(*v + k1.1 * (0.5 * h)),
                wm,
                fm,
                g,
            );
            let k3 = derivative(
                &(*q + k2.0 * (0.5 * h)),
                &(*v + k2.1 * (0.5 * h)),
                wm,
                fm,
                g,
            );
            let k4 = derivative(&(*q + k3.0 * h), &(*v + k3.1 * h), w1, f1, g);
            *q += (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0);
            *v += (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0);
            *p += (k1.2 + k2.2 * 2.0 + k3.2 * 2.0 + k4.2) * (h / 6.0);
            *q = q.normalize();
        }
        NavState {
            t_s: w.t_s[j + 1],
            attitude: Rotation::assume_from_quaternion(UnitQuaternion::new_unchecked(*q)),
            velocity_m_s: Vec3::from_nalgebra(*v),
            position_m: Vec3::from_nalgebra(*p),
        }
    }
}

/// Strapdown of rate samples by RK4 (`substeps` ≥ 1 per interval) with quintic interpolation,
/// written into `out` (same length; `out[0]` is the initial state at `t_s[0]`). Needs at least
/// 6 samples.
///
/// # Errors
/// Mismatched lengths, fewer than 6 samples, non-finite values, times that do not increase.
pub fn strapdown_rates_rk4<N: NavFrame>(
    t_s: &[f64],
    gyro_rad_s: &[[f64; 3]],
    accel_m_s2: &[[f64; 3]],
    initial: NavState<N>,
    gravity_m_s2: f64,
    substeps: usize,
    out: &mut [NavState<N>],
) -> Result<(), StrapdownError> {
    let n = t_s.len();
    check_lengths(
        n,
        &[
            ("gyro_rad_s", gyro_rad_s.len()),
            ("accel_m_s2", accel_m_s2.len()),
            ("output", out.len()),
        ],
    )?;
    if n < NODES {
        return Err(StrapdownError::LengthMismatch {
            field: "samples (RK4 needs at least 6)",
            expected: NODES,
            got: n,
        });
    }
    for i in 0..n {
        if !(t_s[i].is_finite()
            && gyro_rad_s[i]
                .iter()
                .chain(&accel_m_s2[i])
                .all(|c| c.is_finite()))
        {
            return Err(StrapdownError::NotFinite { index: i });
        }
        if i > 0 && t_s[i] <= t_s[i - 1] {
            return Err(StrapdownError::TimeNotIncreasing { index: i });
        }
    }
    let mut nav = Rk4Strapdown::new(initial, gravity_m_s2, substeps);
    out[0] = NavState {
        t_s: t_s[0],
        ..initial
    };
    for k in 0..n - 1 {
        let start = window_start(k, n);
        let window = RateWindow {
            t_s: core::array::from_fn(|j| t_s[start + j]),
            gyro_rad_s: core::array::from_fn(|j| gyro_rad_s[start + j]),
            accel_m_s2: core::array::from_fn(|j| accel_m_s2[start + j]),
        };
        out[k + 1] = nav.interval(&window, k - start);
    }
    Ok(())
}
