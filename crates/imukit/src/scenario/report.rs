//! Silent slips a run should speak of: before it, figures implausible for their unit (a
//! gyroscope noise density in °/√h pasted as SI, angles in degrees where radians are read);
//! after it, readings clipped at a sensor's measurement range and sampling too coarse for the
//! motion. Warnings never change a number; the command line prints them, Python raises them as
//! `imukit.ImuWarning`.
use imu_core::sensor::ImuReading;

use crate::io::params::ImuParams;
use crate::io::units::convert;

/// Above this turn between two samples (rad) the sampling is too coarse for the motion: the
/// body's rotation is no longer resolved, and navigation from the readings loses accuracy
/// fast (the coning error grows with the cube of the turn per sample).
pub const MAX_TURN_PER_SAMPLE_RAD: f64 = 0.25;

/// A figure as implausible for its unit: above `high`, no part of any grade has it.
struct Plausible {
    key: &'static str,
    sensor: &'static str,
    unit: &'static str,
    high: f64,
    /// The units a pasted figure was likely written in, as `imukit convert` names them.
    likely: &'static [&'static str],
    /// The figure's three axes in the parameters.
    of: fn(&ImuParams) -> [f64; 3],
}

const PLAUSIBLE: [Plausible; 6] = [
    Plausible {
        key: "noise_density",
        sensor: "gyroscope",
        unit: "rad/s/√Hz",
        high: 0.01,
        likely: &["°/√h", "mdps/√Hz"],
        of: |p| p.gyroscope.noise_density,
    },
    Plausible {
        key: "bias_instability",
        sensor: "gyroscope",
        unit: "rad/s",
        high: 0.01,
        likely: &["°/h", "°/s"],
        of: |p| p.gyroscope.bias_instability,
    },
    Plausible {
        key: "constant_bias",
        sensor: "gyroscope",
        unit: "rad/s",
        high: 1.0,
        likely: &["°/h", "°/s"],
        of: |p| p.gyroscope.constant_bias,
    },
    Plausible {
        key: "noise_density",
        sensor: "accelerometer",
        unit: "m/s²/√Hz",
        high: 0.05,
        likely: &["µg/√Hz"],
        of: |p| p.accelerometer.noise_density,
    },
    Plausible {
        key: "bias_instability",
        sensor: "accelerometer",
        unit: "m/s²",
        high: 0.5,
        likely: &["µg", "mg"],
        of: |p| p.accelerometer.bias_instability,
    },
    Plausible {
        key: "constant_bias",
        sensor: "accelerometer",
        unit: "m/s²",
        high: 5.0,
        likely: &["mg", "µg"],
        of: |p| p.accelerometer.constant_bias,
    },
];

/// Warnings for sensor figures no part of any grade has, each naming the likely unit slip and
/// what the figure would be in SI if it was one.
#[must_use]
pub fn implausible_figures(params: &ImuParams) -> Vec<String> {
    let mut out = Vec::new();
    for p in &PLAUSIBLE {
        let values = (p.of)(params);
        let Some(worst) = values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        else {
            continue;
        };
        if worst.abs() <= p.high {
            continue;
        }
        let readings: Vec<String> = p
            .likely
            .iter()
            .filter_map(|unit| {
                convert(worst, unit)
                    .ok()
                    .map(|c| format!("as {unit} it is {:.4e} {}", c.value, c.unit))
            })
            .collect();
        out.push(format!(
            "imu.{}.{}: {worst} {} is more than any {} of any grade has (at most {}); a figure in \
             another unit? {} (`imukit convert {worst} \"{}\"`)",
            p.sensor,
            p.key,
            p.unit,
            p.sensor,
            p.high,
            readings.join(", "),
            p.likely[0]
        ));
    }
    out
}

/// Warnings for angles given as numbers that are beyond a full turn: likely degrees.
#[must_use]
pub fn angles_beyond_a_turn(key: &str, values: &[f64]) -> Option<String> {
    let worst = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))?;
    (worst.abs() > core::f64::consts::TAU).then(|| {
        format!(
            "{key}: {worst} rad is more than a full turn; if it is in degrees, it is {:.6} rad",
            worst.to_radians()
        )
    })
}

