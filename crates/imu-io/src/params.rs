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
//!
//! MATLAB's names (`MeasurementRange`, `Resolution`, `ConstantBias`, `AxesMisalignment`,
//! `NoiseDensity`, `BiasInstability`, `BiasInstabilityCoefficients` with `Numerator` and
//! `Denominator`, `RandomWalk`, `NoiseType`, `TemperatureBias`, `TemperatureScaleFactor`,
//! `AccelerationBias`) are accepted in the same tables, in SI units as MATLAB takes them.
use std::collections::BTreeMap;
use std::path::Path;

use imu_core::AccelSign;
use imu_core::sensor::{GyroAccelerationInput, NoiseType};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, invalid};
use crate::sensor::{BiasInstabilityModel, FilterCoefficients, SensorParams};

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

fn as_number(v: &ParamValue, field: &str) -> Result<f64> {
    match v {
        ParamValue::Number(x) if x.is_nan() => Err(invalid(field, "not a finite number (NaN)")),
        ParamValue::Number(x) => Ok(*x),
        #[allow(clippy::cast_precision_loss)]
        ParamValue::Integer(i) => Ok(*i as f64),
        ParamValue::Text(s)
            if matches!(s.to_ascii_lowercase().as_str(), "inf" | "infinity" | "+inf") =>
        {
            Ok(f64::INFINITY)
        }
        other => Err(invalid(field, format!("expected a number, got {other}"))),
    }
}

fn finite_number(v: &ParamValue, field: &str) -> Result<f64> {
    let x = as_number(v, field)?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(field, "must be finite"))
    }
}

/// A number (same on every axis) or a 3-vector.
fn triple(v: &ParamValue, field: &str) -> Result<[f64; 3]> {
    match v {
        ParamValue::List(a) if a.len() == 3 => Ok([
            finite_number(&a[0], &format!("{field}[0]"))?,
            finite_number(&a[1], &format!("{field}[1]"))?,
            finite_number(&a[2], &format!("{field}[2]"))?,
        ]),
        ParamValue::List(a) => Err(invalid(
            field,
            format!("expected a number or 3 numbers, got {} values", a.len()),
        )),
        other => Ok([finite_number(other, field)?; 3]),
    }
}

/// MATLAB's AxesMisalignment forms: scalar, 3-vector or 3×3, percent.
fn misalignment(v: &ParamValue, field: &str) -> Result<[[f64; 3]; 3]> {
    match v {
        // MATLAB also takes a 3×1 column for the 3-vector form.
        ParamValue::List(rows)
            if rows.len() == 3
                && rows
                    .iter()
                    .all(|r| matches!(r, ParamValue::List(c) if c.len() == 1)) =>
        {
            let column: Vec<ParamValue> = rows
                .iter()
                .filter_map(|r| match r {
                    ParamValue::List(c) => c.first().cloned(),
                    _ => None,
                })
                .collect();
            Ok(SensorParams::misalignment_from_vector(triple(
                &ParamValue::List(column),
                field,
            )?))
        }
        ParamValue::List(rows) if rows.len() == 3 && rows.iter().all(ParamValue::is_list) => {
            let mut m = [[0.0; 3]; 3];
            for (i, row) in rows.iter().enumerate() {
                m[i] = triple(row, &format!("{field}[{i}]"))?;
            }
            Ok(m)
        }
        ParamValue::List(_) => Ok(SensorParams::misalignment_from_vector(triple(v, field)?)),
        other => Ok(SensorParams::misalignment_from_scalar(finite_number(
            other, field,
        )?)),
    }
}

fn list(v: &ParamValue, field: &str) -> Result<Vec<f64>> {
    match v {
        ParamValue::List(a) => a
            .iter()
            .enumerate()
            .map(|(k, x)| finite_number(x, &format!("{field}[{k}]")))
            .collect(),
        other => Ok(vec![finite_number(other, field)?]),
    }
}

fn noise_type(v: &ParamValue, field: &str) -> Result<NoiseType> {
    match v.as_str().map(str::to_ascii_lowercase).as_deref() {
        Some("single-sided") => Ok(NoiseType::SingleSided),
        Some("double-sided") => Ok(NoiseType::DoubleSided),
        _ => Err(invalid(
            field,
            format!("expected \"single-sided\" or \"double-sided\", got {v}"),
        )),
    }
}

