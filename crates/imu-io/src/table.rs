//! The CSV schema (docs/design.md §3) and column tables shared by the CLI and Python.
//!
//! A [`Table`] is named columns over row-major `f64` data. CSV output uses shortest round-trip
//! formatting (`zmij`), so a written file reads back bit for bit, and is written to a temporary file
//! that is renamed into place only when complete.
use std::collections::HashMap;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use imu_core::sensor::ImuReading;
use imu_core::{NavFrame, Truth};

use crate::TableFormat;
use crate::column_map::{ColumnMap, Source, TimeUnit};
use crate::columns::{
    ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, TRUTH_COLUMNS,
};
use crate::description::Description;
use crate::error::{Error, Result, invalid};
use crate::input::Input;
use crate::output::write_atomically;

/// What the accelerometer and gyroscope columns hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImuOutput {
    /// Specific force (m/s²) and angular rate (rad/s) at each sample.
    #[default]
    Rates,
    /// Δv (m/s) and Δθ (rad) integrated over the interval ending at each sample (trapezoid of
    /// the readings; zero at the first sample); the magnetometer stays instantaneous.
    Increments,
}

impl ImuOutput {
    /// Column names of readings of `kind` in this form: the time, then the accelerometer's
    /// (specific force or Δv) and, when `kind` has them, the gyroscope's (rate or Δθ) and the
    /// magnetometer's.
    #[must_use]
    pub fn columns(self, kind: ImuKind) -> Vec<&'static str> {
        match self {
            Self::Rates => kind.columns(),
            Self::Increments => reading_columns(kind, DV_COLUMNS, DTHETA_COLUMNS),
        }
    }
}

/// `t_s`, the accelerometer's columns, then the gyroscope's and the magnetometer's when `kind`
/// has them.
fn reading_columns(
    kind: ImuKind,
    accel: [&'static str; 3],
    gyro: [&'static str; 3],
) -> Vec<&'static str> {
    let mut c = vec!["t_s"];
    c.extend(accel);
    if kind.has_gyro() {
        c.extend(gyro);
    }
    if kind.has_mag() {
        c.extend(MAG_COLUMNS);
    }
    c
}

/// Which sensors an IMU has (MATLAB's `IMUType`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImuKind {
    /// Accelerometer and gyroscope.
    AccelGyro,
    /// Accelerometer and magnetometer.
    AccelMag,
    /// All three (the default: the ideal magnetometer costs nothing).
    #[default]
    AccelGyroMag,
}

impl crate::choice::Choice for ImuKind {
    const WHAT: &'static str = "IMU type";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("accel-gyro", Self::AccelGyro),
        ("accel-mag", Self::AccelMag),
        ("accel-gyro-mag", Self::AccelGyroMag),
    ];
}

crate::choice::display_as_name!(ImuKind);

impl ImuKind {
    /// True when the kind includes a gyroscope.
    #[must_use]
    pub fn has_gyro(self) -> bool {
        self != Self::AccelMag
    }
    /// True when the kind includes a magnetometer.
    #[must_use]
    pub fn has_mag(self) -> bool {
        self != Self::AccelGyro
    }
    /// Column names of readings of this kind.
    #[must_use]
    pub fn columns(self) -> Vec<&'static str> {
        reading_columns(self, ACCEL_COLUMNS, GYRO_COLUMNS)
    }
}

/// Named columns over row-major data.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// Row-major values, `rows × columns.len()`.
    pub data: Vec<f64>,
}

/// Refuses rows (row-major, `columns.len()` wide) holding a value that is not finite, naming the
/// first one (rows counted from 2, below a header).
///
/// # Errors
/// [`Error::NotFinite`] for `what`.
pub fn check_finite<S: AsRef<str>>(columns: &[S], data: &[f64], what: &str) -> Result<()> {
    check_finite_from(columns, data, what, 2)
}

/// [`check_finite`] for rows that start at file row `first_row`.
///
/// # Errors
/// [`Error::NotFinite`] for `what`.
pub fn check_finite_from<S: AsRef<str>>(
    columns: &[S],
    data: &[f64],
    what: &str,
    first_row: usize,
) -> Result<()> {
    match first_not_finite(data) {
        None => Ok(()),
        Some(i) => Err(Error::NotFinite {
            what: what.into(),
            row: i / columns.len().max(1) + first_row,
            column: columns
                .get(i % columns.len().max(1))
                .map_or_else(String::new, |c| c.as_ref().to_string()),
            value: data[i],
        }),
    }
}

/// The longest column name a table file takes, bytes.
pub const MAX_COLUMN_NAME_BYTES: usize = 255;

/// Refuses column names that a table file could not carry back, before anything is written:
/// one rule for every format, so that a table written as one reads back as any other. A name
/// is 1 to [`MAX_COLUMN_NAME_BYTES`] bytes of text with no control character, no `,` `"` `'`
/// `\` `/` (CSV's separator and quotes, the quotes and escapes of a `.npy` header, a `.npz`
/// member's folder), no space at either end (CSV trims it) and no `#` first (a CSV comment);
/// no name twice.
///
/// # Errors
/// [`Error::CsvFormat`] naming `path`, the column's place and what is wrong with it.
pub fn check_column_names<S: AsRef<str>>(columns: &[S], path: &Path) -> Result<()> {
    let refuse = |k: usize, name: &str, why: String| {
        let shown: String = name.chars().take(40).collect();
        let cut = if shown.len() < name.len() { "…" } else { "" };
        Err(Error::CsvFormat {
            file: path.into(),
            message: format!("column {} ({shown:?}{cut}) cannot be written: {why}", k + 1),
        })
    };
    let mut seen: HashMap<&str, usize> = HashMap::with_capacity(columns.len());
    for (k, name) in columns.iter().enumerate() {
        let name = name.as_ref();
        if name.is_empty() {
            return refuse(k, name, "a column needs a name".into());
        }
        if name.len() > MAX_COLUMN_NAME_BYTES {
            return refuse(
                k,
                name,
                format!(
                    "a name of {} bytes (at most {MAX_COLUMN_NAME_BYTES})",
                    name.len()
                ),
            );
        }
        if let Some(c) = name
            .chars()
            .find(|c| c.is_control() || matches!(c, ',' | '"' | '\'' | '\\' | '/'))
        {
            return refuse(k, name, format!("it holds {c:?}"));
        }
        if name.trim() != name {
            return refuse(k, name, "a space at its start or end".into());
        }
        if name.starts_with('#') {
            return refuse(k, name, "a name starting with # (a comment in CSV)".into());
        }
        if let Some(first) = seen.insert(name, k) {
            return refuse(k, name, format!("the name of column {} too", first + 1));
        }
    }
    Ok(())
}

