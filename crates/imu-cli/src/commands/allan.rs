//! `imukit allan IMU.csv [--column NAME …] --out ADEV.csv`.
use std::path::Path;

use imukit::io::Input;
use imukit::io::columns::{ACCEL_COLUMNS, GYRO_COLUMNS};
use imukit::io::output::check_outputs;
use imukit::io::read::{read_columns, read_header};
use imukit::io::rows::{TimeWindow, not_increasing, repeated_rows};
use imukit::run::allan::{AllanResult, allan, mean_rate};

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

/// Reads `columns` (default: every gyro and accel column) and `t_s` of `input` and computes
/// their Allan curves and noise terms; errors name the file and column.
pub(crate) fn analyse(
    source: &Input,
    columns: &[String],
    window: TimeWindow,
) -> Result<AllanResult, CliError> {
    let input = source.path();
    let header = read_header(source)?;
    let chosen: Vec<String> = if columns.is_empty() {
        GYRO_COLUMNS
            .iter()
            .chain(&ACCEL_COLUMNS)
            .filter(|c| header.iter().any(|h| h == *c))
            .map(|c| (*c).to_string())
            .collect()
    } else {
        columns.to_vec()
    };
    let mut required: Vec<&str> = vec!["t_s"];
    required.extend(chosen.iter().map(String::as_str));
    let hint = if chosen.is_empty() {
        "; no gyro_* or accel_* columns: name columns with --column"
    } else {
        ""
    };
    let data = read_columns(source, &required, hint)?;
    // A logger's exact copies of its last sample carry nothing: dropped, and said. The times
    // left must increase (refused by file row); `kept` maps samples back to rows.
    let (repeated, repeats) = repeated_rows(data.get("t_s"), |i| {
        chosen.iter().all(|c| data.get(c)[i] == data.get(c)[i - 1])
    });
    if let Some(m) = repeats.message(&input.display().to_string(), 2) {
        crate::report::warn(&m);
    }
    let kept: Vec<usize> = (0..repeated.len()).filter(|&i| !repeated[i]).collect();
    let all_t: Vec<f64> = kept.iter().map(|&i| data.get("t_s")[i]).collect();
    if let Some(k) = (1..all_t.len()).find(|&k| all_t[k].is_nan() || all_t[k] <= all_t[k - 1]) {
        return Err(not_increasing(&input.display().to_string(), kept[k] + 2).into());
    }
    // The window's rows.
    let rows = match (window.is_whole(), all_t.first()) {
        (false, Some(&t0)) => {
            let (lo, hi) = window.bounds(t0);
            let from = all_t.partition_point(|&t| t < lo);
            let to = all_t.partition_point(|&t| t <= hi);
            if to < from + 2 {
                return Err(imukit::Error::Invalid {
                    field: input.display().to_string(),
                    message: format!(
                        "{} row(s) lie in the window {} (seconds after the first sample); at \
                         least 2 needed",
                        to.saturating_sub(from),
                        window.describe()
                    ),
                }
                .into());
            }
            from..to
        }
        _ => 0..all_t.len(),
    };
    let t = &all_t[rows.clone()];
    // The Allan deviation takes the samples as evenly spaced: gaps are said (the clusters that
    // span them are not the sensor's noise).
    let mut gaps = imukit::io::rows::Gaps::of_times(t, 0);
    if gaps.count > 0 {
        gaps.longest_after_row = kept[rows.start + gaps.longest_after_row] + 2;
        crate::report::warn(&format!(
            "{}: {} interval(s) longer than {} median intervals ({} s), the longest {} s after \
             row {}: the Allan deviation takes the samples as evenly spaced, so its clusters \
             across the gaps are not the sensor's noise (cut the log at the gaps)",
            input.display(),
            gaps.count,
            imukit::io::rows::MAX_GAP_FACTOR,
            (gaps.median_s * 1e6).round() / 1e6,
            (gaps.longest_s * 1e6).round() / 1e6,
            gaps.longest_after_row
        ));
    }
    let rate = mean_rate(t)?;
    let series: Vec<(String, Vec<f64>)> = chosen
        .iter()
        .map(|c| {
            let kept_values: Vec<f64> =
                kept[rows.clone()].iter().map(|&i| data.get(c)[i]).collect();
            (c.clone(), kept_values)
        })
        .collect();
    // The library names the column; the file is named here.
    let in_file = |column: String| format!("{}, column {column}", input.display());
    let result = allan(&series, rate).map_err(|e| match e {
        imukit::Error::Invalid { field, message } => imukit::Error::Invalid {
            field: in_file(field),
            message,
        },
        imukit::Error::Allan { context, source } => imukit::Error::Allan {
            context: in_file(context),
            source,
        },
        other => other,
    })?;
    Ok(result)
}
