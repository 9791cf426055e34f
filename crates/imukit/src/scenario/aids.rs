//! The barometer (`[baro]`) and the wheel odometer (`[odometer]`) of a scenario: readings every
//! `rate_hz` (a divisor of the scenario's rate, so at IMU samples) of the height (up: ENU `z`,
//! −NED `z`, or the WGS-84 height) and of the body's forward speed, with a constant error and
//! white noise ([`imu_core::aiding::SimpleAid`]), each on its own seeded stream.
use imu_core::aiding::SimpleAid;
use imu_core::sensor::SeededNormals;
use imu_core::{NavFrame, Truth};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::io::columns::{BARO_COLUMNS, ODOMETER_COLUMNS};
use crate::io::table::Table;

/// Noise streams (the IMU's is 0, the GNSS receiver's 1).
const BARO_STREAM: u64 = 2;
const ODOMETER_STREAM: u64 = 3;

/// `[baro]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaroSpec {
    /// Readings per second, Hz (10); must divide the scenario's `rate_hz`.
    pub rate_hz: Option<f64>,
    /// Constant bias, m (0).
    pub bias_m: Option<f64>,
    /// White noise one-sigma, m (0.5).
    pub noise_m: Option<f64>,
}

/// `[odometer]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometerSpec {
    /// Readings per second, Hz (10); must divide the scenario's `rate_hz`.
    pub rate_hz: Option<f64>,
    /// Scale-factor error, fraction (0; 0.01 reads 1 % fast).
    pub scale_factor_error: Option<f64>,
    /// White noise one-sigma, m/s (0.05).
    pub noise_m_s: Option<f64>,
}

/// A resolved barometer or odometer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AidSetup {
    /// One reading every this many IMU samples.
    pub every: usize,
    /// The error.
    pub error: SimpleAid,
    /// Seed (the IMU's).
    pub seed: u64,
}

/// A rate that divides the IMU's: readings every so many samples.
fn every(field: &str, rate_hz: f64, imu_rate_hz: f64) -> Result<usize> {
    let ratio = imu_rate_hz / rate_hz;
    let whole = ratio.round();
    if rate_hz.is_finite() && rate_hz > 0.0 && whole >= 1.0 && (ratio - whole).abs() < 1e-9 * ratio
    {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        Ok(whole as usize)
    } else {
        Err(invalid(
            field,
            format!(
                "must be > 0 and divide the scenario's rate_hz ({imu_rate_hz} Hz / {rate_hz} Hz is not a whole number ≥ 1)"
            ),
        ))
    }
}

fn finite(field: &str, v: f64, non_negative: bool) -> Result<f64> {
    if v.is_finite() && (!non_negative || v >= 0.0) {
        Ok(v)
    } else {
        let rule = if non_negative { " ≥ 0" } else { "" };
        Err(invalid(
            field,
            format!("must be a finite number{rule}, got {v}"),
        ))
    }
}

impl BaroSpec {
    /// Checked against the scenario's sample rate.
    ///
    /// # Errors
    /// A key out of range, named (`baro.rate_hz`, …).
    pub fn resolve(&self, imu_rate_hz: f64, seed: u64) -> Result<AidSetup> {
        Ok(AidSetup {
            every: every("baro.rate_hz", self.rate_hz.unwrap_or(10.0), imu_rate_hz)?,
            error: SimpleAid {
                constant: finite("baro.bias_m", self.bias_m.unwrap_or(0.0), false)?,
                noise: finite("baro.noise_m", self.noise_m.unwrap_or(0.5), true)?,
            },
            seed,
        })
    }
}

impl OdometerSpec {
    /// Checked against the scenario's sample rate.
    ///
    /// # Errors
    /// A key out of range, named (`odometer.rate_hz`, …).
    pub fn resolve(&self, imu_rate_hz: f64, seed: u64) -> Result<AidSetup> {
        Ok(AidSetup {
            every: every(
                "odometer.rate_hz",
                self.rate_hz.unwrap_or(10.0),
                imu_rate_hz,
            )?,
            error: SimpleAid {
                constant: finite(
                    "odometer.scale_factor_error",
                    self.scale_factor_error.unwrap_or(0.0),
                    false,
                )?,
                noise: finite("odometer.noise_m_s", self.noise_m_s.unwrap_or(0.05), true)?,
            },
            seed,
        })
    }
}

/// What an aid reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AidKind {
    /// Height, m.
    Baro,
    /// Forward speed, m/s.
    Odometer,
}

/// A barometer or odometer running over a scenario's samples.
#[derive(Debug)]
pub struct AidStream {
    setup: AidSetup,
    kind: AidKind,
    noise: SeededNormals,
    next_sample: usize,
}

impl AidStream {
    /// The aid of run `run` (`None`: the single run).
    #[must_use]
    pub fn new(setup: AidSetup, kind: AidKind, run: Option<u64>) -> Self {
        let stream = match kind {
            AidKind::Baro => BARO_STREAM,
            AidKind::Odometer => ODOMETER_STREAM,
        };
        Self {
            setup,
            kind,
            noise: SeededNormals::for_sensor(setup.seed, run, stream),
            next_sample: 0,
        }
    }

    /// Readings of the next samples: `truth` in frame `N`; `heights_m` the WGS-84 heights of
    /// the same samples on the Earth (else the height is the frame's up coordinate).
    pub fn measure<N: NavFrame>(&mut self, truth: &[Truth<N>], heights_m: Option<&[f64]>) -> Table {
        let columns = match self.kind {
            AidKind::Baro => BARO_COLUMNS,
            AidKind::Odometer => ODOMETER_COLUMNS,
        };
        let mut t = Table::new(&columns);
        for (i, s) in truth.iter().enumerate() {
            let k = self.next_sample;
            self.next_sample += 1;
            if !k.is_multiple_of(self.setup.every) {
                continue;
            }
            let value = match self.kind {
                AidKind::Baro => {
                    let h = heights_m.map_or(N::Z_UP * s.position_m.z(), |h| h[i]);
                    self.setup.error.baro(h, &mut self.noise)
                }
                AidKind::Odometer => {
                    let forward = s.attitude.inverse().apply(s.velocity_m_s).x();
                    self.setup.error.odometer(forward, &mut self.noise)
                }
            };
            t.push_row(&[s.t_s, value]);
        }
        t
    }
}