/// The index of the first value of `data` that is not finite. Blocks of 32 values
/// are tested whole, without stopping at the first failure, so that the test is a few vector
/// operations a block; only a block that fails is searched.
#[must_use]
pub fn first_not_finite(data: &[f64]) -> Option<usize> {
    let mut blocks = data.chunks_exact(FINITE_BLOCK);
    let mut start = 0;
    for block in &mut blocks {
        if !block.iter().fold(true, |all, v| all & v.is_finite()) {
            break;
        }
        start += FINITE_BLOCK;
    }
    data[start..]
        .iter()
        .position(|v| !v.is_finite())
        .map(|k| start + k)
}

/// The values [`first_not_finite`] tests at once.
const FINITE_BLOCK: usize = 32;

impl Table {
    /// Refuses a table holding a value that is not finite (see [`check_finite`]).
    ///
    /// # Errors
    /// [`Error::NotFinite`] naming `what`, the row and the column.
    pub fn check_finite(&self, what: &str) -> Result<()> {
        check_finite(&self.columns, &self.data, what)
    }

    /// Three columns read row by row as `[a, b, c]` (an x, y, z triple); `None` when one is
    /// missing.
    #[must_use]
    pub fn triples(&self, names: &[&str; 3]) -> Option<Vec<[f64; 3]>> {
        let c: Vec<Vec<f64>> = names
            .iter()
            .map(|n| self.column(n))
            .collect::<Option<_>>()?;
        Some(
            (0..self.rows())
                .map(|i| [c[0][i], c[1][i], c[2][i]])
                .collect(),
        )
    }

