//! Noise terms fitted to an Allan curve, each with its uncertainty, and reported only where the
//! curve resolves it.
//!
//! The Allan variance of the five classical IMU terms adds (IEEE Std 952-1997, Annex C):
//! `σ²(τ) = 3Q²/τ² + N²/τ + (2 ln 2/π)·B² + K²τ/3 + R²τ²/2` — quantisation `Q`, white noise
//! (angle/velocity random walk) `N`, bias instability `B` (the floor of flicker noise), rate
//! random walk `K` and rate ramp `R`. The model is linear in the squares `X²`, so they are fitted
//! by generalised least squares to the estimated variances `σ̂²(τᵢ)`: each has the variance
//! `2σ⁴(τᵢ)/νᵢ` (`νᵢ` its equivalent degrees of freedom, [`super::edf`]), with `σ²` the model's own
//! value (iterated, so that the weights do not favour points that came out low), and estimates
//! at τ a ratio `r ≥ 2` apart are correlated. For white rate noise the correlation is
//! `ρ = (3/2)·r^(−3/2)` (from the estimators' weight functions in a long record: 0.53 an octave
//! apart, 0.19 two octaves apart); estimates dominated by flicker or by a random walk share more
//! of their low frequencies, `ρ = 1.4/r` and `ρ = r^(−0.29)` (measured over 200 seeded records:
//! 0.72, 0.38, 0.22 and 0.89, 0.67, 0.49 at 1, 2, 3 octaves; the random walk's as a geometric
//! decay, which keeps the matrix positive definite). Where the terms mix, each estimate's
//! fluctuation is taken as the sum of each noise's, in proportion to its share of the model's
//! variance there: `ρᵢⱼ = Σ_f √(λᵢ_f λⱼ_f)·ρ_f(τⱼ/τᵢ)`, positive definite since each `ρ_f` is.
//! Treating the estimates as independent, or as white noise's where they are not, would count
//! the same data several times and state intervals too narrow.
//! The squares are kept non-negative by choosing, among all subsets of terms, the best fit whose
//! coefficients are all positive (with five terms, that is the exact non-negative solution).
//!
//! Which terms a curve holds is itself uncertain, so each term's 95 % interval spans its
//! intervals in every non-negative fit that describes the curve about as well as the best one
//! (χ² within 3.84 of it), and is 0 at the lower end if one of those leaves the term out. A term
//! is **resolved** when that lower end is above zero. Otherwise the fit states an upper bound and
//! the record length that would resolve a term of that size with 95 % power.
//!
//! Exponentially correlated (Markov) noise and a sinusoid ([`super::scale_terms`]) are linear in
//! their amplitude squared once their time scale is fixed. Each is sought over a grid of time
//! scales (four per octave, the best refined by golden-section search) and joins the model when
//! it lowers χ² by more than `4 ln n` for `n` points: the Bayesian information criterion's
//! `ln n` for each of its two parameters, and `2 ln n` more because the scale was searched
//! (about one independent trial per point, and the largest of `n` null drops grows as
//! `2 ln n`). A term kept must also be resolved (its amplitude's interval, below, excludes
//! zero); one that is not is left out and the model fitted again. On 200 seeded records without
//! either term, none was kept. Its time scale's interval is every scale whose best fit describes
//! the curve as well (χ² within the margin below), its amplitude's spans its intervals over
//! those scales.

use super::gls::{
    Column, Curve, POWER_COLUMNS, Solution, VecC, best_non_negative, converge, degrees_of_freedom,
    non_negative, solve, weights,
};
pub use super::gls::{Family, family_correlation, octave_correlation};
use super::scale_terms::ScaleTerm;
use crate::math;

/// The number of noise terms.
pub const TERMS: usize = 5;

/// The number of terms with a time scale ([`ScaleTerm`]).
pub const SCALE_TERMS: usize = 2;

/// Columns of the least-squares design: the five power laws and at most one of each term with
/// a time scale.
pub(super) const COLUMNS: usize = TERMS + SCALE_TERMS;

