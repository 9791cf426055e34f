//! Sensor parameter files: imukit's own (TOML or JSON, every key with its unit) and MATLAB's
//! `loadparams` JSON, read as MATLAB reads it.
//!
//! imukit's keys, with `U` the measurand's unit — `m_s2` (accelerometer), `rad_s` (gyroscope),
//! `ut` (magnetometer):
//!
//! | key | meaning | value |
//! |---|---|---|
//! | `measurement_range_U` | saturation | number or `"inf"` |
//! | `resolution_U` | quantisation step per LSB | number |
//! | `constant_bias_U` | bias | number or `[x, y, z]` |
//! | `axes_misalignment_pct` | misalignment, % | number s, `[a, b, c]` or 3×3 (MATLAB's forms) |
//! | `noise_density_U_per_rt_hz` | white noise density | number or 3-vector |
//! | `bias_instability_U` | bias instability | number or 3-vector |
//! | `bias_instability_numerator`, `bias_instability_denominator` | MATLAB's filter | lists |
//! | `bias_instability_flicker_tau_s` | flicker floor 0.664·B over `[τ_min, τ_max]` | 2 numbers |
//! | `bias_instability_correlation_time_s` | Gauss–Markov instead | number |
//! | `random_walk_U_rt_hz` | rate random walk, U·√Hz | number or 3-vector |
//! | `noise_type` | `"single-sided"` (default) or `"double-sided"` | string |
//! | `temperature_bias_U_per_c` | bias per °C from 25 °C | number or 3-vector |
//! | `temperature_scale_factor_pct_per_c` | scale factor per °C, % | number or 3-vector |
//! | `acceleration_bias_rad_s_per_m_s2` | gyroscope g-sensitivity | number or 3-vector |
//! | `quantization_carry` | carry quantisation residuals to the next sample | `true`/`false` |
//! | `scale_factor_nonlinearity_per_U` | second-order nonlinearity `K₂` (reads `u + K₂u²`), 1/U | number or 3-vector |
//! | `scale_factor_asymmetry_pct` | scale factor for `u > 0` over `u < 0`, % of the mean | number or 3-vector |
//! | `acceleration_squared_bias_rad_s_per_m2_s4` | gyroscope g²-sensitivity | number or 3-vector |
//!
//! MATLAB's names (`MeasurementRange`, `Resolution`, `ConstantBias`, `AxesMisalignment`,
//! `NoiseDensity`, `BiasInstability`, `BiasInstabilityCoefficients` with `Numerator` and
//! `Denominator`, `RandomWalk`, `NoiseType`, `TemperatureBias`, `TemperatureScaleFactor`,
//! `AccelerationBias`) are accepted in the same tables, in SI units as MATLAB takes them, and
//! in the same style the terms MATLAB lacks (`ScaleFactorNonlinearity`, `ScaleFactorAsymmetry`
//! in %, `AccelerationSquaredBias`).
use std::collections::BTreeMap;

use imu_core::AccelSign;
use imu_core::sensor::{GyroAccelerationInput, NoiseType};
use serde::{Deserialize, Serialize};

use crate::sensor::SensorParams;

mod sensor;

pub use sensor::parse_sensor;
pub(crate) use sensor::parse_sensor_keys;

/// A value as written in a parameter or scenario file or handed over from Python: a boolean, an
/// integer, a number (infinity allowed where the key allows it; TOML writes `inf`, MATLAB's
/// JSON `"inf"`), a string, a list (vectors, 3×3 matrices, filter coefficients) or a table of
/// named values. Typed all the way from the file or the Python object: no value passes through
/// JSON text (which has no infinity).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// `true`/`false`.
    Bool(bool),
    /// An integer (a seed, a count), exactly, of up to 128 bits: every `i64` and `u64` a file or
    /// Python holds (a seed may be any `u64`); also a number where one is expected.
    Integer(i128),
    /// A number.
    Number(f64),
    /// A string (`"inf"`, `"single-sided"`).
    Text(String),
    /// A list of values.
    List(Vec<ParamValue>),
    /// Named values (a sensor's parameters, MATLAB's `BiasInstabilityCoefficients`).
    Table(BTreeMap<String, ParamValue>),
    /// JSON's `null`.
    Null,
}

