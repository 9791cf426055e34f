//! `imukit allan IMU.csv [--column NAME …] --out ADEV.csv`.
use std::path::Path;

use imukit::allan::{AllanResult, allan_of_log};
use imukit::io::Input;
use imukit::io::output::check_outputs;
use imukit::io::rows::TimeWindow;

use super::CliError;

pub fn run(
    source: &Input,
    columns: &[String],
    window: TimeWindow,
    out: &Path,
    plot: Option<&Path>,
    size: imu_plot::FigureSize,
) -> Result<(), CliError> {
    let input = source.path();
    if let Some(p) = plot {
        imu_plot::check_figure_path(p)?;
    }
    let mut outputs = vec![("--out", out)];
    outputs.extend(plot.map(|p| ("--plot", p)));
    check_outputs(&[("input", input)], &outputs)?;
    imukit::io::output::check_table_outputs(&[("--out", out)])?;
    crate::report::warn_implausible(source);
    let result = analyse(source, columns, window)?;
    result.table.write(out)?;
    if let Some(p) = plot {
        imu_plot::allan_figure(p, &result, &file_name(input), size)?;
    }
    crate::out_line!(
        "{:<16} {:>14} {:>14} {:>14}",
        "column",
        "N (·/√Hz)",
        "B",
        "K (·√Hz)"
    );
    // A term the curve does not resolve shows as its 95 % bound.
    let show = |e: &imu_core::allan::TermEstimate| {
        if e.resolved {
            format!("{:.4e}", e.value)
        } else {
            format!("<{:.3e}", e.upper)
        }
    };
    for c in &result.noise {
        use imu_core::allan::NoiseTerm as T;
        crate::out_line!(
            "{:<16} {:>14} {:>14} {:>14}",
            c.column,
            show(c.fit.term(T::White)),
            show(c.fit.term(T::BiasInstability)),
            show(c.fit.term(T::RandomWalk))
        );
    }
    crate::out_line!(
        "(\"<x\": not resolved, below x with 95 % confidence; `imukit identify` says more)"
    );
    if let Some(p) = plot {
        crate::note!("imukit: figure written to {}", p.display());
    }
    crate::note!(
        "imukit: Allan deviation of {} columns at {} τ values ({} Hz) written to {}",
        result.noise.len(),
        result.table.rows(),
        result.sample_rate_hz,
        out.display()
    );
    Ok(())
}

/// The input's file name, to title figures.
pub(crate) fn file_name(input: &Path) -> String {
    input.file_name().map_or_else(
        || input.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The Allan curves of `columns` of `source` over `window` ([`allan_of_log`]), its warnings
/// printed.
pub(crate) fn analyse(
    source: &Input,
    columns: &[String],
    window: TimeWindow,
) -> Result<AllanResult, CliError> {
    let log = allan_of_log(source, columns, window)?;
    for w in &log.warnings {
        crate::report::warn(w);
    }
    Ok(log.result)
}
