//! Reading a table file, whatever its format ([`crate::TableFormat`]): whole ([`read_table`],
//! the named columns with [`read_columns`]) or row by row ([`CsvRows`]: memory does not grow
//! with the file); a CSV file by its header, through the EuRoC/TUM-VI layout its header
//! announces, or through the input's column map. Errors name the file, the row and the column.
use std::collections::HashMap;
use std::fs::File;
use std::path::{Path, PathBuf};

use imu_core::calibration::Correction;

use crate::TableFormat;
use crate::calibration::CalibrationFile;
use crate::column_map::{ColumnMap, Source, TimeUnit};
use crate::error::{Error, Result};
use crate::input::Input;
use crate::table::Table;

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
    let whole = match TableFormat::of(path) {
        TableFormat::Parquet => crate::parquet::read_table(path),
        TableFormat::Npz => crate::npz::read_table(path),
        TableFormat::Mcap => crate::bag::read_table(&input, &[]),
        TableFormat::Nmea => crate::nmea::read_table(path),
        TableFormat::Npy | TableFormat::Csv => {
            let header = read_header(&input)?;
            let names: Vec<&str> = header.iter().map(String::as_str).collect();
            return read_table_columns(&input, &names, "");
        }
    };
    let mut table = whole?;
    if let Some(c) = input.calibration() {
        c.apply_to_table(&mut table, &path.display().to_string())?;
    }
    Ok(table)
}

/// [`read_table`], a bag's topic chosen among those of `role` (other formats hold one table).
///
/// # Errors
/// As [`read_table`].
pub fn read_table_as(input: impl Into<Input>, role: crate::bag::Role) -> Result<Table> {
    let input = input.into();
    match TableFormat::of(input.path()) {
        TableFormat::Mcap => {
            let mut table = crate::bag::read_table_as(&input, role)?;
            if let Some(c) = input.calibration() {
                c.apply_to_table(&mut table, &input.path().display().to_string())?;
            }
            Ok(table)
        }
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

/// Where the columns of each sensor the calibration `c` corrects sit among `wanted`, the ones
/// not requested added to it: a sensor counts when one of its columns is requested, and then
/// needs all three.
fn calibrated_columns(
    c: &CalibrationFile,
    index: &HashMap<&str, usize>,
    wanted: &mut Vec<(usize, String)>,
    path: &Path,
) -> Result<Vec<(Correction, [usize; 3])>> {
    let mut out = Vec::new();
    for (correction, columns) in c.columns() {
        if !columns.iter().any(|n| wanted.iter().any(|(_, w)| w == n)) {
            continue;
        }
        let mut at = [0; 3];
        for (slot, name) in at.iter_mut().zip(columns) {
            let Some(&field) = index.get(name) else {
                return Err(Error::MissingColumns {
                    file: path.into(),
                    missing: vec![name.to_string()],
                    hint: format!("the calibration corrects {} together", columns.join(", ")),
                });
            };
            *slot = match wanted.iter().position(|(_, w)| w == name) {
                Some(k) => k,
                None => {
                    wanted.push((field, name.to_string()));
                    wanted.len() - 1
                }
            };
        }
        out.push((*correction, at));
    }
    Ok(out)
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
    pub(crate) path: PathBuf,
    reader: RowSource,
    record: csv::ByteRecord,
    /// The header's column names.
    names: Vec<String>,
    /// (field index, column name) of each requested column, in request order.
    pub(crate) wanted: Vec<(usize, String)>,
    /// Comment lines before a CSV file's header (its description line): not rows.
    comments: usize,
    /// How each column is made from the fields ([`Layout`]; `None`: column k is field k).
    sources: Option<Vec<Source>>,
    /// The time origin of the stamps, set by the first row ([`TimeUnit::seconds_after_origin`]).
    origin_ns: std::cell::Cell<Option<i64>>,
    /// The file's own column names, by field, for messages.
    file_names: Option<Vec<String>>,
    /// Rows given only from `.1` to `.2` in the time column `.0` ([`CsvRows::within`]).
    pub(crate) window: Option<(usize, f64, f64)>,
    /// Per requested column: an empty or NaN cell is a missing value, given as NaN
    /// ([`CsvRows::allowing_missing`]).
    missing_ok: Vec<bool>,
    /// The part's calibration: each sensor's correction and where its three columns are in
    /// `wanted` (those not requested read after the requested ones).
    calibration: Vec<(Correction, [usize; 3])>,
    /// A row of every column read, when the calibration reads more than was requested.
    scratch: Vec<f64>,
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
        let mut wanted: Vec<(usize, String)> = required
            .iter()
            .map(|c| (index.get(*c).copied().unwrap_or(0), (*c).to_string()))
            .collect();
        let calibration = match input.calibration() {
            Some(c) => calibrated_columns(c, &index, &mut wanted, path)?,
            None => Vec::new(),
        };
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
            calibration,
            scratch: Vec::new(),
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
            let row = self.next_row_calibrated(out)?;
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

    /// The next row, whatever its time, its readings corrected by the part's calibration.
    fn next_row_calibrated(&mut self, out: &mut [f64]) -> Result<Option<usize>> {
        if self.calibration.is_empty() {
            return self.next_row_any(out);
        }
        let mut row = std::mem::take(&mut self.scratch);
        row.resize(self.wanted.len(), 0.0);
        let line = self.next_row_any(&mut row);
        if let Ok(Some(at)) = line {
            for (c, [x, y, z]) in &self.calibration {
                let v = c.apply([row[*x], row[*y], row[*z]]);
                // A missing cell (NaN) stays missing; anything else must stay a number.
                for (k, (&i, value)) in [*x, *y, *z].iter().zip(v).enumerate() {
                    if value.is_infinite() || (value.is_nan() && !row[i].is_nan()) {
                        let column = &self.wanted[[*x, *y, *z][k]].1;
                        return Err(crate::calibration::not_finite(
                            &self.path.display().to_string(),
                            at,
                            column,
                            value,
                        ));
                    }
                }
                [row[*x], row[*y], row[*z]] = v;
            }
            let n = out.len();
            out.copy_from_slice(&row[..n]);
        }
        self.scratch = row;
        line
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

#[cfg(all(test, not(feature = "bags")))]
mod bag_refused {
    #[test]
    fn a_bag_is_refused_by_name() {
        let e = super::read_table(std::path::Path::new("run.mcap"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("run.mcap") && e.contains("`bags` feature is off"),
            "{e}"
        );
    }
}

#[cfg(all(test, not(feature = "nmea")))]
mod nmea_refused {
    #[test]
    fn a_log_is_refused_by_name() {
        let e = super::read_table(std::path::Path::new("fixes.nmea"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fixes.nmea") && e.contains("`nmea` feature is off"),
            "{e}"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
