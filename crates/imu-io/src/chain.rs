//! A part's signal chain as files describe it (a scenario's `[imu.chain]`): the rate the part
//! samples at inside, per sensor if they differ, and each sensor's digital low-pass, in the
//! words data sheets use. `imukit`'s `scenario::chain` resolves it into the core's
//! [`imu_core::signal::Chain`]s.
use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::params::ParamValue;
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
    /// What a data sheet gives: the −3 dB bandwidth and the delay (the group delay at zero
    /// frequency), realised by the one second-order section that has both
    /// ([`LowPass::BandwidthDelay`]).
    BandwidthDelay {
        /// −3 dB frequency, Hz.
        bandwidth_hz: f64,
        /// Delay, s.
        delay_s: f64,
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
            Self::BandwidthDelay {
                bandwidth_hz,
                delay_s,
            } => LowPass::BandwidthDelay {
                bandwidth_hz: *bandwidth_hz,
                delay_s: *delay_s,
            },
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
    /// One of the part's settings (its file's `[chain]` table, a preset's data-sheet table:
    /// the MPU-6050's `DLPF_CFG = 3`), the keys above given here taking its place.
    pub setting: Option<SettingName>,
}

/// A part's setting as a scenario names it: a whole number (`setting = 3`) or text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SettingName {
    /// A register value.
    Number(i64),
    /// A name.
    Text(String),
}

impl fmt::Display for SettingName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Number(n) => write!(f, "{n}"),
            Self::Text(t) => f.write_str(t),
        }
    }
}

/// A part's signal-chain settings as its data sheet tabulates them: a part file's `[chain]`
/// table (each preset whose data sheet gives them).
///
/// ```toml
/// [chain]
/// register = "DLPF_CFG"
/// line = "Register 26 (CONFIG): DLPF_CFG"
/// [chain.settings.3]
/// internal_rate_hz = 1000
/// gyroscope = { filter = "bandwidth_delay", bandwidth_hz = 42, delay_s = 0.0048 }
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartChains {
    /// What the part calls the setting (a register field).
    pub register: String,
    /// Where the table is in the data sheet.
    pub line: String,
    /// Each setting's chain, by its value.
    pub settings: BTreeMap<String, ChainSpec>,
}

impl PartChains {
    /// The `[chain]` table `v` of the file `origin`.
    ///
    /// # Errors
    /// The key that does not fit (`origin: chain.settings.3.gyroscope`), and a setting that
    /// names a setting itself.
    pub fn parse(v: &ParamValue, origin: &str) -> Result<Self> {
        let chains: Self = crate::value_tree::read(v).map_err(|e| {
            let at = if e.path.is_empty() {
                format!("{origin}: chain")
            } else {
                format!("{origin}: chain.{}", e.path)
            };
            invalid(at, e.message)
        })?;
        if let Some(name) = chains.settings.iter().find(|(_, c)| c.setting.is_some()) {
            return Err(invalid(
                format!("{origin}: chain.settings.{}.setting", name.0),
                "a setting is a chain, not another setting",
            ));
        }
        Ok(chains)
    }
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

impl ChainSpec {
    /// This table with its `setting` taken from the part's settings `part` (`part_name` for
    /// the messages): the setting's keys, each replaced by this table's where it gives one.
    /// Without a `setting`, the table as it is.
    ///
    /// # Errors
    /// `imu.chain.setting` when the part has no settings or not this one (naming those it has).
    pub fn with_setting(&self, part: Option<&PartChains>, part_name: &str) -> Result<Self> {
        let Some(name) = &self.setting else {
            return Ok(self.clone());
        };
        let Some(part) = part else {
            return Err(invalid(
                "imu.chain.setting",
                format!(
                    "{part_name} has no chain settings: give [imu] preset = \"mpu-6050\" (or \
                     another part whose file has a [chain] table), or the chain's own keys"
                ),
            ));
        };
        let Some(base) = part.settings.get(&name.to_string()) else {
            let known: Vec<&str> = part.settings.keys().map(String::as_str).collect();
            return Err(invalid(
                "imu.chain.setting",
                format!(
                    "{part_name}'s {} has no setting {name} (it has {})",
                    part.register,
                    known.join(", ")
                ),
            ));
        };
        Ok(Self {
            internal_rate_hz: self.internal_rate_hz.or(base.internal_rate_hz),
            accelerometer_internal_rate_hz: self
                .accelerometer_internal_rate_hz
                .or(base.accelerometer_internal_rate_hz),
            gyroscope_internal_rate_hz: self
                .gyroscope_internal_rate_hz
                .or(base.gyroscope_internal_rate_hz),
            magnetometer_internal_rate_hz: self
                .magnetometer_internal_rate_hz
                .or(base.magnetometer_internal_rate_hz),
            accelerometer: self
                .accelerometer
                .clone()
                .or_else(|| base.accelerometer.clone()),
            gyroscope: self.gyroscope.clone().or_else(|| base.gyroscope.clone()),
            magnetometer: self
                .magnetometer
                .clone()
                .or_else(|| base.magnetometer.clone()),
            setting: None,
        })
    }
}
