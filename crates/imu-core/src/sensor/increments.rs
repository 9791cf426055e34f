//! Δθ/Δv increments: readings integrated over each sample interval.
//!
//! `Δ_k = ∫_{t_{k−1}}^{t_k} x dt`, by the trapezoidal rule on the readings (exact for readings
//! linear in time within an interval; error O(Δt³) per interval otherwise); `Δ_0 = 0`. Sums of
//! increments are the trapezoidal integral of the readings.

/// Increments of the 3-vector series `x` at times `t_s`, written into `out` (same length).
pub fn trapezoid(t_s: &[f64], x: &[[f64; 3]], out: &mut [[f64; 3]]) {
    let n = t_s.len().min(x.len()).min(out.len());
    if n == 0 {
        return;
    }
    out[0] = [0.0; 3];
    for k in 1..n {
        let h = 0.5 * (t_s[k] - t_s[k - 1]);
        out[k] = core::array::from_fn(|i| h * (x[k - 1][i] + x[k][i]));
    }
}
