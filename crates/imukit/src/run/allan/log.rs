//! The Allan deviation of a logged file: its rate columns as a logger wrote them, with the
//! logger's exact repeats dropped, cut to a time window, and the gaps that break the
//! deviation's even spacing said.
use crate::error::{Error, Result, invalid};
use crate::io::Input;
use crate::io::columns::{ACCEL_COLUMNS, GYRO_COLUMNS};
use crate::io::read::{read_columns, read_header};
use crate::io::rows::{Gaps, MAX_GAP_FACTOR, TimeWindow, not_increasing, repeated_rows};

use super::{AllanResult, allan, mean_rate};

/// A log's Allan curves and what a reader should know about the log.
#[derive(Clone, Debug, PartialEq)]
pub struct AllanLog {
    /// The curves and noise terms.
    pub result: AllanResult,
    /// Warnings about the log (repeated rows dropped, gaps), each naming the file and its rows.
    pub warnings: Vec<String>,
}

/// The Allan curves and noise terms of `columns` of `source` (none given: every gyroscope and
/// accelerometer column it has) over `window`. A logger's exact copies of its last sample are
/// dropped and said; the times left must increase; gaps longer than
/// [`MAX_GAP_FACTOR`] median intervals are said (the deviation takes the samples as evenly
/// spaced). Refusals name the file, its row and the column.
///
/// # Errors
/// A file that cannot be read, a missing column, times that do not increase, fewer than two
/// rows in the window, and as [`allan`].
pub fn allan_of_log(source: &Input, columns: &[String], window: TimeWindow) -> Result<AllanLog> {
    let file = source.path().display().to_string();
    let chosen = chosen_columns(source, columns)?;
    let mut required: Vec<&str> = vec!["t_s"];
    required.extend(chosen.iter().map(String::as_str));
    let hint = if chosen.is_empty() {
        "; no gyro_* or accel_* columns: name columns with --column"
    } else {
        ""
    };
    let data = read_columns(source, &required, hint)?;
    let mut warnings = Vec::new();
    // A logger's exact copies of its last sample carry nothing: dropped, and said. The times
    // left must increase (refused by file row); `kept` maps samples back to rows.
    let (repeated, repeats) = repeated_rows(data.get("t_s"), |i| {
        chosen.iter().all(|c| data.get(c)[i] == data.get(c)[i - 1])
    });
    warnings.extend(repeats.message(&file, 2));
    let kept: Vec<usize> = (0..repeated.len()).filter(|&i| !repeated[i]).collect();
    let all_t: Vec<f64> = kept.iter().map(|&i| data.get("t_s")[i]).collect();
    if let Some(k) = (1..all_t.len()).find(|&k| all_t[k].is_nan() || all_t[k] <= all_t[k - 1]) {
        return Err(not_increasing(&file, kept[k] + 2));
    }
    let rows = window_rows(&all_t, window, &file)?;
    let t = &all_t[rows.clone()];
    warnings.extend(gap_warning(t, &kept[rows.clone()], &file));
    let rate = mean_rate(t)?;
    let series: Vec<(String, Vec<f64>)> = chosen
        .iter()
        .map(|c| {
            let kept_values: Vec<f64> =
                kept[rows.clone()].iter().map(|&i| data.get(c)[i]).collect();
            (c.clone(), kept_values)
        })
        .collect();
    // The curves name the column; the file is named here.
    let in_file = |column: String| format!("{file}, column {column}");
    let result = allan(&series, rate).map_err(|e| match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: in_file(field.to_string()).into(),
            message,
        },
        Error::Allan { context, source } => Error::Allan {
            context: in_file(context),
            source,
        },
        other => other,
    })?;
    Ok(AllanLog { result, warnings })
}

/// The columns to analyse: `columns`, or every gyroscope and accelerometer column of the file.
fn chosen_columns(source: &Input, columns: &[String]) -> Result<Vec<String>> {
    if !columns.is_empty() {
        return Ok(columns.to_vec());
    }
    let header = read_header(source)?;
    Ok(GYRO_COLUMNS
        .iter()
        .chain(&ACCEL_COLUMNS)
        .filter(|c| header.iter().any(|h| h == *c))
        .map(|c| (*c).to_string())
        .collect())
}

/// The samples (of times `t`) in `window`, whose seconds count from the first sample.
///
/// # Errors
/// Fewer than two samples in the window.
fn window_rows(t: &[f64], window: TimeWindow, file: &str) -> Result<std::ops::Range<usize>> {
    let (false, Some(&t0)) = (window.is_whole(), t.first()) else {
        return Ok(0..t.len());
    };
    let (lo, hi) = window.bounds(t0);
    let from = t.partition_point(|&x| x < lo);
    let to = t.partition_point(|&x| x <= hi);
    if to < from + 2 {
        return Err(invalid(
            file,
            format!(
                "{} row(s) lie in the window {} (seconds after the first sample); at least 2 \
                 needed",
                to.saturating_sub(from),
                window.describe()
            ),
        ));
    }
    Ok(from..to)
}

/// The warning for the gaps of samples at times `t` (`rows[k]`: sample `k`'s index among the
/// file's data rows), if any.
fn gap_warning(t: &[f64], rows: &[usize], file: &str) -> Option<String> {
    let gaps = Gaps::of_times(t, 0);
    (gaps.count > 0).then(|| {
        format!(
            "{file}: {} interval(s) longer than {MAX_GAP_FACTOR} median intervals ({} s), the \
             longest {} s after row {}: the Allan deviation takes the samples as evenly spaced, \
             so its clusters across the gaps are not the sensor's noise (cut the log at the gaps)",
            gaps.count,
            (gaps.median_s * 1e6).round() / 1e6,
            (gaps.longest_s * 1e6).round() / 1e6,
            rows[gaps.longest_after_row] + 2
        )
    })
}
