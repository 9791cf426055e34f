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

use nalgebra::{SMatrix, SVector};

use super::edf::overlapping_edf;
use super::scale_terms::ScaleTerm;
use crate::math;

/// The number of noise terms.
pub const TERMS: usize = 5;

/// The number of terms with a time scale ([`ScaleTerm`]).
pub const SCALE_TERMS: usize = 2;

/// Columns of the least-squares design: the five power laws and at most one of each term with
/// a time scale.
const COLUMNS: usize = TERMS + SCALE_TERMS;

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

/// From this many correlation times on, Markov noise's Allan estimates are counted as white
/// noise's (its variance is then within 20 % of the white asymptote `2σ²T_c/τ`); below, as a
/// random walk's, with fewer degrees of freedom and stronger correlation: the conservative side
/// of the transition.
const MARKOV_WHITE_FROM: f64 = 8.0;

/// Intervals of the time scale's interval at whose ends and joints the amplitude's interval is
/// taken.
const AMPLITUDE_SCALES: usize = 8;

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

type Mat = SMatrix<f64, COLUMNS, COLUMNS>;
type VecC = SVector<f64, COLUMNS>;

/// At most this many τ: cluster sizes are octaves, so 64 covers any record in memory.
pub const MAX_POINTS: usize = 64;

/// One column of the least-squares design: a power law, or a term with a time scale at a given
/// scale (its coefficient is then the amplitude squared).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Column {
    Power(NoiseTerm),
    Scaled(ScaleTerm, f64),
}

impl Column {
    /// The column's Allan variance for a unit coefficient at `tau` (`m` samples at `fs`).
    fn basis(self, tau: f64, m: usize, fs: f64) -> f64 {
        match self {
            Self::Power(t) => num_traits::Float::powi(tau, t.tau_power()),
            Self::Scaled(t, scale) => t.variance(1.0, scale, m, fs),
        }
    }

    /// The noise family whose estimates the term's resemble at `tau`: Markov noise is counted
    /// as a random walk up to [`MARKOV_WHITE_FROM`] correlation times and white beyond; a
    /// sinusoid as white (its estimates scatter less than that, so its points are weighted no
    /// more than they deserve).
    fn family(self, tau: f64) -> Family {
        match self {
            Self::Power(t) => Family::of(t),
            Self::Scaled(ScaleTerm::Markov, tc) if tau < MARKOV_WHITE_FROM * tc => {
                Family::RandomWalk
            }
            Self::Scaled(..) => Family::White,
        }
    }

    /// The rate PSD exponent whose degrees of freedom the term's estimates have at `tau` (as
    /// [`Self::family`] counts them).
    fn psd_exponent(self, tau: f64) -> i32 {
        match self {
            Self::Power(t) => t.psd_exponent(),
            Self::Scaled(ScaleTerm::Markov, tc) if tau < MARKOV_WHITE_FROM * tc => -2,
            Self::Scaled(..) => 0,
        }
    }
}

