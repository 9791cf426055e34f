//! The weighted least-squares design an Allan fit solves: the columns (power laws and terms
//! with a time scale) at each τ, the estimates' degrees of freedom and correlation, the
//! generalised least-squares solution on a subset of columns, the best non-negative subset, and
//! the reweighting until it settles ([`super::fit`] holds the model, the search and the
//! intervals).
use nalgebra::{SMatrix, SVector};

use super::edf::overlapping_edf;
use super::fit::{COLUMNS, MAX_POINTS, NoiseTerm, TERMS};
use super::scale_terms::ScaleTerm;
use crate::math;

/// From this many correlation times on, Markov noise's Allan estimates are counted as white
/// noise's (its variance is then within 20 % of the white asymptote `2σ²T_c/τ`); below, as a
/// random walk's, with fewer degrees of freedom and stronger correlation: the conservative side
/// of the transition.
pub(super) const MARKOV_WHITE_FROM: f64 = 8.0;

/// Passes of reweighting (and of choosing each point's noise type for its degrees of freedom).
pub(super) const PASSES: usize = 12;

pub(super) type Mat = SMatrix<f64, COLUMNS, COLUMNS>;
pub(super) type VecC = SVector<f64, COLUMNS>;

/// One column of the least-squares design: a power law, or a term with a time scale at a given
/// scale (its coefficient is then the amplitude squared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Column {
    Power(NoiseTerm),
    Scaled(ScaleTerm, f64),
}

impl Column {
    /// The column's Allan variance for a unit coefficient at `tau` (`m` samples at `fs`).
    pub(super) fn basis(self, tau: f64, m: usize, fs: f64) -> f64 {
        match self {
            Self::Power(t) => num_traits::Float::powi(tau, t.tau_power()),
            Self::Scaled(t, scale) => t.variance(1.0, scale, m, fs),
        }
    }

    /// The noise family whose estimates the term's resemble at `tau`: Markov noise is counted
    /// as a random walk up to [`MARKOV_WHITE_FROM`] correlation times and white beyond; a
    /// sinusoid as white (its estimates scatter less than that, so its points are weighted no
    /// more than they deserve).
    pub(super) fn family(self, tau: f64) -> Family {
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
    pub(super) fn psd_exponent(self, tau: f64) -> i32 {
        match self {
            Self::Power(t) => t.psd_exponent(),
            Self::Scaled(ScaleTerm::Markov, tc) if tau < MARKOV_WHITE_FROM * tc => -2,
            Self::Scaled(..) => 0,
        }
    }
}

/// The curve a fit sees: τ, estimated variance, degrees of freedom, the Cholesky factor of
/// the estimates' correlation, and the design's columns at each τ.
pub(super) struct Curve {
    pub(super) tau: [f64; MAX_POINTS],
    pub(super) var: [f64; MAX_POINTS],
    pub(super) nu: [f64; MAX_POINTS],
    pub(super) m: [usize; MAX_POINTS],
    pub(super) len: usize,
    pub(super) sample_rate_hz: f64,
    /// Each point's share of the model variance per noise family ([`Family`]).
    pub(super) share: [[f64; FAMILIES]; MAX_POINTS],
    /// Lower-triangular `L` with `L·Lᵀ` the correlation matrix.
    pub(super) chol: [[f64; MAX_POINTS]; MAX_POINTS],
    pub(super) columns: [Column; COLUMNS],
    pub(super) ncols: usize,
    /// `basis[j][i]`: column `j` at point `i`.
    pub(super) basis: [[f64; MAX_POINTS]; COLUMNS],
}

/// How many noise families the correlation of the estimates distinguishes.
pub(super) const FAMILIES: usize = 3;

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
pub(super) const POWER_COLUMNS: [Column; TERMS] = [
    Column::Power(NoiseTerm::Quantization),
    Column::Power(NoiseTerm::White),
    Column::Power(NoiseTerm::BiasInstability),
    Column::Power(NoiseTerm::RandomWalk),
    Column::Power(NoiseTerm::RateRamp),
];

impl Curve {
    pub(super) fn new(tau: &[f64], var: &[f64], m: &[usize], columns: &[Column]) -> Self {
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
    pub(super) fn set_column(&mut self, k: usize, column: Column) {
        self.columns[k] = column;
        for i in 0..self.len {
            self.basis[k][i] = column.basis(self.tau[i], self.m[i], self.sample_rate_hz);
        }
    }

    /// The model's variance at point `i` for coefficients `c`.
    pub(super) fn model(&self, c: &VecC, i: usize) -> f64 {
        (0..self.ncols).map(|j| c[j] * self.basis[j][i]).sum()
    }

    /// The Cholesky factor of the estimates' correlation for the present shares (positive
    /// definite for ratios ≥ 2: each family's symbol 1 + 2Σρ_k cos kω stays above 0.06).
    pub(super) fn factor(&mut self) {
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
    pub(super) fn whiten(&self, b: &mut [f64]) {
        for i in 0..self.len {
            let sum: f64 = (0..i).map(|k| self.chol[i][k] * b[k]).sum();
            b[i] = (b[i] - sum) / self.chol[i][i];
        }
    }
}

/// The weighted least-squares solution on the columns in `mask` (bit `j` for column `j`), with
/// weights `w`; `None` if singular. Returns the coefficients (`scale·X²` of a power law, the
/// amplitude squared of a term with a time scale) and their covariance.
pub(super) fn solve(curve: &Curve, w: &[f64], mask: u32) -> Option<Solution> {
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
pub(super) struct Solution {
    pub(super) c: VecC,
    pub(super) cov: Mat,
    pub(super) chi2: f64,
}

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
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
pub(super) fn non_negative(sol: &Solution, mask: u32) -> bool {
    (0..COLUMNS).all(|j| {
        mask & (1 << j) == 0 || sol.c[j].partial_cmp(&0.0) == Some(core::cmp::Ordering::Greater)
    })
}

/// The best non-negative fit for weights `w` among the subsets of the design's columns that hold
/// every column of `required`: the subset (bit `j` for column `j`) and its solution.
pub(super) fn best_non_negative(
    curve: &Curve,
    w: &[f64],
    required: u32,
) -> Option<(u32, Solution)> {
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
pub(super) fn degrees_of_freedom(curve: &mut Curve, c: &VecC, n: usize) {
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
pub(super) fn weights(curve: &Curve, c: Option<&VecC>, w: &mut [f64]) {
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
pub(super) fn converge(
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