/// Parses one sensor table (imukit's or MATLAB's keys) onto `base`; `prefix` names the table in
/// messages (e.g. `imu.gyroscope`); `default_noise` is the noise type when the table has none
/// (`None` keeps `base`'s).
///
/// # Errors
/// Unknown keys (the known ones listed), bad values, invalid parameters — each named.
pub fn parse_sensor(
    map: &SensorTable,
    sensor: Sensor,
    prefix: &str,
    default_noise: Option<NoiseType>,
    base: SensorParams,
) -> Result<SensorParams> {
    parse_sensor_keys(map, sensor, prefix, default_noise, base, None)
}

/// [`parse_sensor`], skipping unknown keys into `skipped` when it is given (MATLAB's
/// `loadparams` ignores properties it does not know) instead of refusing them.
fn parse_sensor_keys(
    map: &SensorTable,
    sensor: Sensor,
    prefix: &str,
    default_noise: Option<NoiseType>,
    base: SensorParams,
    mut skipped: Option<&mut Vec<String>>,
) -> Result<SensorParams> {
    let u = sensor.unit();
    let key = |name: &str| format!("{name}_{u}");
    let mut p = base;
    let mut noise_set = false;
    let mut numerator: Option<Vec<f64>> = None;
    let mut denominator: Option<Vec<f64>> = None;
    let mut flicker: Option<[f64; 2]> = None;
    let mut correlation: Option<f64> = None;
    let known = [
        key("measurement_range"),
        key("resolution"),
        key("constant_bias"),
        "axes_misalignment_pct".into(),
        format!("noise_density_{u}_per_rt_hz"),
        key("bias_instability"),
        "bias_instability_numerator".into(),
        "bias_instability_denominator".into(),
        "bias_instability_flicker_tau_s".into(),
        "bias_instability_correlation_time_s".into(),
        format!("random_walk_{u}_rt_hz"),
        "noise_type".into(),
        format!("temperature_bias_{u}_per_c"),
        "temperature_scale_factor_pct_per_c".into(),
        "acceleration_bias_rad_s_per_m_s2".into(),
        "quantization_carry".into(),
    ];
    for (k, v) in map {
        let field = format!("{prefix}.{k}");
        let own = known.iter().position(|n| n == k);
        match (own, k.as_str()) {
            (Some(0), _) | (_, "MeasurementRange") => p.measurement_range = as_number(v, &field)?,
            (Some(1), _) | (_, "Resolution") => p.resolution = finite_number(v, &field)?,
            (Some(2), _) | (_, "ConstantBias") => p.constant_bias = triple(v, &field)?,
            (Some(3), _) | (_, "AxesMisalignment") => {
                p.axes_misalignment_pct = misalignment(v, &field)?
            }
            (Some(4), _) | (_, "NoiseDensity") => p.noise_density = triple(v, &field)?,
            (Some(5), _) | (_, "BiasInstability") => p.bias_instability = triple(v, &field)?,
            (Some(6), _) => numerator = Some(list(v, &field)?),
            (Some(7), _) => denominator = Some(list(v, &field)?),
            (_, "BiasInstabilityCoefficients") => {
                let ParamValue::Table(t) = v else {
                    return Err(invalid(field, "needs Numerator and Denominator"));
                };
                if let Some(other) = t
                    .keys()
                    .find(|k| !matches!(k.as_str(), "Numerator" | "Denominator"))
                {
                    return Err(invalid(
                        format!("{field}.{other}"),
                        "unknown key (BiasInstabilityCoefficients has Numerator and Denominator)",
                    ));
                }
                let get = |name: &str| {
                    t.get(name)
                        .map(|x| list(x, &format!("{field}.{name}")))
                        .transpose()
                };
                numerator = get("Numerator")?;
                denominator = get("Denominator")?;
                if numerator.is_none() || denominator.is_none() {
                    return Err(invalid(field, "needs Numerator and Denominator"));
                }
            }
            (Some(8), _) => {
                let l = list(v, &field)?;
                if l.len() != 2 {
                    return Err(invalid(field, "expected [tau_min_s, tau_max_s]"));
                }
                flicker = Some([l[0], l[1]]);
            }
            (Some(9), _) => correlation = Some(finite_number(v, &field)?),
            (Some(10), _) | (_, "RandomWalk") => p.random_walk = triple(v, &field)?,
            (Some(11), _) | (_, "NoiseType") => {
                p.noise_type = noise_type(v, &field)?;
                noise_set = true;
            }
            (Some(12), _) | (_, "TemperatureBias") => p.temperature_bias = triple(v, &field)?,
            (Some(13), _) | (_, "TemperatureScaleFactor") => {
                p.temperature_scale_factor_pct = triple(v, &field)?
            }
            (Some(15), _) => {
                let ParamValue::Bool(carry) = v else {
                    return Err(invalid(field, format!("expected true or false, got {v}")));
                };
                p.quantization_carry = *carry;
            }
            (Some(14), _) | (_, "AccelerationBias") if sensor == Sensor::Gyroscope => {
                p.acceleration_bias = triple(v, &field)?;
            }
            _ => {
                if let Some(list) = skipped.as_deref_mut() {
                    list.push(format!(
                        "{field}: unknown property, skipped (as MATLAB does)"
                    ));
                    continue;
                }
                return Err(invalid(
                    field,
                    format!(
                        "unknown parameter (known for the {}: {})",
                        sensor.key(),
                        known.join(", ")
                    ),
                ));
            }
        }
    }
    if let (false, Some(n)) = (noise_set, default_noise) {
        p.noise_type = n;
    }
    let chosen = [
        numerator.is_some() || denominator.is_some(),
        flicker.is_some(),
        correlation.is_some(),
    ];
    if chosen.iter().filter(|c| **c).count() > 1 {
        return Err(invalid(
            format!("{prefix}.bias_instability"),
            "give one of the filter coefficients, bias_instability_flicker_tau_s or bias_instability_correlation_time_s",
        ));
    }
    if numerator.is_some() || denominator.is_some() {
        let num = numerator.unwrap_or_else(|| vec![1.0]);
        let den = denominator.unwrap_or_else(|| vec![1.0, -0.5]);
        let c = FilterCoefficients::new(&num, &den).map_err(|source| Error::Param {
            context: prefix.into(),
            source,
        })?;
        p.bias_instability_model = BiasInstabilityModel::Filter(c);
    }
    if let Some([tau_min_s, tau_max_s]) = flicker {
        p.bias_instability_model = BiasInstabilityModel::Flicker {
            tau_min_s,
            tau_max_s,
        };
    }
    if let Some(correlation_time_s) = correlation {
        p.bias_instability_model = BiasInstabilityModel::GaussMarkov { correlation_time_s };
    }
    p.validate().map_err(|source| Error::Param {
        context: prefix.into(),
        source,
    })?;
    Ok(p)
}