/// The deepest a tree of values may nest, lists and tables counted: a scenario needs six levels
/// (scenario, `imu`, a sensor, `BiasInstabilityCoefficients`, `Numerator`, a number). Front
/// ends that build trees from their own objects refuse deeper ones before reading on (a tree is
/// read, and dropped, by recursion: ten thousand levels overflowed the stack); the file parsers
/// have limits of their own (JSON 128 levels, TOML fewer).
pub const MAX_DEPTH: usize = 64;

/// One sensor's parameters by name (imukit's unit-suffixed keys or MATLAB's property names).
pub type SensorTable = BTreeMap<String, ParamValue>;

impl ParamValue {
    /// True for a list.
    #[must_use]
    pub fn is_list(&self) -> bool {
        matches!(self, Self::List(_))
    }

    /// The string, when this is one.
    #[must_use]
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Self::Text(s) => Some(s),
            _ => None,
        }
    }
}

/// Read by the value's own kind (`deserialize_any`), as `serde_json::Value` is: an untagged enum
/// would buffer each value and try the variants in turn, formatting an error message for each
/// that fails: more than half of the time a Python call spent reading its scenario dict, a third
/// of a short call's time in Rust (the formula job at 10 samples, in a profile).
impl<'de> Deserialize<'de> for ParamValue {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        deserializer.deserialize_any(ParamValueVisitor)
    }
}

struct ParamValueVisitor;

impl<'de> serde::de::Visitor<'de> for ParamValueVisitor {
    type Value = ParamValue;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a boolean, number, string, list, table or null")
    }

    fn visit_bool<E>(self, v: bool) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Integer(v.into()))
    }

    fn visit_u64<E>(self, v: u64) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Integer(v.into()))
    }

    fn visit_i128<E>(self, v: i128) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Integer(v))
    }

    /// An integer beyond `i128` is kept as the nearest number.
    fn visit_u128<E>(self, v: u128) -> std::result::Result<ParamValue, E> {
        Ok(i128::try_from(v).map_or(ParamValue::Number(v as f64), ParamValue::Integer))
    }

    fn visit_f64<E>(self, v: f64) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Number(v))
    }

    fn visit_str<E>(self, v: &str) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Text(v.to_owned()))
    }

    fn visit_string<E>(self, v: String) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Text(v))
    }

    fn visit_unit<E>(self) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Null)
    }

    fn visit_none<E>(self) -> std::result::Result<ParamValue, E> {
        Ok(ParamValue::Null)
    }

    fn visit_some<D: serde::Deserializer<'de>>(
        self,
        deserializer: D,
    ) -> std::result::Result<ParamValue, D::Error> {
        ParamValue::deserialize(deserializer)
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> std::result::Result<ParamValue, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(ParamValue::List(items))
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<ParamValue, A::Error> {
        let mut table = BTreeMap::new();
        while let Some((key, value)) = map.next_entry::<String, ParamValue>()? {
            table.insert(key, value);
        }
        Ok(ParamValue::Table(table))
    }
}

impl std::fmt::Display for ParamValue {
    /// Written as JSON writes it, for messages.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Bool(b) => write!(f, "{b}"),
            Self::Integer(i) => write!(f, "{i}"),
            Self::Number(x) => write!(f, "{x:?}"),
            Self::Text(t) => write!(f, "{t:?}"),
            Self::Null => write!(f, "null"),
            Self::List(l) => {
                write!(f, "[")?;
                for (k, v) in l.iter().enumerate() {
                    write!(f, "{}{v}", if k == 0 { "" } else { "," })?;
                }
                write!(f, "]")
            }
            Self::Table(t) => {
                write!(f, "{{")?;
                for (k, (name, v)) in t.iter().enumerate() {
                    write!(f, "{}{name:?}:{v}", if k == 0 { "" } else { "," })?;
                }
                write!(f, "}}")
            }
        }
    }
}

