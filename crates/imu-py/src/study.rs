//! The outage study for Python (`imukit.study`): the plan, one run and the summary of a study
//! file, so that Python can spread the runs over threads or Dask workers.
use std::path::Path;

use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;

use crate::convert::{TableOut, table_out};
use crate::errors::refused;

/// One run of an outage study (`imukit study`'s file at `path`): preset number `case`, run
/// `run` → `(t_s, horizontal_error_m, horizontal_sigma_m, None, resets, smoothed_error_m)`
/// through the first outage (the last empty unless the study smooths), or
/// `(None, None, None, message, 0, None)` when the filter diverged.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn study_run<'py>(
    py: Python<'py>,
    path: &str,
    case: usize,
    run: u64,
) -> PyResult<(
    Option<Bound<'py, PyArray1<f64>>>,
    Option<Bound<'py, PyArray1<f64>>>,
    Option<Bound<'py, PyArray1<f64>>>,
    Option<String>,
    usize,
    Option<Bound<'py, PyArray1<f64>>>,
)> {
    use imukit::study::{RunOutcome, Study};
    let path = Path::new(path).to_path_buf();
    let outcome = py
        .detach(move || Study::from_file(&path)?.run_one(case, run))
        .map_err(refused)?;
    Ok(match outcome {
        RunOutcome::Outage(r) => (
            Some(r.t_s.into_pyarray(py)),
            Some(r.horizontal_error_m.into_pyarray(py)),
            Some(r.horizontal_sigma_m.into_pyarray(py)),
            None,
            r.resets,
            Some(r.smoothed_error_m.into_pyarray(py)),
        ),
        RunOutcome::Diverged(message) => (None, None, None, Some(message), 0, None),
    })
}

/// The study at `path`: the presets it compares that are not described alike, a line each
/// (`Study::undescribed`).
#[pyfunction]
fn study_undescribed(path: &str) -> PyResult<Vec<String>> {
    let s = imukit::study::Study::from_file(Path::new(path)).map_err(refused)?;
    Ok(s.undescribed())
}

/// The study at `path`: its presets and runs per preset.
#[pyfunction]
fn study_plan(path: &str) -> PyResult<(Vec<String>, u64)> {
    let s = imukit::study::Study::from_file(Path::new(path)).map_err(refused)?;
    Ok((s.presets().map(str::to_string).collect(), s.runs()))
}

/// The study's table and per-preset summaries from every run's outcome, `outcomes[case][run]` as
/// [`study_run`] returns them.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn study_summarise<'py>(
    py: Python<'py>,
    path: &str,
    outcomes: Vec<
        Vec<(
            Option<Vec<f64>>,
            Option<Vec<f64>>,
            Option<Vec<f64>>,
            Option<String>,
            usize,
            Option<Vec<f64>>,
        )>,
    >,
) -> PyResult<(
    TableOut<'py>,
    Vec<(
        String,
        usize,
        usize,
        Option<f64>,
        Option<f64>,
        f64,
        usize,
        Option<(f64, f64)>,
    )>,
)> {
    use imukit::study::{OutageRun, RunOutcome, Study};
    let study = Study::from_file(Path::new(path)).map_err(refused)?;
    let outcomes: Vec<Vec<RunOutcome>> = outcomes
        .into_iter()
        .map(|runs| {
            runs.into_iter()
                .map(|(t, e, s, message, resets, smoothed)| match (t, e, s) {
                    (Some(t_s), Some(horizontal_error_m), Some(horizontal_sigma_m)) => {
                        RunOutcome::Outage(OutageRun {
                            t_s,
                            horizontal_error_m,
                            horizontal_sigma_m,
                            smoothed_error_m: smoothed.unwrap_or_default(),
                            resets,
                        })
                    }
                    _ => RunOutcome::Diverged(message.unwrap_or_default()),
                })
                .collect()
        })
        .collect();
    let (table, summaries) = study.summarise(&outcomes).map_err(refused)?;
    let summaries = summaries
        .into_iter()
        .map(|m| {
            (
                m.preset,
                m.completed,
                m.diverged.0,
                m.rms_error_m,
                m.sigma_m,
                m.outage_s,
                m.resets.1,
                m.smoothed_rms_error_m,
            )
        })
        .collect();
    Ok((table_out(py, table)?, summaries))
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(study_plan, m)?)?;
    m.add_function(wrap_pyfunction!(study_undescribed, m)?)?;
    m.add_function(wrap_pyfunction!(study_run, m)?)?;
    m.add_function(wrap_pyfunction!(study_summarise, m)?)?;
    Ok(())
}