/// Time scales tried per octave when a term with a time scale is sought (a golden-section
/// search then refines the best).
const SCALES_PER_OCTAVE: f64 = 4.0;

/// The two-sided 95 % point of the normal distribution.
pub const Z_95: f64 = 1.959_963_984_540_054;

/// The 95 % point of χ² with one degree of freedom (`Z_95²`).
const CHI2_1_95: f64 = Z_95 * Z_95;

/// The one-sided 95 % point: a term at the bound is resolved with this much to spare.
const Z_POWER: f64 = 1.644_853_626_951_472_6;

/// Record lengths tried when a term is not resolved: the present one doubled up to this many
/// times.
const MAX_DOUBLINGS: u32 = 24;

/// Bisections of each end of a time scale's interval (each halves its log-ratio).
const BISECTIONS: usize = 20;

/// Intervals of the time scale's interval at whose ends and joints the amplitude's interval is
/// taken.
const AMPLITUDE_SCALES: usize = 8;

/// One of the five noise terms of an Allan curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseTerm {
    /// Quantisation `Q`, units of the integral (rad, m/s): `σ² = 3Q²/τ²`.
    Quantization,
    /// White noise `N` (angle or velocity random walk), `[u]/√Hz`: `σ² = N²/τ`.
    White,
    /// Bias instability `B`, `[u]`: `σ² = (2 ln 2/π)·B²`.
    BiasInstability,
    /// Rate random walk `K`, `[u]·√Hz`: `σ² = K²τ/3`.
    RandomWalk,
    /// Rate ramp `R`, `[u]/s`: `σ² = R²τ²/2`.
    RateRamp,
}

impl NoiseTerm {
    /// The five terms, in order of the power of τ.
    pub const ALL: [Self; TERMS] = [
        Self::Quantization,
        Self::White,
        Self::BiasInstability,
        Self::RandomWalk,
        Self::RateRamp,
    ];

    /// The power of τ of the term's Allan variance.
    #[must_use]
    pub const fn tau_power(self) -> i32 {
        match self {
            Self::Quantization => -2,
            Self::White => -1,
            Self::BiasInstability => 0,
            Self::RandomWalk => 1,
            Self::RateRamp => 2,
        }
    }

    /// `c` in `σ² = c·X²·τ^p`.
    #[must_use]
    pub const fn scale(self) -> f64 {
        match self {
            Self::Quantization => 3.0,
            Self::White => 1.0,
            // 2 ln 2 / π = 0.664…² (IEEE Std 952, Annex C).
            Self::BiasInstability => {
                super::BIAS_INSTABILITY_FACTOR * super::BIAS_INSTABILITY_FACTOR
            }
            Self::RandomWalk => 1.0 / 3.0,
            Self::RateRamp => 0.5,
        }
    }

    /// Exponent α of the rate's spectral density `S(f) ∝ f^α` for the term (the rate ramp, a
    /// drift, is given the random walk's).
    #[must_use]
    pub const fn psd_exponent(self) -> i32 {
        match self {
            Self::Quantization => 2,
            Self::White => 0,
            Self::BiasInstability => -1,
            Self::RandomWalk | Self::RateRamp => -2,
        }
    }

    /// The term's Allan variance at `tau_s` for coefficient `x`.
    #[must_use]
    pub fn variance(self, x: f64, tau_s: f64) -> f64 {
        self.scale() * x * x * num_traits::Float::powi(tau_s, self.tau_power())
    }

    /// The name used in output columns and messages.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Quantization => "quantization",
            Self::White => "white_noise",
            Self::BiasInstability => "bias_instability",
            Self::RandomWalk => "random_walk",
            Self::RateRamp => "rate_ramp",
        }
    }

    /// The usual symbol (Q, N, B, K, R).
    #[must_use]
    pub const fn symbol(self) -> &'static str {
        match self {
            Self::Quantization => "Q",
            Self::White => "N",
            Self::BiasInstability => "B",
            Self::RandomWalk => "K",
            Self::RateRamp => "R",
        }
    }
}

