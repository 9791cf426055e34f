//! The IMU's signal chain as a scenario gives it (`[imu.chain]`): the part samples at an
//! internal rate, low-pass filters each sensor's signal digitally and keeps every `M`-th sample
//! (the scenario's rate); the error model then applies at the output rate, as before. See
//! [`imu_core::signal`] and docs/models.md.
use crate::error::{Error, Result, invalid};
use crate::io::table::Table;
use crate::scenario::spec::TrajectorySpec;
use crate::scenario::times::SampleTimes;
use crate::sensor::Chain;
use imu_core::signal::SignalError;
pub use imu_io::chain::{ChainSpec, LowPassSpec, SENSORS};

/// Most internal samples per output sample a sensor's chain may take.
pub const MAX_DECIMATION: usize = 1_000_000;

/// A resolved signal chain: each sensor's internal rate and filter, checked at the scenario's
/// rate.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSetup {
    /// The accelerometer's, gyroscope's and magnetometer's internal rate, Hz.
    pub internal_rates_hz: [f64; 3],
    /// The accelerometer's, gyroscope's and magnetometer's low-pass.
    pub low_pass: [LowPassSpec; 3],
    /// Each sensor's internal samples per output sample.
    pub decimations: [usize; 3],
}

/// The instants one output period holds when the sensors sample inside at rates of their own:
/// the union of each sensor's `j/M` (fractions of the period), in order, with the sensors that
/// sample at each. The period's first instant is every sensor's and the output sample's.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionPattern {
    /// Each instant's offset in the period, fractions of it, from 0.
    pub offsets: Vec<f64>,
    /// Which of the accelerometer, gyroscope and magnetometer sample at each instant.
    pub sampled: Vec<[bool; 3]>,
}

impl ChainSetup {
    /// The chain of `spec` for output at `rate_hz`, every rate and filter checked.
    ///
    /// # Errors
    /// [`Error::Invalid`] on the key (`imu.chain.internal_rate_hz`, `imu.chain.gyroscope`, …)
    /// whose value the chain cannot take.
    pub fn resolve(spec: &ChainSpec, rate_hz: f64) -> Result<Self> {
        let mut internal_rates_hz = [rate_hz; 3];
        for (k, (key, rate)) in spec.internal_rates().into_iter().enumerate() {
            let Some(rate) = rate else { continue };
            if !(rate.is_finite() && rate > 0.0) {
                let e = SignalError::NotPositive {
                    field: "internal_rate_hz",
                    value: rate,
                };
                return Err(invalid(format!("imu.chain.{key}"), e.to_string()));
            }
            if rate / rate_hz > MAX_DECIMATION as f64 {
                return Err(invalid(
                    format!("imu.chain.{key}"),
                    format!(
                        "{rate} Hz is more than {MAX_DECIMATION} times the output rate                          ({rate_hz} Hz)"
                    ),
                ));
            }
            internal_rates_hz[k] = rate;
        }
        let mut setup = Self {
            internal_rates_hz,
            low_pass: spec.low_passes(),
            decimations: [1; 3],
        };
        setup.decimations = setup.chains(rate_hz)?.map(|c| c.decimation());
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
        // The motion is sampled at each sensor's instants: as many as a scenario may have.
        let per_period: f64 = spec
            .internal_rates()
            .iter()
            .map(|(_, r)| r.unwrap_or(sample_rate_hz) / sample_rate_hz)
            .sum();
        #[allow(clippy::cast_precision_loss)]
        let motion_samples = t_s.len().saturating_sub(1) as f64 * per_period;
        if motion_samples > 1e9 || !motion_samples.is_finite() {
            return Err(invalid(
                INTERNAL_RATE_KEY,
                format!(
                    "the motion sampled at these rates from the first sample to the last would \
                     be {motion_samples:.2e} samples, more than 10⁹"
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
            Chain::new(
                self.internal_rates_hz[k],
                rate_hz,
                &self.low_pass[k].low_pass(),
            )
            .map_err(|e| chain_error(SENSORS[k], &e))
        };
        Ok([make(0)?, make(1)?, make(2)?])
    }

    /// The highest of the sensors' internal rates, Hz.
    #[must_use]
    pub fn fastest_rate_hz(&self) -> f64 {
        self.internal_rates_hz.into_iter().fold(0.0, f64::max)
    }

    /// The instants of one output period at which the motion is sampled: each sensor's
    /// `j/M_k`, `j = 0..M_k`, merged (equal fractions once).
    #[must_use]
    pub fn motion_pattern(&self) -> MotionPattern {
        // (numerator, denominator, sensor) in lowest terms, sorted by value.
        let mut fractions: Vec<(u64, u64, usize)> = Vec::new();
        for (k, &m) in self.decimations.iter().enumerate() {
            let m = m as u64;
            for j in 0..m {
                let g = gcd(j, m);
                fractions.push((j / g, m / g, k));
            }
        }
        fractions.sort_by(|a, b| {
            (u128::from(a.0) * u128::from(b.1)).cmp(&(u128::from(b.0) * u128::from(a.1)))
        });
        let mut pattern = MotionPattern {
            offsets: Vec::new(),
            sampled: Vec::new(),
        };
        let mut last: Option<(u64, u64)> = None;
        for (j, m, k) in fractions {
            if last != Some((j, m)) {
                #[allow(clippy::cast_precision_loss)]
                pattern.offsets.push(j as f64 / m as f64);
                pattern.sampled.push([false; 3]);
                last = Some((j, m));
            }
            if let Some(s) = pattern.sampled.last_mut() {
                s[k] = true;
            }
        }
        pattern
    }
}

/// The greatest common divisor (`gcd(0, m) = m`).
fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
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
