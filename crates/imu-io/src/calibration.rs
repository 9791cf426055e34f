//! A part's calibration file (`imukit calibrate --out`, read by `--calibration FILE`): per
//! sensor the correction `matrix · (reading − bias)` and what the fit says of it.
//!
//! ```toml
//! [accelerometer]
//! matrix = [[1.0021, 0.0013, -0.0004], [0.0, 0.9987, 0.0021], [0.0, 0.0, 1.0005]]
//! bias_m_s2 = [0.051, -0.112, 0.087]
//! matrix_sigma = [[2.1e-5, 1.9e-5, 2.2e-5], [0.0, 2.0e-5, 2.3e-5], [0.0, 0.0, 2.1e-5]]
//! bias_sigma_m_s2 = [2.4e-4, 2.2e-4, 2.6e-4]
//! rests = 18
//! residual_rms_m_s2 = 4.1e-4
//! [gyroscope]      # matrix, bias_rad_s, …, rotations, residual_rms_rad
//! [magnetometer]   # matrix, bias_ut, …, readings, field_ut, field_sigma_ut, fit_error
//! ```
//!
//! Only `matrix` and `bias_<unit>` are needed to apply it; a sensor left out is read as it is.
//! The correction applies to the three columns of its sensor after any column map, so a
//! command that reads one axis reads the other two as well.
use std::path::Path;

use imu_core::calibration::Correction;
use imu_core::calibration::accelerometer::AccelCalibration;
use imu_core::calibration::gyroscope::GyroCalibration;
use imu_core::calibration::magnetometer::MagCalibration;

use crate::columns::{ACCEL_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS};
use crate::error::{Error, Result};

/// The sensors of a calibration file: table name, unit suffix of the bias, columns.
const SENSORS: [(&str, &str, [&str; 3]); 3] = [
    ("accelerometer", "m_s2", ACCEL_COLUMNS),
    ("gyroscope", "rad_s", GYRO_COLUMNS),
    ("magnetometer", "ut", MAG_COLUMNS),
];

/// The corrections of a calibration file, accelerometer, gyroscope and magnetometer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CalibrationFile {
    /// Each sensor's correction, when the file has it.
    pub corrections: [Option<Correction>; 3],
}

