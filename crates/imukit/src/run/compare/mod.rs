//! Errors of an estimate against truth on the estimate's times: the truth is interpolated
//! linearly in position and velocity and by quaternion slerp in attitude between the two truth
//! samples that bracket each estimate time.
//!
//! Two kinds of estimate: a navigation output (`t_s`, `pos_*`, `vel_*`, `q_*`; errors in
//! [`ERROR_COLUMNS`]) and an orientation output (`t_s`, `q_*` only, as `imukit orient` writes;
//! errors in [`ORIENTATION_ERROR_COLUMNS`]: the quaternion distance, its heading and
//! inclination parts, and the z-y-x Euler angle differences, wrapped to (−π, π]; scored as
//! orientation benchmarks do, [`heading_inclination`]). Both stream: rows are read in time order, and
//! memory does not grow with the files.
mod earth;
mod orientation;

pub use orientation::heading_inclination;

use crate::io::read::CsvRows;

use crate::io::Input;
use crate::io::columns::{
    EARTH_ERROR_COLUMNS, ERROR_COLUMNS, ORIENTATION_COLUMNS, ORIENTATION_ERROR_COLUMNS,
};
use std::path::Path;

use imu_core::earth::Geodetic;
use imu_core::orientation::{DistanceStats, quaternion_distance};
use imu_core::{Body, Ecef, Enu, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::columns::{SIGMA_COLUMNS, STATE_COLUMNS};
use crate::io::output::AtomicFile;
use crate::io::rows::TimeWindow;
use crate::io::table::Table;
use crate::run::reference::{Layout, ned_of_difference};

/// What kind of estimate a table or file holds, judged by its columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EstimateKind {
    /// Position, velocity and attitude.
    Navigation,
    /// Attitude only.
    Orientation,
}

impl EstimateKind {
    /// The kind of an estimate with columns `names`: navigation when it has every state
    /// column, orientation when it has `t_s` and the quaternion.
    ///
    /// # Errors
    /// Neither set of columns.
    pub fn of(names: &[String]) -> Result<Self> {
        let has = |cols: &[&str]| cols.iter().all(|c| names.iter().any(|n| n == c));
        if has(STATE_COLUMNS) {
            Ok(Self::Navigation)
        } else if has(&ORIENTATION_COLUMNS) {
            Ok(Self::Orientation)
        } else {
            Err(invalid(
                "estimate",
                "needs t_s, pos_*, vel_*, q_* (navigation) or t_s, q_w, q_x, q_y, q_z (orientation)",
            ))
        }
    }

    /// Its error columns.
    #[must_use]
    pub fn error_columns(self) -> &'static [&'static str] {
        match self {
            Self::Navigation => &ERROR_COLUMNS,
            Self::Orientation => &ORIENTATION_ERROR_COLUMNS,
        }
    }
}

/// RMS, maximum and final value of each error norm (position and velocity only for
/// navigation estimates). Values in rad, m and m/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorSummary {
    /// The kind of estimate.
    pub kind: EstimateKind,
    /// Position error norm, m.
    pub position: Option<DistanceStats>,
    /// Velocity error norm, m/s.
    pub velocity: Option<DistanceStats>,
    /// Attitude error angle (quaternion distance), rad (`None`: a reference without one).
    pub attitude: Option<DistanceStats>,
    /// Orientation estimates: the heading part of the error angle, rad.
    pub heading: Option<DistanceStats>,
    /// Orientation estimates: the inclination part of the error angle, rad.
    pub inclination: Option<DistanceStats>,
    /// Orientation estimates: the constant heading offset removed (`--align-heading`), else
    /// the circular mean of the signed heading error, rad.
    pub heading_offset_rad: Option<f64>,
    /// Estimate rows not scored: outside the reference's times, or where it has a hole
    /// (orientation estimates; navigation estimates refuse such rows).
    pub skipped: usize,
    /// Rows compared.
    pub rows: usize,
}

