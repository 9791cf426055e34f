//! A vendor's CSV read through a column map: which of its columns hold the time, the
//! accelerometer, the gyroscope and the magnetometer, in which units, and how the sensor's axes
//! lie in the body frame. A small TOML file says it:
//!
//! ```toml
//! time = { column = "Timestamp", unit = "ns" }               # s, ms, us or ns
//! accel = { columns = ["AccX", "AccY", "AccZ"], unit = "g" }  # m/s^2, g, mg
//! gyro = { columns = ["GyrX", "GyrY", "GyrZ"], unit = "deg/s" } # rad/s, deg/s, dps, mdps
//! mag = { columns = ["MagX", "MagY", "MagZ"], unit = "mG" }  # uT, nT, gauss (G), mG
//! axes = ["x", "-y", "-z"]   # body x is the sensor's x, body y its −y, body z its −z
//! ```
//!
//! `axes` may instead be `rotation = [[…], […], […]]`, the matrix that takes sensor axes to
//! body axes (rows are body axes). A table `[columns]` gives a file's column to one of imukit's
//! by name, as it is (`pos_x_sigma_m = "pos_std_1"`): a receiver's fixes and accuracies, an
//! odometer's, a barometer's or a truth's columns under their vendor's names. Every key but `time` is optional; the units are the units
//! room's ([`crate::units`]), read for the quantity they are given to (so `mG` on the
//! magnetometer is milligauss, `mg` on the accelerometer milli-g). Integer-nanosecond stamps are
//! kept exactly, as in the ASL layout ([`crate::asl`]).
//!
//! A map is read ([`ColumnMap::read`]) and resolved against a file's header
//! ([`ColumnMap::resolve`]); the table reader then gives the file's rows as imukit's columns
//! (`t_s`, `accel_x_m_s2`, …), the file's other columns under their own names. A map travels
//! with its file as one argument, [`crate::Input::with_map`]: the command line's `--map FILE`,
//! Python's `imukit.read(path, map=…)`.
use std::path::Path;

use serde::Deserialize;

use crate::error::{Error, Result, invalid};
use crate::units;

/// A time column's unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
pub enum TimeUnit {
    /// Seconds.
    #[serde(rename = "s")]
    Seconds,
    /// Milliseconds.
    #[serde(rename = "ms")]
    Milliseconds,
    /// Microseconds.
    #[serde(rename = "us", alias = "µs")]
    Microseconds,
    /// Nanoseconds (integer stamps kept exactly).
    #[serde(rename = "ns")]
    Nanoseconds,
}

impl TimeUnit {
    /// Nanoseconds per unit.
    #[must_use]
    pub fn nanoseconds(self) -> i64 {
        match self {
            Self::Seconds => 1_000_000_000,
            Self::Milliseconds => 1_000_000,
            Self::Microseconds => 1_000,
            Self::Nanoseconds => 1,
        }
    }