impl CalibrationFile {
    /// Reads the file at `path`.
    ///
    /// # Errors
    /// An unreadable file, TOML that does not parse, an unknown table or key, a matrix or bias
    /// that is not three finite numbers a row, a singular matrix (it would lose an axis).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses a calibration file's text, `origin` naming it in messages.
    ///
    /// # Errors
    /// As [`Self::read`].
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let table: toml::Table = toml::from_str(text).map_err(|e| Error::Scenario {
            origin: origin.into(),
            message: e.to_string(),
        })?;
        let invalid = |key: String, message: String| Error::Scenario {
            origin: origin.into(),
            message: format!("{key}: {message}"),
        };
        if let Some(other) = table.keys().find(|k| !SENSORS.iter().any(|(s, ..)| s == k)) {
            return Err(invalid(
                other.clone(),
                "unknown table (accelerometer, gyroscope, magnetometer)".into(),
            ));
        }
        let mut file = Self::default();
        for (slot, (sensor, unit, _)) in file.corrections.iter_mut().zip(SENSORS) {
            let Some(value) = table.get(sensor) else {
                continue;
            };
            let toml::Value::Table(t) = value else {
                return Err(invalid(sensor.into(), "expected a table".into()));
            };
            let known = known_keys(sensor, unit);
            if let Some(other) = t.keys().find(|k| !known.contains(k)) {
                return Err(invalid(
                    format!("{sensor}.{other}"),
                    format!("unknown key ({})", known.join(", ")),
                ));
            }
            let number = |v: &toml::Value, key: &str| match v {
                toml::Value::Float(x) if x.is_finite() => Ok(*x),
                #[allow(clippy::cast_precision_loss)]
                toml::Value::Integer(i) => Ok(*i as f64),
                other => Err(invalid(
                    key.into(),
                    format!("expected a finite number, got {other}"),
                )),
            };
            let triple = |v: &toml::Value, key: &str| -> Result<[f64; 3]> {
                match v {
                    toml::Value::Array(a) if a.len() == 3 => Ok([
                        number(&a[0], &format!("{key}[0]"))?,
                        number(&a[1], &format!("{key}[1]"))?,
                        number(&a[2], &format!("{key}[2]"))?,
                    ]),
                    _ => Err(invalid(key.into(), "expected 3 numbers".into())),
                }
            };
            let required = |key: &str| {
                t.get(key)
                    .ok_or_else(|| invalid(format!("{sensor}.{key}"), "missing".into()))
            };
            let matrix_key = format!("{sensor}.matrix");
            let matrix = match required("matrix")? {
                toml::Value::Array(rows) if rows.len() == 3 => [
                    triple(&rows[0], &format!("{matrix_key}[0]"))?,
                    triple(&rows[1], &format!("{matrix_key}[1]"))?,
                    triple(&rows[2], &format!("{matrix_key}[2]"))?,
                ],
                _ => return Err(invalid(matrix_key, "expected 3 rows of 3 numbers".into())),
            };
            let bias_key = format!("bias_{unit}");
            let bias = triple(required(&bias_key)?, &format!("{sensor}.{bias_key}"))?;
            let m = &matrix;
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            if det.abs() < 1e-9 || !det.is_finite() {
                return Err(invalid(
                    matrix_key,
                    format!("singular (determinant {det:e}): it would lose an axis"),
                ));
            }
            // The informative keys are numbers (or the model's name) when present.
            for (key, v) in t {
                if key != "matrix" && *key != bias_key && key != "model" {
                    let ok = match v {
                        toml::Value::Array(a) => a.iter().all(|x| match x {
                            toml::Value::Array(r) => {
                                r.iter().all(|y| y.is_float() || y.is_integer())
                            }
                            y => y.is_float() || y.is_integer(),
                        }),
                        y => y.is_float() || y.is_integer(),
                    };
                    if !ok {
                        return Err(invalid(
                            format!("{sensor}.{key}"),
                            "expected numbers".into(),
                        ));
                    }
                }
            }
            *slot = Some(Correction { matrix, bias });
        }
        Ok(file)
    }

    /// Each sensor's correction with the columns it applies to.
    pub fn columns(&self) -> impl Iterator<Item = (&Correction, [&'static str; 3])> {
        self.corrections
            .iter()
            .zip(SENSORS)
            .filter_map(|(c, (_, _, cols))| c.as_ref().map(|c| (c, cols)))
    }

    /// Applies the corrections to the rows of `table` that have their sensor's columns.
    ///
    /// # Errors
    /// A corrected value that is not finite (a reading near the largest number times the
    /// matrix), naming `source`, the row (the header is row 1) and the column.
    pub fn apply_to_table(&self, table: &mut crate::table::Table, source: &str) -> Result<()> {
        for (c, cols) in self.columns() {
            let Some(idx) = cols
                .iter()
                .map(|n| table.columns.iter().position(|c| c == n))
                .collect::<Option<Vec<usize>>>()
            else {
                continue;
            };
            let width = table.columns.len();
            for (r, row) in table.data.chunks_exact_mut(width).enumerate() {
                let out = c.apply([row[idx[0]], row[idx[1]], row[idx[2]]]);
                if let Some(k) = out.iter().position(|v| !v.is_finite()) {
                    return Err(not_finite(source, r + 2, cols[k], out[k]));
                }
                for (k, v) in idx.iter().zip(out) {
                    row[*k] = v;
                }
            }
        }
        Ok(())
    }
}

/// The refusal of a corrected reading that is not finite.
pub(crate) fn not_finite(source: &str, row: usize, column: &str, value: f64) -> Error {
    Error::CsvValue {
        file: source.into(),
        row,
        column: column.into(),
        message: format!("{value} once corrected by the calibration: not a reading"),
    }
}

fn known_keys(sensor: &str, unit: &str) -> Vec<String> {
    let mut keys = vec![
        "matrix".to_string(),
        format!("bias_{unit}"),
        "matrix_sigma".into(),
        format!("bias_sigma_{unit}"),
        "model".into(),
    ];
    keys.extend(
        match sensor {
            "accelerometer" => vec!["rests", "residual_rms_m_s2"],
            "gyroscope" => vec!["rotations", "residual_rms_rad"],
            _ => vec!["readings", "field_ut", "field_sigma_ut", "fit_error"],
        }
        .into_iter()
        .map(String::from),
    );
    keys
}