/// How to compare.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CompareOptions {
    /// Orientation estimates: remove one constant heading offset first (a 6D estimate, whose
    /// heading is arbitrary).
    pub align_heading: bool,
}

impl ErrorSummary {
    /// Every figure by name with its unit: `position_rms_m`, `position_max_m`,
    /// `position_final_m`, the same for `velocity` (`_m_s`), `attitude`, `heading` and
    /// `inclination` (`_rad`); position and velocity only for navigation estimates, heading and
    /// inclination (with `heading_offset_rad` and `skipped_rows`) only for orientation ones,
    /// each only where the reference has it.
    #[must_use]
    pub fn entries(&self) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        let mut put = |name: &str, unit: &str, s: &DistanceStats| {
            out.push((format!("{name}_rms_{unit}"), s.rms()));
            out.push((format!("{name}_max_{unit}"), s.max()));
            out.push((format!("{name}_final_{unit}"), s.last()));
        };
        if let Some(p) = &self.position {
            put("position", "m", p);
        }
        if let Some(v) = &self.velocity {
            put("velocity", "m_s", v);
        }
        if let Some(a) = &self.attitude {
            put("attitude", "rad", a);
        }
        if let Some(h) = &self.heading {
            put("heading", "rad", h);
        }
        if let Some(i) = &self.inclination {
            put("inclination", "rad", i);
        }
        if let Some(o) = self.heading_offset_rad {
            out.push(("heading_offset_rad".to_string(), o));
        }
        if self.kind == EstimateKind::Orientation {
            out.push(("skipped_rows".to_string(), self.skipped as f64));
        }
        out
    }

    /// Rows compared.
    #[must_use]
    pub fn rows(&self) -> usize {
        self.rows
    }
}

/// Errors per estimate row and their summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Per sample ([`EstimateKind::error_columns`]).
    pub table: Table,
    /// RMS, maximum and final values.
    pub summary: ErrorSummary,
}

/// What a comparison of navigation estimates covers, and in which axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Parts {
    /// Positions are ECEF points and their errors north, east, down at the reference point
    /// (else plane coordinates, errors in the plane's axes).
    earth: bool,
    /// Velocities are compared.
    velocity: bool,
    /// Attitudes are compared.
    attitude: bool,
}

impl Parts {
    /// Plane coordinates, everything compared.
    const PLANE: Self = Self {
        earth: false,
        velocity: true,
        attitude: true,
    };

    /// The error columns.
    fn columns(self) -> Vec<&'static str> {
        let all = if self.earth {
            &EARTH_ERROR_COLUMNS
        } else {
            &ERROR_COLUMNS
        };
        let mut c = all[..5].to_vec();
        if self.velocity {
            c.extend(&all[5..8]);
        }
        if self.attitude {
            c.push(all[8]);
        }
        c
    }
}

/// A state row in [`STATE_COLUMNS`] order: `t_s`, position, velocity, `q_wxyz` (position and
/// velocity zero for an orientation estimate).
type StateRow = [f64; 11];

/// Where an estimate row's values sit in its columns (`None`: absent, left zero).
fn state_index(names: &[String], kind: EstimateKind) -> Vec<Option<usize>> {
    STATE_COLUMNS
        .iter()
        .map(|c| {
            let wanted = kind == EstimateKind::Navigation || ORIENTATION_COLUMNS.contains(c);
            wanted.then(|| names.iter().position(|n| n == c)).flatten()
        })
        .collect()
}

/// Whether an estimate carries the filter's one-sigma ([`SIGMA_COLUMNS`], as `imukit fuse`
/// writes them): then its errors carry them too, after [`ERROR_COLUMNS`].
fn has_sigmas(names: &[String], kind: EstimateKind) -> bool {
    kind == EstimateKind::Navigation && SIGMA_COLUMNS.iter().all(|c| names.iter().any(|n| n == c))
}

