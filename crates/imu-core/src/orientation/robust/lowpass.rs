//! The second-order Butterworth low-pass the robust filter smooths its signals with, for any
//! number of channels and any sample interval.
//!
//! The time constant `tau` names the filter as the robust filter's settings do: the cut-off is
//! `f_c = √2 / (2π τ)`, so the non-oscillating part of the step response decays with `τ`
//! (the convention of VQF, Laidig & Seel 2023). Discretised by the bilinear transform with the
//! cut-off pre-warped, `C = tan(π f_c Δt)`:
//! `b = (C², 2C², C²)/D`, `a₁ = 2(C² − 1)/D`, `a₂ = (1 − √2 C + C²)/D`, `D = C² + √2 C + 1`,
//! run in transposed direct form II. A time constant shorter than half the interval passes
//! the signal through.
//!
//! Start-up: for the first `τ` seconds the output is the running mean of the samples so far
//! (a filter started at its first sample would carry that sample's noise for a whole `τ`);
//! then the state is set to the steady state of that mean and filtering begins. When the
//! interval changes (real time stamps), the coefficients are recomputed and the state moved so
//! that a steady signal stays where it is.
use crate::math;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Coefficients {
    b: [f64; 3],
    a: [f64; 2],
}

impl Coefficients {
    fn new(tau_s: f64, dt_s: f64) -> Self {
        if tau_s < dt_s / 2.0 {
            return Self {
                b: [1.0, 0.0, 0.0],
                a: [0.0, 0.0],
            };
        }
        let fc = core::f64::consts::SQRT_2 / (2.0 * core::f64::consts::PI * tau_s);
        let c = math::tan(core::f64::consts::PI * fc * dt_s);
        let d = c * c + core::f64::consts::SQRT_2 * c + 1.0;
        let b0 = c * c / d;
        Self {
            b: [b0, 2.0 * b0, b0],
            a: [
                2.0 * (c * c - 1.0) / d,
                (1.0 - core::f64::consts::SQRT_2 * c + c * c) / d,
            ],
        }
    }

    /// The state that holds a constant input `y` at output `y`.
    fn steady(&self, y: f64) -> [f64; 2] {
        [y * (1.0 - self.b[0]), y * (self.b[2] - self.a[1])]
    }
}

/// A Butterworth low-pass over `N` channels (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LowPass<const N: usize> {
    tau_s: f64,
    dt_s: f64,
    coefficients: Coefficients,
    state: [[f64; 2]; N],
    /// Start-up: samples and time so far, and their sum; `None` once filtering.
    warmup: Option<(f64, f64, [f64; N])>,
    last: [f64; N],
}

impl<const N: usize> LowPass<N> {
    /// A filter with time constant `tau_s`, for samples `dt_s` apart (until told otherwise).
    pub(crate) fn new(tau_s: f64, dt_s: f64) -> Self {
        Self {
            tau_s,
            dt_s,
            coefficients: Coefficients::new(tau_s, dt_s),
            state: [[0.0; 2]; N],
            warmup: Some((0.0, 0.0, [0.0; N])),
            last: [0.0; N],
        }
    }

    /// The filter of the negated signal (a linear filter's state negated).
    pub(crate) fn negated(mut self) -> Self {
        for s in self.state.iter_mut().flatten() {
            *s = -*s;
        }
        for y in &mut self.last {
            *y = -*y;
        }
        if let Some((_, _, sum)) = self.warmup.as_mut() {
            for v in sum.iter_mut() {
                *v = -*v;
            }
        }
        self
    }

