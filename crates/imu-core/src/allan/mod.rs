//! Overlapping Allan deviation of rate data and noise identification (IEEE Std 952-1997,
//! Annex C; MATLAB's `allanvar` formula), on slices the caller owns.
//!
//! With `θ_k = Σ_{i≤k} (Ω_i − Ω̄)/fs` (the mean is taken out for precision; it does not change
//! the second differences), cluster size `m` and `τ = m/fs`:
//! `σ²(τ) = Σ_{k=0}^{N−2m−1} (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²(N − 2m))`.
//!
//! Each estimate's uncertainty is its equivalent degrees of freedom ([`edf`]); the noise terms are
//! fitted to the curve with those as weights, each with its interval ([`fit`]).
use core::fmt;

pub mod edf;
pub mod fit;
mod gls;
pub mod scale_terms;

pub use edf::{deviation_interval, overlapping_edf};
pub use fit::{FitError, NoiseFit, NoiseTerm, ScaleEstimate, TermEstimate, fit_noise};
pub use scale_terms::ScaleTerm;

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
