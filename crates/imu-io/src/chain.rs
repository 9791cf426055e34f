//! A part's signal chain as files describe it (a scenario's `[imu.chain]`): the rate the part
//! samples at inside, per sensor if they differ, and each sensor's digital low-pass, in the
//! words data sheets use. `imukit`'s `scenario::chain` resolves it into the core's
//! [`imu_core::signal::Chain`]s.
use serde::{Deserialize, Serialize};

use imu_core::signal::LowPass;

/// A sensor's digital low-pass, as a data sheet describes it (`filter = "…"` and its keys).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "filter", rename_all = "snake_case", deny_unknown_fields)]
pub enum LowPassSpec {
    /// No filter: decimation alone.
    None,
    /// Butterworth of `order` (1–8) with its −3 dB point at `cutoff_hz`.
    Butterworth {
        /// Order.
        order: usize,
        /// −3 dB frequency, Hz.
        cutoff_hz: f64,
    },
    /// The mean of the last `taps` internal samples.
    MovingAverage {
        /// Samples averaged.
        taps: usize,
    },
    /// Two moving averages of `taps` in a row (a triangular window).
    Bartlett {
        /// Samples of each average.
        taps: usize,
    },
    /// A finite impulse response, `h₀` first.
    Fir {
        /// The impulse response.
        coefficients: Vec<f64>,
    },
    /// `b(z⁻¹)/a(z⁻¹)`.
    Rational {
        /// `b₀ … b_m`.
        numerator: Vec<f64>,
        /// `a₀ … a_n`.
        denominator: Vec<f64>,
    },
}

impl LowPassSpec {
    /// The core's description of this filter.
    #[must_use]
    pub fn low_pass(&self) -> LowPass<'_> {
        match self {
            Self::None => LowPass::None,
            Self::Butterworth { order, cutoff_hz } => LowPass::Butterworth {
                order: *order,
                cutoff_hz: *cutoff_hz,
            },
            Self::MovingAverage { taps } => LowPass::MovingAverage { taps: *taps },
            Self::Bartlett { taps } => LowPass::Bartlett { taps: *taps },
            Self::Fir { coefficients } => LowPass::Fir { coefficients },
            Self::Rational {
                numerator,
                denominator,
            } => LowPass::Rational {
                numerator,
                denominator,
            },
        }
    }
}

/// The `[imu.chain]` table. A sensor samples inside at its own rate key
/// (`gyroscope_internal_rate_hz`, …), else at `internal_rate_hz`, else at the output rate (no
/// oversampling: its filter alone).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChainSpec {
    /// The rate every sensor samples at inside, Hz, unless its own is given: a whole multiple
    /// of the scenario's rate.
    pub internal_rate_hz: Option<f64>,
    /// The accelerometer's own internal rate, Hz.
    pub accelerometer_internal_rate_hz: Option<f64>,
    /// The gyroscope's own internal rate, Hz.
    pub gyroscope_internal_rate_hz: Option<f64>,
    /// The magnetometer's own internal rate, Hz.
    pub magnetometer_internal_rate_hz: Option<f64>,
    /// The accelerometer's low-pass (default none).
    pub accelerometer: Option<LowPassSpec>,
    /// The gyroscope's low-pass (default none).
    pub gyroscope: Option<LowPassSpec>,
    /// The magnetometer's low-pass (default none).
    pub magnetometer: Option<LowPassSpec>,
}

/// The sensors in the order a chain keeps them, as their keys name them.
pub const SENSORS: [&str; 3] = ["accelerometer", "gyroscope", "magnetometer"];

impl ChainSpec {
    /// Each sensor's internal-rate key and value (its own, else `internal_rate_hz`); `None`
    /// where neither is given.
    #[must_use]
    pub fn internal_rates(&self) -> [(&'static str, Option<f64>); 3] {
        let own = [
            self.accelerometer_internal_rate_hz,
            self.gyroscope_internal_rate_hz,
            self.magnetometer_internal_rate_hz,
        ];
        let keys = [
            "accelerometer_internal_rate_hz",
            "gyroscope_internal_rate_hz",
            "magnetometer_internal_rate_hz",
        ];
        [0, 1, 2].map(|k| match own[k] {
            Some(r) => (keys[k], Some(r)),
            None => ("internal_rate_hz", self.internal_rate_hz),
        })
    }

    /// Each sensor's low-pass (none where not given).
    #[must_use]
    pub fn low_passes(&self) -> [LowPassSpec; 3] {
        [&self.accelerometer, &self.gyroscope, &self.magnetometer]
            .map(|f| f.clone().unwrap_or(LowPassSpec::None))
    }
}