/// The curve a fit sees: τ, estimated variance, degrees of freedom, the Cholesky factor of
/// the estimates' correlation, and the design's columns at each τ.
struct Curve {
    tau: [f64; MAX_POINTS],
    var: [f64; MAX_POINTS],
    nu: [f64; MAX_POINTS],
    m: [usize; MAX_POINTS],
    len: usize,
    sample_rate_hz: f64,
    /// Each point's share of the model variance per noise family ([`Family`]).
    share: [[f64; FAMILIES]; MAX_POINTS],
    /// Lower-triangular `L` with `L·Lᵀ` the correlation matrix.
    chol: [[f64; MAX_POINTS]; MAX_POINTS],
    columns: [Column; COLUMNS],
    ncols: usize,
    /// `basis[j][i]`: column `j` at point `i`.
    basis: [[f64; MAX_POINTS]; COLUMNS],
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

/// The five power laws, as design columns.
const POWER_COLUMNS: [Column; TERMS] = [
    Column::Power(NoiseTerm::Quantization),
    Column::Power(NoiseTerm::White),
    Column::Power(NoiseTerm::BiasInstability),
    Column::Power(NoiseTerm::RandomWalk),
    Column::Power(NoiseTerm::RateRamp),
];

impl Curve {
    fn new(tau: &[f64], var: &[f64], m: &[usize], columns: &[Column]) -> Self {
        let len = tau.len();
        let mut curve = Self {
            tau: [0.0; MAX_POINTS],
            var: [0.0; MAX_POINTS],
            nu: [1.0; MAX_POINTS],
            m: [1; MAX_POINTS],
            len,
            sample_rate_hz: m[0] as f64 / tau[0],
            share: [[1.0, 0.0, 0.0]; MAX_POINTS],
            chol: [[0.0; MAX_POINTS]; MAX_POINTS],
            columns: [Column::Power(NoiseTerm::White); COLUMNS],
            ncols: 0,
            basis: [[0.0; MAX_POINTS]; COLUMNS],
        };
        curve.tau[..len].copy_from_slice(tau);
        curve.var[..len].copy_from_slice(var);
        curve.m[..len].copy_from_slice(m);
        for (k, c) in columns.iter().enumerate() {
            curve.set_column(k, *c);
        }
        curve.ncols = columns.len();
        curve.factor();
        curve
    }

    /// Puts `column` at index `k` of the design.
    fn set_column(&mut self, k: usize, column: Column) {
        self.columns[k] = column;
        for i in 0..self.len {
            self.basis[k][i] = column.basis(self.tau[i], self.m[i], self.sample_rate_hz);
        }
    }

    /// The model's variance at point `i` for coefficients `c`.
    fn model(&self, c: &VecC, i: usize) -> f64 {
        (0..self.ncols).map(|j| c[j] * self.basis[j][i]).sum()
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

/// The weighted least-squares solution on the columns in `mask` (bit `j` for column `j`), with
/// weights `w`; `None` if singular. Returns the coefficients (`scale·X²` of a power law, the
/// amplitude squared of a term with a time scale) and their covariance.
fn solve(curve: &Curve, w: &[f64], mask: u32) -> Option<Solution> {
    let active = heapless_terms::Active::of(mask);
    let k = active.len;
    if k == 0 {
        return None;
    }
    // Columns scaled to unit weighted norm, so that normal equations spanning τ⁻² … τ² stay
    // well conditioned.
    let mut norm = [0.0; COLUMNS];
    for (a, n) in active.iter().zip(norm.iter_mut()) {
        let s: f64 = (0..curve.len)
            .map(|i| w[i] * curve.basis[a][i] * curve.basis[a][i])
            .sum();
        *n = math::sqrt(s);
        if !(*n > 0.0 && n.is_finite()) {
            return None;
        }
    }
    // Rows scaled by the standard deviations, then decorrelated: columns of `L⁻¹·D⁻¹·[A y]`.
    let mut cols = [[0.0; MAX_POINTS]; COLUMNS + 1];
    for i in 0..curve.len {
        let sw = math::sqrt(w[i]);
        for (r, (a, n)) in active.iter().zip(norm).enumerate() {
            cols[r][i] = sw * curve.basis[a][i] / n;
        }
        cols[COLUMNS][i] = sw * curve.var[i];
    }
    for r in (0..k).chain(core::iter::once(COLUMNS)) {
        curve.whiten(&mut cols[r][..curve.len]);
    }
    let mut ata = Mat::zeros();
    let mut aty = VecC::zeros();
    for r in 0..k {
        aty[r] = dot(&cols[r][..curve.len], &cols[COLUMNS][..curve.len]);
        for c in 0..k {
            ata[(r, c)] = dot(&cols[r][..curve.len], &cols[c][..curve.len]);
        }
    }
    for d in k..COLUMNS {
        ata[(d, d)] = 1.0;
    }
    let chol = ata.cholesky()?;
    let sol = chol.solve(&aty);
    let inv = chol.inverse();
    let mut c = VecC::zeros();
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
            num_traits::Float::powi(cols[COLUMNS][i] - fitted, 2)
        })
        .sum();
    Some(Solution { c, cov, chi2 })
}

/// A least-squares solution: coefficients, their covariance, χ².
#[derive(Clone, Copy)]
struct Solution {
    c: VecC,
    cov: Mat,
    chi2: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The active set of columns as indices, without allocation.
mod heapless_terms {
    use super::COLUMNS;