/// One term's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermEstimate {
    /// The term.
    pub term: NoiseTerm,
    /// The fitted coefficient (0 when the term is not in the best non-negative fit).
    pub value: f64,
    /// Lower end of the 95 % interval (0 unless resolved).
    pub lower: f64,
    /// Upper end of the 95 % interval (for a term not resolved, the bound it is below).
    pub upper: f64,
    /// Whether the data resolve the term: its 95 % interval excludes zero.
    pub resolved: bool,
    /// For a term not resolved: the record length, s, that would resolve a term as large as
    /// `upper` with 95 % power (`None` when even `2^24` times the record would not, or the term is
    /// resolved).
    pub needs_record_s: Option<f64>,
}

/// A term with a time scale ([`ScaleTerm`]) that the curve supports: kept when adding it lowers
/// the fit's χ² by more than [`NoiseFit::criterion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleEstimate {
    /// The term.
    pub term: ScaleTerm,
    /// Its amplitude (Markov: stationary deviation σ; sinusoid: peak Ω₀), rate units.
    pub value: f64,
    /// Lower end of the amplitude's 95 % interval (0 when a fit without the term describes the
    /// curve about as well).
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
    /// Its time scale: the correlation time, s, or the frequency, Hz.
    pub scale: f64,
    /// Lower end of the time scale's 95 % interval.
    pub scale_lower: f64,
    /// Upper end.
    pub scale_upper: f64,
    /// How much the term lowered the fit's χ² when it was added.
    pub chi2_drop: f64,
}

impl ScaleEstimate {
    /// The term's Allan variance at `τ = m/f_s`.
    #[must_use]
    pub fn variance(&self, m: usize, sample_rate_hz: f64) -> f64 {
        self.term
            .variance(self.value, self.scale, m, sample_rate_hz)
    }
}

/// Noise terms fitted to an Allan curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseFit {
    /// The five terms, in [`NoiseTerm::ALL`] order.
    pub terms: [TermEstimate; TERMS],
    /// The terms with a time scale the curve supports, in [`ScaleTerm::ALL`] order (`None` for
    /// a term not kept).
    pub scaled: [Option<ScaleEstimate>; SCALE_TERMS],
    /// Reduced χ² of the fit (about 1 when the model, the degrees of freedom and the
    /// correlations describe the curve).
    pub reduced_chi2: f64,
    /// The information criterion a term with a time scale had to pass: the fall in χ² it must
    /// buy, `4 ln n` for `n` points (module documentation).
    pub criterion: f64,
    /// Each point's equivalent degrees of freedom, for the noise type the fit found dominant
    /// there (the first `points` entries).
    pub edf: [f64; MAX_POINTS],
    /// The number of points fitted.
    pub points: usize,
    /// The sample rate of the record, Hz (`m/τ` of the first point).
    pub sample_rate_hz: f64,
}

impl NoiseFit {
    /// The estimate of `term`.
    #[must_use]
    pub fn term(&self, term: NoiseTerm) -> &TermEstimate {
        &self.terms[term as usize]
    }

    /// The estimate of a term with a time scale, if the curve supports it.
    #[must_use]
    pub fn scaled(&self, term: ScaleTerm) -> Option<&ScaleEstimate> {
        self.scaled[term as usize].as_ref()
    }

    /// The fitted Allan variance at `tau_s` (every term at its fitted value; the sinusoid's at
    /// the nearest whole number of samples).
    #[must_use]
    pub fn variance_at(&self, tau_s: f64) -> f64 {
        let power: f64 = self
            .terms
            .iter()
            .map(|t| t.term.variance(t.value, tau_s))
            .sum();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let m = math::round(tau_s * self.sample_rate_hz).max(1.0) as usize;
        power
            + self
                .scaled
                .iter()
                .flatten()
                .map(|e| e.variance(m, self.sample_rate_hz))
                .sum::<f64>()
    }
}