/// A parameter file's content: the three sensors (missing ones ideal) and its description.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamFile {
    /// Parameters.
    pub params: ImuParams,
    /// Which sensors the file described.
    pub present: [bool; 3],
    /// `name`, `grade`, `source` and other descriptive strings from the file.
    pub info: BTreeMap<String, String>,
    /// The part's data-sheet figures (`[datasheet.<sensor>]`), when the file gives them.
    pub datasheet: Option<crate::datasheet::Datasheet>,
    /// What was skipped in a MATLAB file (keys MATLAB's `loadparams` ignores), for the front end
    /// to show as warnings.
    pub warnings: Vec<String>,
}

const INFO_KEYS: [&str; 4] = ["name", "grade", "source", "notes"];

/// Parses an imukit parameter document (`[accelerometer]`, `[gyroscope]`, `[magnetometer]`
/// tables and descriptive strings) given as a JSON value.
///
/// # Errors
/// As [`parse_sensor`]; unknown top-level keys.
pub fn parse_param_document(doc: &ParamValue, origin: &str, profile: Profile) -> Result<ParamFile> {
    parse_document(doc, origin, profile, false)
}

/// [`parse_param_document`]; `matlab` skips (with a warning) what MATLAB's `loadparams` skips:
/// keys of a part that are not sensors, and properties it does not know.
fn parse_document(
    doc: &ParamValue,
    origin: &str,
    profile: Profile,
    matlab: bool,
) -> Result<ParamFile> {
    let ParamValue::Table(map) = doc else {
        return Err(invalid(
            origin,
            "expected a table with accelerometer, gyroscope, magnetometer",
        ));
    };
    let mut out = ParamFile::default();
    for (k, v) in map {
        if let Some(i) = Sensor::ALL
            .iter()
            .position(|s| s.key() == k || s.matlab_key() == k)
        {
            let s = Sensor::ALL[i];
            let noise = Some(profile.noise_type());
            let ParamValue::Table(table) = v else {
                return Err(invalid(
                    format!("{origin}: {k}"),
                    "expected a table of parameters",
                ));
            };
            let skipped = matlab.then_some(&mut out.warnings);
            *out.params.get_mut(s) = parse_sensor_keys(
                table,
                s,
                &format!("{origin}: {k}"),
                noise,
                SensorParams::default(),
                skipped,
            )?;
            out.present[i] = true;
        } else if k == "datasheet" && !matlab {
            out.datasheet = Some(crate::datasheet::Datasheet::parse(
                v,
                &format!("{origin}: datasheet"),
            )?);
        } else if INFO_KEYS.contains(&k.as_str()) {
            out.info.insert(
                k.clone(),
                v.as_str().map_or_else(|| v.to_string(), str::to_string),
            );
        } else if matlab {
            out.warnings.push(format!(
                "{origin}: {k}: not a sensor, skipped (as MATLAB does)"
            ));
        } else {
            return Err(invalid(
                format!("{origin}: {k}"),
                "unknown key (expected accelerometer, gyroscope, magnetometer, name, grade, source, notes, datasheet)",
            ));
        }
    }
    // A data sheet given beside the parameters must say what they are: a range quoted as a
    // spread, or a figure the parameters do not follow, is refused rather than carried along.
    if let Some(sheet) = &out.datasheet {
        let problems = sheet.check(&out.params, out.present);
        if !problems.is_empty() {
            return Err(invalid(format!("{origin}: datasheet"), problems.join("; ")));
        }
    }
    Ok(out)
}

