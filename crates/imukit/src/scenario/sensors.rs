//! The realistic-sensor part of a scenario's `[imu]` table, resolved: parameters (preset,
//! parameter file, inline tables), profile, seed and temperature.
//!
//! ```toml
//! [imu]
//! kind = "accel-gyro-mag"
//! profile = "default"          # or "matlab"
//! seed = 67
//! temperature_c = 35.0         # or a CSV file: t_s, temperature_c (or accel_/gyro_/mag_temperature_c)
//! preset = "ideal"             # or params = "my_imu.toml" / "matlab_params.json" (part = "…")
//! [imu.gyroscope]              # inline tables override the preset or file key by key
//! noise_density_rad_s_per_rt_hz = 1e-4
//! [[imu.perturbations]]        # Monte Carlo: drawn per run (see `perturb`)
//! parameter = "gyroscope.constant_bias_rad_s"
//! distribution = "normal"
//! mean = 0.0
//! std = 0.01
//! ```
use std::path::{Path, PathBuf};

use imu_core::sensor::{GyroAccelerationInput, ImuReading, Temperatures};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::io::chain::PartChains;
use crate::io::params::{ImuParams, Profile, Sensor, parse_sensor};
use crate::io::part_file::read_param_file;
use crate::io::presets;
use crate::io::read::read_columns;
use crate::scenario::perturb::Perturbation;
use crate::scenario::resolve::check_temperature;
use crate::scenario::spec::{ImuSpec, NumberOrText, number_or_text};

/// `temperature_c`: a constant, or a CSV file of a temperature profile.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum TemperatureSpec {
    /// The same temperature throughout, °C.
    Constant(f64),
    /// A CSV file with `t_s` and `temperature_c`, or per sensor `accel_temperature_c`,
    /// `gyro_temperature_c`, `mag_temperature_c` (missing ones fall back to `temperature_c`).
    File(PathBuf),
}

impl<'de> Deserialize<'de> for TemperatureSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let expecting = "a temperature in °C, or the path of a CSV file of temperatures";
        Ok(match number_or_text(d, expecting)? {
            NumberOrText::Number(v) => Self::Constant(v),
            NumberOrText::Text(s) => Self::File(s.into()),
        })
    }
}

/// Sensor temperatures over time.
#[derive(Clone, Debug, PartialEq)]
pub enum Temperature {
    /// Constant, °C.
    Constant(f64),
    /// Linear interpolation of a profile (held at its ends).
    Profile {
        /// Times, s, increasing.
        t_s: Vec<f64>,
        /// Accelerometer, gyroscope, magnetometer temperatures, °C.
        values: [Vec<f64>; 3],
    },
}

impl Default for Temperature {
    fn default() -> Self {
        Self::Constant(25.0)
    }
}

impl Temperature {
    /// The temperatures at time `t` (s).
    #[must_use]
    pub fn at(&self, t: f64) -> Temperatures {
        match self {
            Self::Constant(c) => Temperatures::uniform(*c),
            Self::Profile { t_s, values } => {
                let k = t_s.partition_point(|&x| x <= t);
                let interp = |v: &[f64]| {
                    if k == 0 {
                        v[0]
                    } else if k >= t_s.len() {
                        v[t_s.len() - 1]
                    } else {
                        let w = (t - t_s[k - 1]) / (t_s[k] - t_s[k - 1]);
                        v[k - 1] + w * (v[k] - v[k - 1])
                    }
                };
                Temperatures {
                    accel_c: interp(&values[0]),
                    gyro_c: interp(&values[1]),
                    mag_c: interp(&values[2]),
                }
            }
        }
    }

    /// Reads a temperature profile file.
    ///
    /// # Errors
    /// Missing columns, bad values, times that do not increase.
    pub fn from_csv(path: &Path) -> Result<Self> {
        let header = crate::io::read::read_header(path)?;
        let has = |c: &str| header.iter().any(|h| h == c);
        let per = [
            "accel_temperature_c",
            "gyro_temperature_c",
            "mag_temperature_c",
        ];
        let mut required = vec!["t_s"];
        if has("temperature_c") {
            required.push("temperature_c");
        }
        required.extend(per.iter().filter(|c| has(c)));
        if required.len() == 1 {
            required.push("temperature_c");
        }
        let cols = read_columns(
            path,
            &required,
            "; give temperature_c or accel_/gyro_/mag_temperature_c",
        )?;
        let t = cols.get("t_s").to_vec();
        if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            return Err(invalid(
                format!("{}, row {}", path.display(), i + 2),
                "t_s does not increase",
            ));
        }
        let col = |name: &str| {
            if has(name) {
                cols.get(name).to_vec()
            } else {
                cols.get("temperature_c").to_vec()
            }
        };
        Ok(Self::Profile {
            t_s: t,
            values: [col(per[0]), col(per[1]), col(per[2])],
        })
    }
}

