//! A multi-position calibration procedure (`type = "positions"`): the part set down in `count`
//! orientations (6 to 24), `rest_s` still in each, turned from one to the next in `turn_s`, with
//! exact derivatives — what `imukit calibrate` takes.
//!
//! The orientations are a fixed table of pitch and roll that spreads gravity's direction over
//! the sphere (the first six along and across the axes, then the diagonals and between), pitch
//! within ±70° so the Euler angles stay clear of their singularity, and a yaw that grows by
//! 37° a position, so the turns are about every axis. A turn moves yaw, pitch and roll from one
//! position's to the next's (the shorter way round) along the quintic `10s³ − 15s⁴ + 6s⁵`, so
//! the rate and the angular acceleration are zero where a rest begins and ends. The part turns
//! about its own point: the position stays at `position_m`.
use crate::error::{Result, invalid};
use crate::motion::analytic::{Motion, Scalar};

/// Pitch and roll of the positions, degrees, in the order they are taken.
const TABLE_DEG: [(f64, f64); 24] = [
    (0.0, 0.0),
    (0.0, 90.0),
    (0.0, 180.0),
    (0.0, -90.0),
    (70.0, 0.0),
    (-70.0, 0.0),
    (45.0, 45.0),
    (45.0, 135.0),
    (45.0, -135.0),
    (45.0, -45.0),
    (-45.0, 45.0),
    (-45.0, 135.0),
    (-45.0, -135.0),
    (-45.0, -45.0),
    (20.0, 160.0),
    (-20.0, -20.0),
    (60.0, 100.0),
    (-60.0, -100.0),
    (30.0, -160.0),
    (-30.0, 160.0),
    (10.0, 60.0),
    (-10.0, -120.0),
    (65.0, -60.0),
    (-65.0, 120.0),
];

/// The fewest and the most positions.
pub const COUNT_RANGE: std::ops::RangeInclusive<usize> = 6..=24;

/// Yaw added from one position to the next, degrees.
const YAW_STEP_DEG: f64 = 37.0;

/// The procedure (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct PositionsMotion {
    /// `[yaw, pitch, roll]` of each position, rad, unwrapped so that each turn is the shorter
    /// way round.
    angles: Vec<[f64; 3]>,
    rest_s: f64,
    turn_s: f64,
    position_m: [f64; 3],
}

impl PositionsMotion {
    /// `count` positions, `rest_s` in each, `turn_s` between them, at `position_m`.
    ///
    /// # Errors
    /// A count outside [`COUNT_RANGE`], times that are not finite and positive, a position
    /// that is not finite; each named by its key.
    pub fn new(count: usize, rest_s: f64, turn_s: f64, position_m: [f64; 3]) -> Result<Self> {
        if !COUNT_RANGE.contains(&count) {
            return Err(invalid(
                "trajectory.count",
                format!("must be 6 to 24 positions, got {count}"),
            ));
        }
        for (key, v) in [("rest_s", rest_s), ("turn_s", turn_s)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    format!("trajectory.{key}"),
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
        }
        if position_m.iter().any(|v| !v.is_finite()) {
            return Err(invalid("trajectory.position_m", "must be finite"));
        }
        let mut angles: Vec<[f64; 3]> = Vec::with_capacity(count);
        for (k, &(pitch, roll)) in TABLE_DEG.iter().take(count).enumerate() {
            let next = [YAW_STEP_DEG * k as f64, pitch, roll].map(f64::to_radians);
            let angle = match angles.last() {
                // Each angle within half a turn of the one before.
                Some(prev) => core::array::from_fn(|i| {
                    let d = (next[i] - prev[i]).rem_euclid(std::f64::consts::TAU);
                    prev[i]
                        + if d > std::f64::consts::PI {
                            d - std::f64::consts::TAU
                        } else {
                            d
                        }
                }),
                None => next,
            };
            angles.push(angle);
        }
        Ok(Self {
            angles,
            rest_s,
            turn_s,
            position_m,
        })
    }

    /// The procedure's length: every rest and the turns between them, s.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        let n = self.angles.len() as f64;
        n * self.rest_s + (n - 1.0) * self.turn_s
    }
}

impl Motion for PositionsMotion {
    fn position<D: Scalar>(&self, _t: D) -> [D; 3] {
        self.position_m.map(D::from)
    }

    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        let period = self.rest_s + self.turn_s;
        let last = self.angles.len() - 1;
        let tr = t.re().max(0.0);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let k = ((tr / period).floor() as usize).min(last);
        let into = t - k as f64 * period - self.rest_s;
        let here = self.angles[k];
        if k == last || into.re() <= 0.0 {
            return Some(here.map(D::from));
        }
        let s = into / self.turn_s;
        let s3 = s * s * s;
        let p = s3 * 10.0 - s3 * s * 15.0 + s3 * s * s * 6.0;
        let next = self.angles[k + 1];
        Some(core::array::from_fn(|i| p * (next[i] - here[i]) + here[i]))
    }
}
