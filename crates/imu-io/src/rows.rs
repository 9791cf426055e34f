//! Time-ordered rows of IMU files: the one rule for sample times, and the streamed row reader
//! that applies it (`TimedRows`) for `imukit integrate` and `imukit orient`.
//!
//! Times must increase. Each sample is integrated over its own interval, whatever its length,
//! so jitter and lost samples cost only what the motion did meanwhile. An interval longer than
//! [`MAX_GAP_FACTOR`] median intervals is a *gap*: it is bridged like any other (the strapdown
//! and the filters carry their state across it), and counted and reported ([`Gaps`]) so that a
//! user knows the data had holes. Nothing is refused for jitter or gaps.
//!
//! A [`TimeWindow`] keeps the rows of a stretch of a log (`--start-s`, `--end-s`), counted in
//! seconds from the first sample of the command's first input, so that the same numbers cut
//! every file of one run (the fixes, the reference) at the same instants.
use std::collections::VecDeque;

use crate::error::{Data, Result, invalid};
use crate::read::CsvRows;
use crate::table::Table;

/// A stretch of a run: from `start_s` to `end_s` seconds after the first sample of the run's
/// first input (either end open when `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TimeWindow {
    /// Seconds after the first sample where the stretch begins (≥ 0).
    pub start_s: Option<f64>,
    /// Seconds after the first sample where it ends (> `start_s`).
    pub end_s: Option<f64>,
}

impl TimeWindow {
    /// The window, checked: finite, `start_s ≥ 0`, `end_s > start_s` (and > 0).
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `start_s` or `end_s`.
    pub fn new(start_s: Option<f64>, end_s: Option<f64>) -> Result<Self> {
        if let Some(s) = start_s
            && !(s.is_finite() && s >= 0.0)
        {
            return Err(crate::error::refused(
                crate::error::RequestOption::StartS,
                format!("must be a finite number of seconds ≥ 0 after the first sample, got {s}"),
            ));
        }
        let after = start_s.unwrap_or(0.0);
        if let Some(e) = end_s
            && !(e.is_finite() && e > after)
        {
            return Err(crate::error::refused(
                crate::error::RequestOption::EndS,
                format!("must be a finite number of seconds after the start ({after} s), got {e}"),
            ));
        }
        Ok(Self { start_s, end_s })
    }

    /// True when the window keeps every row.
    #[must_use]
    pub fn is_whole(&self) -> bool {
        self.start_s.is_none() && self.end_s.is_none()
    }

    /// The rows of `table` whose `t_s` lies in the window, its seconds counted from `t0` (the
    /// first sample of the run's first input, [`Self::first_time`]); the table itself when the
    /// window is whole.
    ///
    /// # Errors
    /// A table without `t_s`, or with fewer than `at_least` rows in the window, naming `source`
    /// and the window.
    pub fn apply(&self, table: Table, t0: f64, source: &str, at_least: usize) -> Result<Table> {
        if self.is_whole() {
            return Ok(table);
        }
        let Some(k) = table.columns.iter().position(|c| c == "t_s") else {
            return Err(invalid(
                source,
                "has no t_s column to cut a time window from",
            ));
        };
        let (lo, hi) = self.bounds(t0);
        let width = table.columns.len();
        let mut kept = Table {
            columns: table.columns.clone(),
            data: Vec::new(),
        };
        for row in table.data.chunks_exact(width) {
            if row[k] >= lo && row[k] <= hi {
                kept.data.extend_from_slice(row);
            }
        }
        if kept.rows() < at_least {
            return Err(invalid(
                source,
                format!(
                    "{} row(s) of {} lie in the window {} (seconds after the first sample, \
                     t_s = {t0}); at least {at_least} needed",
                    kept.rows(),
                    table.rows(),
                    self.describe()
                ),
            ));
        }
        Ok(kept)
    }

    /// The window's ends as times, its seconds counted from `t0`: `(t0 + start, t0 + end)`,
    /// the start `t0` and the end +∞ when not given.
    #[must_use]
    pub fn bounds(&self, t0: f64) -> (f64, f64) {
        (
            t0 + self.start_s.unwrap_or(0.0),
            self.end_s.map_or(f64::INFINITY, |e| t0 + e),
        )
    }

