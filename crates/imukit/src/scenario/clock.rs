//! The logger's clock (`[imu.clock]`): the IMU's readings are taken at the true instants and
//! stamped by a clock with an offset, a drift and white jitter,
//! `stamp = t + offset_s + drift_ppm·10⁻⁶·t + jitter_s·n`. The truth keeps the true times; the
//! readings' `t_s` column is the stamps, as a logged file has them.
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::io::table::Table;
use imu_core::sensor::{NoiseSource, SeededNormals};

/// The noise stream of the clock's jitter.
const CLOCK_STREAM: u64 = 5;

/// The `[imu.clock]` table.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClockSpec {
    /// The stamp of the true instant 0, s.
    #[serde(default)]
    pub offset_s: f64,
    /// How fast the clock runs against true time, parts per million (50: 50 µs fast per
    /// second).
    #[serde(default)]
    pub drift_ppm: f64,
    /// One-sigma of each stamp's white jitter, s (≥ 0). Jitter beyond a few tenths of the
    /// sample interval makes stamps that do not increase, as such loggers do.
    #[serde(default)]
    pub jitter_s: f64,
}

impl ClockSpec {
    /// The clock, checked.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] on the key: values that are not finite, a negative jitter, a
    /// drift of −10⁶ ppm or below (a clock that stands or runs backwards).
    pub fn check(&self) -> Result<()> {
        for (key, v) in [
            ("offset_s", self.offset_s),
            ("drift_ppm", self.drift_ppm),
            ("jitter_s", self.jitter_s),
        ] {
            if !v.is_finite() {
                return Err(invalid(format!("imu.clock.{key}"), "must be finite"));
            }
        }
        if self.jitter_s < 0.0 {
            return Err(invalid("imu.clock.jitter_s", "must be ≥ 0"));
        }
        if self.drift_ppm <= -1e6 {
            return Err(invalid(
                "imu.clock.drift_ppm",
                "must be above −10⁶ ppm (a clock that runs forward)",
            ));
        }
        Ok(())
    }

    /// The clock's stamps, its jitter seeded from `seed` and the Monte Carlo run.
    #[must_use]
    pub fn source(&self, seed: u64, run: Option<u64>) -> ClockSource {
        ClockSource {
            spec: self.clone(),
            noise: SeededNormals::for_sensor(seed, run, CLOCK_STREAM),
        }
    }
}

/// A clock stamping tables, chunk after chunk (one normal per stamp when it jitters).
#[derive(Clone, Debug)]
pub struct ClockSource {
    spec: ClockSpec,
    noise: SeededNormals,
}

impl ClockSource {
    /// The stamp of the true instant `t_s`.
    pub fn stamp(&mut self, t_s: f64) -> f64 {
        let jitter = if self.spec.jitter_s > 0.0 {
            self.spec.jitter_s * self.noise.standard_normal()
        } else {
            0.0
        };
        t_s + self.spec.offset_s + self.spec.drift_ppm * 1e-6 * t_s + jitter
    }

    /// `table`'s `t_s` column (true instants) replaced by their stamps.
    pub fn stamp_table(&mut self, table: &mut Table) {
        let Some(at) = table.columns.iter().position(|c| c == "t_s") else {
            return;
        };
        let width = table.columns.len();
        for row in table.data.chunks_exact_mut(width) {
            row[at] = self.stamp(row[at]);
        }
    }
}
