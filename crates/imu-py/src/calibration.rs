//! A part calibrated from the readings of a procedure (`imukit.calibrate`), and a calibration
//! applied to readings (`Calibration.apply`, `imukit.read(..., calibration=)`).
use std::path::Path;

use imukit::Table;
use imukit::calibrate::calibrate_table;
use imukit::io::calibration::CalibrationFile;
use imukit::io::output::write_atomically;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::convert::{TableOut, table_in, table_out};
use crate::errors::refused;

/// What a calibration found: the calibration file's text, the rests (start, end sample), the
/// warnings, the white noise learnt (accelerometer m/s², gyroscope rad/s a sample) and the
/// residuals by name (`imukit::calibrate::Residuals`'s fields).
type Calibrated = (
    String,
    Vec<(usize, usize)>,
    Vec<String>,
    Option<(f64, f64)>,
    Vec<(&'static str, Vec<f64>)>,
);

/// Calibrates from the readings `values` with `columns` (`t_s` and the sensors' columns).
#[pyfunction]
fn calibrate(
    py: Python<'_>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'_, f64>,
    gravity_m_s2: f64,
    source: &str,
) -> PyResult<Calibrated> {
    let t: Table = table_in("readings", columns, &values)?;
    let r = py
        .detach(|| calibrate_table(&t, gravity_m_s2, source))
        .map_err(refused)?;
    let x = r.residuals.clone();
    let residuals = vec![
        ("rest_t_s", x.rest_t_s),
        ("accel_raw_m_s2", x.accel_raw_m_s2),
        ("accel_m_s2", x.accel_m_s2),
        ("rotation_t_s", x.rotation_t_s),
        ("gyro_raw_rad", x.gyro_raw_rad),
        ("gyro_rad", x.gyro_rad),
        ("mag_t_s", x.mag_t_s),
        ("mag_raw", x.mag_raw),
        ("mag", x.mag),
    ];
    Ok((
        r.to_toml(),
        r.rests.iter().map(|x| (x.start, x.end)).collect(),
        r.warnings.clone(),
        r.noise.map(|n| (n.accel, n.gyro)),
        residuals,
    ))
}

/// The readings with each sensor's columns corrected by the calibration file's text.
#[pyfunction]
fn apply_calibration<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    text: &str,
    origin: &str,
) -> PyResult<TableOut<'py>> {
    let file = CalibrationFile::parse(text, origin).map_err(refused)?;
    let mut t: Table = table_in("readings", columns, &values)?;
    file.apply_to_table(&mut t, "readings").map_err(refused)?;
    table_out(py, t)
}

/// The text of the calibration file at `path`, checked.
#[pyfunction]
fn read_calibration(path: &str) -> PyResult<String> {
    let text = std::fs::read_to_string(path).map_err(|source| {
        refused(imukit::Error::Io {
            path: path.into(),
            source,
        })
    })?;
    CalibrationFile::parse(&text, path).map_err(refused)?;
    Ok(text)
}

/// Writes a calibration file's text to `path` (atomically).
#[pyfunction]
fn write_calibration(path: &str, text: &str) -> PyResult<()> {
    write_atomically(Path::new(path), |w| {
        std::io::Write::write_all(w, text.as_bytes())
    })
    .map_err(refused)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(apply_calibration, m)?)?;
    m.add_function(wrap_pyfunction!(read_calibration, m)?)?;
    m.add_function(wrap_pyfunction!(write_calibration, m)?)?;
    Ok(())
}