    /// The first `t_s` of `table`, the origin of the window's seconds.
    ///
    /// # Errors
    /// A table without `t_s` or rows, naming `source`.
    pub fn first_time(table: &Table, source: &str) -> Result<f64> {
        let k = table.columns.iter().position(|c| c == "t_s");
        k.and_then(|k| table.data.get(k).copied())
            .ok_or_else(|| invalid(source, "has no t_s column or no rows"))
    }

    /// The first `t_s` of the file at `path` (its first row alone is read), the origin of the
    /// window's seconds for a command whose first input is that file.
    ///
    /// # Errors
    /// Missing `t_s`, a bad first row, a file without rows.
    pub fn first_time_in(input: impl Into<crate::Input>) -> Result<f64> {
        let input = input.into();
        let path = input.path();
        let mut rows = CsvRows::open(&input, &["t_s"], "")?;
        let mut t = [0.0];
        match rows.next_row(&mut t)? {
            Some(_) => Ok(t[0]),
            None => Err(crate::Error::CsvFormat {
                file: path.into(),
                message: "no data rows after the header".into(),
            }),
        }
    }

    /// The window as `[10 s, 60 s]`.
    #[must_use]
    pub fn describe(&self) -> String {
        let end = self
            .end_s
            .map_or_else(|| "the end".to_string(), |e| format!("{e} s"));
        format!("[{} s, {end}]", self.start_s.unwrap_or(0.0))
    }
}

/// Intervals longer than this many median intervals count as gaps in the data.
pub const MAX_GAP_FACTOR: f64 = 2.5;

/// The gaps in a run's sample times: intervals longer than [`MAX_GAP_FACTOR`] times the
/// reference (median) interval, bridged and reported.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gaps {
    /// The reference interval, s: the median interval (of the first
    /// [`GAP_WINDOW`] rows when streamed); 0 with fewer than two samples.
    pub median_s: f64,
    /// How many intervals are gaps.
    pub count: usize,
    /// The time the gaps span in all, s.
    pub total_s: f64,
    /// The longest gap, s (0 without gaps).
    pub longest_s: f64,
    /// The file row (a CSV header is row 1) of the sample before the longest gap.
    pub longest_after_row: usize,
}

impl Gaps {
    /// No gaps yet, against the reference interval `median_s`.
    #[must_use]
    pub fn against(median_s: f64) -> Self {
        Self {
            median_s,
            ..Self::default()
        }
    }

    /// The gaps of increasing times `t_s`, sample 0 being file row `first_row`.
    #[must_use]
    pub fn of_times(t_s: &[f64], first_row: usize) -> Self {
        if t_s.len() < 2 {
            return Self::default();
        }
        let mut gaps = Self::against(median_interval(t_s));
        for (i, w) in t_s.windows(2).enumerate() {
            gaps.note(w[1] - w[0], i + first_row);
        }
        gaps
    }

    /// Notes one interval, after the sample at file row `row`.
    pub fn note(&mut self, interval_s: f64, row: usize) {
        if interval_s > MAX_GAP_FACTOR * self.median_s {
            self.count += 1;
            self.total_s += interval_s;
            if interval_s > self.longest_s {
                self.longest_s = interval_s;
                self.longest_after_row = row;
            }
        }
    }

    /// What a run tells its user about the gaps of `what` (`None` without gaps).
    #[must_use]
    pub fn message(&self, what: &str) -> Option<String> {
        (self.count > 0).then(|| {
            let (n, s) = (self.count, if self.count == 1 { "" } else { "s" });
            // To the microsecond: what a reader compares, not the stamps' last digits.
            let us = |v: f64| (v * 1e6).round() / 1e6;
            format!(
                "{what}: {n} gap{s} longer than {MAX_GAP_FACTOR} median intervals ({} s), \
                 {} s in all, integrated across; the longest, {} s, after row {}",
                us(self.median_s),
                us(self.total_s),
                us(self.longest_s),
                self.longest_after_row
            )
        })
    }
}

/// The median interval of increasing times (at least 2).
pub fn median_interval(t_s: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    dt[dt.len() / 2]
}

/// The refusal of a time that does not increase, at file row `row`.
pub fn not_increasing(what: impl Into<crate::error::Subject>, row: usize) -> crate::Error {
    invalid(
        what,
        format!("time at row {row} does not increase after row {}", row - 1),
    )
}

