//! Overlapping Allan deviation of rate data and noise identification (IEEE Std 952-1997,
//! Annex C; MATLAB's `allanvar` formula), on slices the caller owns.
//!
//! With `θ_k = Σ_{i≤k} (Ω_i − Ω̄)/fs` (the mean is taken out for precision; it does not change
//! the second differences), cluster size `m` and `τ = m/fs`:
//! `σ²(τ) = Σ_{k=0}^{N−2m−1} (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²(N − 2m))`.
//!
//! Noise identification fits lines of fixed slope in log-log through the parts of the curve whose
//! slope is near it: angle/velocity random walk `N` is the −½ line at τ = 1 s, rate random walk `K`
//! the +½ line at τ = 3 s, bias instability `B` the flat part divided by `√(2 ln 2/π) ≈ 0.664`.
use core::fmt;

use crate::math;

/// `√(2 ln 2 / π)` (IEEE Std 952, Annex C): the Allan floor of flicker noise of bias instability
/// B is this times B.
pub const BIAS_INSTABILITY_FACTOR: f64 = 0.664_282_470_267_960_1;

/// Why an Allan deviation could not be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AllanError {
    /// Fewer than 3 samples.
    TooFewSamples {
        /// Samples given.
        got: usize,
    },
    /// A NaN or infinite sample.
    NotFinite {
        /// Its index.
        index: usize,
    },
    /// A cluster size of 0 or more than (N − 1)/2.
    BadClusterSize {
        /// The cluster size.
        m: usize,
        /// The number of samples.
        n: usize,
    },
    /// Non-positive or non-finite sample rate.
    BadRate {
        /// The rate, Hz.
        rate_hz: f64,
    },
    /// Scratch or output slices of the wrong length.
    LengthMismatch {
        /// Which slice.
        field: &'static str,
        /// Needed length.
        expected: usize,
        /// Given length.
        got: usize,
    },
}

impl fmt::Display for AllanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooFewSamples { got } => {
                write!(f, "Allan deviation needs at least 3 samples, got {got}")
            }
            Self::NotFinite { index } => write!(f, "sample {index} is not a finite number"),
            Self::BadClusterSize { m, n } => {
                write!(
                    f,
                    "cluster size {m} is not in 1..={} for {n} samples",
                    n.saturating_sub(1) / 2
                )
            }
            Self::BadRate { rate_hz } => write!(f, "sample rate must be > 0, got {rate_hz}"),
            Self::LengthMismatch {
                field,
                expected,
                got,
            } => write!(f, "{field} has length {got}, expected {expected}"),
        }
    }
}

impl core::error::Error for AllanError {}

/// Cluster sizes 1, 2, 4, … up to (N − 1)/2, written into `out`; returns how many were written.
#[must_use]
pub fn octave_cluster_sizes(n: usize, out: &mut [usize]) -> usize {
    let mut m = 1;
    let mut count = 0;
    while m <= n.saturating_sub(1) / 2 && count < out.len() {
        out[count] = m;
        count += 1;
        m *= 2;
    }
    count
}

/// Fills `theta` (length N) with the mean-removed integral `θ_k = Σ_{i≤k} (Ω_i − Ω̄)/fs`.
///
/// # Errors
/// Too few or non-finite samples, bad rate, `theta` of the wrong length.
pub fn integrate(rate: &[f64], sample_rate_hz: f64, theta: &mut [f64]) -> Result<(), AllanError> {
    let n = rate.len();
    if n < 3 {
        return Err(AllanError::TooFewSamples { got: n });
    }
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(AllanError::BadRate {
            rate_hz: sample_rate_hz,
        });
    }
    if theta.len() != n {
        return Err(AllanError::LengthMismatch {
            field: "theta",
            expected: n,
            got: theta.len(),
        });
    }
    if let Some(index) = rate.iter().position(|v| !v.is_finite()) {
        return Err(AllanError::NotFinite { index });
    }
    let mean = rate.iter().sum::<f64>() / n as f64;
    let mut acc = 0.0;
    let mut comp = 0.0; // Kahan compensation
    for (t, r) in theta.iter_mut().zip(rate) {
        let y = (r - mean) / sample_rate_hz - comp;
        let s = acc + y;
        comp = (s - acc) - y;
        acc = s;
        *t = acc;
    }
    Ok(())
}

/// Overlapping Allan deviation at cluster size `m` from the integrated series `theta`.
///
/// # Errors
/// [`AllanError::BadClusterSize`].
pub fn deviation_at(theta: &[f64], sample_rate_hz: f64, m: usize) -> Result<f64, AllanError> {
    let n = theta.len();
    if m == 0 || 2 * m >= n {
        return Err(AllanError::BadClusterSize { m, n });
    }
    let tau = m as f64 / sample_rate_hz;
    let count = n - 2 * m;
    let sum: f64 = (0..count)
        .map(|k| {
            let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
            d * d
        })
        .sum();
    Ok(math::sqrt(sum / (2.0 * tau * tau * count as f64)))
}

/// Allan deviation of `rate` at each cluster size in `m`, written into `adev` (same length as
/// `m`); `theta` is scratch of the length of `rate`.
///
/// # Errors
/// As [`integrate`] and [`deviation_at`].
pub fn allan_deviation(
    rate: &[f64],
    sample_rate_hz: f64,
    m: &[usize],
    theta: &mut [f64],
    adev: &mut [f64],
) -> Result<(), AllanError> {
    if adev.len() != m.len() {
        return Err(AllanError::LengthMismatch {
            field: "adev",
            expected: m.len(),
            got: adev.len(),
        });
    }
    integrate(rate, sample_rate_hz, theta)?;
    for (out, &mi) in adev.iter_mut().zip(m) {
        *out = deviation_at(theta, sample_rate_hz, mi)?;
    }
    Ok(())
}

