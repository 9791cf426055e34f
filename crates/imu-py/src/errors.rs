//! Python's exceptions: `imukit.ImuError` (a `ValueError`) for what the library refused, with
//! `field`, `file`, `row` and `column` attributes where the library knows them, so a program can
//! react; shape and type problems are plain `ValueError`/`TypeError` naming the argument.
use imu_plot::PlotError;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    _core,
    ImuError,
    PyValueError,
    "imukit refused the input; the message says what and where, and the attributes field, file, \
     row and column say it to programs (None where unknown)."
);

/// The attributes every `ImuError` has (class-level `None`, set per instance where known).
const ATTRIBUTES: [&str; 4] = ["field", "file", "row", "column"];

/// The library's refusal as an `ImuError` with its location.
pub(crate) fn refused(e: imukit::Error) -> PyErr {
    let location = e.location();
    let err = ImuError::new_err(e.to_string());
    Python::attach(|py| {
        let value = err.value(py);
        // Setting an attribute on a fresh exception instance cannot fail; if it did, the
        // class-level None would stand.
        let _ = value.setattr("field", location.field);
        let _ = value.setattr("file", location.file.map(|f| f.display().to_string()));
        let _ = value.setattr("row", location.row);
        let _ = value.setattr("column", location.column);
    });
    err
}

/// A figure's refusal: data errors as [`refused`], the others with their option named.
pub(crate) fn refused_figure(e: PlotError) -> PyErr {
    match e {
        PlotError::Data(e) => refused(e),
        PlotError::Invalid { field, message } => refused(imukit::Error::Invalid {
            field: field.into(),
            message,
        }),
        PlotError::Option { option, message } => refused(imukit::Error::Invalid {
            field: option.key().into(),
            message,
        }),
        other @ PlotError::Draw { .. } => ImuError::new_err(other.to_string()),
    }
}

/// A wrong shape or length, naming the argument.
pub(crate) fn shape_error(message: String) -> PyErr {
    PyValueError::new_err(message)
}

/// Adds `ImuError` with its attributes to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let class = m.py().get_type::<ImuError>();
    for a in ATTRIBUTES {
        class.setattr(a, m.py().None())?;
    }
    m.add("ImuError", class)
}