/// The one-sigma of the attitude error's angle: the root sum of squares of the three axes'
/// one-sigma, what the angle `att_err_rad` is drawn against (±3σ).
pub const ATTITUDE_SIGMA_COLUMN: &str = "att_sigma_rad";

/// The error columns of `kind`, with [`SIGMA_COLUMNS`] and [`ATTITUDE_SIGMA_COLUMN`] when
/// `sigmas`.
fn output_columns(kind: EstimateKind, sigmas: bool) -> Vec<&'static str> {
    let mut columns = kind.error_columns().to_vec();
    if sigmas {
        columns.extend(SIGMA_COLUMNS);
        columns.push(ATTITUDE_SIGMA_COLUMN);
    }
    columns
}

/// Appends an estimate row's one-sigma ([`SIGMA_COLUMNS`]) and the attitude angle's
/// ([`ATTITUDE_SIGMA_COLUMN`]) to an error row.
fn push_sigmas(row: &mut Vec<f64>, sigmas: &[f64; SIGMA_COLUMNS.len()]) {
    row.extend_from_slice(sigmas);
    let [x, y, z] = [sigmas[6], sigmas[7], sigmas[8]];
    row.push((x * x + y * y + z * z).sqrt());
}

/// Compares an estimate table with a truth table (see the module docs).
///
/// # Errors
/// Missing columns; truth or estimate times that do not increase (or are not finite); estimate
/// times outside the truth's span; zero quaternions.
pub fn compare(truth: &Table, estimate: &Table) -> Result<Comparison> {
    compare_with(truth, estimate, CompareOptions::default())
}

/// [`compare`] with `options`. A navigation estimate and its truth must be finite throughout;
/// an orientation reference may have holes (NaN quaternions), which are skipped.
///
/// # Errors
/// As [`compare`].
pub fn compare_with(
    truth: &Table,
    estimate: &Table,
    options: CompareOptions,
) -> Result<Comparison> {
    let kind = EstimateKind::of(&estimate.columns)?;
    check_truth(&truth.columns, kind)?;
    estimate.check_finite("estimate")?;
    if kind == EstimateKind::Orientation {
        if let Some(t) = truth.column("t_s") {
            crate::io::table::check_finite(&["t_s"], &t, "truth")?;
        }
        let mut table = Table::new(kind.error_columns());
        let score = |align: Option<f64>, table: &mut Table| {
            let (mut tr, mut er) = (state_rows(truth, kind), state_rows(estimate, kind));
            orientation::compare_orientation_rows(
                ["truth", "estimate"],
                |row| Ok(tr.next().map(|r| *row = r).is_some()),
                |row| Ok(er.next().map(|r| *row = r).is_some()),
                align,
                |e| {
                    table.push_row(e);
                    Ok(())
                },
            )
        };
        let summary = if options.align_heading {
            let offset = score(None, &mut Table::new(kind.error_columns()))?.heading_offset_rad;
            score(offset, &mut table)?
        } else {
            score(None, &mut table)?
        };
        return Ok(Comparison { table, summary });
    }
    truth.check_finite("truth")?;
    let (mut tr, mut er) = (state_rows(truth, kind), state_rows(estimate, kind));
    let sigmas: Vec<Vec<f64>> = if has_sigmas(&estimate.columns, kind) {
        SIGMA_COLUMNS
            .iter()
            .filter_map(|c| estimate.column(c))
            .collect()
    } else {
        Vec::new()
    };
    let mut table = Table::new(&output_columns(kind, !sigmas.is_empty()));
    let mut out = Vec::with_capacity(table.columns.len());
    let summary = compare_rows(
        Parts::PLANE,
        ["truth", "estimate"],
        |row| Ok(tr.next().map(|r| *row = r).is_some()),
        |row| Ok(er.next().map(|r| *row = r).is_some()),
        |e| {
            // One error row per estimate row, in order.
            let k = table.rows();
            out.clear();
            out.extend_from_slice(e);
            if !sigmas.is_empty() {
                let mut row = [0.0; SIGMA_COLUMNS.len()];
                for (r, s) in row.iter_mut().zip(&sigmas) {
                    *r = s[k];
                }
                push_sigmas(&mut out, &row);
            }
            table.push_row(&out);
            Ok(())
        },
    )?;
    Ok(Comparison { table, summary })
}

