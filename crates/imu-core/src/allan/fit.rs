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

use nalgebra::{SMatrix, SVector};

use super::edf::overlapping_edf;
use crate::math;

/// The number of noise terms.
pub const TERMS: usize = 5;

/// The two-sided 95 % point of the normal distribution.
pub const Z_95: f64 = 1.959_963_984_540_054;

/// The 95 % point of χ² with one degree of freedom (`Z_95²`).
const CHI2_1_95: f64 = Z_95 * Z_95;

/// The one-sided 95 % point: a term at the bound is resolved with this much to spare.
const Z_POWER: f64 = 1.644_853_626_951_472_6;

/// Record lengths tried when a term is not resolved: the present one doubled up to this many
/// times.
const MAX_DOUBLINGS: u32 = 24;

/// Passes of reweighting (and of choosing each point's noise type for its degrees of freedom).
const PASSES: usize = 12;

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

/// Noise terms fitted to an Allan curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseFit {
    /// The five terms, in [`NoiseTerm::ALL`] order.
    pub terms: [TermEstimate; TERMS],
    /// Reduced χ² of the fit (about 1 when the five-term model, the degrees of freedom and the
    /// correlations describe the curve).
    pub reduced_chi2: f64,
    /// Each point's equivalent degrees of freedom, for the noise type the fit found dominant
    /// there (the first `points` entries).
    pub edf: [f64; MAX_POINTS],
    /// The number of points fitted.
    pub points: usize,
}

impl NoiseFit {
    /// The estimate of `term`.
    #[must_use]
    pub fn term(&self, term: NoiseTerm) -> &TermEstimate {
        &self.terms[term as usize]
    }

    /// The fitted Allan variance at `tau_s` (every term at its fitted value).
    #[must_use]
    pub fn variance_at(&self, tau_s: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| t.term.variance(t.value, tau_s))
            .sum()
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

type Mat = SMatrix<f64, TERMS, TERMS>;
type Vec5 = SVector<f64, TERMS>;

/// At most this many τ: cluster sizes are octaves, so 64 covers any record in memory.
pub const MAX_POINTS: usize = 64;

/// The curve a fit sees: τ, estimated variance, degrees of freedom, and the Cholesky factor of
/// the estimates' correlation.
struct Curve {
    tau: [f64; MAX_POINTS],
    var: [f64; MAX_POINTS],
    nu: [f64; MAX_POINTS],
    len: usize,
    /// Each point's share of the model variance per noise family ([`Family`]).
    share: [[f64; FAMILIES]; MAX_POINTS],
    /// Lower-triangular `L` with `L·Lᵀ` the correlation matrix.
    chol: [[f64; MAX_POINTS]; MAX_POINTS],
}

/// How many noise families the correlation of the estimates distinguishes.
const FAMILIES: usize = 3;

/// Noise families whose Allan estimates correlate alike across τ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// White rate noise, and quantisation.
    White,
    /// Flicker (bias instability).
    Flicker,
    /// Random walk, and the rate ramp.
    RandomWalk,
}

impl Family {
    const ALL: [Self; FAMILIES] = [Self::White, Self::Flicker, Self::RandomWalk];

    /// The family of a term.
    #[must_use]
    pub const fn of(term: NoiseTerm) -> Self {
        match term {
            NoiseTerm::Quantization | NoiseTerm::White => Self::White,
            NoiseTerm::BiasInstability => Self::Flicker,
            NoiseTerm::RandomWalk | NoiseTerm::RateRamp => Self::RandomWalk,
        }
    }
}

/// Correlation of overlapping Allan variance estimates of white rate noise at τ a ratio `r ≥ 2`
/// apart.
#[must_use]
pub fn octave_correlation(r: f64) -> f64 {
    family_correlation(Family::White, r)
}

/// Correlation of overlapping Allan variance estimates at τ a ratio `r ≥ 2` apart, for noise of
/// `family` (module documentation).
#[must_use]
pub fn family_correlation(family: Family, r: f64) -> f64 {
    match family {
        Family::White => 1.5 / (r * math::sqrt(r)),
        Family::Flicker => 1.4 / r,
        Family::RandomWalk => math::powf(r, -0.29),
    }
}

impl Curve {
    fn new(tau: &[f64], var: &[f64]) -> Self {
        let len = tau.len();
        let mut curve = Self {
            tau: [0.0; MAX_POINTS],
            var: [0.0; MAX_POINTS],
            nu: [1.0; MAX_POINTS],
            len,
            share: [[1.0, 0.0, 0.0]; MAX_POINTS],
            chol: [[0.0; MAX_POINTS]; MAX_POINTS],
        };
        curve.tau[..len].copy_from_slice(tau);
        curve.var[..len].copy_from_slice(var);
        curve.factor();
        curve
    }

