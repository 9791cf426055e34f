//! A chain's frequency response and group delay in closed form, from the coefficients that
//! filter.
use super::FilterBuffer;
use super::Section;

/// A filter's response at one frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// `|H|`.
    pub gain: f64,
    /// `arg H`, rad (negative: the output lags).
    pub phase_rad: f64,
}

/// `Σ p_k e^{−jωk}` and `Σ k·p_k e^{−jωk}` of the polynomial `p(z⁻¹)` at `ω`.
fn evaluate(p: &[f64], omega: f64) -> ((f64, f64), (f64, f64)) {
    let (mut s, mut ks) = ((0.0, 0.0), (0.0, 0.0));
    for (k, &c) in p.iter().enumerate() {
        #[allow(clippy::cast_precision_loss)]
        let kf = k as f64;
        let (sin, cos) = crate::math::sin_cos(omega * kf);
        s.0 += c * cos;
        s.1 -= c * sin;
        ks.0 += kf * c * cos;
        ks.1 -= kf * c * sin;
    }
    (s, ks)
}

/// The response of the sections in a row at `f` cycles per sample.
pub(super) fn of_sections<B: FilterBuffer>(sections: &[Section<B>], f: f64) -> Response {
    let omega = 2.0 * core::f64::consts::PI * f;
    let (mut re, mut im) = (1.0, 0.0);
    for s in sections {
        let ((br, bi), _) = evaluate(s.numerator(), omega);
        let ((ar, ai), _) = evaluate(s.denominator(), omega);
        let d = ar * ar + ai * ai;
        let (hr, hi) = ((br * ar + bi * ai) / d, (bi * ar - br * ai) / d);
        (re, im) = (re * hr - im * hi, re * hi + im * hr);
    }
    Response {
        gain: crate::math::hypot(re, im),
        phase_rad: crate::math::atan2(im, re),
    }
}

/// The group delay of the sections in a row at `f` cycles per sample, in samples: for each
/// polynomial `p`, `τ_p = Re(Σ k p_k e^{−jωk} / Σ p_k e^{−jωk})`, and a section's delay is its
/// numerator's less its denominator's.
pub(super) fn group_delay_samples<B: FilterBuffer>(sections: &[Section<B>], f: f64) -> f64 {
    let omega = 2.0 * core::f64::consts::PI * f;
    let delay = |p: &[f64]| {
        let ((sr, si), (kr, ki)) = evaluate(p, omega);
        (kr * sr + ki * si) / (sr * sr + si * si)
    };
    sections
        .iter()
        .map(|s| delay(s.numerator()) - delay(s.denominator()))
        .sum()
}