    /// An empty table with these columns.
    #[must_use]
    pub fn new(columns: &[&str]) -> Self {
        Self {
            columns: columns.iter().map(|c| (*c).to_string()).collect(),
            data: Vec::new(),
        }
    }
    /// Number of rows.
    #[must_use]
    pub fn rows(&self) -> usize {
        if self.columns.is_empty() {
            0
        } else {
            self.data.len() / self.columns.len()
        }
    }
    /// The values of column `name`, if present.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(
            self.data
                .iter()
                .skip(k)
                .step_by(self.columns.len())
                .copied()
                .collect(),
        )
    }
    /// Appends one row (its length must equal the number of columns).
    pub fn push_row(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.columns.len());
        self.data.extend_from_slice(row);
    }

    /// Truth samples as a table with [`TRUTH_COLUMNS`].
    #[must_use]
    pub fn from_truth<N: NavFrame>(truth: &[Truth<N>]) -> Self {
        let mut t = Self::new(&[]);
        t.refill_truth(truth);
        t
    }

    /// Makes this table [`Self::from_truth`]`(truth)` in the memory it already has (a streamed
    /// run refills one table chunk after chunk).
    pub fn refill_truth<N: NavFrame>(&mut self, truth: &[Truth<N>]) {
        self.set_columns(&TRUTH_COLUMNS);
        self.data.clear();
        self.data.reserve(truth.len() * TRUTH_COLUMNS.len());
        for s in truth {
            self.push_row(&truth_row(s));
        }
    }

    /// Sets the column names (kept when already equal), leaving the data alone.
    fn set_columns(&mut self, columns: &[&str]) {
        if !self
            .columns
            .iter()
            .map(String::as_str)
            .eq(columns.iter().copied())
        {
            self.columns = columns.iter().map(|c| (*c).to_string()).collect();
        }
    }

    /// Readings as Δv/Δθ increments ([`ImuOutput::Increments`]).
    #[must_use]
    pub fn from_increments(t_s: &[f64], readings: &[ImuReading], kind: ImuKind) -> Self {
        use imu_core::sensor::increments::trapezoid;
        let n = readings.len();
        let (mut dv, mut dtheta) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let accel: Vec<[f64; 3]> = readings.iter().map(|r| r.accel_m_s2).collect();
        let gyro: Vec<[f64; 3]> = readings.iter().map(|r| r.gyro_rad_s).collect();
        trapezoid(t_s, &accel, &mut dv);
        trapezoid(t_s, &gyro, &mut dtheta);
        let mut t = Self::new(&ImuOutput::Increments.columns(kind));
        for k in 0..n {
            let mut row = vec![t_s[k]];
            row.extend(dv[k]);
            if kind.has_gyro() {
                row.extend(dtheta[k]);
            }
            if kind.has_mag() {
                row.extend(readings[k].mag_ut);
            }
            t.push_row(&row);
        }
        t
    }

    /// Readings with their times as a table with the columns of `kind`.
    #[must_use]
    pub fn from_readings(t_s: &[f64], readings: &[ImuReading], kind: ImuKind) -> Self {
        let mut t = Self::new(&[]);
        t.refill_readings(t_s, readings, kind);
        t
    }

    /// Makes this table [`Self::from_readings`]`(t_s, readings, kind)` in the memory it already
    /// has.
    pub fn refill_readings(&mut self, t_s: &[f64], readings: &[ImuReading], kind: ImuKind) {
        self.set_columns(&kind.columns());
        self.data.clear();
        self.data.reserve(readings.len() * self.columns.len());
        for (ti, r) in t_s.iter().zip(readings) {
            // The kind's column order: t, accelerometer, then gyroscope and magnetometer when
            // it has them (at most ten values).
            let mut row = [0.0; 10];
            let mut k = 0;
            let mut put = |v: &[f64]| {
                row[k..k + v.len()].copy_from_slice(v);
                k += v.len();
            };
            put(&[*ti]);
            put(&r.accel_m_s2);
            if kind.has_gyro() {
                put(&r.gyro_rad_s);
            }
            if kind.has_mag() {
                put(&r.mag_ut);
            }
            self.push_row(&row[..k]);
        }
    }

    /// Writes the table in the format its path's extension names ([`TableFormat::written`]:
    /// Parquet for `.parquet`, NumPy for `.npy` and `.npz`, a bag for `.mcap`, CSV for `.csv`,
    /// `.txt` or no extension), atomically.
    ///
    /// # Errors
    /// A name of another format; a value that is not finite; [`Error::Io`] naming the file.
    pub fn write(&self, path: &Path) -> Result<()> {
        self.write_described(path, &Description::of_columns(&self.columns))
    }

    /// [`Self::write`] with `description` in the file ([`crate::description`]: Parquet's
    /// metadata, CSV's first line; the NumPy formats have no room for it), its kind, when it
    /// gives none, found from the columns.
    ///
    /// # Errors
    /// As [`Self::write`].
    pub fn write_described(&self, path: &Path, description: &Description) -> Result<()> {
        let kinded;
        let description = if description.kind.is_none() {
            kinded = Description {
                kind: crate::schema::TableKind::detect(&self.columns),
                ..description.clone()
            };
            &kinded
        } else {
            description
        };
        match TableFormat::written(&path.display().to_string(), path)? {
            TableFormat::Parquet
            | TableFormat::Npy
            | TableFormat::Npz
            | TableFormat::Mcap
            | TableFormat::Nmea => self.write_binary(path, description),
            TableFormat::Csv => self.write_csv_described(path, description),
        }
    }

    /// Writes the table in the binary format its path's extension names (Parquet, `.npy`,
    /// `.npz`), with `description` where the format has room for it, atomically; every value must
    /// be finite (refused, naming row and column — rows from 1, no header row — before the file
    /// is made).
    ///
    /// # Errors
    /// A value that is not finite; the writer's or the file system's refusal, naming the file.
    pub(crate) fn write_binary(&self, path: &Path, description: &Description) -> Result<()> {
        check_finite_from(&self.columns, &self.data, &path.display().to_string(), 1)?;
        let mut file = crate::output::AtomicFile::create(path)?;
        file.begin_table(&self.columns, description)?;
        file.write_table_rows(&self.data)?;
        file.commit()
    }

    /// Writes the table as CSV with a header row, atomically (temporary file, then rename),
    /// described by its kind ([`Self::write`]).
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        self.write_csv_described(path, &Description::of_columns(&self.columns))
    }

    fn write_csv_described(&self, path: &Path, description: &Description) -> Result<()> {
        check_column_names(&self.columns, path)?;
        self.check_finite(&path.display().to_string())?;
        let line = description.csv_line();
        write_atomically(path, |w| {
            if let Some(l) = &line {
                writeln!(w, "{l}")?;
            }
            self.write_header(w)?;
            self.write_body(w)
        })
    }

    /// Writes the CSV header row.
    ///
    /// # Errors
    /// I/O errors.
    pub fn write_header(&self, w: &mut impl Write) -> std::io::Result<()> {
        writeln!(w, "{}", self.columns.join(","))
    }

    /// Writes the rows as CSV (shortest round-trip numbers), without the header.
    ///
    /// # Errors
    /// I/O errors.
    pub fn write_body(&self, w: &mut impl Write) -> std::io::Result<()> {
        write_rows(w, &self.data, self.columns.len().max(1), b",")
    }
}

/// Writes row-major `data` in rows of `width`, values in shortest round-trip form separated by
/// `separator`.
///
/// # Errors
/// I/O errors.
pub fn write_rows(
    w: &mut impl Write,
    data: &[f64],
    width: usize,
    separator: &[u8],
) -> std::io::Result<()> {
    // Rows are formatted into one local buffer (zmij straight into it) and handed to the writer
    // a block at a time: no call into the writer per field, and few calls into the system.
    let mut buf = zmij::Buffer::new();
    let mut text: Vec<u8> = Vec::with_capacity(crate::output::WRITE_BLOCK + 4096);
    for row in data.chunks(width.max(1)) {
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                text.extend_from_slice(separator);
            }
            text.extend_from_slice(buf.format(*v).as_bytes());
        }
        text.push(b'\n');
        if text.len() >= crate::output::WRITE_BLOCK {
            w.write_all(&text)?;
            text.clear();
        }
    }
    w.write_all(&text)
}

/// One truth sample in [`TRUTH_COLUMNS`] order.
#[must_use]
pub fn truth_row<N: NavFrame>(s: &Truth<N>) -> [f64; 23] {
    let [px, py, pz] = s.position_m.to_array();
    let [vx, vy, vz] = s.velocity_m_s.to_array();
    let [ax, ay, az] = s.acceleration_m_s2.to_array();
    let [qw, qx, qy, qz] = s.attitude.to_wxyz();
    let [wx, wy, wz] = s.omega_b_rad_s.to_array();
    let [bx, by, bz] = s.alpha_b_rad_s2.to_array();
    let e = s.euler;
    [
        s.t_s,
        px,
        py,
        pz,
        vx,
        vy,
        vz,
        ax,
        ay,
        az,
        qw,
        qx,
        qy,
        qz,
        e.yaw_rad,
        e.pitch_rad,
        e.roll_rad,
        wx,
        wy,
        wz,
        bx,
        by,
        bz,
    ]
}

