//! Python bindings of imukit (`imukit._core`), one file per area, each with its `register`:
//! convert the Python arguments ([`convert`]), release the GIL, call the `imukit` library (or
//! `imu-plot` for figure specs), convert back; refusals become `imukit.ImuError` with the field,
//! file, row and column they name ([`errors`]). No numerics here.
mod convert;
mod errors;
mod figures;
mod io;
mod navigation;
mod orientation;
mod rotations;
mod sensor;
mod study;
mod truth;

use pyo3::prelude::*;

/// The compiled core of the `imukit` package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    truth::register(m)?;
    rotations::register(m)?;
    sensor::register(m)?;
    navigation::register(m)?;
    orientation::register(m)?;
    io::register(m)?;
    figures::register(m)?;
    study::register(m)?;
    Ok(())
}
