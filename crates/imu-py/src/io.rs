//! Files: imukit tables in and out (CSV, Parquet by extension), and the file names of Monte
//! Carlo runs.
use std::path::Path;

use imukit::Table;
use imukit::io::Input;
use imukit::io::calibration::CalibrationFile;
use imukit::io::column_map::ColumnMap;
use imukit::io::description::Description;
use imukit::io::read::read_table;
use imukit::io::table::run_path as run_file;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{DescribedOut, described_out, description_dict, description_in, table_in};
use crate::errors::refused;

/// A table read from `path` with what the file says it holds, else what its columns show.
fn read_out<'py>(py: Python<'py>, path: &str, t: Table) -> PyResult<DescribedOut<'py>> {
    let d = py
        .detach(|| Description::read(Path::new(path)))
        .map_err(refused)?
        .unwrap_or_default();
    let d = Description {
        kind: d.kind.or_else(|| Description::of_columns(&t.columns).kind),
        ..d
    };
    described_out(py, t, &d)
}

/// Every column of an imukit CSV file, with its description.
#[pyfunction]
fn read_csv<'py>(py: Python<'py>, path: &str) -> PyResult<DescribedOut<'py>> {
    let t = read_table(Path::new(path)).map_err(refused)?;
    read_out(py, path, t)
}

/// Every column of a table file, its format by its extension (`.parquet`, else CSV); a CSV
/// file through a column map when one is given (a TOML file's path, or JSON text); the readings
/// corrected by a calibration file when one is given.
#[pyfunction]
#[pyo3(signature = (path, map_path = None, map_json = None, topic = None, receive_time = false, calibration_path = None))]
fn read_table_file<'py>(
    py: Python<'py>,
    path: &str,
    map_path: Option<&str>,
    map_json: Option<&str>,
    topic: Option<String>,
    receive_time: bool,
    calibration_path: Option<&str>,
) -> PyResult<DescribedOut<'py>> {
    use imukit::io::input::{Clock, Selection};
    let mut input = Input::new(path);
    if topic.is_some() || receive_time {
        let clock = if receive_time {
            Clock::Receive
        } else {
            Clock::Header
        };
        input = input.with_selection(Selection {
            topics: topic.into_iter().collect(),
            clock,
        });
    }
    if let Some(c) = calibration_path {
        input = input.with_calibration(CalibrationFile::read(Path::new(c)).map_err(refused)?);
    }
    let map = match (map_path, map_json) {
        (Some(p), _) => Some(ColumnMap::read(Path::new(p)).map_err(refused)?),
        (None, Some(text)) => Some(ColumnMap::from_json(text, "map").map_err(refused)?),
        (None, None) => None,
    };
    let mapped = map.is_some();
    if let Some(m) = map {
        input = input.with_map(m);
    }
    let t = py.detach(|| read_table(&input)).map_err(refused)?;
    if mapped {
        // A vendor's file says nothing of itself: what its columns show.
        let d = Description::of_columns(&t.columns);
        described_out(py, t, &d)
    } else {
        read_out(py, path, t)
    }
}

/// Writes a table in the format its path's extension names (`.parquet`, `.npy`, `.npz`, else
/// CSV), atomically, with its description (`description`'s entries; else what its columns show).
#[pyfunction]
#[pyo3(signature = (path, columns, values, description = None))]
fn write_table_file(
    py: Python<'_>,
    path: &str,
    columns: Vec<String>,
    values: PyReadonlyArray2<'_, f64>,
    description: Option<Bound<'_, PyDict>>,
) -> PyResult<()> {
    let d = description
        .map(|d| description_in("table", &d))
        .transpose()?
        .filter(|d| !d.is_empty());
    let t: Table = table_in("values", columns, &values)?;
    py.detach(move || match d {
        Some(d) => t.write_described(Path::new(path), &d),
        None => t.write(Path::new(path)),
    })
    .map_err(refused)
}

/// Writes a table as an imukit CSV (shortest round-trip numbers, atomically).
#[pyfunction]
fn write_csv(
    py: Python<'_>,
    path: &str,
    columns: Vec<String>,
    values: PyReadonlyArray2<'_, f64>,
) -> PyResult<()> {
    let t: Table = table_in("values", columns, &values)?;
    py.detach(move || t.write_csv(Path::new(path)))
        .map_err(refused)
}

/// What a table file says it holds (its description's entries, keys without the `imukit.`
/// prefix), or `None` when it has none.
#[pyfunction]
fn read_description<'py>(py: Python<'py>, path: &str) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(d) = Description::read(Path::new(path)).map_err(refused)? else {
        return Ok(None);
    };
    description_dict(py, &d).map(Some)
}

/// What in IMU readings (`columns`, `values`) read from `source` looks like a unit slip (g as
/// m/s², °/s as rad/s, ms as s), one sentence each.
#[pyfunction]
fn implausible(
    columns: Vec<String>,
    values: PyReadonlyArray2<'_, f64>,
    source: &str,
) -> PyResult<Vec<String>> {
    // Only the rows looked at are copied.
    let v = values.as_array();
    if v.ncols() != columns.len() {
        return Err(crate::errors::shape_error(format!(
            "values has {} columns but {} column names",
            v.ncols(),
            columns.len()
        )));
    }
    let t = Table {
        columns,
        data: v
            .rows()
            .into_iter()
            .take(imukit::io::plausible::HEAD_ROWS)
            .flat_map(|r| r.to_vec())
            .collect(),
    };
    Ok(imukit::io::plausible::readings(
        &t,
        source,
        "declare the file's units with map=, docs/formats.md",
    ))
}

/// The file of Monte Carlo run `run` of `runs` for the output `out` (`imu.csv` → `imu_run0007.csv`).
#[pyfunction]
fn run_path(out: &str, run: u64, runs: u64) -> String {
    run_file(Path::new(out), run, runs).display().to_string()
}

/// The shipped examples: (name, what) of each.
#[pyfunction]
fn example_list() -> Vec<(&'static str, &'static str)> {
    imukit::examples::EXAMPLES
        .iter()
        .map(|e| (e.name, e.what))
        .collect()
}

/// Writes the examples named under `folder`: (path, written) of each file, `written` false for a
/// file already there with the shipped text.
#[pyfunction]
fn write_examples(names: Vec<String>, folder: &str) -> PyResult<Vec<(String, bool)>> {
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let done = imukit::examples::write(&names, Path::new(folder)).map_err(refused)?;
    Ok(done
        .into_iter()
        .map(|w| {
            let new = matches!(w, imukit::examples::Written::New(_));
            (w.path().display().to_string(), new)
        })
        .collect())
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(write_csv, m)?)?;
    m.add_function(wrap_pyfunction!(read_table_file, m)?)?;
    m.add_function(wrap_pyfunction!(write_table_file, m)?)?;
    m.add_function(wrap_pyfunction!(run_path, m)?)?;
    m.add_function(wrap_pyfunction!(read_description, m)?)?;
    m.add_function(wrap_pyfunction!(implausible, m)?)?;
    m.add_function(wrap_pyfunction!(example_list, m)?)?;
    m.add_function(wrap_pyfunction!(write_examples, m)?)?;
    Ok(())
}