/// The three sensors of an IMU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensor {
    /// Accelerometer (m/s²).
    Accelerometer,
    /// Gyroscope (rad/s).
    Gyroscope,
    /// Magnetometer (µT).
    Magnetometer,
}

impl Sensor {
    /// All three, in the order of the random-number draws.
    pub const ALL: [Self; 3] = [Self::Accelerometer, Self::Gyroscope, Self::Magnetometer];

    /// Table name in parameter files (`accelerometer`, …).
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Accelerometer => "accelerometer",
            Self::Gyroscope => "gyroscope",
            Self::Magnetometer => "magnetometer",
        }
    }

    /// MATLAB's name (`Accelerometer`, …).
    #[must_use]
    pub fn matlab_key(self) -> &'static str {
        match self {
            Self::Accelerometer => "Accelerometer",
            Self::Gyroscope => "Gyroscope",
            Self::Magnetometer => "Magnetometer",
        }
    }

    /// Unit suffix of the measurand in key names.
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Self::Accelerometer => "m_s2",
            Self::Gyroscope => "rad_s",
            Self::Magnetometer => "ut",
        }
    }
}

/// Parameters of the three sensors.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuParams {
    /// Accelerometer.
    pub accelerometer: SensorParams,
    /// Gyroscope.
    pub gyroscope: SensorParams,
    /// Magnetometer.
    pub magnetometer: SensorParams,
}

impl ImuParams {
    /// The parameters of `sensor`.
    #[must_use]
    pub fn get(&self, sensor: Sensor) -> &SensorParams {
        match sensor {
            Sensor::Accelerometer => &self.accelerometer,
            Sensor::Gyroscope => &self.gyroscope,
            Sensor::Magnetometer => &self.magnetometer,
        }
    }

    /// The parameters of `sensor`, mutable.
    pub fn get_mut(&mut self, sensor: Sensor) -> &mut SensorParams {
        match sensor {
            Sensor::Accelerometer => &mut self.accelerometer,
            Sensor::Gyroscope => &mut self.gyroscope,
            Sensor::Magnetometer => &mut self.magnetometer,
        }
    }
}

/// Conventions that differ between imukit's defaults and MATLAB's imuSensor.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Profile {
    /// Single-sided noise densities, specific-force sign, gyro g-sensitivity to the body-frame
    /// specific force.
    #[default]
    Default,
    /// MATLAB imuSensor: double-sided, gravity-minus-acceleration sign, g-sensitivity to the raw
    /// navigation-frame acceleration, bias-instability filter `[1], [1, −0.5]`.
    Matlab,
}

impl crate::choice::Choice for Profile {
    const WHAT: &'static str = "profile";
    const NAMES: &'static [(&'static str, Self)] =
        &[("default", Self::Default), ("matlab", Self::Matlab)];
}

impl Profile {
    /// The noise type a sensor gets when its table does not say.
    #[must_use]
    pub fn noise_type(self) -> NoiseType {
        match self {
            Self::Default => NoiseType::SingleSided,
            Self::Matlab => NoiseType::DoubleSided,
        }
    }
    /// The accelerometer sign when the scenario does not say.
    #[must_use]
    pub fn accel_sign(self) -> AccelSign {
        match self {
            Self::Default => AccelSign::SpecificForce,
            Self::Matlab => AccelSign::Matlab,
        }
    }
    /// What the gyroscope's AccelerationBias multiplies.
    #[must_use]
    pub fn gyro_acceleration(self) -> GyroAccelerationInput {
        match self {
            Self::Default => GyroAccelerationInput::BodySpecificForce,
            Self::Matlab => GyroAccelerationInput::NavAcceleration,
        }
    }
}