/// Why a fit could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FitError {
    /// Fewer points than needed, or slices of different lengths.
    BadCurve {
        /// Points given.
        points: usize,
    },
    /// A τ, deviation or cluster size that is not finite, positive and increasing.
    BadPoint {
        /// Its index.
        index: usize,
    },
}

impl core::fmt::Display for FitError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::BadCurve { points } => write!(
                f,
                "a noise fit needs τ, deviations and cluster sizes of one length, at least one \
                 point (got {points})"
            ),
            Self::BadPoint { index } => write!(
                f,
                "point {index} of the Allan curve is not finite, non-negative and at a larger τ \
                 than the one before"
            ),
        }
    }
}

impl core::error::Error for FitError {}

/// At most this many τ: cluster sizes are octaves, so 64 covers any record in memory.
pub const MAX_POINTS: usize = 64;

/// The time scales tried for `term` on `curve`: correlation times over the curve's τ range, and
/// frequencies whose hump (at τ ≈ 0.371/f₀) lies within it, below the Nyquist frequency.
fn scale_grid(term: ScaleTerm, curve: &Curve) -> impl Iterator<Item = f64> + use<> {
    let (first, last) = (curve.tau[0], curve.tau[curve.len - 1]);
    let (lo, hi) = match term {
        ScaleTerm::Markov => (first, last),
        ScaleTerm::Sinusoid => (0.25 / last, 0.5 * curve.sample_rate_hz * (1.0 - 1e-9)),
    };
    let step = math::powf(2.0, 1.0 / SCALES_PER_OCTAVE);
    let count = if hi > lo {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let k = (num_traits::Float::log2(hi / lo) * SCALES_PER_OCTAVE) as usize;
        k + 1
    } else {
        0
    };
    (0..count).map(move |k| lo * num_traits::Float::powi(step, k as i32))
}

/// The χ² of the best non-negative fit with column `k` at `scale` (holding it), with weights `w`.
fn chi2_at(
    curve: &mut Curve,
    w: &[f64],
    k: usize,
    term: ScaleTerm,
    scale: f64,
) -> Option<Solution> {
    curve.set_column(k, Column::Scaled(term, scale));
    best_non_negative(curve, w, 1 << k).map(|(_, s)| s)
}

/// The time scale of column `k` (a `term`) that fits best with weights `w`: the best of the grid,
/// refined by a golden-section search on log scale between its neighbours. Leaves the column at
/// that scale. `None` when no non-negative fit holds the term.
fn best_scale(curve: &mut Curve, w: &[f64], k: usize, term: ScaleTerm) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    for scale in scale_grid(term, curve) {
        if let Some(sol) = chi2_at(curve, w, k, term, scale)
            && best.is_none_or(|b| sol.chi2 < b.1)
        {
            best = Some((scale, sol.chi2));
        }
    }
    let (scale, chi2) = best?;
    let step = math::powf(2.0, 1.0 / SCALES_PER_OCTAVE);
    let ln = num_traits::Float::ln;
    let (mut a, mut b) = (ln(scale / step), ln(scale * step));
    let ratio = 0.5 * (math::sqrt(5.0) - 1.0);
    let eval = |x: f64, curve: &mut Curve| {
        chi2_at(curve, w, k, term, num_traits::Float::exp(x)).map_or(f64::INFINITY, |s| s.chi2)
    };
    let (mut x1, mut x2) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut f1, mut f2) = (eval(x1, curve), eval(x2, curve));
    for _ in 0..24 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - ratio * (b - a);
            f1 = eval(x1, curve);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + ratio * (b - a);
            f2 = eval(x2, curve);
        }
    }
    let (x, f) = if f1 < f2 { (x1, f1) } else { (x2, f2) };
    let found = if f < chi2 {
        (num_traits::Float::exp(x), f)
    } else {
        (scale, chi2)
    };
    curve.set_column(k, Column::Scaled(term, found.0));
    Some(found)
}