/// Columns read from a CSV file, by name.
#[derive(Clone, Debug)]
pub struct CsvColumns {
    /// The file.
    pub file: PathBuf,
    header: HashMap<String, usize>,
    values: Vec<Vec<f64>>, // per header column, only the requested ones filled
}

impl CsvColumns {
    /// True when the header has `name`.
    #[must_use]
    pub fn has(&self, name: &str) -> bool {
        self.header.contains_key(name)
    }
    /// The values of a column that was requested when reading.
    #[must_use]
    pub fn get(&self, name: &str) -> &[f64] {
        self.header
            .get(name)
            .map_or(&[], |&k| self.values[k].as_slice())
    }
    /// Number of data rows.
    #[must_use]
    pub fn rows(&self) -> usize {
        self.values.iter().map(Vec::len).max().unwrap_or(0)
    }
}

/// The file of Monte Carlo run `run` of `runs`: `dir/imu.csv`, run 7 → `dir/imu_run0007.csv`
/// (at least 4 digits, more when `runs` needs them).
#[must_use]
pub fn run_path(out: &Path, run: u64, runs: u64) -> PathBuf {
    let digits = runs.saturating_sub(1).max(1).to_string().len().max(4);
    let stem = out
        .file_stem()
        .map_or_else(|| "imu".into(), |s| s.to_string_lossy().into_owned());
    let ext = out
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    out.with_file_name(format!("{stem}_run{run:0digits$}{ext}"))
}

/// The column names of a table file: a CSV file's header (trimmed names), a Parquet, `.npy` or
/// `.npz` file's fields or members ([`TableFormat`]).
///
/// # Errors
/// Unreadable or empty file, a column name that appears twice.
pub fn read_header(input: impl Into<Input>) -> Result<Vec<String>> {
    let input = input.into();
    let path = input.path();
    match TableFormat::of(path) {
        TableFormat::Parquet => crate::parquet::column_names(path),
        TableFormat::Npy => crate::npy::column_names(path),
        TableFormat::Npz => crate::npz::column_names(path),
        TableFormat::Mcap => crate::bag::column_names(&input, &[]),
        TableFormat::Nmea => Ok(crate::nmea::read_table(path)?.columns),
        TableFormat::Csv => Ok(csv_layout(path, input.map())?.names),
    }
}

/// How a CSV file's fields become a table's columns: as they are, through the ASL layout its
/// header announces ([`crate::asl`]), or through the column map it is read with
/// ([`crate::column_map`]).
struct Layout {
    /// The table's column names.
    names: Vec<String>,
    /// How each column is made (`None`: column k is field k).
    sources: Option<Vec<Source>>,
    /// The file's own column names, when they differ from the table's (for messages).
    file_names: Option<Vec<String>>,
    /// Whether `#` lines are comments (not in an ASL file, whose header starts with `#`).
    comments: bool,
    /// The time origin its stamps count from when it is fixed before the first row: the
    /// sequence's, for a file of a EuRoC/TUM-VI sequence ([`crate::asl::sequence_origin_ns`]).
    origin_ns: Option<i64>,
}

/// The layout of the CSV file at `path`, read through `map` when given, else by its header.
fn csv_layout(path: &Path, map: Option<&ColumnMap>) -> Result<Layout> {
    if let Some(map) = map {
        let raw = plain_header(path)?;
        let (names, sources) = map.resolve(&raw, path)?;
        return Ok(Layout {
            names,
            sources: Some(sources),
            file_names: Some(raw),
            comments: true,
            origin_ns: None,
        });
    }
    if let Some(line) = asl_header(path)? {
        let names = crate::asl::column_names(&line, &path.display().to_string())?;
        let sources = names
            .iter()
            .enumerate()
            .map(|(k, n)| match n.as_str() {
                "t_s" => Source::Time(k, TimeUnit::Nanoseconds),
                _ => Source::Field(k),
            })
            .collect();
        return Ok(Layout {
            names,
            sources: Some(sources),
            file_names: Some(crate::asl::file_names(&line)),
            comments: false,
            origin_ns: crate::asl::sequence_origin_ns(path),
        });
    }
    Ok(Layout {
        names: plain_header(path)?,
        sources: None,
        file_names: None,
        comments: true,
        origin_ns: None,
    })
}

/// A CSV file's header row as it is (trimmed names), after any comment lines.
fn plain_header(path: &Path) -> Result<Vec<String>> {
    let mut r = reader(path, true)?;
    let h = r.headers().map_err(|e| csv_error(path, &e))?;
    let names: Vec<String> = h.iter().map(|s| s.trim().to_string()).collect();
    if names.iter().all(String::is_empty) {
        return Err(Error::CsvFormat {
            file: path.into(),
            message: "empty file (no header row)".into(),
        });
    }
    // A column name read twice would make every reader pick one of them silently (or worse).
    let mut seen: HashMap<&str, usize> = HashMap::with_capacity(names.len());
    for (j, name) in names.iter().enumerate() {
        if let Some(&i) = seen.get(name.as_str()) {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: format!(
                    "column {name} appears twice in the header (fields {} and {})",
                    i + 1,
                    j + 1
                ),
            });
        }
        seen.insert(name, j);
    }
    Ok(names)
}

fn reader(path: &Path, comments: bool) -> Result<csv::Reader<File>> {
    let file = File::open(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    // Fields are trimmed where they are parsed ([`CsvRows::next_row`]): the csv crate's own
    // trimming of fields makes a new record per row.
    Ok(csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::Headers)
        .comment(comments.then_some(b'#'))
        .from_reader(file))
}