    /// A stamp's text in this unit as `t_s`, seconds after the time origin, which the first
    /// stamp read sets (`origin_ns`): the UTC midnight before an integer stamp, else 0. Integer
    /// stamps are subtracted exactly ([`crate::asl::seconds_after`]), so integer
    /// nanoseconds come back to the nanosecond; `None` for text that is not a number.
    #[must_use]
    #[allow(clippy::cast_precision_loss)]
    pub fn seconds_after_origin(self, text: &str, origin_ns: &mut Option<i64>) -> Option<f64> {
        let per = self.nanoseconds();
        if let Some(ns) = text.parse::<i64>().ok().and_then(|v| v.checked_mul(per)) {
            let origin = *origin_ns.get_or_insert_with(|| crate::asl::time_origin_ns(ns));
            return Some(crate::asl::seconds_after(ns, origin));
        }
        let v: f64 = text.parse().ok().filter(|v: &f64| v.is_finite())?;
        let origin = *origin_ns.get_or_insert(0);
        Some(v * (per as f64 * 1e-9) - origin as f64 * 1e-9)
    }
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeSpec {
    column: String,
    unit: TimeUnit,
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct TripleSpec {
    columns: [String; 3],
    unit: String,
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct MapSpec {
    time: TimeSpec,
    accel: Option<TripleSpec>,
    gyro: Option<TripleSpec>,
    mag: Option<TripleSpec>,
    axes: Option<[String; 3]>,
    rotation: Option<[[f64; 3]; 3]>,
    /// imukit column → the file's column, taken as it is (already in imukit's unit).
    columns: Option<std::collections::BTreeMap<String, String>>,
}

/// The columns a map may give a file's column to by name ([`MapSpec::columns`]): those of the
/// tables imukit reads beside the IMU's — fixes (flat or geodetic) with their accuracies,
/// odometer, barometer, truth.
fn renamable() -> Vec<&'static str> {
    use crate::columns as c;
    let mut all: Vec<&'static str> = [
        &c::GNSS_COLUMNS[..],
        &c::GNSS_EARTH_COLUMNS[..],
        &c::FIX_ACCURACY_COLUMNS[..],
        &c::FIX_SIGMA_COLUMNS[..],
        &c::ODOMETER_COLUMNS[..],
        &c::BARO_COLUMNS[..],
        &c::TRUTH_COLUMNS[..],
        &c::GEODETIC_COLUMNS[..],
    ]
    .concat();
    all.retain(|name| *name != "t_s");
    all.sort_unstable();
    all.dedup();
    all
}

/// The sensors a map may name: `(key, imukit columns, the SI unit its units convert to)`.
const SENSORS: [(&str, [&str; 3], &str); 3] = [
    (
        "accel",
        ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"],
        "m/s²",
    ),
    (
        "gyro",
        ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"],
        "rad/s",
    ),
    ("mag", ["mag_x_ut", "mag_y_ut", "mag_z_ut"], "µT"),
];

/// How one imukit column is made from a file's fields.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A field as it is.
    Field(usize),
    /// A time field in a unit (integer nanoseconds kept exactly).
    Time(usize, TimeUnit),
    /// `Σ coefficient · field`: a unit and the axes' rotation.
    Combination(Vec<(usize, f64)>),
}