    pub(super) struct Active {
        idx: [usize; COLUMNS],
        pub(super) len: usize,
    }

    impl Active {
        pub(super) fn of(mask: u32) -> Self {
            let mut idx = [0; COLUMNS];
            let mut len = 0;
            for j in 0..COLUMNS {
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

/// Whether every column of `mask` has a positive coefficient in `sol`.
fn non_negative(sol: &Solution, mask: u32) -> bool {
    (0..COLUMNS).all(|j| {
        mask & (1 << j) == 0 || sol.c[j].partial_cmp(&0.0) == Some(core::cmp::Ordering::Greater)
    })
}

/// The best non-negative fit for weights `w` among the subsets of the design's columns that hold
/// every column of `required`: the subset (bit `j` for column `j`) and its solution.
fn best_non_negative(curve: &Curve, w: &[f64], required: u32) -> Option<(u32, Solution)> {
    let mut best: Option<(u32, Solution)> = None;
    for mask in 1..(1u32 << curve.ncols) {
        if mask & required != required {
            continue;
        }
        let Some(sol) = solve(curve, w, mask) else {
            continue;
        };
        if !non_negative(&sol, mask) {
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
fn degrees_of_freedom(curve: &mut Curve, c: &VecC, n: usize) {
    for i in 0..curve.len {
        let tau = curve.tau[i];
        let mut parts = [0.0; COLUMNS];
        for (j, p) in parts.iter_mut().enumerate().take(curve.ncols) {
            *p = c[j].max(0.0) * curve.basis[j][i];
        }
        let dominant = (0..curve.ncols)
            .max_by(|a, b| parts[*a].total_cmp(&parts[*b]))
            .map_or(0, |j| curve.columns[j].psd_exponent(tau));
        curve.nu[i] = overlapping_edf(dominant, curve.m[i], n).unwrap_or(1.0);
        let total: f64 = parts.iter().sum();
        if total > 0.0 && total.is_finite() {
            let mut share = [0.0; FAMILIES];
            for (j, v) in parts.iter().enumerate().take(curve.ncols) {
                share[curve.columns[j].family(tau) as usize] += v / total;
            }
            curve.share[i] = share;
        }
    }
    curve.factor();
}

/// Weights `ν/(2μ²)` with `μ` the model (or the estimate, where the model is zero).
fn weights(curve: &Curve, c: Option<&VecC>, w: &mut [f64]) {
    for (i, wi) in w.iter_mut().enumerate().take(curve.len) {
        let mu = c.map_or(curve.var[i], |c| curve.model(c, i));
        let mu = if mu > 0.0 { mu } else { curve.var[i] };
        *wi = if mu > 0.0 {
            curve.nu[i] / (2.0 * mu * mu)
        } else {
            0.0
        };
    }
}

/// Reweights until the chosen columns and coefficients settle: each pass takes the degrees of
/// freedom, correlations and weights from the previous fit (the first from `start`, or from
/// white noise and the estimates themselves). The fit returned is the one made with the
/// weights left in `w`.
fn converge(
    curve: &mut Curve,
    w: &mut [f64; MAX_POINTS],
    start: Option<&VecC>,
    n: usize,
    required: u32,
) -> Option<(u32, Solution)> {
    let len = curve.len;
    match start {
        Some(c) => {
            degrees_of_freedom(curve, c, n);
            weights(curve, Some(c), w);
        }
        None => {
            let mut white = VecC::zeros();
            white[NoiseTerm::White as usize] = 1.0;
            degrees_of_freedom(curve, &white, n);
            weights(curve, None, w);
        }
    }
    let mut fit = best_non_negative(curve, &w[..len], required);
    for _ in 0..PASSES {
        let Some((_, Solution { c, .. })) = fit else {
            break;
        };
        degrees_of_freedom(curve, &c, n);
        weights(curve, Some(&c), w);
        let next = best_non_negative(curve, &w[..len], required);
        let settled = match (&next, &fit) {
            (Some(a), Some(b)) => {
                a.0 == b.0
                    && (0..COLUMNS).all(|j| math::abs(a.1.c[j] - b.1.c[j]) <= 1e-9 * b.1.c[j])
            }
            _ => true,
        };
        fit = next;
        if settled {
            break;
        }
    }
    fit
}

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
    let criterion = out.criterion;
    let mut w = [0.0; MAX_POINTS];
    let Some(mut fit) = converge(curve, &mut w, None, n, 0) else {
        out.edf = curve.nu;
        return 0;
    };
    let mut drops = [0.0; SCALE_TERMS];
    let mut required = 0u32;
    // The terms with a time scale, the better first, each kept if it pays for its parameters.
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
        let before = (fit, curve.nu, curve.share, curve.chol, w);
        curve.set_column(k, Column::Scaled(term, scale));
        let start = fit.1.c;
        let refit = converge(curve, &mut w, Some(&start), n, required | 1 << k)
            .and_then(|_| best_scale(curve, &w[..len], k, term))
            .and_then(|_| converge(curve, &mut w, Some(&start), n, required | 1 << k));
        let Some(next) = refit else {
            // Reweighted, no non-negative fit holds the term: it is not kept.
            (fit, curve.nu, curve.share, curve.chol, w) = before;
            curve.ncols -= 1;
            break;
        };
        drops[term as usize] = fit.1.chi2 - chi2;
        required |= 1 << k;
        fit = next;
    }
    let (mask, Solution { c, chi2, .. }) = fit;
    // Each term with a time scale also spends a degree of freedom on its scale.
    let parameters = mask.count_ones() + required.count_ones();
    let dof = len.saturating_sub(parameters as usize).max(1);
    // A curve the model does not describe (reduced χ² above 1) widens every interval by the
    // Birge ratio: the coefficients' covariance, and the χ² margin within which another subset
    // of terms counts as describing the curve as well, are scaled by χ²/dof (as the PDG scales
    // inconsistent measurements); a fit that describes its curve keeps them.
    let birge = (chi2 / dof as f64).max(1.0);
    let margin = CHI2_1_95 * birge;
    // Every non-negative fit that describes the curve as well as the best (χ² within the 95 %
    // point of χ² with one degree of freedom) is a candidate; each term's interval spans its
    // intervals in all of them (0 in those that leave it out), so that which terms the best fit
    // happened to pick does not narrow it.
    let (mut lower, mut upper) = ([f64::INFINITY; COLUMNS], [0.0_f64; COLUMNS]);
    for subset in 1..(1u32 << curve.ncols) {
        let Some(sol) = solve(curve, &w[..len], subset) else {
            continue;
        };
        if !non_negative(&sol, subset) || sol.chi2 > chi2 + margin {
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
        let (mut lo, mut hi) = (lower[k], upper[k]);
        // The time scale's interval: every scale whose best fit holding the term describes the
        // curve as well (χ² within the margin), found on the grid and its edges bisected. The
        // amplitude's errors correlate with the scale's, so its interval spans its intervals
        // at scales across that interval, not only at the best.
        let accepts = |curve: &mut Curve, s: f64| {
            chi2_at(curve, &w[..len], k, term, s).filter(|sol| sol.chi2 <= chi2 + margin)
        };
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
        for step in 0..=AMPLITUDE_SCALES {
            let s =
                scale_lo * math::powf(scale_hi / scale_lo, step as f64 / AMPLITUDE_SCALES as f64);
            if let Some(sol) = chi2_at(curve, &w[..len], k, term, s) {
                let (a, b) = coefficient_interval(&sol, k, birge);
                lo = lo.min(a);
                hi = hi.max(b);
            }
        }
        curve.set_column(k, Column::Scaled(term, scale));
        out.scaled[term as usize] = Some(ScaleEstimate {
            term,
            value: math::sqrt(c[k].max(0.0)),
            lower: math::sqrt(lo.max(0.0)),
            upper: math::sqrt(hi.max(c[k])),
            scale,
            scale_lower: scale_lo,
            scale_upper: scale_hi,
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