/// Fits the five noise terms to an overlapping Allan curve: `tau_s` increasing, `adev` the
/// deviations, `m` the cluster sizes they were computed at, from `n` integrated points (the
/// record's sample count). Exponentially correlated noise and a sinusoid ([`ScaleTerm`]) join
/// the model when the curve supports them: the best time scale of each is sought, and a term is
/// kept when it lowers χ² (with the weights of the fit without it) by more than `4 ln n`
/// (module documentation); the better of the two is tried first.
///
/// # Errors
/// Slices of different lengths, empty or longer than [`MAX_POINTS`], a point that is not finite,
/// or τ not increasing by at least a factor 2. A curve of fewer points than terms resolves none.
pub fn fit_noise(tau_s: &[f64], adev: &[f64], m: &[usize], n: usize) -> Result<NoiseFit, FitError> {
    let len = tau_s.len();
    if !(1..=MAX_POINTS).contains(&len) || adev.len() != len || m.len() != len {
        return Err(FitError::BadCurve { points: len });
    }
    let mut var = [0.0; MAX_POINTS];
    for i in 0..len {
        let ok = tau_s[i].is_finite()
            && tau_s[i] > 0.0
            && adev[i].is_finite()
            && adev[i] >= 0.0
            && m[i] > 0
            && (i == 0 || (tau_s[i] >= 2.0 * tau_s[i - 1] && m[i] >= 2 * m[i - 1]));
        if !ok {
            return Err(FitError::BadPoint { index: i });
        }
        var[i] = adev[i] * adev[i];
    }
    let mut curve = Curve::new(tau_s, &var[..len], m, &POWER_COLUMNS);
    let criterion = 4.0 * num_traits::Float::ln(len.max(2) as f64);
    let unresolved = |term: NoiseTerm| TermEstimate {
        term,
        value: 0.0,
        lower: 0.0,
        upper: 0.0,
        resolved: false,
        needs_record_s: None,
    };
    let mut out = NoiseFit {
        terms: NoiseTerm::ALL.map(unresolved),
        scaled: [None; SCALE_TERMS],
        reduced_chi2: 0.0,
        criterion,
        edf: curve.nu,
        points: len,
        sample_rate_hz: curve.sample_rate_hz,
    };
    if curve.var[..len].iter().all(|v| *v == 0.0) {
        return Ok(out);
    }
    // A term with a time scale kept by the criterion but not resolved (a fit without it
    // describes the curve about as well at some scale) is left out, and the model fitted again.
    let mut excluded = 0u32;
    loop {
        curve.ncols = TERMS;
        let unresolved = fit_model(&mut curve, n, excluded, &mut out);
        if unresolved == 0 {
            return Ok(out);
        }
        excluded |= unresolved;
        out.scaled = [None; SCALE_TERMS];
    }
}