/// The longest first line read to recognise a layout, bytes.
const FIRST_LINE_LIMIT: u64 = 1 << 20;

/// The first line of a CSV file when it is an ASL header ([`crate::asl`]).
fn asl_header(path: &Path) -> Result<Option<String>> {
    use std::io::{BufRead, Read};
    let io = |source| Error::Io {
        path: path.into(),
        source,
    };
    let file = File::open(path).map_err(io)?;
    let mut line = Vec::new();
    std::io::BufReader::new(file.take(FIRST_LINE_LIMIT))
        .read_until(b'\n', &mut line)
        .map_err(io)?;
    let line = String::from_utf8_lossy(&line);
    Ok(crate::asl::is_header(&line).then(|| line.into_owned()))
}

/// The number of comment lines (`#` first) at the start of the file at `path`, read through
/// without keeping them.
fn leading_comment_lines(path: &Path) -> Result<usize> {
    use std::io::BufRead;
    let io = |source| Error::Io {
        path: path.into(),
        source,
    };
    let mut r = std::io::BufReader::new(File::open(path).map_err(io)?);
    let mut count = 0;
    loop {
        if r.fill_buf().map_err(io)?.first() != Some(&b'#') {
            return Ok(count);
        }
        // Through the end of the line, a buffer at a time.
        loop {
            let buf = r.fill_buf().map_err(io)?;
            if buf.is_empty() {
                return Ok(count + 1);
            }
            if let Some(end) = buf.iter().position(|&b| b == b'\n') {
                r.consume(end + 1);
                break;
            }
            let n = buf.len();
            r.consume(n);
        }
        count += 1;
    }
}

fn csv_error(path: &Path, e: &csv::Error) -> Error {
    csv_error_after(path, e, 0)
}

/// A CSV reader's error, its row counted without the `comments` lines before the header.
fn csv_error_after(path: &Path, e: &csv::Error, comments: usize) -> Error {
    let row = |pos: &Option<csv::Position>| {
        pos.as_ref()
            .map_or(0, |p| (p.line() as usize).saturating_sub(comments))
    };
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } => format!(
            "row {} has {len} fields, the header has {expected_len} (truncated or malformed file)",
            row(pos)
        ),
        csv::ErrorKind::Utf8 { pos, .. } => {
            format!("row {} is not valid UTF-8", row(pos))
        }
        _ => e.to_string(),
    };
    Error::CsvFormat {
        file: path.into(),
        message,
    }
}

/// Reads every column of a table file in the format its extension names ([`TableFormat`]):
/// Parquet, `.npy`, `.npz`, else CSV with a header row (through the input's column map when it
/// has one: `t_s` and the sensors' columns in SI and body axes, then its other columns).
///
/// # Errors
/// As [`read_columns`]: values that are not finite numbers, malformed or empty files; a column
/// the map names that the file lacks.
pub fn read_table(input: impl Into<Input>) -> Result<Table> {
    let input = input.into();
    let path = input.path();
    match TableFormat::of(path) {
        TableFormat::Parquet => return crate::parquet::read_table(path),
        TableFormat::Npz => return crate::npz::read_table(path),
        TableFormat::Mcap => return crate::bag::read_table(&input, &[]),
        TableFormat::Nmea => return crate::nmea::read_table(path),
        TableFormat::Npy | TableFormat::Csv => {}
    }
    let header = read_header(&input)?;
    let names: Vec<&str> = header.iter().map(String::as_str).collect();
    read_table_columns(&input, &names, "")
}

/// [`read_table`], a bag's topic chosen among those of `role` (other formats hold one table).
///
/// # Errors
/// As [`read_table`].
pub fn read_table_as(input: impl Into<Input>, role: crate::bag::Role) -> Result<Table> {
    let input = input.into();
    match TableFormat::of(input.path()) {
        TableFormat::Mcap => crate::bag::read_table_as(&input, role),
        _ => read_table(input),
    }
}

/// Reads the named columns of a CSV file as a table with those columns, in that order.
///
/// # Errors
/// As [`read_columns`].
pub fn read_table_columns(input: impl Into<Input>, names: &[&str], hint: &str) -> Result<Table> {
    whole_table(CsvRows::open(input, names, hint)?, names)
}

/// Every row of `rows` (opened for `names`) as a table, refused when there is none.
fn whole_table(mut rows: CsvRows, names: &[&str]) -> Result<Table> {
    let mut t = Table::new(names);
    let mut row = vec![0.0; names.len()];
    while rows.next_row(&mut row)?.is_some() {
        t.push_row(&row);
    }
    if t.rows() == 0 {
        return Err(Error::CsvFormat {
            file: rows.path,
            message: "no data rows after the header".into(),
        });
    }
    Ok(t)
}

/// Reads the named columns of a CSV file with a header row; other columns are ignored.
///
/// # Errors
/// Missing columns (all named at once, with `hint`), values that are not finite numbers (file,
/// row, column), malformed or empty files.
pub fn read_columns(input: impl Into<Input>, required: &[&str], hint: &str) -> Result<CsvColumns> {
    let mut rows = CsvRows::open(input, required, hint)?;
    let header: HashMap<String, usize> = rows
        .names
        .iter()
        .enumerate()
        .map(|(k, n)| (n.clone(), k))
        .collect();
    let mut values = vec![Vec::new(); header.len()];
    let mut row = vec![0.0; required.len()];
    while rows.next_row(&mut row)?.is_some() {
        for (name, v) in required.iter().zip(&row) {
            values[header[*name]].push(*v);
        }
    }
    if values.iter().all(Vec::is_empty) {
        return Err(Error::CsvFormat {
            file: rows.path,
            message: "no data rows after the header".into(),
        });
    }
    Ok(CsvColumns {
        file: rows.path,
        header,
        values,
    })
}

