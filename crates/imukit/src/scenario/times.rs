//! The sample times of a scenario.

use crate::error::{Result, invalid};
use crate::scenario::resolve::finite_positive;

/// Sample times `k/rate_hz`, `k = 0..=round(duration_s·rate_hz)`.
///
/// # Errors
/// Non-positive rate, negative or non-finite duration, more than 10⁹ samples.
pub fn sample_times(rate_hz: f64, duration_s: f64) -> Result<Vec<f64>> {
    Ok(regular_times(rate_hz, duration_s)?.to_vec())
}

/// The regular grid `k / rate_hz`, `k = 0..=round(duration_s · rate_hz)`, kept as a rule.
///
/// # Errors
/// A rate that is not finite and positive, a negative or non-finite duration, more than 10⁹
/// samples.
pub fn regular_times(rate_hz: f64, duration_s: f64) -> Result<SampleTimes> {
    let rate = finite_positive("rate_hz", rate_hz)?;
    if !(duration_s.is_finite() && duration_s >= 0.0) {
        return Err(invalid(
            "duration_s",
            format!("must be a finite number ≥ 0, got {duration_s}"),
        ));
    }
    let last = (duration_s * rate).round();
    if last > 1e9 {
        return Err(invalid(
            "duration_s",
            format!("{duration_s} s at {rate} Hz is more than 10⁹ samples"),
        ));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let count = last as usize + 1;
    Ok(SampleTimes::Regular {
        rate_hz: rate,
        count,
    })
}

/// The sample times of a scenario: a regular grid computed on demand (long runs do not hold
/// their times) or the times listed in a file.
#[derive(Clone, Debug, PartialEq)]
pub enum SampleTimes {
    /// `k / rate_hz` for `k = 0..count`.
    Regular {
        /// Sample rate, Hz.
        rate_hz: f64,
        /// Number of samples.
        count: usize,
    },
    /// Times read from a file, s.
    Listed(Vec<f64>),
    /// A pattern repeated every output period: `(k + offsets[j]) / rate_hz` for
    /// `k = 0..count − 1` and every `j`, then `k = count − 1` with `j = 0` alone (the last
    /// sample's instant). `offsets` starts at 0 and increases below 1 (a signal chain's
    /// internal instants, [`crate::scenario::chain::MotionPattern`]).
    Repeated {
        /// Output rate, Hz.
        rate_hz: f64,
        /// Output samples.
        count: usize,
        /// The instants of one period, fractions of it.
        offsets: Vec<f64>,
    },
}

impl SampleTimes {
    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Regular { count, .. } => *count,
            Self::Listed(t) => t.len(),
            Self::Repeated { count, offsets, .. } => {
                count.saturating_sub(1) * offsets.len() + usize::from(*count > 0)
            }
        }
    }

    /// True when there are no samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Time of sample `k`, s (`k < len()`).
    #[must_use]
    pub fn at(&self, k: usize) -> f64 {
        match self {
            #[allow(clippy::cast_precision_loss)]
            Self::Regular { rate_hz, .. } => k as f64 / rate_hz,
            Self::Listed(t) => t[k],
            #[allow(clippy::cast_precision_loss)]
            Self::Repeated {
                rate_hz, offsets, ..
            } => {
                let n = offsets.len().max(1);
                ((k / n) as f64 + offsets.get(k % n).copied().unwrap_or(0.0)) / rate_hz
            }
        }
    }

    /// All times, s.
    #[must_use]
    pub fn to_vec(&self) -> Vec<f64> {
        (0..self.len()).map(|k| self.at(k)).collect()
    }
}