/// A column map, read and checked ([`ColumnMap::read`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnMap {
    origin: String,
    time: TimeSpec,
    /// `(imukit columns, file columns, factor to SI)` per sensor named.
    sensors: Vec<([&'static str; 3], [String; 3], f64)>,
    /// Sensor axes to body axes.
    rotation: [[f64; 3]; 3],
    /// `(imukit column, file column)` taken as they are.
    renames: Vec<(String, String)>,
}

impl ColumnMap {
    /// Parses a map's TOML `text`; `origin` names it in messages.
    ///
    /// # Errors
    /// The parser's message (key and line); an unknown unit, a unit of another quantity, axes
    /// or a rotation that are not a rotation, named by key.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        let spec: MapSpec = toml::from_str(text).map_err(|e: toml::de::Error| Error::Scenario {
            origin: origin.into(),
            message: e.to_string(),
        })?;
        Self::from_spec(spec, origin)
    }

    /// Parses a map given as JSON text with the same keys (a Python dict's way in).
    ///
    /// # Errors
    /// As [`ColumnMap::from_toml`].
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let mut json = serde_json::Deserializer::from_str(text);
        let spec: MapSpec = serde_path_to_error::deserialize(&mut json).map_err(|e| {
            let path = e.path().to_string();
            Error::Invalid {
                field: format!("{origin}: {path}").into(),
                message: e.into_inner().to_string(),
            }
        })?;
        Self::from_spec(spec, origin)
    }

    fn from_spec(spec: MapSpec, origin: &str) -> Result<Self> {
        let key = |k: &str| format!("{origin}: {k}");
        let mut sensors = Vec::new();
        for ((name, columns, si), spec) in SENSORS.iter().zip([&spec.accel, &spec.gyro, &spec.mag])
        {
            if let Some(t) = spec {
                let factor = units::factor_to(&t.unit, si)
                    .map_err(|e| invalid(key(&format!("{name}.unit")), e))?;
                sensors.push((*columns, t.columns.clone(), factor));
            }
        }
        let rotation = match (&spec.axes, spec.rotation) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    key("axes"),
                    "give the axes or a rotation, not both",
                ));
            }
            (Some(axes), None) => axes_rotation(axes).map_err(|e| invalid(key("axes"), e))?,
            (None, Some(r)) => {
                check_rotation(&r).map_err(|e| invalid(key("rotation"), e))?;
                r
            }
            (None, None) => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        };
        let known = renamable();
        let mut renames = Vec::new();
        for (imukit, file) in spec.columns.unwrap_or_default() {
            if !known.contains(&imukit.as_str()) {
                return Err(invalid(
                    key(&format!("columns.{imukit}")),
                    format!(
                        "is not a column imukit reads from a fix, odometer, barometer or truth                          table (known: {})",
                        known.join(", ")
                    ),
                ));
            }
            renames.push((imukit, file));
        }
        Ok(Self {
            origin: origin.into(),
            time: spec.time,
            sensors,
            rotation,
            renames,
        })
    }

    /// Reads the map at `path`.
    ///
    /// # Errors
    /// An unreadable file, and as [`ColumnMap::from_toml`].
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// The columns a file with header `header` gives through this map, and how each is made:
    /// `t_s` and the sensors' imukit columns, then the file's other columns as they are.
    ///
    /// # Errors
    /// A column the map names that the header lacks, or an imukit column the file already has
    /// (named with the map and the file).
    pub fn resolve(&self, header: &[String], file: &Path) -> Result<(Vec<String>, Vec<Source>)> {
        let field =
            |name: &str| {
                header.iter().position(|h| h == name).ok_or_else(|| Error::CsvFormat {
                file: file.into(),
                message: format!(
                    "the column map {} names column {name:?}, which the header does not have \
                     (it has: {})",
                    self.origin,
                    header.join(", ")
                ),
            })
            };
        let mut names = vec!["t_s".to_string()];
        let time_field = field(&self.time.column)?;
        let mut sources = vec![Source::Time(time_field, self.time.unit)];
        let mut used = vec![time_field];
        for (imukit, columns, factor) in &self.sensors {
            let fields = [
                field(&columns[0])?,
                field(&columns[1])?,
                field(&columns[2])?,
            ];
            // One column of the file is one quantity on one axis: read twice, it would be the
            // same reading on two axes (or the time and a reading) without a word.
            for (f, name) in fields.iter().zip(columns.iter()) {
                if used.contains(f) {
                    return Err(Error::CsvFormat {
                        file: file.into(),
                        message: format!(
                            "the column map {} reads column {name:?} twice: each column of the \
                             file is one quantity on one axis",
                            self.origin
                        ),
                    });
                }
                used.push(*f);
            }
            for (row, name) in self.rotation.iter().zip(imukit) {
                names.push((*name).to_string());
                sources.push(Source::Combination(
                    fields
                        .iter()
                        .zip(row)
                        .filter(|(_, c)| **c != 0.0)
                        .map(|(f, c)| (*f, c * factor))
                        .collect(),
                ));
            }
        }
        for (imukit, column) in &self.renames {
            let f = field(column)?;
            if used.contains(&f) {
                return Err(Error::CsvFormat {
                    file: file.into(),
                    message: format!(
                        "the column map {} reads column {column:?} twice: each column of the                          file is one quantity",
                        self.origin
                    ),
                });
            }
            used.push(f);
            names.push(imukit.clone());
            sources.push(Source::Field(f));
        }
        for (k, h) in header.iter().enumerate() {
            if used.contains(&k) {
                continue;
            }
            if names.contains(h) {
                return Err(Error::CsvFormat {
                    file: file.into(),
                    message: format!(
                        "has a column {h} and the column map {} makes another",
                        self.origin
                    ),
                });
            }
            names.push(h.clone());
            sources.push(Source::Field(k));
        }
        Ok((names, sources))
    }
}

/// The rotation of `axes` (`"x"`, `"-y"`, …: the sensor axis each body axis is).
fn axes_rotation(axes: &[String; 3]) -> std::result::Result<[[f64; 3]; 3], String> {
    let mut r = [[0.0; 3]; 3];
    for (row, axis) in r.iter_mut().zip(axes) {
        let a = axis.trim();
        let (sign, name) = match a.strip_prefix('-') {
            Some(rest) => (-1.0, rest),
            None => (1.0, a.strip_prefix('+').unwrap_or(a)),
        };
        let k = match name {
            "x" | "X" => 0,
            "y" | "Y" => 1,
            "z" | "Z" => 2,
            _ => return Err(format!("{axis:?} is not an axis (x, y, z with a sign)")),
        };
        row[k] = sign;
    }
    check_rotation(&r)?;
    Ok(r)
}