/// Where [`CsvRows`] reads: a CSV file, a Parquet file's rows or a `.npy` file's records.
#[derive(Debug)]
enum RowSource {
    Csv(csv::Reader<File>),
    Parquet(crate::parquet::ParquetRows),
    Npy(crate::npy::NpyRows),
    /// A table read whole (a `.npz` archive), and the rows given so far.
    Whole(Table, usize),
}

/// The named columns of a CSV (or Parquet, or `.npy`) file, row by row (memory does not grow with the
/// file).
#[derive(Debug)]
pub struct CsvRows {
    path: PathBuf,
    reader: RowSource,
    record: csv::ByteRecord,
    /// The header's column names.
    names: Vec<String>,
    /// (field index, column name) of each requested column, in request order.
    wanted: Vec<(usize, String)>,
    /// Comment lines before a CSV file's header (its description line): not rows.
    comments: usize,
    /// How each column is made from the fields ([`Layout`]; `None`: column k is field k).
    sources: Option<Vec<Source>>,
    /// The time origin of the stamps, set by the first row ([`TimeUnit::seconds_after_origin`]).
    origin_ns: std::cell::Cell<Option<i64>>,
    /// The file's own column names, by field, for messages.
    file_names: Option<Vec<String>>,
    /// Rows given only from `.1` to `.2` in the time column `.0` ([`CsvRows::within`]).
    window: Option<(usize, f64, f64)>,
    /// Per requested column: an empty or NaN cell is a missing value, given as NaN
    /// ([`CsvRows::allowing_missing`]).
    missing_ok: Vec<bool>,
}

impl CsvRows {
    /// Takes an empty cell or `NaN` in the requested columns `names` as a missing value, given
    /// as NaN (a reference that lost track for a while), instead of refusing it. Infinite values
    /// are still refused. CSV only: the binary formats' readers refuse a missing value.
    #[must_use]
    pub fn allowing_missing(mut self, names: &[&str]) -> Self {
        self.missing_ok = self
            .wanted
            .iter()
            .map(|(_, name)| names.contains(&name.as_str()))
            .collect();
        self
    }