/// Checks that the times `t_s` increase (sample 0 at file row `first_row`).
///
/// # Errors
/// [`crate::Error::Invalid`] naming the first row whose time does not increase (or is NaN).
pub fn check_increasing(
    t_s: &[f64],
    what: impl Into<crate::error::Subject>,
    first_row: usize,
) -> Result<()> {
    match (1..t_s.len()).find(|&i| t_s[i].is_nan() || t_s[i] <= t_s[i - 1]) {
        Some(i) => Err(not_increasing(what, i + first_row)),
        None => Ok(()),
    }
}

/// Samples that repeat the sample before them exactly — the same time and the same readings:
/// a logger's copy of its last sample, written when it missed one. They carry nothing new and
/// no interval to integrate over, so the jobs drop them and say so; a repeated time with other
/// readings stays a refusal ([`check_increasing`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Repeats {
    /// How many samples repeat the one before.
    pub count: usize,
    /// The index of the first that does.
    pub first: Option<usize>,
}

/// Per sample at times `t_s` with `readings` (each as long as `t_s`), whether it repeats the
/// sample before exactly ([`Repeats`]), and the count.
#[must_use]
pub fn repeated_samples(t_s: &[f64], readings: &[&[[f64; 3]]]) -> (Vec<bool>, Repeats) {
    repeated_rows(t_s, |i| {
        readings
            .iter()
            .all(|r| r.get(i).is_some() && r.get(i) == r.get(i - 1))
    })
}

/// Per row at times `t_s`, whether it repeats the row before exactly: the same time, and
/// `same(i)` says its values equal row `i − 1`'s ([`repeated_samples`] for triads of readings).
#[must_use]
pub fn repeated_rows(t_s: &[f64], same: impl Fn(usize) -> bool) -> (Vec<bool>, Repeats) {
    let repeated: Vec<bool> = (0..t_s.len())
        .map(|i| i > 0 && t_s[i] == t_s[i - 1] && same(i))
        .collect();
    let count = repeated.iter().filter(|r| **r).count();
    let first = repeated.iter().position(|r| *r);
    (repeated, Repeats { count, first })
}

/// `values` without the entries `drop` marks.
#[must_use]
pub fn without<T>(values: Vec<T>, drop: &[bool]) -> Vec<T> {
    values
        .into_iter()
        .zip(drop.iter().copied().chain(core::iter::repeat(false)))
        .filter_map(|(x, d)| (!d).then_some(x))
        .collect()
}

impl Repeats {
    /// What a run tells its user about the repeats of `what`, its sample 0 at file row
    /// `first_row` (`None` without repeats).
    #[must_use]
    pub fn message(&self, what: &str, first_row: usize) -> Option<String> {
        let first = self.first?;
        let (n, s) = (self.count, if self.count == 1 { "" } else { "s" });
        Some(format!(
            "{what}: {n} row{s} repeat the row before exactly (time and readings; the first at \
             row {}): a logger's copies of its last sample, dropped",
            first + first_row
        ))
    }
}

/// The time of the last sample a run in chunks has taken, so that each chunk's first sample
/// gets its interval from the chunk before.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleClock {
    last_t_s: Option<f64>,
}

impl SampleClock {
    /// The interval before each of `t_s` (`None` for the first sample of a run), after
    /// checking the times are finite and increase, from the last time of the chunk before.
    /// The clock moves to the last time only through [`SampleClock::advance`], once the chunk
    /// has been taken.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `t_s` and the index of a time that is not finite or
    /// does not increase.
    pub fn intervals(&self, t_s: &[f64]) -> Result<Vec<Option<f64>>> {
        let mut previous = self.last_t_s;
        t_s.iter()
            .enumerate()
            .map(|(i, &t)| {
                if !t.is_finite() {
                    return Err(invalid("t_s", format!("row {i}: {t} is not a finite time")));
                }
                let interval = match previous {
                    Some(p) if t <= p => {
                        return Err(invalid(
                            "t_s",
                            format!("row {i}: the time {t} s does not increase (after {p} s)"),
                        ));
                    }
                    Some(p) => Some(t - p),
                    None => None,
                };
                previous = Some(t);
                Ok(interval)
            })
            .collect()
    }

    /// Moves the clock to the last of `t_s` (`None`: forgets the time, so the next sample
    /// starts a new run's timing).
    pub fn advance(&mut self, t_s: Option<&[f64]>) {
        self.last_t_s = match t_s {
            Some(t) => t.last().copied().or(self.last_t_s),
            None => None,
        };
    }
}