/// What one run found, gathered chunk by chunk ([`RunReport::add_readings`],
/// [`RunReport::add_turns`]) and merged across chunks and runs. The default has no ranges (none
/// clipped) and nothing counted.
#[derive(Clone, Debug, PartialEq)]
pub struct RunReport {
    /// Readings measured.
    pub samples: u64,
    /// Readings at the measurement range (clipped), per sensor (accelerometer, gyroscope,
    /// magnetometer) and axis.
    pub clipped: [[u64; 3]; 3],
    /// The measurement ranges, per sensor (infinite: none).
    pub ranges: [f64; 3],
    /// From this magnitude on a reading counts as clipped: the range less half a quantisation
    /// step, per sensor.
    pub clip_at: [f64; 3],
    /// The largest angle the body turned between two consecutive samples, rad.
    pub max_turn_per_sample_rad: f64,
}

impl Default for RunReport {
    fn default() -> Self {
        Self {
            samples: 0,
            clipped: [[0; 3]; 3],
            ranges: [f64::INFINITY; 3],
            clip_at: [f64::INFINITY; 3],
            max_turn_per_sample_rad: 0.0,
        }
    }
}

impl RunReport {
    /// A report for the sensors of `params`, nothing counted yet.
    #[must_use]
    pub fn for_sensors(params: &ImuParams) -> Self {
        let sensors = [
            &params.accelerometer,
            &params.gyroscope,
            &params.magnetometer,
        ];
        Self {
            ranges: sensors.map(|s| s.measurement_range),
            clip_at: sensors.map(|s| {
                let half_step = if s.resolution > 0.0 {
                    s.resolution / 2.0
                } else {
                    0.0
                };
                s.measurement_range - half_step
            }),
            ..Self::default()
        }
    }

    /// Counts the readings at their sensor's range.
    pub fn add_readings(&mut self, readings: &[ImuReading]) {
        self.samples += readings.len() as u64;
        for r in readings {
            for (s, values) in [r.accel_m_s2, r.gyro_rad_s, r.mag_ut].iter().enumerate() {
                if self.clip_at[s].is_finite() {
                    for (axis, v) in values.iter().enumerate() {
                        if v.abs() >= self.clip_at[s] {
                            self.clipped[s][axis] += 1;
                        }
                    }
                }
            }
        }
    }

    /// Notes the turn between consecutive samples: body-rate magnitudes `omega_rad_s` at times
    /// `t_s` (the trapezoid of the rates over each interval).
    pub fn add_turns(&mut self, t_s: &[f64], omega_rad_s: &[f64]) {
        for k in 1..t_s.len().min(omega_rad_s.len()) {
            let turn = 0.5 * (omega_rad_s[k] + omega_rad_s[k - 1]) * (t_s[k] - t_s[k - 1]);
            if turn > self.max_turn_per_sample_rad {
                self.max_turn_per_sample_rad = turn;
            }
        }
    }

    /// This report and `other` (the next chunk, or another run) as one.
    pub fn merge(&mut self, other: &Self) {
        if self.samples == 0 {
            self.ranges = other.ranges;
            self.clip_at = other.clip_at;
        }
        self.samples += other.samples;
        for (a, b) in self.clipped.iter_mut().zip(other.clipped) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
        self.max_turn_per_sample_rad = self
            .max_turn_per_sample_rad
            .max(other.max_turn_per_sample_rad);
    }