    /// Gives only the rows whose `t_s` (a column asked for) lies in `window`, its seconds
    /// counted from `t0`: the rows before it are skipped, and the rows end after it.
    ///
    /// # Errors
    /// `t_s` not among the columns asked for.
    pub fn within(mut self, window: crate::rows::TimeWindow, t0: f64) -> Result<Self> {
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

    /// Opens `input` and checks that its header has every column of `required`; a CSV file is
    /// read through the input's column map when it has one (a vendor's columns and units).
    ///
    /// # Errors
    /// Missing columns (all named at once, with `hint`), unreadable or empty files; a column the
    /// map names that the file lacks.
    pub fn open(input: impl Into<Input>, required: &[&str], hint: &str) -> Result<Self> {
        let input = input.into();
        let path = input.path();
        // A bag's topic is chosen by the columns asked for, and read whole; an NMEA log too.
        let whole = match TableFormat::of(path) {
            TableFormat::Mcap => Some(crate::bag::read_table(&input, required)?),
            TableFormat::Nmea => Some(crate::nmea::read_table(path)?),
            _ => None,
        };
        let layout = match TableFormat::of(path) {
            TableFormat::Csv => csv_layout(path, input.map())?,
            TableFormat::Mcap | TableFormat::Nmea => Layout {
                names: whole
                    .as_ref()
                    .map(|t| t.columns.clone())
                    .unwrap_or_default(),
                sources: None,
                file_names: None,
                comments: true,
                origin_ns: None,
            },
            _ => Layout {
                names: read_header(path)?,
                sources: None,
                file_names: None,
                comments: true,
                origin_ns: None,
            },
        };
        let names = layout.names;
        // Looked up by name, so a file of many columns costs linear time, not quadratic.
        let index: HashMap<&str, usize> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), i))
            .collect();
        let missing: Vec<String> = required
            .iter()
            .filter(|c| !index.contains_key(**c))
            .map(|c| (*c).to_string())
            .collect();
        if !missing.is_empty() {
            // A header with none of imukit's columns is a vendor's or another program's: its
            // columns are read through a map.
            let foreign = layout.sources.is_none()
                && !names.iter().any(|n| {
                    crate::schema::TableKind::detect(std::slice::from_ref(n)).is_some()
                        || n == "t_s"
                        || n.ends_with("_m_s2")
                        || n.ends_with("_rad_s")
                        || n.ends_with("_m")
                });
            let hint = if foreign && matches!(TableFormat::of(path), TableFormat::Csv) {
                format!(
                    "{hint}; the header has none of imukit's columns ({}): read a vendor's CSV \
                     through a column map, --map FILE (Python: map=), docs/formats.md",
                    names
                        .iter()
                        .take(6)
                        .map(String::as_str)
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            } else {
                hint.to_string()
            };
            return Err(Error::MissingColumns {
                file: path.into(),
                missing,
                hint,
            });
        }
        let wanted = required
            .iter()
            .map(|c| (index.get(*c).copied().unwrap_or(0), (*c).to_string()))
            .collect();
        let reader = match TableFormat::of(path) {
            TableFormat::Parquet => RowSource::Parquet(crate::parquet::ParquetRows::open(path)?.1),
            TableFormat::Npy => RowSource::Npy(crate::npy::NpyRows::open(path)?.1),
            TableFormat::Npz => RowSource::Whole(crate::npz::read_table(path)?, 0),
            TableFormat::Mcap | TableFormat::Nmea => RowSource::Whole(whole.unwrap_or_default(), 0),
            TableFormat::Csv => RowSource::Csv(reader(path, layout.comments)?),
        };
        // Rows are counted from the header, row 1, whatever comment lines (the description's)
        // come before it.
        let comments = match reader {
            RowSource::Csv(_) if layout.comments => leading_comment_lines(path)?,
            _ => 0,
        };
        Ok(Self {
            path: path.into(),
            reader,
            record: csv::ByteRecord::new(),
            names,
            wanted,
            comments,
            sources: layout.sources,
            origin_ns: std::cell::Cell::new(layout.origin_ns),
            file_names: layout.file_names,
            window: None,
            missing_ok: Vec::new(),
        })
    }

    /// The columns of the table read (a CSV file's header, a bag topic's columns).
    #[must_use]
    pub fn columns(&self) -> &[String] {
        &self.names
    }

    /// Parses the next data row into `out` (the requested columns in order) and returns its
    /// file line, or `None` at the end of the file.
    ///
    /// # Errors
    /// Values that are not finite numbers (file, row, column), malformed rows.
    pub fn next_row(&mut self, out: &mut [f64]) -> Result<Option<usize>> {
        loop {
            let row = self.next_row_any(out)?;
            let (Some(line), Some((k, lo, hi))) = (row, self.window) else {
                return Ok(row);
            };
            match out.get(k) {
                Some(&t) if t < lo => {}
                Some(&t) if t > hi => return Ok(None),
                _ => return Ok(Some(line)),
            }
        }
    }

    /// The next row, whatever its time.
    fn next_row_any(&mut self, out: &mut [f64]) -> Result<Option<usize>> {
        let reader = match &mut self.reader {
            RowSource::Csv(r) => r,
            RowSource::Parquet(rows) => return rows.next_row(&self.wanted, out),
            RowSource::Npy(rows) => return rows.next_row(&self.wanted, out),
            RowSource::Whole(table, given) => {
                let width = table.columns.len();
                let Some(row) = table.data.chunks_exact(width).nth(*given) else {
                    return Ok(None);
                };
                for ((k, _), slot) in self.wanted.iter().zip(out.iter_mut()) {
                    *slot = row[*k];
                }
                *given += 1;
                return Ok(Some(*given));
            }
        };
        match reader.read_byte_record(&mut self.record) {
            Ok(false) => return Ok(None),
            Ok(true) => {}
            Err(e) => return Err(csv_error_after(&self.path, &e, self.comments)),
        }
        let row = self
            .record
            .position()
            .map_or(0, |p| (p.line() as usize).saturating_sub(self.comments));
        for (i, ((k, name), slot)) in self.wanted.iter().zip(out.iter_mut()).enumerate() {
            let missing_ok = self.missing_ok.get(i).copied().unwrap_or(false);
            *slot = match self.sources.as_ref().map(|s| &s[*k]) {
                None if missing_ok => self.number_or_missing(*k, name, row)?,
                Some(Source::Field(f)) if missing_ok => self.number_or_missing(*f, name, row)?,
                None => self.number(*k, name, row)?,
                Some(Source::Field(f)) => self.number(*f, name, row)?,
                Some(Source::Time(f, unit)) => {
                    let text = self.text(*f, name, row)?;
                    let mut origin = self.origin_ns.get();
                    let t = unit
                        .seconds_after_origin(text, &mut origin)
                        .ok_or_else(|| {
                            self.bad(*f, name, row, format!("not a time stamp: \"{text}\""))
                        })?;
                    self.origin_ns.set(origin);
                    t
                }
                Some(Source::Combination(terms)) => {
                    let mut v = 0.0;
                    for (f, c) in terms {
                        v += c * self.number(*f, name, row)?;
                    }
                    // A finite reading in the file's unit may overflow in SI (1e308 g).
                    if !v.is_finite() {
                        let f = terms.first().map_or(0, |(f, _)| *f);
                        return Err(self.bad(
                            f,
                            name,
                            row,
                            format!("{v} once in SI units: not a reading"),
                        ));
                    }
                    v
                }
            };
        }
        Ok(Some(row))
    }

    /// The error of field `f` in `row`, read for column `name`: the file's column by its own
    /// name, then the table's.
    fn bad(&self, f: usize, name: &str, row: usize, message: String) -> Error {
        Error::CsvValue {
            file: self.path.clone(),
            row,
            column: match self.file_names.as_ref().and_then(|n| n.get(f)) {
                Some(own) if own != name => format!("{own} ({name})"),
                _ => name.to_string(),
            },
            message,
        }
    }

    /// Field `f` of the current record as trimmed text.
    fn text(&self, f: usize, name: &str, row: usize) -> Result<&str> {
        let field = self.record.get(f).unwrap_or_default();
        // Whitespace around a value, Unicode's definition, as the csv crate's trimming had it.
        std::str::from_utf8(field).map(str::trim).map_err(|_| {
            let lossy = String::from_utf8_lossy(field);
            self.bad(f, name, row, format!("not a number: \"{}\"", lossy.trim()))
        })
    }

    /// Field `f` of the current record as a finite number, or NaN for an empty or NaN cell.
    fn number_or_missing(&self, f: usize, name: &str, row: usize) -> Result<f64> {
        let text = self.text(f, name, row)?;
        if text.is_empty() || text.eq_ignore_ascii_case("nan") {
            Ok(f64::NAN)
        } else {
            self.number(f, name, row)
        }
    }

    /// Field `f` of the current record as a finite number.
    fn number(&self, f: usize, name: &str, row: usize) -> Result<f64> {
        let text = self.text(f, name, row)?;
        let v: f64 = text
            .parse()
            .map_err(|_| self.bad(f, name, row, format!("not a number: \"{text}\"")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.bad(f, name, row, format!("not a finite number: \"{text}\"")))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_value_not_finite_is_found_wherever_it_is() {
        // Every place in and around the blocks tested whole (one, two and a half blocks), each
        // kind of value that is not finite, and a second one after it that must not be named.
        for len in [0_u32, 1, 31, 32, 33, 64, 80] {
            let clean: Vec<f64> = (0..len).map(|i| f64::from(i) - 40.0).collect();
            let len = clean.len();
            assert_eq!(first_not_finite(&clean), None, "{len}");
            for at in 0..len {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut data = clean.clone();
                    data[at] = bad;
                    if at + 1 < len {
                        data[len - 1] = f64::NAN;
                    }
                    assert_eq!(first_not_finite(&data), Some(at), "{len} {at} {bad}");
                }
            }
        }
    }

    #[test]
    fn rows_of_any_width_read_back_as_the_numbers_written() {
        // Rows wider than the blocks handed to the writer (`WRITE_BLOCK`, a mebibyte: 80 000
        // values of 3 to 24 characters), and numbers from one to 24 characters of text (all
        // finite: nothing else reaches a file).
        let values = [
            0.0,
            -1.0,
            0.1,
            -1.234_567_890_123_456_7e-300,
            6.02e23,
            1.797_693_134_862_315_7e300,
            1e16,
        ];
        for width in [1, 7, 80_000] {
            let data: Vec<f64> = (0..3 * width)
                .map(|i| values[i % values.len()] * (1.0 + i as f64))
                .collect();
            let mut out = Vec::new();
            write_rows(&mut out, &data, width, b", ").expect("written to memory");
            let text = String::from_utf8(out).expect("text");
            assert_eq!(text.lines().count(), 3);
            if width == 80_000 {
                let row = text.lines().next().map_or(0, str::len);
                assert!(row > crate::output::WRITE_BLOCK, "a row of {row} bytes");
            }
            let back: Vec<f64> = text
                .lines()
                .flat_map(|l| l.split(", ").map(|v| v.parse::<f64>().expect("a number")))
                .collect();
            assert!(
                data.iter().all(|v| v.is_finite()) && back == data,
                "width {width}"
            );
        }
    }

    #[test]
    fn rows_are_each_values_shortest_text_byte_for_byte() {
        // Numbers of every text length (3 to 24 characters: integers, decimals, quantised
        // readings, random bit patterns of every exponent) over several of the blocks handed to the
        // writer (`WRITE_BLOCK`: 200 000 values, about 2.4 MB of text), and every separator length
        // the commands use, against the plain join of zmij's texts.
        let mut z: u64 = 0x0123_4567_89AB_CDEF;
        let mut next = || {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut v = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            v = (v ^ (v >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            v ^ (v >> 31)
        };
        let mut data = Vec::new();
        for i in 0..200_000 {
            let r = next();
            data.push(match i % 5 {
                0 => f64::from_bits(r & !(0x7FF << 52) | ((r % 2046 + 1) << 52)),
                1 => 1e-6 * ((r % 20_000_000) as f64 - 1e7),
                2 => (r % 1000) as f64,
                3 => (r % 10_u64.pow(1 + i % 16)) as f64 / 10_f64.powi((i % 7) as i32),
                _ => f64::from(i) / 100.0,
            });
        }
        let mut lengths = std::collections::BTreeSet::new();
        let mut buf = zmij::Buffer::new();
        for separator in [b",".as_slice(), b" ", b", "] {
            for width in [1, 10, 23] {
                let mut out = Vec::new();
                write_rows(&mut out, &data, width, separator).expect("written to memory");
                let mut want = Vec::new();
                for row in data.chunks(width) {
                    for (k, v) in row.iter().enumerate() {
                        if k > 0 {
                            want.extend_from_slice(separator);
                        }
                        let text = buf.format(*v);
                        lengths.insert(text.len());
                        want.extend_from_slice(text.as_bytes());
                    }
                    want.push(b'\n');
                }
                assert!(out == want, "width {width}, separator {separator:?}");
                assert!(
                    out.len() > 2 * crate::output::WRITE_BLOCK,
                    "{} bytes",
                    out.len()
                );
            }
        }
        assert!(
            lengths.iter().copied().eq(3..=24),
            "text lengths: {lengths:?}"
        );
    }

    #[test]
    fn values_are_read_with_whitespace_trimmed_and_bad_ones_named_by_row_and_column() {
        let dir = tempfile::Builder::new()
            .prefix("imukit-table-trim-")
            .tempdir()
            .unwrap();
        let dir = dir.path();
        let path = dir.join("t.csv");
        // Spaces, a tab and no-break spaces (Unicode whitespace) around names and values.
        std::fs::write(&path, " t_s ,\tx\n 0.5 ,\u{a0}-2\u{a0}\n1,\t3e2 \n").expect("written");
        let columns = read_columns(&path, &["t_s", "x"], "").expect("read");
        assert_eq!(columns.get("t_s"), [0.5, 1.0].as_slice());
        assert_eq!(columns.get("x"), [-2.0, 300.0].as_slice());
        for (row2, message) in [
            (
                b" 2, 1.0x".as_slice(),
                "t.csv, row 3, column x: not a number: \"1.0x\"",
            ),
            (
                b"2,inf",
                "t.csv, row 3, column x: not a finite number: \"inf\"",
            ),
            (
                b"2,\xff1",
                "t.csv, row 3, column x: not a number: \"\u{fffd}1\"",
            ),
        ] {
            let mut text = b"t_s,x\n1,2\n".to_vec();
            text.extend_from_slice(row2);
            std::fs::write(&path, &text).expect("written");
            let err = read_columns(&path, &["t_s", "x"], "").expect_err("a bad value");
            assert!(err.to_string().ends_with(message), "{err}");
        }
        let _ = std::fs::remove_dir_all(dir);
    }
}