/// A table's rows as state rows (the columns of `kind`).
fn state_rows(t: &Table, kind: EstimateKind) -> impl Iterator<Item = StateRow> + '_ {
    let idx = state_index(&t.columns, kind);
    let w = t.columns.len();
    (0..t.rows()).map(move |r| std::array::from_fn(|c| idx[c].map_or(0.0, |i| t.data[r * w + i])))
}

/// Refuses a truth without the columns an estimate of `kind` is compared on.
fn check_truth(names: &[String], kind: EstimateKind) -> Result<()> {
    match (EstimateKind::of(names), kind) {
        (Ok(EstimateKind::Navigation), _)
        | (Ok(EstimateKind::Orientation), EstimateKind::Orientation) => Ok(()),
        _ => Err(invalid(
            "truth",
            match kind {
                EstimateKind::Navigation => {
                    "needs t_s, pos_*, vel_*, q_* to compare a navigation output"
                }
                EstimateKind::Orientation => {
                    "needs t_s, q_w, q_x, q_y, q_z to compare an orientation output"
                }
            },
        )),
    }
}

/// The next row of `rows` (its `kind`'s columns) as a state row.
fn next_state(
    rows: &mut CsvRows,
    buffer: &mut [f64],
    kind: EstimateKind,
    row: &mut StateRow,
) -> Result<bool> {
    if rows.next_row(buffer)?.is_none() {
        return Ok(false);
    }
    match kind {
        EstimateKind::Navigation => row.copy_from_slice(&buffer[..STATE_COLUMNS.len()]),
        EstimateKind::Orientation => {
            *row = [0.0; 11];
            row[0] = buffer[0];
            row[7..].copy_from_slice(&buffer[1..]);
        }
    }
    Ok(true)
}

/// Refuses a truth and an estimate whose descriptions say different navigation frames or
/// Earths: their axes are not compared one by one.
///
/// # Errors
/// [`crate::Error::Invalid`] naming the setting and both inputs.
pub fn check_comparable(described: &crate::io::described::Described) -> Result<()> {
    described.known(crate::error::RequestOption::NavFrame, None, |d| d.nav_frame)?;
    described.known(crate::error::RequestOption::Earth, None, |d| d.earth)?;
    Ok(())
}

/// [`compare`] on two CSV files, streamed; the errors over time go to `out`, which appears only
/// when complete.
///
/// # Errors
/// As [`compare`], CSV errors naming file, row and column, and I/O errors.
pub fn compare_csv(
    truth: impl Into<Input>,
    estimate: impl Into<Input>,
    out: Option<&Path>,
) -> Result<ErrorSummary> {
    compare_csv_within(truth, estimate, TimeWindow::default(), out)
}

/// [`compare_csv`] over the rows of `window` alone, its seconds counted from the truth's first
/// sample (both files cut at the same instants).
///
/// # Errors
/// As [`compare_csv`].
pub fn compare_csv_within(
    truth: impl Into<Input>,
    estimate: impl Into<Input>,
    window: TimeWindow,
    out: Option<&Path>,
) -> Result<ErrorSummary> {
    compare_csv_with(truth, estimate, window, CompareOptions::default(), out)
}