/// A line `log10 σ = slope · log10 τ + intercept` fitted to an Allan curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllanLine {
    /// Slope in log-log (−½, 0 or +½).
    pub slope: f64,
    /// Intercept, log10 of σ at τ = 1 s.
    pub intercept: f64,
    /// Index of the segment (points `index`, `index + 1`) whose slope was closest to the target.
    pub index: usize,
}

impl AllanLine {
    /// The line's σ at `tau_s`.
    #[must_use]
    pub fn at(&self, tau_s: f64) -> f64 {
        num_traits::Float::powf(
            10.0,
            self.slope * num_traits::Float::log10(tau_s) + self.intercept,
        )
    }
}

/// Noise coefficients read off an Allan curve (units of the rate: e.g. rad/s → N in rad/√s,
/// K in rad/s^1.5, B in rad/s). `None` where no part of the curve has a slope near the target.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseIdentification {
    /// White noise (angle/velocity random walk) N = σ of the −½ line at τ = 1 s.
    pub noise_density: Option<f64>,
    /// Rate random walk K = σ of the +½ line at τ = 3 s.
    pub random_walk: Option<f64>,
    /// Bias instability B = floor / 0.664.
    pub bias_instability: Option<f64>,
    /// The −½ line.
    pub white_line: Option<AllanLine>,
    /// The +½ line.
    pub random_walk_line: Option<AllanLine>,
    /// The flat line.
    pub bias_line: Option<AllanLine>,
}

/// Segments whose log-log slope is within this of the target count as matching.
const SLOPE_TOLERANCE: f64 = 0.15;

/// Fits a line of slope `target` through every segment of the curve whose slope is within
/// [`SLOPE_TOLERANCE`] of it, averaging the intercepts with weights `1/τ` (proportional to the
/// number of clusters, so the best-determined part of the curve counts most). On curves of more
/// than 6 points the two segments of largest τ are left out: at octave τ they rest on fewer than
/// about 8 independent clusters, and their chance slopes would otherwise be read as noise terms.
fn fit(tau: &[f64], adev: &[f64], target: f64) -> Option<AllanLine> {
    use num_traits::Float;
    let (mut sum_w, mut sum_wb) = (0.0, 0.0);
    let mut best: Option<(f64, usize)> = None;
    let segments = tau.len().saturating_sub(1);
    let usable = if tau.len() > 6 {
        segments - 2
    } else {
        segments
    };
    for i in 0..usable {
        if !(adev[i] > 0.0 && adev[i + 1] > 0.0 && tau[i] > 0.0 && tau[i + 1] > tau[i]) {
            continue;
        }
        let (lt0, lt1) = (Float::log10(tau[i]), Float::log10(tau[i + 1]));
        let (la0, la1) = (Float::log10(adev[i]), Float::log10(adev[i + 1]));
        let slope = (la1 - la0) / (lt1 - lt0);
        let err = math::abs(slope - target);
        if err < SLOPE_TOLERANCE {
            let w = 1.0 / (tau[i] * tau[i + 1]).sqrt();
            sum_w += w;
            sum_wb += w * (0.5 * (la0 + la1) - target * 0.5 * (lt0 + lt1));
            if best.is_none_or(|(e, _)| err < e) {
                best = Some((err, i));
            }
        }
    }
    best.map(|(_, index)| AllanLine {
        slope: target,
        intercept: sum_wb / sum_w,
        index,
    })
}

/// Reads N, K and B off an Allan curve (`tau_s` increasing, `adev` the deviations).
///
/// N and K come from the −½ and +½ lines. B comes from the flat part after the white and
/// random-walk contributions of those lines are removed (`σ_B² = σ² − N²/τ − K²τ/3`), so that
/// a floor between the two is not read too high.
#[must_use]
pub fn identify_noise(tau_s: &[f64], adev: &[f64]) -> NoiseIdentification {
    let n = tau_s.len().min(adev.len());
    let (tau, adev) = (&tau_s[..n], &adev[..n]);
    let white_line = fit(tau, adev, -0.5);
    let random_walk_line = fit(tau, adev, 0.5);
    let flat = fit(tau, adev, 0.0);
    let noise_density = white_line.map(|l| l.at(1.0));
    let random_walk = random_walk_line.map(|l| l.at(3.0));
    let bias_line = flat.map(|line| {
        let (nd, k) = (noise_density.unwrap_or(0.0), random_walk.unwrap_or(0.0));
        let residual = |i: usize| {
            let t = tau[i];
            let r = adev[i] * adev[i] - nd * nd / t - k * k * t / 3.0;
            if r > 0.0 { math::sqrt(r) } else { 0.0 }
        };
        // The flat segment's two points, corrected; the line keeps the segment's index.
        let floor = 0.5 * (residual(line.index) + residual(line.index + 1));
        let floor = if floor > 0.0 { floor } else { line.at(1.0) };
        AllanLine {
            slope: 0.0,
            intercept: num_traits::Float::log10(floor),
            index: line.index,
        }
    });
    NoiseIdentification {
        noise_density,
        random_walk,
        bias_instability: bias_line.map(|l| l.at(1.0) / BIAS_INSTABILITY_FACTOR),
        white_line,
        random_walk_line,
        bias_line,
    }
}