/// Fits the model to `curve` (its design reset to the five power laws), the terms with a time
/// scale in `excluded` (bit per [`ScaleTerm`]) left out, into `out`. Returns the terms with a
/// time scale it kept whose amplitude the curve does not resolve.
fn fit_model(curve: &mut Curve, n: usize, excluded: u32, out: &mut NoiseFit) -> u32 {
    let len = curve.len;
    let mut w = [0.0; MAX_POINTS];
    let Some(fit) = converge(curve, &mut w, None, n, 0) else {
        out.edf = curve.nu;
        return 0;
    };
    let (fit, required, drops) = add_scaled_terms(curve, &mut w, fit, n, excluded, out.criterion);
    let (mask, Solution { c, chi2, .. }) = fit;
    // Each term with a time scale also spends a degree of freedom on its scale.
    let parameters = mask.count_ones() + required.count_ones();
    let dof = len.saturating_sub(parameters as usize).max(1);
    // A curve the model does not describe (reduced χ² above 1) widens every interval by the
    // Birge ratio: the coefficients' covariance, and the χ² margin within which another subset
    // of terms counts as describing the curve as well, are scaled by χ²/dof (as the PDG scales
    // inconsistent measurements); a fit that describes its curve keeps them.
    let birge = (chi2 / dof as f64).max(1.0);
    let within = chi2 + CHI2_1_95 * birge;
    let (lower, mut upper) = subset_intervals(curve, &w[..len], within, birge);
    let to_x = |term: NoiseTerm, c2: f64| math::sqrt(c2.max(0.0) / term.scale());
    let sample_rate_hz = curve.sample_rate_hz;
    for (j, term) in NoiseTerm::ALL.iter().enumerate() {
        let in_fit = mask & (1 << j) != 0;
        let value = if in_fit { c[j] } else { 0.0 };
        let with = mask | (1 << j);
        let resolved = lower[j] > 0.0;
        if !resolved {
            upper[j] = curve_bound(curve, j);
        }
        out.terms[j] = TermEstimate {
            term: *term,
            value: to_x(*term, value),
            lower: if resolved { to_x(*term, lower[j]) } else { 0.0 },
            upper: to_x(*term, upper[j].max(value)),
            resolved,
            needs_record_s: if resolved {
                None
            } else {
                record_needed(curve, &c, with, j, upper[j], n, sample_rate_hz)
            },
        };
    }
    for k in TERMS..curve.ncols {
        let Column::Scaled(term, scale) = curve.columns[k] else {
            continue;
        };
        let scales = scale_interval(curve, &w[..len], k, within);
        let (lo, hi) = amplitude_interval(curve, &w[..len], k, scales, birge, (lower[k], upper[k]));
        curve.set_column(k, Column::Scaled(term, scale));
        out.scaled[term as usize] = Some(ScaleEstimate {
            term,
            value: math::sqrt(c[k].max(0.0)),
            lower: math::sqrt(lo.max(0.0)),
            upper: math::sqrt(hi.max(c[k])),
            scale,
            scale_lower: scales.0,
            scale_upper: scales.1,
            chi2_drop: drops[term as usize],
        });
    }
    out.reduced_chi2 = chi2 / dof as f64;
    out.edf = curve.nu;
    out.scaled
        .iter()
        .flatten()
        .filter(|e| e.lower <= 0.0)
        .fold(0, |bits, e| bits | 1 << e.term as u32)
}

/// Adds to the power-law fit `fit` the terms with a time scale, the better first, each kept if
/// χ² falls by more than `criterion` and a reweighted non-negative fit holds it; the terms in
/// `excluded` left out. Returns the fit, the columns it requires and each term's χ² drop.
fn add_scaled_terms(
    curve: &mut Curve,
    w: &mut [f64; MAX_POINTS],
    mut fit: (u32, Solution),
    n: usize,
    excluded: u32,
    criterion: f64,
) -> ((u32, Solution), u32, [f64; SCALE_TERMS]) {
    let len = curve.len;
    let mut drops = [0.0; SCALE_TERMS];
    let mut required = 0u32;
    while curve.ncols < COLUMNS {
        let k = curve.ncols;
        curve.ncols += 1;
        let mut best: Option<(ScaleTerm, f64, f64)> = None;
        for term in ScaleTerm::ALL {
            if excluded & (1 << term as u32) != 0
                || (TERMS..k).any(|j| matches!(curve.columns[j], Column::Scaled(t, _) if t == term))
            {
                continue;
            }
            if let Some((scale, chi2)) = best_scale(curve, &w[..len], k, term)
                && best.is_none_or(|b| chi2 < b.2)
            {
                best = Some((term, scale, chi2));
            }
        }
        let Some((term, scale, chi2)) = best.filter(|b| fit.1.chi2 - b.2 > criterion) else {
            curve.ncols -= 1;
            break;
        };
        let before = (fit, curve.nu, curve.share, curve.chol, *w);
        curve.set_column(k, Column::Scaled(term, scale));
        let start = fit.1.c;
        let refit = converge(curve, w, Some(&start), n, required | 1 << k)
            .and_then(|_| best_scale(curve, &w[..len], k, term))
            .and_then(|_| converge(curve, w, Some(&start), n, required | 1 << k));
        let Some(next) = refit else {
            // Reweighted, no non-negative fit holds the term: it is not kept.
            (fit, curve.nu, curve.share, curve.chol, *w) = before;
            curve.ncols -= 1;
            break;
        };
        drops[term as usize] = fit.1.chi2 - chi2;
        required |= 1 << k;
        fit = next;
    }
    (fit, required, drops)
}