/// [`compare_csv_within`] with `options`; an orientation reference may have holes (empty or
/// NaN quaternion cells), which are skipped. Aligning the heading reads both files twice.
///
/// # Errors
/// As [`compare_csv`].
pub fn compare_csv_with(
    truth: impl Into<Input>,
    estimate: impl Into<Input>,
    window: TimeWindow,
    options: CompareOptions,
    out: Option<&Path>,
) -> Result<ErrorSummary> {
    let (truth, estimate) = (&truth.into(), &estimate.into());
    let t0 = if window.is_whole() {
        0.0
    } else {
        TimeWindow::first_time_in(truth)?
    };
    // A reference on the Earth (latitude, longitude, height or ECEF, without imukit's plane
    // coordinates) is compared in the Earth's terms.
    let truth_header = crate::io::read::read_header(truth)?;
    if !matches!(
        EstimateKind::of(&truth_header),
        Ok(EstimateKind::Navigation)
    ) && let Some(layout) = Layout::on_earth(&truth_header)
    {
        return earth::compare_on_earth(truth, estimate, layout, (window, t0), out);
    }
    check_comparable(&crate::io::described::Described::read(&[
        truth.path(),
        estimate.path(),
    ])?)?;
    let header = crate::io::read::read_header(estimate)?;
    let kind = EstimateKind::of(&header)?;
    let sigmas = has_sigmas(&header, kind);
    let wanted: &[&str] = match kind {
        EstimateKind::Navigation => STATE_COLUMNS,
        EstimateKind::Orientation => &ORIENTATION_COLUMNS,
    };
    let estimate_wanted: Vec<&str> = wanted
        .iter()
        .copied()
        .chain(SIGMA_COLUMNS.iter().copied().filter(|_| sigmas))
        .collect();
    let hint = match kind {
        EstimateKind::Navigation => "; the truth needs t_s, pos_*, vel_*, q_*",
        EstimateKind::Orientation => "; the truth needs t_s, q_w, q_x, q_y, q_z",
    };
    let (truth_name, estimate_name) = (
        truth.path().display().to_string(),
        estimate.path().display().to_string(),
    );
    if kind == EstimateKind::Orientation {
        let score = |align: Option<f64>, file: Option<&mut AtomicFile>| {
            let mut truth_rows = CsvRows::open(truth, wanted, hint)?
                .allowing_missing(&ORIENTATION_COLUMNS[1..])
                .within(window, t0)?;
            let mut estimate_rows = CsvRows::open(estimate, wanted, "")?.within(window, t0)?;
            let (mut tb, mut eb) = (vec![0.0; wanted.len()], vec![0.0; wanted.len()]);
            let mut file = file;
            orientation::compare_orientation_rows(
                [&truth_name, &estimate_name],
                |row| next_state(&mut truth_rows, &mut tb, kind, row),
                |row| next_state(&mut estimate_rows, &mut eb, kind, row),
                align,
                |e| file.as_mut().map_or(Ok(()), |f| f.write_row(e)),
            )
        };
        let offset = if options.align_heading {
            score(None, None)?.heading_offset_rad
        } else {
            None
        };
        let mut file = out.map(AtomicFile::create).transpose()?;
        if let Some(f) = file.as_mut() {
            f.write_header(kind.error_columns())?;
        }
        let summary = score(offset, file.as_mut())?;
        file.map_or(Ok(()), AtomicFile::commit)?;
        return Ok(summary);
    }
    let mut truth_rows = CsvRows::open(truth, wanted, hint)?.within(window, t0)?;
    let mut estimate_rows = CsvRows::open(estimate, &estimate_wanted, "")?.within(window, t0)?;
    let (mut truth_buffer, mut estimate_buffer) =
        (vec![0.0; wanted.len()], vec![0.0; estimate_wanted.len()]);
    let mut file = out.map(AtomicFile::create).transpose()?;
    if let Some(f) = file.as_mut() {
        f.write_header(&output_columns(kind, sigmas))?;
    }
    // The estimate row's sigmas, handed from the reader to the writer.
    let row_sigmas = std::cell::Cell::new([0.0; SIGMA_COLUMNS.len()]);
    let mut out_row = Vec::new();
    let summary = compare_rows(
        Parts::PLANE,
        [&truth_name, &estimate_name],
        |row| next_state(&mut truth_rows, &mut truth_buffer, kind, row),
        |row| {
            let more = next_state(&mut estimate_rows, &mut estimate_buffer, kind, row)?;
            if sigmas && more {
                let mut s = [0.0; SIGMA_COLUMNS.len()];
                s.copy_from_slice(&estimate_buffer[wanted.len()..]);
                row_sigmas.set(s);
            }
            Ok(more)
        },
        |e| match file.as_mut() {
            Some(f) if sigmas => {
                out_row.clear();
                out_row.extend_from_slice(e);
                push_sigmas(&mut out_row, &row_sigmas.get());
                f.write_row(&out_row)
            }
            Some(f) => f.write_row(e),
            None => Ok(()),
        },
    )?;
    file.map_or(Ok(()), AtomicFile::commit)?;
    Ok(summary)
}

