//! Parameter files: imukit's TOML or JSON, MATLAB `loadparams` JSON, a part among several, and
//! a part written back as imukit TOML.
use std::collections::BTreeMap;
use std::path::Path;

use imu_core::sensor::NoiseType;

use crate::error::{Error, Result, invalid};
use crate::kalibr::KalibrImu;
use crate::params::{ImuParams, ParamValue, Profile, Sensor, parse_sensor_keys};
use crate::sensor::{BiasInstabilityModel, SensorParams};

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
    /// The part's signal-chain settings (`[chain]`), when the file gives them.
    pub chain: Option<crate::chain::PartChains>,
    /// What was skipped in a MATLAB file (keys MATLAB's `loadparams` ignores), for the front end
    /// to show as warnings.
    pub warnings: Vec<String>,
}

const INFO_KEYS: [&str; 4] = ["name", "grade", "source", "notes"];

/// Parses an imukit parameter document (`[accelerometer]`, `[gyroscope]`, `[magnetometer]`
/// tables and descriptive strings) given as a JSON value.
///
/// # Errors
/// As [`parse_sensor`](crate::params::parse_sensor); unknown top-level keys.
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
        } else if k == "chain" && !matlab {
            out.chain = Some(crate::chain::PartChains::parse(v, origin)?);
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
                "unknown key (expected accelerometer, gyroscope, magnetometer, name, grade, source, notes, datasheet, chain)",
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
        // The element's nonlinear terms only when the part has them (files of parts without
        // them read as before).
        if p.scale_factor_nonlinearity != [0.0; 3] {
            s += &format!(
                "scale_factor_nonlinearity_per_{u} = {}\n",
                fmt3(p.scale_factor_nonlinearity)
            );
        }
        if p.scale_factor_asymmetry_pct != [0.0; 3] {
            s += &format!(
                "scale_factor_asymmetry_pct = {}\n",
                fmt3(p.scale_factor_asymmetry_pct)
            );
        }
        if *sensor == Sensor::Gyroscope && p.acceleration_squared_bias != [0.0; 3] {
            s += &format!(
                "acceleration_squared_bias_rad_s_per_m2_s4 = {}\n",
                fmt3(p.acceleration_squared_bias)
            );
        }
    }
    if let Some(chain) = &file.chain {
        #[derive(serde::Serialize)]
        struct Part<'a> {
            chain: &'a crate::chain::PartChains,
        }
        // Numbers and text only: serialising cannot fail.
        if let Ok(t) = toml::to_string(&Part { chain }) {
            s += "\n";
            s += &t;
        }
    }
    s
}

fn fmt3_full(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", fmt1(v[0]), fmt1(v[1]), fmt1(v[2]))
}

impl KalibrImu {
    /// Kalibr's figures of a parameter file's accelerometer and gyroscope, at `update_rate_hz`
    /// on `rostopic`.
    ///
    /// # Errors
    /// A rate that is not finite and positive, a file without an accelerometer or gyroscope.
    pub fn from_params(file: &ParamFile, update_rate_hz: f64, rostopic: &str) -> Result<Self> {
        if !(update_rate_hz.is_finite() && update_rate_hz > 0.0) {
            return Err(crate::error::refused(
                crate::error::RequestOption::RateHz,
                format!("must be a finite rate above 0 Hz, got {update_rate_hz}"),
            ));
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
            accelerometer: crate::kalibr::sensor(&file.params.accelerometer, "m/s²"),
            gyroscope: crate::kalibr::sensor(&file.params.gyroscope, "rad/s"),
            update_rate_hz,
            rostopic: rostopic.to_owned(),
            name: file.info.get("name").cloned(),
        })
    }
}
