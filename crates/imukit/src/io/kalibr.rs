//! Kalibr's IMU noise file (`imu.yaml`): the four figures Kalibr's camera–IMU calibration takes
//! (and with it most visual–inertial estimators' settings), written from a parameter file.
//!
//! Kalibr's figures are continuous-time, single-sided: a white-noise density `σ_c` whose discrete
//! standard deviation is `σ_c·√f_s`, and a bias random walk `σ_b` whose step is `σ_b/√f_s`
//! (Kalibr wiki, "IMU Noise Model"). imukit's single-sided densities are the same figures; a
//! double-sided file's (MATLAB's convention, bandwidth `f_s/2`) are turned into them: `N/√2` and
//! `K·√2`. Kalibr takes one figure per sensor: the largest axis is written.
//!
//! Kalibr has no bias-instability term. When a part gives none of its bias drift as a random walk
//! but has a bias instability, the random walk written is the one that drift implies:
//! - flicker with its floor `0.664·B` up to `τ₂`: the random walk whose Allan deviation
//!   `K·√(τ/3)` reaches that floor at `τ₂`, `K = 0.664·B·√(3/τ₂)` (below the floor before `τ₂`, the
//!   drift beyond it);
//! - Gauss–Markov of steady deviation `B` and correlation time `T`: its driving noise,
//!   `K = B·√(2/T)` (the random walk it follows over times short against `T`).
//!
//! MATLAB's default bias-instability filter is short-memory noise (white under Allan analysis):
//! it implies no random walk. Every such choice is stated in the file's comments.
use crate::error::{Error, Result};
use crate::io::params::{ParamFile, Sensor};
use imu_core::allan::BIAS_INSTABILITY_FACTOR;
use imu_core::sensor::{BiasInstabilityModel, FilterBuffer, NoiseType, SensorParams};

/// The topic written when none is given: imukit's IMU topic in a ROS bag.
pub const DEFAULT_TOPIC: &str = "/imu";

/// The rate written when none is given, Hz (Kalibr's own example file's); the rate is the
/// logger's, so a user sets it.
pub const DEFAULT_RATE_HZ: f64 = 200.0;

/// Kalibr's figures for one sensor (SI units) and what was done to reach them.
#[derive(Clone, Debug, PartialEq)]
pub struct KalibrSensor {
    /// White-noise density, unit/√Hz (`unit` = rad/s or m/s²).
    pub noise_density: f64,
    /// Bias random walk, unit·√Hz.
    pub random_walk: f64,
    /// How the figures were reached, for the file's comments.
    pub notes: Vec<String>,
}

/// The contents of a Kalibr `imu.yaml`.
#[derive(Clone, Debug, PartialEq)]
pub struct KalibrImu {
    /// The accelerometer's figures (m/s²/√Hz, m/s³/√Hz).
    pub accelerometer: KalibrSensor,
    /// The gyroscope's figures (rad/s/√Hz, rad/s²/√Hz).
    pub gyroscope: KalibrSensor,
    /// The IMU's rate, Hz.
    pub update_rate_hz: f64,
    /// The IMU's topic.
    pub rostopic: String,
    /// The part's name, where the file has one.
    pub name: Option<String>,
}

/// `x` as a YAML 1.1 float (what PyYAML, which Kalibr reads with, takes for one: a point in the
/// mantissa, a sign in the exponent), seven significant digits.
fn yaml_float(x: f64) -> String {
    if x == 0.0 {
        return "0.0".to_owned();
    }
    let text = format!("{x:.6e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) if !exponent.starts_with('-') => {
            format!("{mantissa}e+{exponent}")
        }
        _ => text,
    }
}

fn largest(v: [f64; 3]) -> f64 {
    v.into_iter().fold(0.0, f64::max)
}