/// The angle `a − b` wrapped to (−π, π].
fn angle_difference(a: f64, b: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let d = (a - b).rem_euclid(tau);
    if d > std::f64::consts::PI { d - tau } else { d }
}

/// The comparison of two navigation row streams in time order (orientation estimates are scored
/// by the `orientation` module): for each estimate row the truth rows that
/// bracket its time (a single-row truth brackets with itself; times past the last truth row
/// but within 1e-9 s use the last two), errors handed to `sink`.
fn compare_rows(
    parts: Parts,
    names: [&str; 2],
    mut read_truth: impl FnMut(&mut StateRow) -> Result<bool>,
    mut estimate: impl FnMut(&mut StateRow) -> Result<bool>,
    mut sink: impl FnMut(&[f64]) -> Result<()>,
) -> Result<ErrorSummary> {
    let [truth_name, estimate_name] = names;
    // Truth times must increase strictly: bracketing an estimate time needs them ordered.
    let (mut truth_rows, mut last_truth) = (0usize, f64::NEG_INFINITY);
    let mut truth = |row: &mut StateRow| -> Result<bool> {
        if !read_truth(row)? {
            return Ok(false);
        }
        truth_rows += 1;
        if row[0].partial_cmp(&last_truth) != Some(std::cmp::Ordering::Greater) {
            return Err(invalid(
                format!("{truth_name}, row {}", truth_rows + 1),
                format!(
                    "truth time {} s does not increase (previous {last_truth} s)",
                    row[0]
                ),
            ));
        }
        last_truth = row[0];
        Ok(true)
    };
    let mut bracket = Bracket::start(&mut truth, "compare")?;
    let mut e = [0.0; 11];
    let (mut pos, mut vel, mut att) = (
        DistanceStats::default(),
        DistanceStats::default(),
        DistanceStats::default(),
    );
    let mut previous_t = f64::NEG_INFINITY;
    let mut rows = 0;
    while estimate(&mut e)? {
        let (t, row) = (e[0], rows + 2);
        rows += 1;
        let late = |message: String| {
            invalid(
                estimate_name,
                format!("estimate time {t} s (row {row}) {message}"),
            )
        };
        if !t.is_finite() {
            return Err(late("is not a finite number".into()));
        }
        if t < previous_t {
            return Err(late(format!("goes back from {previous_t} s")));
        }
        previous_t = t;
        bracket.advance(t, &mut truth)?;
        if t < bracket.t0 - 1e-9 {
            return Err(late(format!(
                "is before the truth's first, {} s",
                bracket.t0
            )));
        }
        if bracket.ended && t > bracket.b[0] + 1e-9 {
            return Err(late(format!(
                "is after the truth's last, {} s",
                bracket.b[0]
            )));
        }
        let (dp, dv, angle) = bracket.errors(parts, &e, truth_name, row)?;
        let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let np = norm(&dp);
        pos.push(np);
        let mut out = [0.0; 9];
        out[..5].copy_from_slice(&[t, dp[0], dp[1], dp[2], np]);
        let mut width = 5;
        if parts.velocity {
            vel.push(norm(&dv));
            out[5..8].copy_from_slice(&dv);
            width = 8;
        }
        if parts.attitude {
            att.push(angle);
            out[width] = angle;
            width += 1;
        }
        sink(&out[..width])?;
    }
    if rows == 0 {
        return Err(invalid("compare", "empty table"));
    }
    // The truth rows past the last estimate are read too: a truth file is refused whole or not
    // at all.
    while !bracket.ended && truth(&mut bracket.next)? {}
    Ok(ErrorSummary {
        kind: EstimateKind::Navigation,
        position: Some(pos),
        velocity: parts.velocity.then_some(vel),
        attitude: parts.attitude.then_some(att),
        heading: None,
        inclination: None,
        heading_offset_rad: None,
        skipped: 0,
        rows,
    })
}

