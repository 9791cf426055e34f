//! IEEE Std 952's noise terms with a time scale of their own (Annex C): exponentially correlated
//! (first-order Markov) noise and a sinusoid. Unlike the five power laws, neither is a straight
//! line on the log–log Allan plot: each makes a hump, at τ ≈ 1.89 `T_c` and at τ ≈ 0.371/`f₀`.
//!
//! - **Markov**: a rate `x` with `ẋ = −x/T_c + w`, stationary deviation `σ` and correlation
//!   time `T_c` (one-sided rate PSD `4σ²T_c/(1 + (2πfT_c)²)`), has the Allan variance
//!   `σ²_A(τ) = 2σ²(T_c/τ)·[1 − (T_c/2τ)(3 − 4e^{−τ/T_c} + e^{−2τ/T_c})]`: a random walk
//!   `K²τ/3` with `K² = 2σ²/T_c` for `τ ≪ T_c`, white noise `N²/τ` with `N² = 2σ²T_c` for
//!   `τ ≫ T_c`.
//! - **Sinusoid**: a rate `Ω₀ sin(2πf₀t + φ)` sampled at `f_s` and averaged over clusters of `m`
//!   samples (`τ = m/f_s`), averaged over the phase, has
//!   `σ²_A = Ω₀² sin⁴(πf₀τ) / (m sin(πf₀/f_s))²`; for `f₀ ≪ f_s` this is IEEE Std 952's
//!   `Ω₀² (sin²(πf₀τ)/(πf₀τ))²`. The sampled form is used, exact up to the Nyquist frequency.

use num_traits::Float;

/// The two terms with a time scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScaleTerm {
    /// Exponentially correlated noise: amplitude its stationary deviation `σ` (rate units),
    /// scale its correlation time `T_c`, s.
    Markov,
    /// A sinusoid: amplitude its peak `Ω₀` (rate units), scale its frequency `f₀`, Hz.
    Sinusoid,
}

impl ScaleTerm {
    /// Both terms.
    pub const ALL: [Self; 2] = [Self::Markov, Self::Sinusoid];

    /// The name used in output and messages.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Markov => "markov",
            Self::Sinusoid => "sinusoid",
        }
    }

    /// The symbol printed beside the five power laws' Q, N, B, K, R.
    #[must_use]
    pub const fn symbol(self) -> &'static str {
        match self {
            Self::Markov => "M",
            Self::Sinusoid => "S",
        }
    }

    /// The name of the time scale.
    #[must_use]
    pub const fn scale_name(self) -> &'static str {
        match self {
            Self::Markov => "correlation_time_s",
            Self::Sinusoid => "frequency_hz",
        }
    }

    /// The term's Allan variance at `τ = m/f_s` for amplitude `amplitude` and time scale
    /// `scale` (correlation time, s, or frequency, Hz).
    #[must_use]
    pub fn variance(self, amplitude: f64, scale: f64, m: usize, sample_rate_hz: f64) -> f64 {
        let tau = m as f64 / sample_rate_hz;
        amplitude
            * amplitude
            * match self {
                Self::Markov => markov_shape(tau / scale),
                Self::Sinusoid => sinusoid_shape(scale, m, sample_rate_hz),
            }
    }
}

/// `σ²_A/σ²` of Markov noise at `x = τ/T_c`: `(2/x)·[1 − (3 − 4e^{−x} + e^{−2x})/(2x)]`.
///
/// Below `x = 0.5` the bracket is a difference of nearly equal numbers, so its series is summed
/// instead: `3 − 4e^{−x} + e^{−2x} = Σ_{k≥1} c_k x^k` with `c_k = ((−2)^k − 4(−1)^k)/k!`, of
/// which `c₁ = 2` cancels the 1 and `c₂ = 0`, so the shape is `−Σ_{k≥3} c_k x^{k−2}`.
#[must_use]
pub fn markov_shape(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x < 0.5 {
        // |c_k| ≤ 6·2^k/k!: thirty terms leave less than 1e-25 of the sum.
        let mut sum = 0.0;
        let mut factorial = 2.0;
        let (mut pow_m2, mut pow_m1) = (4.0, 1.0); // (−2)^k and (−1)^k at k = 2
        let mut x_pow = 1.0; // x^{k−2}
        for k in 3..=32 {
            factorial *= f64::from(k);
            pow_m2 *= -2.0;
            pow_m1 = -pow_m1;
            x_pow *= x;
            sum -= (pow_m2 - 4.0 * pow_m1) / factorial * x_pow;
        }
        return sum;
    }
    let bracket = 1.0 - (-4.0 * Float::exp_m1(-x) + Float::exp_m1(-2.0 * x)) / (2.0 * x);
    2.0 * bracket / x
}

/// `σ²_A/Ω₀²` of a sampled sinusoid of `frequency_hz`, clusters of `m` samples at
/// `sample_rate_hz`: `sin⁴(π f₀ m/f_s) / (m sin(π f₀/f_s))²` (0 at f₀ = 0, where the
/// sinusoid is a constant).
#[must_use]
pub fn sinusoid_shape(frequency_hz: f64, m: usize, sample_rate_hz: f64) -> f64 {
    let phase = core::f64::consts::PI * frequency_hz / sample_rate_hz;
    let denominator = m as f64 * Float::sin(phase);
    if denominator == 0.0 || !denominator.is_finite() {
        return 0.0;
    }
    let s = Float::sin(phase * m as f64);
    (s * s / denominator) * (s * s / denominator)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markov_series_and_closed_form_meet_at_the_switch() {
        let direct =
            |x: f64| 2.0 / x * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x));
        for x in [0.3, 0.49, 0.4999999] {
            assert!((markov_shape(x) - direct(x)).abs() < 1e-13, "{x}");
        }
        // τ ≪ T_c: K²τ/3 with K² = 2σ²/T_c, i.e. shape 2x/3; τ ≫ T_c: 2σ²T_c/τ, shape 2/x.
        assert!((markov_shape(1e-6) / (2e-6 / 3.0) - 1.0).abs() < 1e-5);
        assert!((markov_shape(1e6) / 2e-6 - 1.0).abs() < 2e-6);
    }

    #[test]
    fn sampled_sinusoid_tends_to_ieee_952_below_nyquist() {
        let (f0, fs) = (0.3, 1000.0);
        for m in [10, 300, 1000, 5000] {
            let tau = m as f64 / fs;
            let x = core::f64::consts::PI * f0 * tau;
            let ieee = (x.sin().powi(2) / x).powi(2);
            assert!((sinusoid_shape(f0, m, fs) - ieee).abs() < 1e-6 * ieee.max(1e-12));
        }
    }
}