    /// The Cholesky factor of the estimates' correlation for the present shares (positive
    /// definite for ratios ≥ 2: each family's symbol 1 + 2Σρ_k cos kω stays above 0.06).
    fn factor(&mut self) {
        for i in 0..self.len {
            for j in 0..=i {
                let rho = if i == j {
                    1.0
                } else {
                    let r = self.tau[i] / self.tau[j];
                    Family::ALL
                        .iter()
                        .enumerate()
                        .map(|(f, family)| {
                            math::sqrt(self.share[i][f] * self.share[j][f])
                                * family_correlation(*family, r)
                        })
                        .sum()
                };
                let sum: f64 = (0..j).map(|k| self.chol[i][k] * self.chol[j][k]).sum();
                if i == j {
                    self.chol[i][i] = math::sqrt((rho - sum).max(1e-12));
                } else {
                    self.chol[i][j] = (rho - sum) / self.chol[j][j];
                }
            }
        }
    }

    /// Solves `L·x = b` in place (forward substitution).
    fn whiten(&self, b: &mut [f64]) {
        for i in 0..self.len {
            let sum: f64 = (0..i).map(|k| self.chol[i][k] * b[k]).sum();
            b[i] = (b[i] - sum) / self.chol[i][i];
        }
    }
}

/// The weighted least-squares solution on the terms in `mask` (bit `j` for term `j`), with
/// weights `w`; `None` if singular. Returns coefficients of the squares (`scale·X²`, scaled back)
/// and their covariance.
fn solve(curve: &Curve, w: &[f64], mask: u32) -> Option<Solution> {
    let active: heapless_terms::Active = heapless_terms::Active::of(mask);
    let k = active.len;
    if k == 0 {
        return None;
    }
    // Columns τ^p scaled to unit weighted norm, so that normal equations spanning τ⁻² … τ² stay
    // well conditioned.
    let mut norm = [0.0; TERMS];
    for (a, n) in active.iter().zip(norm.iter_mut()) {
        let p = NoiseTerm::ALL[a].tau_power();
        let s: f64 = (0..curve.len)
            .map(|i| w[i] * num_traits::Float::powi(num_traits::Float::powi(curve.tau[i], p), 2))
            .sum();
        *n = math::sqrt(s);
        if !(*n > 0.0 && n.is_finite()) {
            return None;
        }
    }
    // Rows scaled by the standard deviations, then decorrelated: columns of `L⁻¹·D⁻¹·[A y]`.
    let mut cols = [[0.0; MAX_POINTS]; TERMS + 1];
    for i in 0..curve.len {
        let sw = math::sqrt(w[i]);
        for (r, (a, n)) in active.iter().zip(norm).enumerate() {
            cols[r][i] =
                sw * num_traits::Float::powi(curve.tau[i], NoiseTerm::ALL[a].tau_power()) / n;
        }
        cols[TERMS][i] = sw * curve.var[i];
    }
    for r in (0..k).chain(core::iter::once(TERMS)) {
        curve.whiten(&mut cols[r][..curve.len]);
    }
    let mut ata = Mat::zeros();
    let mut aty = Vec5::zeros();
    for r in 0..k {
        aty[r] = dot(&cols[r][..curve.len], &cols[TERMS][..curve.len]);
        for c in 0..k {
            ata[(r, c)] = dot(&cols[r][..curve.len], &cols[c][..curve.len]);
        }
    }
    for d in k..TERMS {
        ata[(d, d)] = 1.0;
    }
    let chol = ata.cholesky()?;
    let sol = chol.solve(&aty);
    let inv = chol.inverse();
    let mut c = Vec5::zeros();
    let mut cov = Mat::zeros();
    for (r, (a, n)) in active.iter().zip(norm).enumerate() {
        c[a] = sol[r] / n;
        for (q, (b, m)) in active.iter().zip(norm).enumerate() {
            cov[(a, b)] = inv[(r, q)] / (n * m);
        }
    }
    // χ² of the decorrelated residuals.
    let chi2 = (0..curve.len)
        .map(|i| {
            let fitted: f64 = (0..k).map(|r| cols[r][i] * sol[r]).sum();
            num_traits::Float::powi(cols[TERMS][i] - fitted, 2)
        })
        .sum();
    Some(Solution { c, cov, chi2 })
}

/// A least-squares solution: coefficients of the squares, their covariance, χ².
struct Solution {
    c: Vec5,
    cov: Mat,
    chi2: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The active set of terms as indices, without allocation.
mod heapless_terms {
    use super::TERMS;

    pub(super) struct Active {
        idx: [usize; TERMS],
        pub(super) len: usize,
    }