/// Rows a streamed run reads ahead to set the reference interval of [`Gaps`] (the median of
/// their intervals; files this short are judged exactly as a whole table is).
pub const GAP_WINDOW: usize = 1001;

/// Rows of an IMU CSV file in time order, for the streamed integration and orientation: each
/// row's time must increase; intervals longer than [`MAX_GAP_FACTOR`] median intervals of the
/// first [`GAP_WINDOW`] rows (read ahead when the file is opened) are noted as [`Gaps`]. Memory
/// does not grow with the file.
pub struct TimedRows {
    rows: CsvRows,
    ahead: VecDeque<Vec<f64>>,
    first_t: f64,
    median: Option<f64>,
    previous_t: Option<f64>,
    interval: Option<f64>,
    gaps: Gaps,
    taken: usize,
    /// The rows given: from `window.0` to `window.1` (absolute times), the others skipped.
    window: (f64, f64),
    /// The window as the user gave it, and the file, for the message when it holds no row.
    asked: TimeWindow,
    path: std::path::PathBuf,
    given: usize,
    /// The time of the last row skipped before the window (for the order check).
    skipped_t: Option<f64>,
    width: usize,
    /// The last row given, to drop a logger's exact copy of it ([`Repeats`]).
    last: Vec<f64>,
    /// The rows dropped as exact copies of the row before, by sample index from file row 2.
    repeats: Repeats,
}

impl TimedRows {
    /// Opens `input` for `columns` (`t_s` first) and reads the look-ahead.
    ///
    /// # Errors
    /// Missing columns (with `hint`), bad cells, a file without data rows.
    pub fn open(input: impl Into<crate::Input>, columns: &[&str], hint: &str) -> Result<Self> {
        let input = input.into();
        let path = input.path();
        let mut rows = CsvRows::open(&input, columns, hint)?;
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
        // Out-of-order look-ahead rows are refused by row when they are read; the reference
        // interval is then never used.
        let median = (times.len() > 1).then(|| median_interval(&times));
        Ok(Self {
            rows,
            first_t,
            median,
            ahead,
            previous_t: None,
            interval: None,
            gaps: Gaps::against(median.unwrap_or(0.0)),
            taken: 0,
            window: (f64::NEG_INFINITY, f64::INFINITY),
            asked: TimeWindow::default(),
            path: path.into(),
            given: 0,
            skipped_t: None,
            width: columns.len(),
            last: Vec::new(),
            repeats: Repeats::default(),
        })
    }

    /// Gives only the rows of `window` (its seconds counted from this file's first row): the
    /// rows before it are read, checked in order and skipped, and the file ends with it.
    pub fn within(mut self, window: TimeWindow) -> Self {
        if !window.is_whole() {
            self.window = window.bounds(self.first_t);
            self.asked = window;
        }
        self
    }

    /// The time of the first row given, s: the file's first row, or the first in the window
    /// ([`Self::within`]; the rows before it are read, checked in order and skipped).
    ///
    /// # Errors
    /// Bad cells, times that do not increase, a window that holds no row.
    pub fn start_time(&mut self) -> Result<f64> {
        loop {
            if self.ahead.is_empty() {
                let mut row = vec![0.0; self.width];
                if self.rows.next_row(&mut row)?.is_none() {
                    self.ended()?;
                    return Ok(self.first_t);
                }
                self.ahead.push_back(row);
            }
            let t = self.ahead[0][0];
            if self.is_copy(&self.ahead[0]) {
                self.count_copy(self.taken + 2);
                self.ahead.pop_front();
                self.taken += 1;
                continue;
            }
            if let Some(p) = self.skipped_t
                && t <= p
            {
                return Err(not_increasing(Data::Imu, self.taken + 2));
            }
            if t >= self.window.0 {
                if t > self.window.1 {
                    self.ended()?;
                }
                return Ok(t);
            }
            self.skipped_t = Some(t);
            if let Some(row) = self.ahead.pop_front() {
                self.last = row;
            }
            self.taken += 1;
        }
    }

    /// The median interval of the look-ahead rows, s (`None` for a single row).
    pub fn median_interval(&self) -> Option<f64> {
        self.median
    }

