//! A fourth-order strapdown for rate samples on any [`EarthModel`]: classical Runge–Kutta on
//! the navigation equations (see the [module](super) page), with `substeps` RK4 steps per
//! sample interval and the rates between samples taken from the quintic Lagrange polynomial
//! through the six samples around the interval (one-sided near the ends, so the interpolation
//! error, O(Δt⁶), stays below the integration error, O(Δt⁴/substeps⁴)). Errors fall as Δt⁴ on
//! smooth motion, where the coning/sculling scheme of [`increments`](super::increments) falls
//! as Δt². The quaternion is renormalised after every substep, and the specific force is
//! turned by the normalised stage quaternion.
use crate::earth::EarthModel;

use super::equations::{State, all_finite, check_initial, derivative, finish, start};
use super::{NavState, StrapdownError, StrapdownOptions, check_baro, check_lengths};

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
pub struct Rk4<E: EarthModel> {
    earth: E,
    state: State,
    options: StrapdownOptions,
    substeps: usize,
}

impl<E: EarthModel> Rk4<E> {
    /// Starts from `initial` on `earth` with `substeps` (≥ 1; 0 counts as 1) RK4 steps per
    /// interval (the coning and sculling options do not apply).
    ///
    /// # Errors
    /// A non-finite initial state, one outside the frame's domain, a baro time constant ≤ 0.
    pub fn new(
        earth: E,
        initial: &NavState<E>,
        options: StrapdownOptions,
        substeps: usize,
    ) -> Result<Self, StrapdownError> {
        check_initial(&earth, initial, &options)?;
        Ok(Self {
            earth,
            state: start(initial, options.vertical),
            options,
            substeps: substeps.max(1),
        })
    }

    /// Integrates from `w.t_s[j]` to `w.t_s[j + 1]` (`j < 5`; values finite, times increasing,
    /// checked by the callers) with the barometric height `baro_height_m` (used by
    /// [`super::VerticalChannel::Baro`] only), and returns the state there; `index` names the
    /// sample in errors.
    ///
    /// # Errors
    /// The position leaves the frame's domain ([`StrapdownError::NearPole`]) or the state
    /// stops being finite.
    pub fn interval(
        &mut self,
        w: &RateWindow,
        j: usize,
        baro_height_m: f64,
        index: usize,
    ) -> Result<NavState<E>, StrapdownError> {
        let (earth, vertical) = (&self.earth, self.options.vertical);
        let m = self.substeps;
        let h = (w.t_s[j + 1] - w.t_s[j]) / m as f64;
        let at = |x: f64| -> ([f64; 3], [f64; 3]) {
            let l = lagrange(&w.t_s, x);
            let sum = |s: &[[f64; 3]; NODES]| -> [f64; 3] {
                core::array::from_fn(|i| (0..NODES).map(|k| l[k] * s[k][i]).sum())
            };
            (sum(&w.gyro_rad_s), sum(&w.accel_m_s2))
        };
        let rate = |s: &State, w: [f64; 3], f: [f64; 3]| {
            derivative(earth, vertical, s, w, f, baro_height_m)
        };
        let mut s = self.state;
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
            let k1 = rate(&s, w0, f0);
            let k2 = rate(&s.add(&k1, 0.5 * h), wm, fm);
            let k3 = rate(&s.add(&k2, 0.5 * h), wm, fm);
            let k4 = rate(&s.add(&k3, h), w1, f1);
            s = State {
                q: s.q + (k1.q + k2.q * 2.0 + k3.q * 2.0 + k4.q) * (h / 6.0),
                v: s.v + (k1.v + k2.v * 2.0 + k3.v * 2.0 + k4.v) * (h / 6.0),
                c: core::array::from_fn(|i| {
                    s.c[i] + (k1.c[i] + 2.0 * k2.c[i] + 2.0 * k3.c[i] + k4.c[i]) * (h / 6.0)
                }),
                b: s.b + (k1.b + 2.0 * k2.b + 2.0 * k3.b + k4.b) * (h / 6.0),
            };
            s.q = s.q.normalize();
            if !earth.in_domain(&s.c) {
                return Err(StrapdownError::NearPole { index });
            }
        }
        let q = &s.q.coords;
        if !all_finite(&[q.x, q.y, q.z, q.w]) {
            return Err(StrapdownError::NotFinite { index });
        }
        let out = finish(earth, &mut s, w.t_s[j + 1], index)?;
        self.state = s;
        Ok(out)
    }
}

/// Strapdown of rate samples by RK4 (`substeps` ≥ 1 per interval) with quintic interpolation,
/// written into `out` (same length; `out[0]` is `initial` at `t_s[0]`); `baro_height_m` gives
/// the barometric height per sample for [`super::VerticalChannel::Baro`] (required then,
/// ignored otherwise). Needs at least 6 samples.
///
/// # Errors
/// Mismatched lengths, fewer than 6 samples, non-finite values, times that do not increase, a
/// position outside the frame's domain, a baro channel without heights.
#[allow(clippy::too_many_arguments)]
pub fn strapdown_rates_rk4<E: EarthModel>(
    earth: E,
    t_s: &[f64],
    gyro_rad_s: &[[f64; 3]],
    accel_m_s2: &[[f64; 3]],
    baro_height_m: Option<&[f64]>,
    initial: NavState<E>,
    options: StrapdownOptions,
    substeps: usize,
    out: &mut [NavState<E>],
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
    let baro = check_baro(n, baro_height_m, &options)?;
    if n < NODES {
        return Err(StrapdownError::LengthMismatch {
            field: "samples (RK4 needs at least 6)",
            expected: NODES,
            got: n,
        });
    }
    for i in 0..n {
        let finite = t_s[i].is_finite()
            && gyro_rad_s[i]
                .iter()
                .chain(&accel_m_s2[i])
                .all(|c| c.is_finite())
            && baro.is_none_or(|b| b[i].is_finite());
        if !finite {
            return Err(StrapdownError::NotFinite { index: i });
        }
        if i > 0 && t_s[i] <= t_s[i - 1] {
            return Err(StrapdownError::TimeNotIncreasing { index: i });
        }
    }
    let first = NavState {
        t_s: t_s[0],
        ..initial
    };
    let mut nav = Rk4::new(earth, &first, options, substeps)?;
    out[0] = first;
    for k in 0..n - 1 {
        let start = window_start(k, n);
        let window = RateWindow {
            t_s: core::array::from_fn(|j| t_s[start + j]),
            gyro_rad_s: core::array::from_fn(|j| gyro_rad_s[start + j]),
            accel_m_s2: core::array::from_fn(|j| accel_m_s2[start + j]),
        };
        let baro_k = baro.map_or(0.0, |b| b[k]);
        out[k + 1] = nav.interval(&window, k - start, baro_k, k + 1)?;
    }
    Ok(())
}