/// Shortest text that reads back as the same number.
fn num(x: f64) -> String {
    zmij::Buffer::new().format(x).to_string()
}

fn row(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]))
}

fn matrix(m: [[f64; 3]; 3]) -> String {
    format!("[{}, {}, {}]", row(m[0]), row(m[1]), row(m[2]))
}

/// The text of a calibration file with the results given (a sensor left out when `None`).
#[must_use]
pub fn to_toml(
    accel: Option<&AccelCalibration>,
    gyro: Option<&GyroCalibration>,
    mag: Option<&MagCalibration>,
) -> String {
    let mut s = String::from(
        "# A part's calibration (imukit calibrate): calibrated = matrix · (reading − bias);\n\
         # read with --calibration FILE. The sigmas are one standard deviation.\n",
    );
    if let Some(a) = accel {
        s += &format!(
            "\n[accelerometer]\nmodel = \"{}\"\nmatrix = {}\nbias_m_s2 = {}\nmatrix_sigma = {}\n\
             bias_sigma_m_s2 = {}\nrests = {}\nresidual_rms_m_s2 = {}\n",
            if a.full {
                "scale, misalignment and bias"
            } else {
                "scale and bias"
            },
            matrix(a.correction.matrix),
            row(a.correction.bias),
            matrix(a.matrix_sigma),
            row(a.bias_sigma),
            a.rests,
            num(a.residual_rms_m_s2)
        );
    }
    if let Some(g) = gyro {
        s += &format!(
            "\n[gyroscope]\nmatrix = {}\nbias_rad_s = {}\nmatrix_sigma = {}\nbias_sigma_rad_s = {}\n\
             rotations = {}\nresidual_rms_rad = {}\n",
            matrix(g.correction.matrix),
            row(g.correction.bias),
            matrix(g.matrix_sigma),
            row(g.bias_sigma),
            g.rotations,
            num(g.residual_rms_rad)
        );
    }
    if let Some(m) = mag {
        s += &format!(
            "\n[magnetometer]\nmatrix = {}\nbias_ut = {}\nmatrix_sigma = {}\nbias_sigma_ut = {}\n\
             readings = {}\nfield_ut = {}\nfield_sigma_ut = {}\nfit_error = {}\n",
            matrix(m.correction.matrix),
            row(m.correction.bias),
            matrix(m.matrix_sigma),
            row(m.bias_sigma),
            m.readings,
            num(m.field_ut),
            num(m.field_sigma_ut),
            num(m.fit_error)
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_file_reads_back_its_corrections_and_bad_ones_are_named() {
        let accel = AccelCalibration {
            correction: Correction {
                matrix: [
                    [1.01, 0.002, -0.003],
                    [0.0, 0.99, 0.001],
                    [0.0, 0.0, 1.0 / 3.0],
                ],
                bias: [0.1, -0.2, 0.3],
            },
            matrix_sigma: [[1e-5; 3]; 3],
            bias_sigma: [1e-4; 3],
            wander_m_s2: 0.0,
            full: true,
            residual_rms_m_s2: 1e-3,
            rests: 18,
        };
        let text = to_toml(Some(&accel), None, None);
        let back = CalibrationFile::parse(&text, "cal.toml").unwrap();
        assert_eq!(back.corrections[0], Some(accel.correction));
        assert_eq!(back.corrections[1], None);
        let e = CalibrationFile::parse(&text.replace("bias_m_s2 =", "bias_rad_s ="), "cal.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cal.toml: accelerometer.bias_rad_s: unknown key"),
            "{e}"
        );
        let e = CalibrationFile::parse(
            "[gyroscope]\nmatrix = [[1, 0, 0], [0, 1, 0], [1, 0, 0]]\nbias_rad_s = [0, 0, 0]\n",
            "cal.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("gyroscope.matrix: singular"), "{e}");
        let e = CalibrationFile::parse("[gyro]\n", "cal.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("gyro: unknown table"), "{e}");
        let e = CalibrationFile::parse(
            "[magnetometer]\nmatrix = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n",
            "c",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("magnetometer.bias_ut: missing"), "{e}");
    }
}