/// Refuses a matrix that is not a proper rotation (orthonormal, determinant +1) to 1e-9.
fn check_rotation(r: &[[f64; 3]; 3]) -> std::result::Result<(), String> {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for i in 0..3 {
        for j in 0..3 {
            let expected = if i == j { 1.0 } else { 0.0 };
            let v = dot(&r[i], &r[j]);
            if !v.is_finite() || (v - expected).abs() > 1e-9 {
                return Err("is not a rotation: its rows must be orthonormal".into());
            }
        }
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return Err("is a reflection (determinant −1), not a rotation: flip one more axis".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAP: &str = r#"
time = { column = "Timestamp", unit = "ms" }
accel = { columns = ["AccX", "AccY", "AccZ"], unit = "g" }
gyro = { columns = ["GyrX", "GyrY", "GyrZ"], unit = "deg/s" }
mag = { columns = ["MagX", "MagY", "MagZ"], unit = "mG" }
axes = ["x", "-y", "-z"]
"#;

    fn header(names: &str) -> Vec<String> {
        names.split(',').map(str::to_string).collect()
    }

    #[test]
    fn a_map_gives_imukit_columns_in_si_and_body_axes() {
        let map = ColumnMap::from_toml(MAP, "v.toml").unwrap();
        let h = header("Timestamp,AccX,AccY,AccZ,GyrX,GyrY,GyrZ,MagX,MagY,MagZ,Temp");
        let (names, sources) = map.resolve(&h, Path::new("v.csv")).unwrap();
        assert_eq!(names[0], "t_s");
        assert_eq!(
            names[1..4],
            ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]
        );
        assert_eq!(names[10], "Temp");
        assert_eq!(sources[0], Source::Time(0, TimeUnit::Milliseconds));
        let g = units::STANDARD_GRAVITY;
        assert_eq!(sources[2], Source::Combination(vec![(2, -g)]));
        let deg = std::f64::consts::PI / 180.0;
        assert_eq!(sources[4], Source::Combination(vec![(4, deg)]));
        // Milligauss on the magnetometer: 0.1 µT.
        assert_eq!(sources[9], Source::Combination(vec![(9, -0.1)]));
        assert_eq!(sources[10], Source::Field(10));
    }

    #[test]
    fn bad_maps_are_named_by_key() {
        let e = |text: &str| {
            ColumnMap::from_toml(text, "m.toml")
                .unwrap_err()
                .to_string()
        };
        let time = "time = { column = \"t\", unit = \"s\" }\n";
        let m = e(&format!(
            "{time}gyro = {{ columns = [\"a\", \"b\", \"c\"], unit = \"furlongs\" }}"
        ));
        assert!(
            m.contains("m.toml: gyro.unit") && m.contains("furlongs"),
            "{m}"
        );
        let m = e(&format!(
            "{time}gyro = {{ columns = [\"a\", \"b\", \"c\"], unit = \"g\" }}"
        ));
        assert!(m.contains("gyro.unit") && m.contains("rad/s"), "{m}");
        let m = e(&format!("{time}axes = [\"x\", \"y\", \"-z\"]"));
        assert!(m.contains("axes") && m.contains("reflection"), "{m}");
        let m = e(&format!("{time}axes = [\"x\", \"x\", \"z\"]"));
        assert!(m.contains("orthonormal"), "{m}");
        let m = e("time = { column = \"t\", unit = \"fortnight\" }");
        assert!(m.contains("m.toml") && m.contains("unit"), "{m}");
        let m = e(&format!("{time}acel = 1"));
        assert!(m.contains("acel"), "{m}");
        let map = ColumnMap::from_toml(MAP, "v.toml").unwrap();
        let m = map
            .resolve(&header("Timestamp,AccX,AccY"), Path::new("v.csv"))
            .unwrap_err()
            .to_string();
        assert!(
            m.contains("v.csv") && m.contains("v.toml names column \"AccZ\""),
            "{m}"
        );
        // One column read for two axes, or for the time and an axis, is refused.
        for (twice, column) in [
            (
                MAP.replace("\"AccY\", \"AccZ\"", "\"AccY\", \"AccY\""),
                "AccY",
            ),
            (MAP.replace("[\"GyrX\"", "[\"Timestamp\""), "Timestamp"),
            (MAP.replace("[\"MagX\"", "[\"AccX\""), "AccX"),
        ] {
            let map = ColumnMap::from_toml(&twice, "v.toml").unwrap();
            let m = map
                .resolve(
                    &header("Timestamp,AccX,AccY,AccZ,GyrX,GyrY,GyrZ,MagX,MagY,MagZ"),
                    Path::new("v.csv"),
                )
                .unwrap_err()
                .to_string();
            assert!(
                m.contains("v.csv") && m.contains(&format!("reads column \"{column}\" twice")),
                "{m}"
            );
        }
    }
}