    impl Active {
        pub(super) fn of(mask: u32) -> Self {
            let mut idx = [0; TERMS];
            let mut len = 0;
            for j in 0..TERMS {
                if mask & (1 << j) != 0 {
                    idx[len] = j;
                    len += 1;
                }
            }
            Self { idx, len }
        }

        pub(super) fn iter(&self) -> impl Iterator<Item = usize> + '_ {
            self.idx[..self.len].iter().copied()
        }
    }
}

fn model(c: &Vec5, tau: f64) -> f64 {
    NoiseTerm::ALL
        .iter()
        .enumerate()
        .map(|(j, t)| c[j] * num_traits::Float::powi(tau, t.tau_power()))
        .sum()
}

/// The best non-negative fit for weights `w`: the subset of terms (bit `j` for term `j`) and
/// its solution.
fn best_non_negative(curve: &Curve, w: &[f64]) -> Option<(u32, Solution)> {
    let mut best: Option<(u32, Solution)> = None;
    for mask in 1..(1u32 << TERMS) {
        let Some(sol) = solve(curve, w, mask) else {
            continue;
        };
        if (0..TERMS).any(|j| {
            mask & (1 << j) != 0 && sol.c[j].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater)
        }) {
            continue;
        }
        if best.as_ref().is_none_or(|b| sol.chi2 < b.1.chi2) {
            best = Some((mask, sol));
        }
    }
    best
}

/// The degrees of freedom of each point for the term that dominates the model there, and the
/// estimates' correlation for the terms' shares of the model at each point.
fn degrees_of_freedom(curve: &mut Curve, c: &Vec5, m: &[usize], n: usize) {
    for (i, &mi) in m.iter().enumerate().take(curve.len) {
        let tau = curve.tau[i];
        let parts = NoiseTerm::ALL
            .map(|t| c[t as usize].max(0.0) * num_traits::Float::powi(tau, t.tau_power()));
        let dominant = NoiseTerm::ALL
            .iter()
            .zip(parts)
            .max_by(|(_, a), (_, b)| a.total_cmp(b))
            .map_or(NoiseTerm::White, |(t, _)| *t);
        curve.nu[i] = overlapping_edf(dominant.psd_exponent(), mi, n).unwrap_or(1.0);
        let total: f64 = parts.iter().sum();
        if total > 0.0 && total.is_finite() {
            let mut share = [0.0; FAMILIES];
            for (t, v) in NoiseTerm::ALL.iter().zip(parts) {
                share[Family::of(*t) as usize] += v / total;
            }
            curve.share[i] = share;
        }
    }
    curve.factor();
}

/// Weights `ν/(2μ²)` with `μ` the model (or the estimate, where the model is zero).
fn weights(curve: &Curve, c: Option<&Vec5>, w: &mut [f64]) {
    for (i, wi) in w.iter_mut().enumerate().take(curve.len) {
        let mu = c.map_or(curve.var[i], |c| model(c, curve.tau[i]));
        let mu = if mu > 0.0 { mu } else { curve.var[i] };
        *wi = if mu > 0.0 {
            curve.nu[i] / (2.0 * mu * mu)
        } else {
            0.0
        };
    }
}

