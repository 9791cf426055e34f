//! Calibrating a part from a procedure, without equipment: the readings of a part set down in
//! a number of orientations with rotations between them (multi-position calibration of the
//! accelerometer and the gyroscope, after D. Tedaldi, A. Pretto and E. Menegatti, "A Robust and
//! Easy to Implement Method for IMU Calibration without External Equipments", ICRA 2014), and of
//! a magnetometer turned through all directions (hard and soft iron by an ellipsoid fit).
//!
//! Each sensor's result is a [`Correction`], `u = A (y − b)`, that turns a reading `y` into the
//! calibrated value `u`, with the standard deviation of every term:
//!
//! - [`rests`]: the static intervals, found in the data (the white noise learnt from the log's
//!   quiet blocks, [`crate::stillness::quiet_noise`]);
//! - [`accelerometer`]: `|A(ā_k − b)| = g` at every rest `k`, `A` upper triangular (the
//!   calibrated frame has its x axis along the accelerometer's x and its y axis in the plane of
//!   its x and y; with fewer than [`accelerometer::FULL_MODEL_RESTS`] rests, `A` diagonal);
//! - [`gyroscope`]: the bias from the rests, then `A` (full) such that the rate integrated over
//!   each rotation turns the gravity direction of one rest into the next one's;
//! - [`magnetometer`]: the algebraic ellipsoid fit, hard iron `b`, soft iron `A` symmetric with
//!   determinant 1, and the field's strength.
//!
//! Uncertainties are the least-squares covariance scaled by the residuals' own scatter
//! (`s²(JᵀJ)⁻¹`), so they hold when the residuals are what the model says they are.
pub mod accelerometer;
pub mod gyroscope;
pub mod magnetometer;
mod solve;

use nalgebra::{Matrix3, Vector3};

use crate::stillness::{ReadingNoise, pooled_variance, quiet_variance_limit};

/// The largest mean rate a rest may read, rad/s (about 115 °/s: above any MEMS part's bias; the
/// rests are found by their variance, [`rests`]).
pub const MAX_REST_RATE_RAD_S: f64 = 2.0;

/// A triad's calibration: the calibrated value is `matrix · (reading − bias)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correction {
    /// `A`, row-major.
    pub matrix: [[f64; 3]; 3],
    /// `b`, in the reading's units.
    pub bias: [f64; 3],
}

impl Default for Correction {
    fn default() -> Self {
        Self::identity()
    }
}

impl Correction {
    /// No correction.
    #[must_use]
    pub const fn identity() -> Self {
        Self {
            matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            bias: [0.0; 3],
        }
    }

    /// The calibrated value of `reading`.
    #[must_use]
    pub fn apply(&self, reading: [f64; 3]) -> [f64; 3] {
        let v: [f64; 3] = core::array::from_fn(|i| reading[i] - self.bias[i]);
        core::array::from_fn(|i| {
            self.matrix[i][0] * v[0] + self.matrix[i][1] * v[1] + self.matrix[i][2] * v[2]
        })
    }

    pub(crate) fn of(matrix: &Matrix3<f64>, bias: &Vector3<f64>) -> Self {
        Self {
            matrix: core::array::from_fn(|i| core::array::from_fn(|j| matrix[(i, j)])),
            bias: (*bias).into(),
        }
    }
}

/// Why a calibration could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibrationError {
    /// Fewer static intervals (or rotations between them) than the fit needs.
    TooFewRests {
        /// Found.
        found: usize,
        /// Needed.
        needed: usize,
    },
    /// Fewer readings than the fit needs.
    TooFewReadings {
        /// Given.
        found: usize,
        /// Needed.
        needed: usize,
    },
    /// The readings do not determine the parameters (all in one plane, the same orientation
    /// twice over, a non-finite value).
    Degenerate(&'static str),
}

impl core::fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooFewRests { found, needed } => write!(
                f,
                "{found} static intervals found, the fit needs at least {needed}: set the part down in more orientations, longer"
            ),
            Self::TooFewReadings { found, needed } => {
                write!(f, "{found} readings, the fit needs at least {needed}")
            }
            Self::Degenerate(why) => {
                write!(f, "the readings do not determine the calibration: {why}")
            }
        }
    }
}

impl core::error::Error for CalibrationError {}

/// A static interval: the samples `start..end` (end exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rest {
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
}

impl Rest {
    /// The mean of `rows` over the interval.
    #[must_use]
    pub fn mean(&self, rows: &[[f64; 3]]) -> [f64; 3] {
        let part = &rows[self.start..self.end];
        let n = part.len() as f64;
        core::array::from_fn(|k| part.iter().map(|r| r[k]).sum::<f64>() / n)
    }

    /// Its length in samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// True for an empty interval.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }
}

/// The static intervals of readings `accel`, `gyro` (the shorter sets the length), cut into
/// blocks of `window` samples: a block is still when the pooled variance of both sensors is
/// within what the white noise `noise` allows (the same test as
/// [`crate::stillness::quiet_noise`]'s); each run of still blocks, less its first and last
/// block (where a rotation may start or end unseen), is a rest when at least `min_blocks`
/// remain. Each rest is handed to `found` in order; returns how many.
pub fn rests(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    window: usize,
    noise: ReadingNoise,
    min_blocks: usize,
    mut found: impl FnMut(Rest),
) -> usize {
    let n = accel.len().min(gyro.len());
    let Some(limit) = quiet_variance_limit(window) else {
        return 0;
    };
    let (va, vg) = (
        noise.accel * noise.accel * limit,
        noise.gyro * noise.gyro * limit,
    );
    let still = |b: usize| {
        let range = b * window..(b + 1) * window;
        pooled_variance(&accel[range.clone()]) <= va && pooled_variance(&gyro[range]) <= vg
    };
    let blocks = n / window;
    let mut count = 0;
    let mut b = 0;
    while b < blocks {
        if !still(b) {
            b += 1;
            continue;
        }
        let first = b;
        while b < blocks && still(b) {
            b += 1;
        }
        // Blocks first..b are still; keep first+1..b−1.
        if b >= first + 2 + min_blocks.max(1) {
            found(Rest {
                start: (first + 1) * window,
                end: (b - 1) * window,
            });
            count += 1;
        }
    }
    count
}
