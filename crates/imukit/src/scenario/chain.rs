//! The IMU's signal chain as a scenario gives it (`[imu.chain]`): the part samples at an
//! internal rate, low-pass filters each sensor's signal digitally and keeps every `M`-th sample
//! (the scenario's rate); the error model then applies at the output rate, as before. See
//! [`imu_core::signal`] and docs/models.md.
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, invalid};
use crate::io::table::Table;
use crate::scenario::spec::TrajectorySpec;
use crate::scenario::times::SampleTimes;
use crate::sensor::Chain;
use imu_core::signal::{LowPass, SignalError};

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

/// The `[imu.chain]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChainSpec {
    /// The rate the part samples at inside, Hz: a whole multiple of the scenario's rate.
    pub internal_rate_hz: f64,
    /// The accelerometer's low-pass (default none).
    pub accelerometer: Option<LowPassSpec>,
    /// The gyroscope's low-pass (default none).
    pub gyroscope: Option<LowPassSpec>,
    /// The magnetometer's low-pass (default none).
    pub magnetometer: Option<LowPassSpec>,
}

/// The sensors in the order the chain keeps them, with their keys.
const SENSORS: [&str; 3] = ["accelerometer", "gyroscope", "magnetometer"];

/// A resolved signal chain: the internal rate and each sensor's filter, checked at the
/// scenario's rate.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSetup {
    /// The internal rate, Hz.
    pub internal_rate_hz: f64,
    /// The accelerometer's, gyroscope's and magnetometer's low-pass.
    pub low_pass: [LowPassSpec; 3],
    /// Internal samples per output sample.
    pub decimation: usize,
}

impl ChainSetup {
    /// The chain of `spec` for output at `rate_hz`, every filter checked.
    ///
    /// # Errors
    /// [`Error::Invalid`] on the key (`imu.chain.internal_rate_hz`, `imu.chain.gyroscope`, …)
    /// whose value the chain cannot take.
    pub fn resolve(spec: &ChainSpec, rate_hz: f64) -> Result<Self> {
        let rate = spec.internal_rate_hz;
        if !(rate.is_finite() && rate > 0.0) {
            let e = SignalError::NotPositive {
                field: "internal_rate_hz",
                value: rate,
            };
            return Err(invalid(INTERNAL_RATE_KEY, e.to_string()));
        }
        let low_pass = [&spec.accelerometer, &spec.gyroscope, &spec.magnetometer]
            .map(|f| f.clone().unwrap_or(LowPassSpec::None));
        let mut setup = Self {
            internal_rate_hz: rate,
            low_pass,
            decimation: 1,
        };
        let [accelerometer, _, _] = setup.chains(rate_hz)?;
        setup.decimation = accelerometer.decimation();
        Ok(setup)
    }

    /// The chain of a scenario's `[imu.chain]`: regular sample times at the scenario's rate
    /// (`sample_rate_hz`), the motion at most 10⁹ samples, every filter checked.
    ///
    /// # Errors
    /// [`Error::Invalid`] on `imu.chain` or the key it names.
    pub fn of_scenario(
        spec: &ChainSpec,
        trajectory: &TrajectorySpec,
        t_s: &SampleTimes,
        sample_rate_hz: f64,
    ) -> Result<Self> {
        if !matches!(t_s, SampleTimes::Regular { .. })
            || matches!(trajectory, TrajectorySpec::Samples(_))
        {
            return Err(invalid(
                "imu.chain",
                "the signal chain samples the motion at its internal rate: it needs the regular \
                 sample times of rate_hz, not a trajectory's own times",
            ));
        }
        // The motion is sampled at the internal rate: as many samples as a scenario may have.
        #[allow(clippy::cast_precision_loss)]
        let motion_samples =
            t_s.len().saturating_sub(1) as f64 * spec.internal_rate_hz / sample_rate_hz;
        if motion_samples > 1e9 {
            return Err(invalid(
                INTERNAL_RATE_KEY,
                format!(
                    "the motion sampled at this rate from the first sample to the last would be \
                     {motion_samples:.2e} samples, more than 10⁹"
                ),
            ));
        }
        Self::resolve(spec, sample_rate_hz)
    }

    /// Each sensor's chain for output at `rate_hz`.
    ///
    /// # Errors
    /// As [`ChainSetup::resolve`].
    pub fn chains(&self, rate_hz: f64) -> Result<[Chain; 3]> {
        let make = |k: usize| {
            Chain::new(self.internal_rate_hz, rate_hz, &self.low_pass[k].low_pass())
                .map_err(|e| chain_error(SENSORS[k], &e))
        };
        Ok([make(0)?, make(1)?, make(2)?])
    }
}

/// The columns of [`ChainSetup::response_table`].
pub const RESPONSE_COLUMNS: [&str; 11] = [
    "frequency_hz",
    "alias_hz",
    "accel_gain",
    "accel_phase_rad",
    "accel_delay_s",
    "gyro_gain",
    "gyro_phase_rad",
    "gyro_delay_s",
    "mag_gain",
    "mag_phase_rad",
    "mag_delay_s",
];

impl ChainSetup {
    /// The chain's response at each of `frequencies_hz` for output at `rate_hz`: where a sine
    /// of that frequency appears in the output (its alias), and per sensor the filter's gain,
    /// phase and group delay there ([`RESPONSE_COLUMNS`]).
    ///
    /// # Errors
    /// As [`ChainSetup::chains`]; a frequency that is negative or not finite, by its index.
    pub fn response_table(&self, rate_hz: f64, frequencies_hz: &[f64]) -> Result<Table> {
        if let Some(k) = frequencies_hz
            .iter()
            .position(|f| !(f.is_finite() && *f >= 0.0))
        {
            return Err(invalid(
                format!("frequencies_hz[{k}]"),
                format!("{} is not a frequency (finite, ≥ 0)", frequencies_hz[k]),
            ));
        }
        let chains = self.chains(rate_hz)?;
        let mut t = Table::new(&RESPONSE_COLUMNS);
        for &f in frequencies_hz {
            let mut row = vec![f, chains[0].alias_hz(f)];
            for c in &chains {
                let h = c.response(f);
                row.extend([h.gain, h.phase_rad, c.group_delay_s(f)]);
            }
            t.push_row(&row);
        }
        Ok(t)
    }
}

/// The key of the internal rate.
const INTERNAL_RATE_KEY: &str = "imu.chain.internal_rate_hz";

/// The core's refusal of a sensor's chain, on the key it came from: the rates are checked
/// before (the internal rate in [`ChainSetup::resolve`], the output rate with the scenario),
/// so what remains is their ratio or the sensor's filter.
fn chain_error(sensor: &str, e: &SignalError) -> Error {
    let field = match e {
        SignalError::NotWholeMultiple { .. } => INTERNAL_RATE_KEY.to_string(),
        _ => format!("imu.chain.{sensor}"),
    };
    invalid(field, e.to_string())
}