/// Fits the five noise terms to an overlapping Allan curve: `tau_s` increasing, `adev` the
/// deviations, `m` the cluster sizes they were computed at, from `n` integrated points (the
/// record's sample count).
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
    let mut curve = Curve::new(tau_s, &var[..len]);
    let unresolved = |term: NoiseTerm| TermEstimate {
        term,
        value: 0.0,
        lower: 0.0,
        upper: 0.0,
        resolved: false,
        needs_record_s: None,
    };
    let mut terms = NoiseTerm::ALL.map(unresolved);
    if curve.var[..len].iter().all(|v| *v == 0.0) {
        return Ok(NoiseFit {
            terms,
            reduced_chi2: 0.0,
            edf: curve.nu,
            points: len,
        });
    }
    // Start from white-noise degrees of freedom and the estimates as their own variances.
    let white = {
        let mut c = Vec5::zeros();
        c[NoiseTerm::White as usize] = 1.0;
        c
    };
    degrees_of_freedom(&mut curve, &white, m, n);
    let mut w = [0.0; MAX_POINTS];
    weights(&curve, None, &mut w);
    let mut fit = best_non_negative(&curve, &w[..len]);
    for _ in 0..PASSES {
        let Some((_, Solution { c, .. })) = fit else {
            break;
        };
        degrees_of_freedom(&mut curve, &c, m, n);
        weights(&curve, Some(&c), &mut w);
        let next = best_non_negative(&curve, &w[..len]);
        let settled = match (&next, &fit) {
            (Some(a), Some(b)) => {
                a.0 == b.0 && (0..TERMS).all(|j| math::abs(a.1.c[j] - b.1.c[j]) <= 1e-9 * b.1.c[j])
            }
            _ => true,
        };
        fit = next;
        if settled {
            break;
        }
    }
    let Some((mask, Solution { c, chi2, .. })) = fit else {
        return Ok(NoiseFit {
            terms,
            reduced_chi2: 0.0,
            edf: curve.nu,
            points: len,
        });
    };
    let dof = len.saturating_sub(mask.count_ones() as usize).max(1);
    // A curve the model does not describe (reduced χ² above 1) widens every interval by the
    // Birge ratio: the coefficients' covariance, and the χ² margin within which another subset
    // of terms counts as describing the curve as well, are scaled by χ²/dof (as the PDG scales
    // inconsistent measurements); a fit that describes its curve keeps them.
    let birge = (chi2 / dof as f64).max(1.0);
    let to_x = |term: NoiseTerm, c2: f64| math::sqrt(c2.max(0.0) / term.scale());
    let sample_rate_hz = m[0] as f64 / tau_s[0];
    // Every non-negative fit that describes the curve as well as the best (χ² within the 95 %
    // point of χ² with one degree of freedom) is a candidate; each term's interval spans its
    // intervals in all of them (0 in those that leave it out), so that which terms the best fit
    // happened to pick does not narrow it.
    let (mut lower, mut upper) = ([f64::INFINITY; TERMS], [0.0_f64; TERMS]);
    for subset in 1..(1u32 << TERMS) {
        let Some(sol) = solve(&curve, &w[..len], subset) else {
            continue;
        };
        let in_subset = |j: usize| subset & (1 << j) != 0;
        if (0..TERMS).any(|j| {
            in_subset(j) && sol.c[j].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater)
        }) || sol.chi2 > chi2 + CHI2_1_95 * birge
        {
            continue;
        }
        for j in 0..TERMS {
            if in_subset(j) {
                let var = sol.cov[(j, j)] * birge;
                let (lo, hi) = interval(sol.c[j], var);
                let wald_lower = sol.c[j] - Z_95 * math::sqrt(var.max(0.0));
                lower[j] = lower[j].min(if wald_lower > 0.0 { lo } else { 0.0 });
                upper[j] = upper[j].max(hi);
            } else {
                lower[j] = lower[j].min(0.0);
            }
        }
    }
    for (j, term) in NoiseTerm::ALL.iter().enumerate() {
        let in_fit = mask & (1 << j) != 0;
        let value = if in_fit { c[j] } else { 0.0 };
        let with = mask | (1 << j);
        let resolved = lower[j] > 0.0;
        if !resolved {
            upper[j] = curve_bound(&curve, *term);
        }
        terms[j] = TermEstimate {
            term: *term,
            value: to_x(*term, value),
            lower: if resolved { to_x(*term, lower[j]) } else { 0.0 },
            upper: to_x(*term, upper[j].max(value)),
            resolved,
            needs_record_s: if resolved {
                None
            } else {
                record_needed(&c, with, j, upper[j], n, sample_rate_hz)
            },
        };
    }
    Ok(NoiseFit {
        terms,
        reduced_chi2: chi2 / dof as f64,
        edf: curve.nu,
        points: len,
    })
}

/// The largest `scale·X²` of `term` the curve allows: at every τ the term alone must stay below
/// the estimate's upper confidence limit, each limit at `1 − 0.05/len` (Bonferroni) so that all
/// hold together with 95 % confidence.
fn curve_bound(curve: &Curve, term: NoiseTerm) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let p = 0.05 / curve.len as f64;
    (0..curve.len)
        .filter_map(|i| {
            let nu = curve.nu[i];
            let chi = ChiSquared::new(nu).ok()?;
            let limit = nu * curve.var[i] / chi.inverse_cdf(p);
            Some(limit / num_traits::Float::powi(curve.tau[i], term.tau_power()))
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
/// Allan curve, if the terms were `c` with term `j` at `bound`, would give `j` a one-sigma no
/// larger than `bound/(1.96 + 1.645)`: resolved with 95 % power.
fn record_needed(
    c: &Vec5,
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
    for doubling in 1..=MAX_DOUBLINGS {
        let n_long = n.checked_mul(1usize << doubling)?;
        let mut sizes = [0usize; MAX_POINTS];
        let count = super::octave_cluster_sizes(n_long, &mut sizes);
        let (mut tau, mut var) = ([0.0; MAX_POINTS], [0.0; MAX_POINTS]);
        for i in 0..count {
            tau[i] = sizes[i] as f64 / sample_rate_hz;
            var[i] = model(&truth, tau[i]);
        }
        let mut curve = Curve::new(&tau[..count], &var[..count]);
        degrees_of_freedom(&mut curve, &truth, &sizes[..count], n_long);
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