    /// The interval from the row before to the row last read, s (`None` for the first row).
    pub fn interval(&self) -> Option<f64> {
        self.interval
    }

    /// The gaps among the rows read so far.
    pub fn gaps(&self) -> Gaps {
        self.gaps
    }

    /// The rows dropped as exact copies of the row before (time and values): a logger's
    /// copies of its last sample ([`Repeats::message`] with first row 2).
    pub fn repeats(&self) -> Repeats {
        self.repeats
    }

    /// The file row (header = 1) of the row last read.
    pub fn last_row(&self) -> usize {
        self.taken + 1
    }

    /// Reads the next row into `row`; `false` at the end of the file.
    ///
    /// # Errors
    /// Bad cells, times that do not increase (rows named).
    pub fn next_row(&mut self, row: &mut [f64]) -> Result<bool> {
        loop {
            match self.ahead.pop_front() {
                Some(r) => row.copy_from_slice(&r),
                None => {
                    if self.rows.next_row(row)?.is_none() {
                        return self.ended();
                    }
                }
            }
            self.taken += 1;
            let (t, line) = (row[0], self.last_row());
            if self.is_copy(row) {
                self.count_copy(line);
                continue;
            }
            if let Some(p) = self.previous_t.or(self.skipped_t)
                && t <= p
            {
                return Err(not_increasing(Data::Imu, line));
            }
            if t > self.window.1 {
                return self.ended();
            }
            if t < self.window.0 {
                // Before the window: checked in order, then skipped as if not in the file.
                self.skipped_t = Some(t);
                self.remember(row);
                continue;
            }
            if let Some(p) = self.previous_t {
                self.gaps.note(t - p, line - 1);
                self.interval = Some(t - p);
            }
            self.previous_t = Some(t);
            self.remember(row);
            self.given += 1;
            return Ok(true);
        }
    }

    /// Whether `row` is a logger's exact copy of the row before it, given or skipped: nothing
    /// new and no interval.
    fn is_copy(&self, row: &[f64]) -> bool {
        self.previous_t.or(self.skipped_t) == Some(row[0]) && self.last == row
    }

    /// Counts the copy at file row `line` in [`Self::repeats`].
    fn count_copy(&mut self, line: usize) {
        self.repeats.count += 1;
        self.repeats.first.get_or_insert(line - 2);
    }

    /// Keeps `row` as the row before the next, to recognise its copy.
    fn remember(&mut self, row: &[f64]) {
        self.last.clear();
        self.last.extend_from_slice(row);
    }

    /// The end of the rows given; refused when a window held none.
    fn ended(&mut self) -> Result<bool> {
        if self.given == 0 && !self.asked.is_whole() {
            return Err(crate::Error::CsvFormat {
                file: self.path.clone(),
                message: format!(
                    "no row lies in the window {} (seconds after the first sample, t_s = {})",
                    self.asked.describe(),
                    self.first_t
                ),
            });
        }
        Ok(false)
    }
}