    /// What the user should be told, one sentence each.
    #[must_use]
    pub fn warnings(&self, sample_rate_hz: f64) -> Vec<String> {
        let mut out = Vec::new();
        let names = [
            ("accelerometer", "m/s²"),
            ("gyroscope", "rad/s"),
            ("magnetometer", "µT"),
        ];
        #[allow(
            clippy::cast_precision_loss,
            reason = "a share of samples, for a percentage"
        )]
        let share = |n: u64| 100.0 * n as f64 / self.samples.max(1) as f64;
        for (s, (name, unit)) in names.iter().enumerate() {
            let clipped = self.clipped[s];
            if clipped.iter().all(|&n| n == 0) {
                continue;
            }
            let axes: Vec<String> = ["x", "y", "z"]
                .iter()
                .zip(clipped)
                .filter(|(_, n)| *n > 0)
                .map(|(axis, n)| format!("{axis} {:.1} %", share(n)))
                .collect();
            out.push(format!(
                "the {name} saturated at its measurement range ±{} {unit}: clipped readings {} \
                 (of {} samples); the motion exceeds the part's range, or the range is too small",
                self.ranges[s],
                axes.join(", "),
                self.samples
            ));
        }
        if self.max_turn_per_sample_rad > MAX_TURN_PER_SAMPLE_RAD {
            out.push(format!(
                "rate_hz = {sample_rate_hz} is coarse for this motion: the body turns up to {:.3} \
                 rad between two samples (above {MAX_TURN_PER_SAMPLE_RAD}); the readings miss \
                 what happens between them",
                self.max_turn_per_sample_rad
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gyroscope_noise_density_in_degrees_per_root_hour_is_named_with_its_si_value() {
        let mut params = ImuParams::default();
        params.gyroscope.noise_density = [0.15; 3];
        let w = implausible_figures(&params);
        assert_eq!(w.len(), 1, "{w:?}");
        // 0.15 °/√h = 0.15 · π/180 / 60 rad/s/√Hz.
        let si = 0.15 * core::f64::consts::PI / 180.0 / 60.0;
        assert!(w[0].contains(&format!("{si:.4e}")), "{}", w[0]);
        assert!(
            w[0].starts_with("imu.gyroscope.noise_density: 0.15 rad/s/√Hz"),
            "{}",
            w[0]
        );
        params.gyroscope.noise_density = [0.005; 3];
        assert!(implausible_figures(&params).is_empty());
    }

    #[test]
    fn clipped_readings_are_counted_per_axis_within_half_a_step_of_the_range() {
        let mut params = ImuParams::default();
        params.accelerometer.measurement_range = 19.6;
        params.accelerometer.resolution = 0.1;
        let mut report = RunReport::for_sensors(&params);
        let reading = |a: [f64; 3]| ImuReading {
            accel_m_s2: a,
            ..ImuReading::default()
        };
        report.add_readings(&[
            reading([19.6, 0.0, -19.6]),
            reading([19.5, 19.0, -19.56]),
            reading([0.0, 0.0, 0.0]),
            reading([-19.6, 0.0, 0.0]),
        ]);
        assert_eq!(report.clipped[0], [2, 0, 2]);
        assert_eq!(report.clipped[1], [0, 0, 0]);
        let w = report.warnings(100.0);
        assert_eq!(w.len(), 1);
        assert!(w[0].contains("x 50.0 %, z 50.0 %"), "{}", w[0]);
    }

    #[test]
    fn a_turn_per_sample_beyond_the_limit_is_reported() {
        let mut report = RunReport::default();
        report.add_turns(&[0.0, 0.1, 0.2], &[1.0, 1.0, 3.0]);
        assert!((report.max_turn_per_sample_rad - 0.2).abs() < 1e-15);
        assert!(report.warnings(10.0).is_empty());
        report.add_turns(&[0.0, 1.0], &[1.0, 1.0]);
        assert_eq!(report.warnings(1.0).len(), 1);
    }

    #[test]
    fn degrees_where_radians_are_read_are_named() {
        let w = angles_beyond_a_turn("euler0_rad", &[90.0, 0.0, 0.0]).unwrap();
        assert!(w.contains("1.570796 rad"), "{w}");
        assert!(angles_beyond_a_turn("euler0_rad", &[3.0, -6.0, 0.0]).is_none());
    }
}
