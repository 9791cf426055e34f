//! Time-ordered rows of IMU files: the one rule for sample times (increasing, no gaps longer
//! than [`MAX_GAP_FACTOR`] median intervals) and the streamed row reader that applies it
//! (`TimedRows`) for `imukit integrate` and `imukit orient`.
use std::collections::VecDeque;
use std::path::Path;

use crate::error::{Result, invalid};
use crate::io::table::CsvRows;

/// Intervals longer than this many median intervals count as gaps in the data.
pub const MAX_GAP_FACTOR: f64 = 2.5;

/// Refuses a gap in sample times: an interval longer than [`MAX_GAP_FACTOR`] median intervals
/// (missing samples would be bridged silently by the integration). `first_row` is the file row of
/// sample 0 (2 below a CSV header), for the message.
///
/// # Errors
/// [`crate::Error::Invalid`] naming the rows and the intervals.
pub fn check_gaps(t_s: &[f64], what: &str, first_row: usize) -> Result<()> {
    if t_s.len() < 3 {
        return Ok(());
    }
    let median = median_interval(t_s);
    let found = t_s
        .windows(2)
        .map(|w| w[1] - w[0])
        .enumerate()
        .find(|(_, d)| *d > MAX_GAP_FACTOR * median);
    match found {
        Some((i, d)) => Err(gap_error(what, i + first_row, d, median)),
        None => Ok(()),
    }
}

/// The median interval of increasing times (at least 2).
pub(crate) fn median_interval(t_s: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    dt[dt.len() / 2]
}

pub(crate) fn gap_error(what: &str, row: usize, d: f64, median: f64) -> crate::Error {
    invalid(
        what,
        format!(
            "gap in the sample times between rows {row} and {} ({d} s, the median interval is {median} s)",
            row + 1
        ),
    )
}

/// Rows a streamed integration reads ahead to set the reference interval of the gap check (the
/// median of their intervals; files this short are checked exactly as [`integrate`](crate::run::navigate::integrate) checks).
pub const GAP_WINDOW: usize = 1001;

/// Rows of an IMU CSV file in time order, for the streamed integration and orientation: each
/// row's time must increase, and no interval may exceed [`MAX_GAP_FACTOR`] median intervals of
/// the first [`GAP_WINDOW`] rows (read ahead when the file is opened). Memory does not grow with
/// the file.
pub(crate) struct TimedRows {
    rows: CsvRows,
    ahead: VecDeque<Vec<f64>>,
    first_t: f64,
    median: Option<f64>,
    previous_t: Option<f64>,
    taken: usize,
}

impl TimedRows {
    /// Opens `path` for `columns` (`t_s` first) and reads the look-ahead.
    ///
    /// # Errors
    /// Missing columns (with `hint`), bad cells, a file without data rows.
    pub(crate) fn open(path: &Path, columns: &[&str], hint: &str) -> Result<Self> {
        let mut rows = CsvRows::open(path, columns, hint)?;
        let mut row = vec![0.0; columns.len()];
        let mut ahead = VecDeque::with_capacity(GAP_WINDOW + 1);
        while ahead.len() <= GAP_WINDOW && rows.next_row(&mut row)?.is_some() {
            ahead.push_back(row.clone());
        }
        let Some(first) = ahead.front() else {
            return Err(crate::Error::CsvFormat {
                file: path.into(),
                message: "no data rows after the header".into(),
            });
        };
        let first_t = first[0];
        let times: Vec<f64> = ahead.iter().map(|r| r[0]).collect();
        Ok(Self {
            rows,
            first_t,
            median: (times.len() > 1).then(|| median_interval(&times)),
            ahead,
            previous_t: None,
            taken: 0,
        })
    }

    /// The first row's time, s.
    pub(crate) fn first_time(&self) -> f64 {
        self.first_t
    }

    /// The median interval of the look-ahead rows, s (`None` for a single row).
    pub(crate) fn median_interval(&self) -> Option<f64> {
        self.median
    }

    /// The file row (header = 1) of the row last read.
    pub(crate) fn last_row(&self) -> usize {
        self.taken + 1
    }

    /// Reads the next row into `row`; `false` at the end of the file.
    ///
    /// # Errors
    /// Bad cells, times that do not increase, gaps (rows named).
    pub(crate) fn next_row(&mut self, row: &mut [f64]) -> Result<bool> {
        match self.ahead.pop_front() {
            Some(r) => row.copy_from_slice(&r),
            None => {
                if self.rows.next_row(row)?.is_none() {
                    return Ok(false);
                }
            }
        }
        self.taken += 1;
        let (t, line) = (row[0], self.last_row());
        if let Some(p) = self.previous_t {
            if t <= p {
                return Err(invalid(
                    "IMU data",
                    format!(
                        "time at row {line} does not increase after row {}",
                        line - 1
                    ),
                ));
            }
            if let Some(m) = self.median.filter(|m| t - p > MAX_GAP_FACTOR * m) {
                return Err(gap_error("IMU data", line - 1, t - p, m));
            }
        }
        self.previous_t = Some(t);
        Ok(true)
    }
}
