//! The CSV schema (docs/design.md §3) and column tables shared by the CLI and Python.
//!
//! A [`Table`] is named columns over row-major `f64` data. CSV output uses shortest round-trip
//! formatting (`zmij`), so a written file reads back bit for bit, and is written to a temporary file
//! that is renamed into place only when complete.
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use imu_core::sensor::ImuReading;
use imu_core::{NavFrame, Truth};

use crate::columns::{
    ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, TRUTH_COLUMNS,
};
use crate::error::{Error, Result};

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
    #[inline]
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
    /// Appends one row (its length must equal the number of columns). Inlined: the jobs of
    /// `imukit` append a row per sample from another crate.
    #[inline]
    pub fn push_row(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.columns.len());
        self.data.extend_from_slice(row);
    }

    /// Appends the columns `names` after this table's, row `i` of them `values[i]`.
    ///
    /// # Errors
    /// [`Error::Invalid`] on `table` when `values` has not one row per row of the table.
    pub fn append_columns<const W: usize>(
        &mut self,
        names: &[&str; W],
        values: &[[f64; W]],
    ) -> Result<()> {
        let rows = self.rows();
        if values.len() != rows {
            return Err(crate::error::invalid(
                "table",
                format!("{} rows of {names:?} for {rows} rows", values.len()),
            ));
        }
        // Widened in place, last row first: each row moves to a place at or after its own,
        // past every row still to move (the table's memory is kept, as a refilled one's is).
        let (width, wider) = (self.columns.len(), self.columns.len() + W);
        self.data.resize(rows * wider, 0.0);
        for (i, more) in values.iter().enumerate().rev() {
            self.data.copy_within(i * width..(i + 1) * width, i * wider);
            self.data[i * wider + width..(i + 1) * wider].copy_from_slice(more);
        }
        self.columns.extend(names.iter().map(|c| (*c).to_string()));
        Ok(())
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
    let mut text: Vec<u8> = Vec::with_capacity(crate::writeback::WRITE_BLOCK + 4096);
    for row in data.chunks(width.max(1)) {
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                text.extend_from_slice(separator);
            }
            text.extend_from_slice(buf.format(*v).as_bytes());
        }
        text.push(b'\n');
        if text.len() >= crate::writeback::WRITE_BLOCK {
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
    fn appended_columns_extend_each_row_and_a_wrong_count_is_refused() {
        let mut t = Table::new(&["t_s", "a"]);
        t.push_row(&[0.0, 1.0]);
        t.push_row(&[0.5, 2.0]);
        t.append_columns(&["b", "c"], &[[3.0, 4.0], [5.0, 6.0]])
            .unwrap();
        assert_eq!(t.columns, ["t_s", "a", "b", "c"]);
        assert_eq!(t.data, [0.0, 1.0, 3.0, 4.0, 0.5, 2.0, 5.0, 6.0]);
        assert_eq!(t.column("c"), Some(vec![4.0, 6.0]));
        let e = t.append_columns(&["d"], &[[7.0]]).unwrap_err().to_string();
        assert!(e.contains("1 rows of [\"d\"] for 2 rows"), "{e}");
        assert_eq!(t.columns.len(), 4, "a refused append leaves the table");
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
                assert!(row > crate::writeback::WRITE_BLOCK, "a row of {row} bytes");
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
                    out.len() > 2 * crate::writeback::WRITE_BLOCK,
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
}