/// Reads a parameter file: imukit TOML or JSON, a MATLAB `loadparams` JSON (a part name
/// holding `Accelerometer`/`Gyroscope`/`Magnetometer`; `part` picks one of several parts), or
/// Kalibr's `imu.yaml` ([`crate::kalibr::read`]).
///
/// # Errors
/// Unreadable file, syntax errors with their line, unknown parts and keys, invalid values.
pub fn read_param_file(path: &Path, part: Option<&str>, profile: Profile) -> Result<ParamFile> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let origin = path.display().to_string();
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let is_yaml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
    let doc: ParamValue = if is_yaml {
        // Kalibr's imu.yaml: its four figures as a parameter file.
        let params = crate::kalibr::read(path)?.to_params_toml();
        toml::from_str(&params).map_err(|e| Error::Scenario {
            origin: origin.clone(),
            message: e.to_string(),
        })?
    } else if is_json {
        serde_json::from_str(&text).map_err(|e| Error::Scenario {
            origin: origin.clone(),
            message: e.to_string(),
        })?
    } else {
        toml::from_str(&text).map_err(|e| Error::Scenario {
            origin: origin.clone(),
            message: e.to_string(),
        })?
    };
    parse_any_document(&doc, &origin, part, profile)
}

/// Parses either document shape: imukit's, or MATLAB's part-name → sensors.
///
/// # Errors
/// As [`read_param_file`].
pub fn parse_any_document(
    doc: &ParamValue,
    origin: &str,
    part: Option<&str>,
    profile: Profile,
) -> Result<ParamFile> {
    let ParamValue::Table(map) = doc else {
        return Err(invalid(origin, "expected a table"));
    };
    let is_sensor_key = |k: &str| {
        Sensor::ALL
            .iter()
            .any(|s| s.key() == k || s.matlab_key() == k)
            || INFO_KEYS.contains(&k)
            || k == "datasheet"
    };
    if map.keys().all(|k| is_sensor_key(k)) {
        return parse_param_document(doc, origin, profile);
    }
    // MATLAB loadparams: { "PartName": { "Accelerometer": {...}, ... }, ... }
    let parts: Vec<&String> = map.keys().collect();
    // MATLAB matches part names as identifiers: case aside, `MPU-6050` is `MPU_6050`.
    let identifier = |s: &str| -> String {
        s.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect()
    };
    let name = match part {
        Some(p) => map
            .get_key_value(p)
            .map(|(k, _)| k)
            .or_else(|| map.keys().find(|k| identifier(k) == identifier(p)))
            .ok_or_else(|| {
                invalid(
                    origin,
                    format!(
                        "no part \"{p}\" (parts: {})",
                        parts
                            .iter()
                            .map(|s| s.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })?,
        None if parts.len() == 1 => parts[0],
        None => {
            return Err(invalid(
                origin,
                format!(
                    "the file holds several parts; choose one with part = \"…\" ({})",
                    parts
                        .iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    };
    // MATLAB's loadparams leaves NoiseType double-sided (its JSON cannot set it): a MATLAB
    // file means what it means in MATLAB, whatever the profile.
    let mut file = parse_document(
        &map[name],
        &format!("{origin}: {name}"),
        Profile::Matlab,
        true,
    )?;
    file.info
        .entry("name".into())
        .or_insert_with(|| name.clone());
    Ok(file)
}

fn fmt3(v: [f64; 3]) -> String {
    if v[0] == v[1] && v[1] == v[2] {
        fmt1(v[0])
    } else {
        format!("[{}, {}, {}]", fmt1(v[0]), fmt1(v[1]), fmt1(v[2]))
    }
}

fn fmt1(x: f64) -> String {
    if x.is_infinite() {
        "\"inf\"".into()
    } else {
        zmij::Buffer::new().format(x).to_string()
    }
}

/// Writes parameters as an imukit TOML parameter file (every field, units in the keys).
#[must_use]
pub fn to_toml(file: &ParamFile) -> String {
    let mut s = String::new();
    for k in INFO_KEYS {
        if let Some(v) = file.info.get(k) {
            s += &format!("{k} = {}\n", toml::Value::String(v.clone()));
        }
    }
    for (i, sensor) in Sensor::ALL.iter().enumerate() {
        if !file.present[i] {
            continue;
        }
        let p = file.params.get(*sensor);
        let u = sensor.unit();
        s += &format!("\n[{}]\n", sensor.key());
        s += &format!("measurement_range_{u} = {}\n", fmt1(p.measurement_range));
        s += &format!("resolution_{u} = {}\n", fmt1(p.resolution));
        s += &format!("constant_bias_{u} = {}\n", fmt3(p.constant_bias));
        let m = p.axes_misalignment_pct;
        s += &format!(
            "axes_misalignment_pct = [{}, {}, {}]\n",
            fmt3_full(m[0]),
            fmt3_full(m[1]),
            fmt3_full(m[2])
        );
        s += &format!("noise_density_{u}_per_rt_hz = {}\n", fmt3(p.noise_density));
        s += &format!("bias_instability_{u} = {}\n", fmt3(p.bias_instability));
        match &p.bias_instability_model {
            BiasInstabilityModel::Filter(c) => {
                let l = |v: &[f64]| v.iter().map(|x| fmt1(*x)).collect::<Vec<_>>().join(", ");
                s += &format!("bias_instability_numerator = [{}]\n", l(c.numerator()));
                s += &format!("bias_instability_denominator = [{}]\n", l(c.denominator()));
            }
            BiasInstabilityModel::Flicker {
                tau_min_s,
                tau_max_s,
            } => {
                s += &format!(
                    "bias_instability_flicker_tau_s = [{}, {}]\n",
                    fmt1(*tau_min_s),
                    fmt1(*tau_max_s)
                );
            }
            BiasInstabilityModel::GaussMarkov { correlation_time_s } => {
                s += &format!(
                    "bias_instability_correlation_time_s = {}\n",
                    fmt1(*correlation_time_s)
                );
            }
        }
        s += &format!("random_walk_{u}_rt_hz = {}\n", fmt3(p.random_walk));
        let nt = match p.noise_type {
            NoiseType::SingleSided => "single-sided",
            NoiseType::DoubleSided => "double-sided",
        };
        s += &format!("noise_type = \"{nt}\"\n");
        s += &format!(
            "temperature_bias_{u}_per_c = {}\n",
            fmt3(p.temperature_bias)
        );
        s += &format!(
            "temperature_scale_factor_pct_per_c = {}\n",
            fmt3(p.temperature_scale_factor_pct)
        );
        if *sensor == Sensor::Gyroscope {
            s += &format!(
                "acceleration_bias_rad_s_per_m_s2 = {}\n",
                fmt3(p.acceleration_bias)
            );
        }
        if p.quantization_carry {
            s += "quantization_carry = true\n";
        }
    }
    s
}

fn fmt3_full(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", fmt1(v[0]), fmt1(v[1]), fmt1(v[2]))
}