/// The two truth rows that bracket an estimate's time, read in time order.
struct Bracket {
    a: StateRow,
    b: StateRow,
    /// The row being read.
    next: StateRow,
    /// No truth row is left.
    ended: bool,
    /// The truth's first time.
    t0: f64,
}

impl Bracket {
    /// The first two truth rows (one row brackets with itself); no row is refused, named `empty`.
    fn start(truth: &mut impl FnMut(&mut StateRow) -> Result<bool>, empty: &str) -> Result<Self> {
        let (mut a, mut b) = ([0.0; 11], [0.0; 11]);
        if !truth(&mut a)? {
            return Err(invalid(empty, "empty table"));
        }
        let ended = !truth(&mut b)?;
        if ended {
            b = a;
        }
        Ok(Self {
            a,
            b,
            next: [0.0; 11],
            ended,
            t0: a[0],
        })
    }

    /// Advances to the first truth row later than `t` (or the last one).
    fn advance(
        &mut self,
        t: f64,
        truth: &mut impl FnMut(&mut StateRow) -> Result<bool>,
    ) -> Result<()> {
        while !self.ended && self.b[0] <= t {
            if truth(&mut self.next)? {
                (self.a, self.b) = (self.b, self.next);
            } else {
                self.ended = true;
            }
        }
        Ok(())
    }

    /// The interpolation weight of time `t` between the two rows (0 at `a`, 1 at `b`).
    fn weight(&self, t: f64) -> f64 {
        let (a, b) = (self.a[0], self.b[0]);
        if b == a {
            0.0
        } else {
            ((t - a) / (b - a)).clamp(0.0, 1.0)
        }
    }

    /// The estimate row `e`'s position error (north, east, down on the Earth), velocity error
    /// and attitude error angle (0 when not compared) against the truth interpolated to its time.
    fn errors(
        &self,
        parts: Parts,
        e: &StateRow,
        truth_name: &str,
        row: usize,
    ) -> Result<([f64; 3], [f64; 3], f64)> {
        let (a, b, w) = (&self.a, &self.b, self.weight(e[0]));
        let q = |r: &StateRow| Rotation::<Body, Enu>::from_wxyz([r[7], r[8], r[9], r[10]]);
        let angle = if parts.attitude {
            let (Some(qa), Some(qb), Some(qe)) = (q(a), q(b), q(e)) else {
                return Err(invalid(
                    "compare",
                    format!("zero quaternion near estimate row {row}"),
                ));
            };
            let qt = Rotation::<Body, Enu>::assume_from_quaternion(
                qa.quaternion().slerp(qb.quaternion(), w),
            );
            quaternion_distance(&qe, &qt)
        } else {
            0.0
        };
        let lerp = |c: usize| a[c] + w * (b[c] - a[c]);
        let mut dp: [f64; 3] = std::array::from_fn(|j| e[1 + j] - lerp(1 + j));
        if parts.earth {
            let point = Vec3::<Ecef>::from_array([lerp(1), lerp(2), lerp(3)]);
            let at = Geodetic::from_ecef(point).ok_or_else(|| {
                invalid(
                    truth_name,
                    format!("no point on the Earth near estimate row {row}"),
                )
            })?;
            dp = ned_of_difference(&at, dp);
        }
        let dv: [f64; 3] = std::array::from_fn(|j| e[4 + j] - lerp(4 + j));
        Ok((dp, dv, angle))
    }
}