    /// Filters one sample `x` taken `dt_s` after the previous one; returns the output.
    pub(crate) fn step(&mut self, x: [f64; N], dt_s: f64) -> [f64; N] {
        if let Some((count, time, sum)) = self.warmup.as_mut() {
            *count += 1.0;
            *time += dt_s;
            for (s, v) in sum.iter_mut().zip(x) {
                *s += v;
            }
            let mean = sum.map(|s| s / *count);
            if *time >= self.tau_s {
                self.dt_s = dt_s;
                self.coefficients = Coefficients::new(self.tau_s, dt_s);
                self.state = mean.map(|y| self.coefficients.steady(y));
                self.warmup = None;
            }
            self.last = mean;
            return mean;
        }
        // Time stamps jitter in their last digits: a relative change below 1e-6 keeps the
        // coefficients (their error is then of that order too).
        if math::abs(dt_s - self.dt_s) > 1e-6 * self.dt_s {
            let new = Coefficients::new(self.tau_s, dt_s);
            let old = self.coefficients;
            for (s, y) in self.state.iter_mut().zip(self.last) {
                // Keep a steady output steady: move the state by the change of the steady state.
                let (was, is) = (old.steady(y), new.steady(y));
                s[0] += is[0] - was[0];
                s[1] += is[1] - was[1];
            }
            self.coefficients = new;
            self.dt_s = dt_s;
        }
        let Coefficients { b, a } = self.coefficients;
        for ((s, v), out) in self.state.iter_mut().zip(x).zip(self.last.iter_mut()) {
            let y = b[0] * v + s[0];
            s[0] = b[1] * v - a[0] * y + s[1];
            s[1] = b[2] * v - a[1] * y;
            *out = y;
        }
        self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_passes_and_a_step_settles_with_the_time_constant() {
        let mut f = LowPass::<1>::new(1.0, 0.01);
        for _ in 0..300 {
            assert!((f.step([2.0], 0.01)[0] - 2.0).abs() < 1e-12);
        }
        // Unit step: a second-order Butterworth with ω_c = √2/τ overshoots by 4.3 %, and its
        // error's envelope decays as e^(−t/τ) (damping ζω_c = 1/τ) — the time constant's meaning.
        let mut ys = [0.0; 1000];
        for y in &mut ys {
            *y = f.step([3.0], 0.01)[0];
        }
        let peak = ys.iter().copied().fold(f64::MIN, f64::max);
        assert!((peak - 3.0 - 0.0432).abs() < 2e-3, "overshoot {peak}");
        for t in [3.0_f64, 5.0, 8.0] {
            let k = (t / 0.01) as usize - 1;
            assert!((ys[k] - 3.0).abs() < 1.5 * (-t).exp(), "{} at {t} τ", ys[k]);
        }
    }

    #[test]
    fn the_gain_at_the_cutoff_is_one_over_root_two() {
        let tau = 0.5;
        let fc = core::f64::consts::SQRT_2 / (2.0 * core::f64::consts::PI * tau);
        let dt = 1e-3;
        let mut f = LowPass::<1>::new(tau, dt);
        let mut peak: f64 = 0.0;
        for i in 0..40_000 {
            let t = i as f64 * dt;
            let y = f.step([(2.0 * core::f64::consts::PI * fc * t).sin()], dt)[0];
            if t > 20.0 {
                peak = peak.max(y.abs());
            }
        }
        assert!(
            (peak - core::f64::consts::FRAC_1_SQRT_2).abs() < 2e-3,
            "gain {peak}"
        );
    }

    #[test]
    fn start_up_is_the_running_mean_and_a_new_interval_keeps_a_steady_output() {
        let mut f = LowPass::<2>::new(0.05, 0.01);
        assert_eq!(f.step([1.0, -1.0], 0.01), [1.0, -1.0]);
        assert_eq!(f.step([3.0, 1.0], 0.01), [2.0, 0.0]);
        for _ in 0..200 {
            f.step([5.0, 5.0], 0.01);
        }
        for dt in [0.02, 0.003, 0.01] {
            let y = f.step([5.0, 5.0], dt);
            assert!(
                (y[0] - 5.0).abs() < 1e-12 && (y[1] - 5.0).abs() < 1e-12,
                "{y:?} at {dt}"
            );
        }
    }
}