impl CsvRows {
    /// Gives only the rows whose `t_s` (a column asked for) lies in `window`, its seconds
    /// counted from `t0`: the rows before it are skipped, and the rows end after it.
    ///
    /// # Errors
    /// `t_s` not among the columns asked for.
    pub fn within(mut self, window: TimeWindow, t0: f64) -> Result<Self> {
        if window.is_whole() {
            return Ok(self);
        }
        let Some(k) = self.wanted.iter().position(|(_, name)| name == "t_s") else {
            return Err(invalid(
                self.path.display().to_string(),
                "has no t_s column to cut a time window from",
            ));
        };
        let (lo, hi) = window.bounds(t0);
        self.window = Some((k, lo, hi));
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log() -> Table {
        let mut t = Table::new(&["t_s", "x"]);
        for k in 0..100 {
            let time = 25_600.0 + f64::from(k) * 0.1;
            t.push_row(&[time, f64::from(k)]);
        }
        t
    }

    #[test]
    fn a_window_keeps_the_rows_of_its_stretch_counted_from_the_first_sample() {
        let t = log();
        let t0 = TimeWindow::first_time(&t, "log.csv").expect("a time");
        assert_eq!(t0, 25_600.0);
        let w = TimeWindow::new(Some(2.0), Some(5.0)).expect("valid");
        let kept = w.apply(t.clone(), t0, "log.csv", 2).expect("rows");
        let x = kept.column("x").expect("x");
        // 25 602.0 is 25 600 + 20 × 0.1 to within a rounding: the rows from 20 or 21 to 50.
        assert!(x[0] == 20.0 || x[0] == 21.0, "{}", x[0]);
        assert!(x[x.len() - 1] == 50.0 || x[x.len() - 1] == 49.0);
        let tail = TimeWindow::new(Some(9.45), None)
            .expect("valid")
            .apply(t.clone(), t0, "log.csv", 2)
            .expect("rows");
        assert_eq!(tail.column("x").expect("x"), [95.0, 96.0, 97.0, 98.0, 99.0]);
        let whole = TimeWindow::default()
            .apply(t.clone(), t0, "log.csv", 2)
            .expect("rows");
        assert_eq!(whole, t);
        // Another file of the run, cut at the same instants.
        let mut fixes = Table::new(&["t_s", "y"]);
        for k in 0..10 {
            fixes.push_row(&[25_600.0 + f64::from(k), 0.0]);
        }
        let cut = w.apply(fixes, t0, "gnss.csv", 1).expect("fixes");
        assert_eq!(
            cut.column("t_s").expect("t"),
            [25_602.0, 25_603.0, 25_604.0, 25_605.0]
        );
    }

    #[test]
    fn a_window_is_checked_and_an_empty_one_named() {
        for (start, end, field) in [
            (Some(-1.0), None, "start_s"),
            (Some(f64::NAN), None, "start_s"),
            (Some(5.0), Some(5.0), "end_s"),
            (None, Some(0.0), "end_s"),
            (None, Some(f64::INFINITY), "end_s"),
        ] {
            let e = TimeWindow::new(start, end)
                .expect_err("refused")
                .to_string();
            assert!(e.starts_with(field), "{e}");
        }
        let e = TimeWindow::new(Some(50.0), None)
            .expect("valid")
            .apply(log(), 25_600.0, "log.csv", 2)
            .expect_err("empty")
            .to_string();
        assert!(
            e.contains("log.csv")
                && e.contains("0 row(s) of 100 lie in the window [50 s, the end]"),
            "{e}"
        );
    }

    /// Rows streamed from `text` (columns `t_s`, `x`) within `window`: the values given, the
    /// repeats dropped, or the refusal.
    fn streamed(text: &str, window: TimeWindow) -> Result<(Vec<[f64; 2]>, Repeats)> {
        let dir = tempfile::tempdir().expect("a folder");
        let path = dir.path().join("log.csv");
        std::fs::write(&path, text).expect("written");
        let mut rows = TimedRows::open(path.as_path(), &["t_s", "x"], "")?.within(window);
        rows.start_time()?;
        let (mut out, mut row) = (Vec::new(), [0.0; 2]);
        while rows.next_row(&mut row)? {
            out.push(row);
        }
        Ok((out, rows.repeats()))
    }

    #[test]
    fn a_loggers_copy_of_its_last_row_is_dropped_and_counted_and_a_new_value_at_its_time_refused() {
        // Rows 3 and 6 (file rows, header 1) copy the row before; row 7 copies row 6's copy.
        let text = "t_s,x\n0,1\n0,1\n0.1,2\n0.2,3\n0.2,3\n0.2,3\n0.3,4\n";
        let (rows, repeats) = streamed(text, TimeWindow::default()).expect("read");
        assert_eq!(rows, [[0.0, 1.0], [0.1, 2.0], [0.2, 3.0], [0.3, 4.0]]);
        assert_eq!(repeats.count, 3);
        let m = repeats.message("log.csv", 2).expect("said");
        assert!(
            m.contains("3 rows repeat") && m.contains("the first at row 3"),
            "{m}"
        );
        // Before a window's start the copies are skipped with their rows.
        let window = TimeWindow {
            start_s: Some(0.15),
            end_s: None,
        };
        let (rows, repeats) = streamed(text, window).expect("read");
        assert_eq!(rows, [[0.2, 3.0], [0.3, 4.0]]);
        assert_eq!((repeats.count, repeats.first), (3, Some(1)));
        // The same time with another value is not a copy: refused by its row.
        let e = streamed("t_s,x\n0,1\n0.1,2\n0.1,5\n", TimeWindow::default())
            .expect_err("refused")
            .to_string();
        assert!(e.contains("time at row 4 does not increase"), "{e}");
    }
}