fn sensor<B: FilterBuffer>(p: &SensorParams<B>, unit: &str) -> KalibrSensor {
    let mut notes = Vec::new();
    let (n, k) = (largest(p.noise_density), largest(p.random_walk));
    if p.noise_density.iter().any(|&x| x != n) || p.random_walk.iter().any(|&x| x != k) {
        notes.push("the axes differ: the largest axis is written".to_owned());
    }
    // The same discrete noise over the whole rate: N·√(share·fs) = σ_c·√fs, K/√(share·fs) = σ_b/√fs.
    let root_share = p.noise_type.bandwidth_share().sqrt();
    let (noise_density, mut random_walk) = (n * root_share, k / root_share);
    if p.noise_type == NoiseType::DoubleSided {
        notes.push("double-sided densities turned single-sided (N/√2, K·√2)".to_owned());
    }
    let b = largest(p.bias_instability);
    if random_walk == 0.0 && b > 0.0 {
        match &p.bias_instability_model {
            BiasInstabilityModel::Flicker { tau_max_s, .. } => {
                random_walk = BIAS_INSTABILITY_FACTOR * b * (3.0 / tau_max_s).sqrt();
                notes.push(format!(
                    "random walk from the bias instability B = {b:.6e} {unit} (flicker floor \
                     0.664·B up to τ₂ = {tau_max_s} s): K = 0.664·B·√(3/τ₂)"
                ));
            }
            BiasInstabilityModel::GaussMarkov { correlation_time_s } => {
                random_walk = b * (2.0 / correlation_time_s).sqrt();
                notes.push(format!(
                    "random walk from the Gauss–Markov bias instability B = {b:.6e} {unit}, \
                     T = {correlation_time_s} s: K = B·√(2/T)"
                ));
            }
            BiasInstabilityModel::Filter(_) => notes.push(
                "the bias instability's MATLAB filter is short-memory noise: no random walk \
                 follows from it"
                    .to_owned(),
            ),
        }
    }
    if random_walk == 0.0 {
        notes.push(
            "random walk 0: the part gives no bias drift, and Kalibr and most estimators need a \
             positive value: set one"
                .to_owned(),
        );
    }
    KalibrSensor {
        noise_density,
        random_walk,
        notes,
    }
}

impl KalibrImu {
    /// Kalibr's figures of a parameter file's accelerometer and gyroscope, at `update_rate_hz`
    /// on `rostopic`.
    ///
    /// # Errors
    /// A rate that is not finite and positive, a file without an accelerometer or gyroscope.
    pub fn from_params(file: &ParamFile, update_rate_hz: f64, rostopic: &str) -> Result<Self> {
        if !(update_rate_hz.is_finite() && update_rate_hz > 0.0) {
            return Err(Error::Invalid {
                field: "rate_hz".into(),
                message: format!("must be a finite rate above 0 Hz, got {update_rate_hz}"),
            });
        }
        for (s, present) in Sensor::ALL.iter().zip(file.present) {
            if *s != Sensor::Magnetometer && !present {
                return Err(Error::Invalid {
                    field: s.key().into(),
                    message: "Kalibr's IMU file needs an accelerometer and a gyroscope".into(),
                });
            }
        }
        Ok(Self {
            accelerometer: sensor(&file.params.accelerometer, "m/s²"),
            gyroscope: sensor(&file.params.gyroscope, "rad/s"),
            update_rate_hz,
            rostopic: rostopic.to_owned(),
            name: file.info.get("name").cloned(),
        })
    }

    /// The file's text (YAML, comments stating the units and every choice made).
    #[must_use]
    pub fn to_yaml(&self) -> String {
        let mut s = String::from("# Kalibr IMU noise model (imu.yaml), written by imukit");
        if let Some(name) = &self.name {
            s += &format!(" from {name}");
        }
        s += "\n# continuous-time, single-sided figures: discrete σ = density·√rate, bias step = \
              random walk/√rate\n";
        for (sensor, what) in [
            (&self.accelerometer, "accelerometer"),
            (&self.gyroscope, "gyroscope"),
        ] {
            for note in &sensor.notes {
                s += &format!("# {what}: {note}\n");
            }
        }
        let num = yaml_float;
        s += &format!("rostopic: {}\n", self.rostopic);
        s += &format!(
            "update_rate: {}  # Hz: the logger's rate (imukit presets … --rate-hz)\n",
            if self.update_rate_hz.fract() == 0.0 && self.update_rate_hz < 1e9 {
                format!("{:.1}", self.update_rate_hz)
            } else {
                yaml_float(self.update_rate_hz)
            }
        );
        s += &format!(
            "accelerometer_noise_density: {}  # m/s^2/sqrt(Hz)\n",
            num(self.accelerometer.noise_density)
        );
        s += &format!(
            "accelerometer_random_walk: {}  # m/s^3/sqrt(Hz)\n",
            num(self.accelerometer.random_walk)
        );
        s += &format!(
            "gyroscope_noise_density: {}  # rad/s/sqrt(Hz)\n",
            num(self.gyroscope.noise_density)
        );
        s += &format!(
            "gyroscope_random_walk: {}  # rad/s^2/sqrt(Hz)\n",
            num(self.gyroscope.random_walk)
        );
        s
    }
}
