//! Attitude conversions between z-y-x Euler angles `[yaw, pitch, roll]`, quaternions `q_nb`
//! `[w, x, y, z]` and direction cosine matrices `C_nb`, row by row.
use imukit::arrays;
use numpy::{PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;

use crate::convert::{matrices_in, matrices_out, rows, rows_out};
use crate::errors::refused;

/// z-y-x Euler angles (N, 3) → quaternions (N, 4).
#[pyfunction]
fn euler_to_quaternion<'py>(
    py: Python<'py>,
    euler_rad: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = rows::<3>("euler_rad", &euler_rad)?;
    rows_out(py, arrays::euler_to_quaternion(&e).map_err(refused)?)
}

/// Quaternions (N, 4) → z-y-x Euler angles (N, 3).
#[pyfunction]
fn quaternion_to_euler<'py>(
    py: Python<'py>,
    quaternion: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = rows::<4>("quaternion", &quaternion)?;
    rows_out(py, arrays::quaternion_to_euler(&q).map_err(refused)?)
}

/// z-y-x Euler angles (N, 3) → direction cosine matrices `C_nb` (N, 3, 3).
#[pyfunction]
fn euler_to_dcm<'py>(
    py: Python<'py>,
    euler_rad: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let e = rows::<3>("euler_rad", &euler_rad)?;
    matrices_out(py, arrays::euler_to_dcm(&e).map_err(refused)?)
}

/// Direction cosine matrices (N, 3, 3) → z-y-x Euler angles (N, 3).
#[pyfunction]
fn dcm_to_euler<'py>(
    py: Python<'py>,
    dcm: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = matrices_in("dcm", &dcm)?;
    rows_out(py, arrays::dcm_to_euler(&m).map_err(refused)?)
}

/// Quaternions (N, 4) → direction cosine matrices (N, 3, 3).
#[pyfunction]
fn quaternion_to_dcm<'py>(
    py: Python<'py>,
    quaternion: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let q = rows::<4>("quaternion", &quaternion)?;
    matrices_out(py, arrays::quaternion_to_dcm(&q).map_err(refused)?)
}

/// Direction cosine matrices (N, 3, 3) → quaternions (N, 4).
#[pyfunction]
fn dcm_to_quaternion<'py>(
    py: Python<'py>,
    dcm: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = matrices_in("dcm", &dcm)?;
    rows_out(py, arrays::dcm_to_quaternion(&m).map_err(refused)?)
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(euler_to_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_to_euler, m)?)?;
    m.add_function(wrap_pyfunction!(euler_to_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_to_euler, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_to_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_to_quaternion, m)?)?;
    Ok(())
}