/// The sensors of a scenario, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorSetup {
    /// Error parameters.
    pub params: ImuParams,
    /// Profile.
    pub profile: Profile,
    /// What the gyroscope's AccelerationBias multiplies.
    pub gyro_acceleration: GyroAccelerationInput,
    /// Seed of the noise stream.
    pub seed: u64,
    /// Temperatures over time.
    pub temperature: Temperature,
    /// Monte Carlo perturbations of the parameters.
    pub perturbations: Vec<Perturbation>,
    /// Each Monte Carlo run draws its own part of this type (see
    /// [`crate::scenario::perturb::drawn_part`]), after the perturbations; off: every run
    /// simulates the same part (MATLAB's fixed parameters). An outage study turns it on.
    pub draw_parts: bool,
    /// What a MATLAB parameter file had that was skipped, for the front end to show.
    pub warnings: Vec<String>,
    /// The part's signal-chain settings (its file's `[chain]`), when it has them, and what the
    /// part is (`preset mpu-6050`, `params my_imu.toml`) for messages.
    pub part_chains: (Option<PartChains>, String),
}

impl Default for SensorSetup {
    fn default() -> Self {
        Self {
            params: ImuParams::default(),
            profile: Profile::Default,
            gyro_acceleration: Profile::Default.gyro_acceleration(),
            seed: 0,
            temperature: Temperature::default(),
            perturbations: Vec::new(),
            draw_parts: false,
            warnings: Vec::new(),
            part_chains: (None, "the ideal IMU".into()),
        }
    }
}

impl SensorSetup {
    /// Resolves the sensor keys; relative files are taken from `base_dir`.
    ///
    /// # Errors
    /// Unknown presets, unreadable or invalid parameter files, invalid inline parameters,
    /// temperature files — each named.
    pub fn resolve(keys: &ImuSpec, base_dir: &Path) -> Result<Self> {
        let profile = keys.profile.unwrap_or_default();
        let file = match (keys.preset.as_deref(), keys.params.as_deref()) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "imu.preset",
                    "give either preset or params, not both",
                ));
            }
            (Some(name), None) => Some(presets::load(name)?),
            (None, Some(path)) => Some(read_param_file(
                &base_dir.join(path),
                keys.part.as_deref(),
                profile,
            )?),
            (None, None) => {
                if keys.part.is_some() {
                    return Err(invalid("imu.part", "part needs params = \"file.json\""));
                }
                None
            }
        };
        let mut params = file.as_ref().map(|f| f.params.clone()).unwrap_or_default();
        for (i, sensor) in Sensor::ALL.iter().enumerate() {
            let from_file = file.as_ref().is_some_and(|f| f.present[i]);
            if !from_file {
                params.get_mut(*sensor).noise_type = profile.noise_type();
            }
            let table = [&keys.accelerometer, &keys.gyroscope, &keys.magnetometer][i];
            if let Some(table) = table {
                let default_noise = if from_file {
                    None
                } else {
                    Some(profile.noise_type())
                };
                let base = params.get(*sensor).clone();
                *params.get_mut(*sensor) = parse_sensor(
                    table,
                    *sensor,
                    &format!("imu.{}", sensor.key()),
                    default_noise,
                    base,
                )?;
            }
        }
        let temperature = match &keys.temperature_c {
            None => Temperature::default(),
            Some(TemperatureSpec::Constant(c)) => {
                Temperature::Constant(check_temperature("imu.temperature_c", *c)?)
            }
            Some(TemperatureSpec::File(p)) => Temperature::from_csv(&base_dir.join(p))?,
        };
        Ok(Self {
            params,
            profile,
            gyro_acceleration: profile.gyro_acceleration(),
            seed: keys.seed.unwrap_or(0),
            temperature,
            perturbations: keys
                .perturbations
                .iter()
                .flatten()
                .enumerate()
                .map(|(i, p)| Perturbation::from_spec(p, i))
                .collect::<Result<_>>()?,
            draw_parts: false,
            part_chains: (
                file.as_ref().and_then(|f| f.chain.clone()),
                match (keys.preset.as_deref(), keys.params.as_deref()) {
                    (Some(name), _) => format!("preset {name}"),
                    (_, Some(path)) => format!("params {}", path.display()),
                    _ => "the IMU without a preset or params".into(),
                },
            ),
            warnings: file.map(|f| f.warnings).unwrap_or_default(),
        })
    }
}

/// Converts an ideal reading to the shape of a sensor reading.
#[must_use]
pub fn ideal_as_reading(r: &imu_core::IdealReading) -> ImuReading {
    ImuReading {
        accel_m_s2: r.accel_m_s2.to_array(),
        gyro_rad_s: r.gyro_rad_s.to_array(),
        mag_ut: r.mag_ut.to_array(),
    }
}