/// Each coefficient's interval over every non-negative fit that describes the curve as well as
/// the best (χ² up to `within`, the best's plus the 95 % point of χ² with one degree of
/// freedom): it spans its intervals in all of them (0 in those that leave it out), so that which
/// terms the best fit happened to pick does not narrow it.
fn subset_intervals(
    curve: &Curve,
    w: &[f64],
    within: f64,
    birge: f64,
) -> ([f64; COLUMNS], [f64; COLUMNS]) {
    let (mut lower, mut upper) = ([f64::INFINITY; COLUMNS], [0.0_f64; COLUMNS]);
    for subset in 1..(1u32 << curve.ncols) {
        let Some(sol) = solve(curve, w, subset) else {
            continue;
        };
        if !non_negative(&sol, subset) || sol.chi2 > within {
            continue;
        }
        for j in 0..curve.ncols {
            if subset & (1 << j) != 0 {
                let (lo, hi) = coefficient_interval(&sol, j, birge);
                lower[j] = lower[j].min(lo);
                upper[j] = upper[j].max(hi);
            } else {
                lower[j] = lower[j].min(0.0);
            }
        }
    }
    (lower, upper)
}

/// The interval of column `k`'s time scale: every scale whose best fit holding the term
/// describes the curve as well (χ² up to `within`), found on the grid and its edges bisected.
fn scale_interval(curve: &mut Curve, w: &[f64], k: usize, within: f64) -> (f64, f64) {
    let Column::Scaled(term, scale) = curve.columns[k] else {
        return (0.0, 0.0);
    };
    let accepts =
        |curve: &mut Curve, s: f64| chi2_at(curve, w, k, term, s).filter(|sol| sol.chi2 <= within);
    let (mut scale_lo, mut scale_hi) = (scale, scale);
    let mut below: Option<f64> = None;
    let mut above: Option<f64> = None;
    for s in scale_grid(term, curve) {
        match accepts(curve, s) {
            Some(_) => {
                scale_lo = scale_lo.min(s);
                scale_hi = scale_hi.max(s);
            }
            None if s < scale => below = Some(s),
            None => above = above.or(Some(s)),
        }
    }
    let below = below.filter(|b| *b < scale_lo);
    let above = above.filter(|a| *a > scale_hi);
    for (inside, outside) in [(scale_lo, below), (scale_hi, above)] {
        let Some(mut outside) = outside else {
            continue;
        };
        let mut inside = inside;
        for _ in 0..BISECTIONS {
            let mid = math::sqrt(inside * outside);
            if accepts(curve, mid).is_some() {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        scale_lo = scale_lo.min(inside);
        scale_hi = scale_hi.max(inside);
    }
    (scale_lo, scale_hi)
}

/// The interval of column `k`'s amplitude (squared), from `(lo, hi)` at the best scale: its
/// errors correlate with the scale's, so it spans its intervals at scales across `scales`, not
/// only at the best.
fn amplitude_interval(
    curve: &mut Curve,
    w: &[f64],
    k: usize,
    (scale_lo, scale_hi): (f64, f64),
    birge: f64,
    (mut lo, mut hi): (f64, f64),
) -> (f64, f64) {
    let Column::Scaled(term, _) = curve.columns[k] else {
        return (lo, hi);
    };
    for step in 0..=AMPLITUDE_SCALES {
        let s = scale_lo * math::powf(scale_hi / scale_lo, step as f64 / AMPLITUDE_SCALES as f64);
        if let Some(sol) = chi2_at(curve, w, k, term, s) {
            let (a, b) = coefficient_interval(&sol, k, birge);
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    (lo, hi)
}

/// The 95 % interval of coefficient `j` of `sol` with its variance scaled by `birge`; its lower
/// end is 0 when the Wald interval reaches zero.
fn coefficient_interval(sol: &Solution, j: usize, birge: f64) -> (f64, f64) {
    let var = sol.cov[(j, j)] * birge;
    let (lo, hi) = interval(sol.c[j], var);
    let wald_lower = sol.c[j] - Z_95 * math::sqrt(var.max(0.0));
    (if wald_lower > 0.0 { lo } else { 0.0 }, hi)
}

/// The largest coefficient of column `j` the curve allows: at every τ the term alone must stay
/// below the estimate's upper confidence limit, each limit at `1 − 0.05/len` (Bonferroni) so
/// that all hold together with 95 % confidence.
fn curve_bound(curve: &Curve, j: usize) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let p = 0.05 / curve.len as f64;
    (0..curve.len)
        .filter_map(|i| {
            let nu = curve.nu[i];
            let chi = ChiSquared::new(nu).ok()?;
            let limit = nu * curve.var[i] / chi.inverse_cdf(p);
            Some(limit / curve.basis[j][i])
        })
        .fold(f64::INFINITY, f64::min)
}

/// The 95 % interval of a coefficient `c > 0` of variance `var`: its estimate is taken as
/// `c·χ²_ν/ν` with Satterthwaite's `ν = 2c²/var`, so that a term fixed by a few long-τ clusters
/// gets the skewed interval those have (the upper end far above, the lower end near, `c`).
fn interval(c: f64, var: f64) -> (f64, f64) {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let nu = 2.0 * c * c / var;
    match ChiSquared::new(nu) {
        Ok(chi) if nu.is_finite() => (
            nu * c / chi.inverse_cdf(0.975),
            nu * c / chi.inverse_cdf(0.025),
        ),
        _ => (c, c),
    }
}

/// The shortest record (the present one doubled, up to [`MAX_DOUBLINGS`] times) whose octave
/// Allan curve, if the terms were `c` (on the design of `fitted`) with column `j` at `bound`,
/// would give `j` a one-sigma no larger than `bound/(1.96 + 1.645)`: resolved with 95 % power.
fn record_needed(
    fitted: &Curve,
    c: &VecC,
    mask: u32,
    j: usize,
    bound: f64,
    n: usize,
    sample_rate_hz: f64,
) -> Option<f64> {
    if !(bound > 0.0 && sample_rate_hz > 0.0) {
        return None;
    }
    let mut truth = *c;
    truth[j] = bound;
    let columns = &fitted.columns[..fitted.ncols];
    for doubling in 1..=MAX_DOUBLINGS {
        let n_long = n.checked_mul(1usize << doubling)?;
        let mut sizes = [0usize; MAX_POINTS];
        let count = super::octave_cluster_sizes(n_long, &mut sizes);
        let mut tau = [0.0; MAX_POINTS];
        for i in 0..count {
            tau[i] = sizes[i] as f64 / sample_rate_hz;
        }
        let mut curve = Curve::new(
            &tau[..count],
            &[1.0; MAX_POINTS][..count],
            &sizes[..count],
            columns,
        );
        for i in 0..count {
            curve.var[i] = curve.model(&truth, i);
        }
        degrees_of_freedom(&mut curve, &truth, n_long);
        let mut w = [0.0; MAX_POINTS];
        weights(&curve, Some(&truth), &mut w);
        if let Some(sol) = solve(&curve, &w[..count], mask)
            && math::sqrt(sol.cov[(j, j)].max(0.0)) * (Z_95 + Z_POWER) <= bound
        {
            return Some(n_long as f64 / sample_rate_hz);
        }
    }
    None
}
