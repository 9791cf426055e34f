//! Tables as NumPy `.npy` files (the `npyz` crate): one structured array, a record per row and
//! a little-endian float64 field per column, the fields named as in the CSV contract. NumPy
//! reads it back bit for bit (`np.load("imu.npy")["accel_x_m_s2"]`; pandas:
//! `pd.DataFrame(np.load("imu.npy"))`). Chosen by the output path's extension (`.npy`),
//! written as every output is: under a temporary name, renamed into place when complete; rows
//! stream to the file (its header's length is filled in when the table ends), so memory stays
//! flat however long the table. A `.npy` file has no place for metadata: the scenario and the
//! frame are not in it (Parquet carries them).
//!
//! Read back by imukit with every row checked finite (row and column named); a file that is not
//! a structured array of float64 fields (a plain 2-D array has no column names) is refused
//! saying what it holds.
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, Write};
use std::path::{Path, PathBuf};

use npyz::{DType, NpyHeader, NpyWriter, TypeStr, WriterBuilder};

use crate::error::{Error, Result};
use crate::writeback::{OutputFile, WRITE_BLOCK};

/// NumPy's own limit on a header's length (`max_header_size` of `numpy.load`), bytes: a longer
/// header is refused before it is read.
pub(crate) const MAX_HEADER_BYTES: usize = 10_000;

/// The type of every column: little-endian float64.
pub(crate) fn float64() -> DType {
    DType::Plain("<f8".parse::<TypeStr>().expect("a valid type string"))
}

fn format_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::CsvFormat {
        file: path.into(),
        message: format!(".npy: {e}"),
    }
}

/// One row of a table: the values of its fields, in order (what [`NpySink`] hands `npyz`).
#[derive(Debug, Default)]
pub struct Record(Vec<f64>);

/// Writes a [`Record`] as the fields of a structured float64 dtype.
#[derive(Debug)]
pub struct RecordWriter {
    width: usize,
}

impl npyz::TypeWrite for RecordWriter {
    type Value = Record;

    fn write_one<W: Write>(&self, mut writer: W, value: &Record) -> std::io::Result<()> {
        debug_assert_eq!(value.0.len(), self.width);
        for v in &value.0 {
            writer.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    }
}

impl npyz::Serialize for Record {
    type TypeWriter = RecordWriter;

    fn writer(dtype: &DType) -> std::result::Result<RecordWriter, npyz::DTypeError> {
        match dtype {
            DType::Record(fields) if fields.iter().all(|f| f.dtype == float64()) => {
                Ok(RecordWriter {
                    width: fields.len(),
                })
            }
            _ => Err(npyz::DTypeError::custom(
                "an imukit table is a structured array of float64 fields",
            )),
        }
    }
}

/// A `.npy` table being written record by record.
pub struct NpySink {
    writer: NpyWriter<Record, BufWriter<OutputFile>>,
    record: Record,
    path: PathBuf,
}

impl std::fmt::Debug for NpySink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NpySink")
            .field("path", &self.path)
            .field("columns", &self.record.0.len())
            .finish_non_exhaustive()
    }
}

impl NpySink {
    /// A sink writing `columns` into `file` (at `path`; a handle of its own on the same open
    /// file, so the caller keeps its own to sync and rename).
    ///
    /// # Errors
    /// The file system's refusal, naming the file.
    pub fn create(file: &File, path: &Path, columns: &[String]) -> Result<Self> {
        let io = |source| Error::Io {
            path: path.into(),
            source,
        };
        let dtype = DType::Record(
            columns
                .iter()
                .map(|name| npyz::Field {
                    name: name.clone(),
                    dtype: float64(),
                })
                .collect(),
        );
        // The header this table gets, made alone first: one NumPy (and imukit) would refuse to
        // read is not written.
        let mut alone = std::io::Cursor::new(Vec::new());
        npyz::WriteOptions::<Record>::new()
            .dtype(dtype.clone())
            .writer(&mut alone)
            .begin_1d()
            .and_then(|w| w.finish())
            .map_err(io)?;
        if check_header_length(path, &mut alone.get_ref().as_slice()).is_err() {
            return Err(format_error(
                path,
                format!(
                    "{} columns make a header of {} bytes, more than NumPy reads \
                     ({MAX_HEADER_BYTES}): write this table as .parquet, .npz or .csv",
                    columns.len(),
                    alone.get_ref().len()
                ),
            ));
        }
        let writer = npyz::WriteOptions::new()
            .dtype(dtype)
            .writer(BufWriter::with_capacity(
                WRITE_BLOCK,
                OutputFile::new(file.try_clone().map_err(io)?),
            ))
            .begin_1d()
            .map_err(io)?;
        Ok(Self {
            writer,
            record: Record(vec![0.0; columns.len()]),
            path: path.into(),
        })
    }

    /// Appends row-major `data` (rows of the table's width).
    ///
    /// # Errors
    /// The file system's refusal, naming the file.
    pub fn write(&mut self, data: &[f64]) -> Result<()> {
        let width = self.record.0.len().max(1);
        for row in data.chunks_exact(width) {
            self.record.0.copy_from_slice(row);
            self.writer.push(&self.record).map_err(|source| Error::Io {
                path: self.path.clone(),
                source,
            })?;
        }
        Ok(())
    }

    /// Writes the number of rows into the header and flushes.
    ///
    /// # Errors
    /// The file system's refusal, naming the file.
    pub fn finish(self) -> Result<()> {
        let path = self.path;
        self.writer
            .finish()
            .map_err(|source| Error::Io { path, source })
    }
}

/// A `.npy` table read record by record (memory does not grow with the file).
#[derive(Debug)]
pub struct NpyRows {
    path: PathBuf,
    reader: BufReader<File>,
    rows: u64,
    row: usize,
    record: Vec<u8>,
}

/// The header of the `.npy` file at `path`, checked to be an imukit table: its column names
/// and the reader positioned at the first record.
fn open(path: &Path) -> Result<(Vec<String>, u64, BufReader<File>)> {
    let mut reader = BufReader::new(File::open(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?);
    check_header_length(path, &mut reader)?;
    let header = NpyHeader::from_reader(&mut reader).map_err(|e| format_error(path, e))?;
    let names = match header.dtype() {
        DType::Record(fields) => {
            if let Some(f) = fields.iter().find(|f| f.dtype != float64()) {
                return Err(format_error(
                    path,
                    format!(
                        "field {} is {}, not little-endian float64 (imukit's tables are numbers)",
                        f.name,
                        f.dtype.descr()
                    ),
                ));
            }
            fields.into_iter().map(|f| f.name).collect::<Vec<_>>()
        }
        other => {
            return Err(format_error(
                path,
                format!(
                    "holds an array of {} with shape {:?}, not a table: imukit's .npy tables are \
                     structured arrays with a float64 field per column (their names are the \
                     columns')",
                    other.descr(),
                    header.shape()
                ),
            ));
        }
    };
    if header.shape().len() != 1 {
        return Err(format_error(
            path,
            format!(
                "shape {:?}: a table is one-dimensional (a record per row)",
                header.shape()
            ),
        ));
    }
    if names.is_empty() {
        return Err(format_error(path, "no fields (columns)"));
    }
    let mut seen = std::collections::HashSet::new();
    if let Some(twice) = names.iter().find(|n| !seen.insert(n.as_str())) {
        return Err(format_error(path, format!("field {twice} appears twice")));
    }
    // The records the header gives must be what the file holds after it.
    let rows = header.shape()[0];
    let io = |source| Error::Io {
        path: path.into(),
        source,
    };
    let start = reader.stream_position().map_err(io)?;
    let held = reader
        .get_ref()
        .metadata()
        .map_err(io)?
        .len()
        .saturating_sub(start);
    let record = 8 * names.len() as u64;
    if rows.checked_mul(record) != Some(held) {
        return Err(format_error(
            path,
            format!(
                "its header gives {rows} rows of {} float64 fields, but {held} bytes follow it \
                 ({} whole rows){}",
                names.len(),
                held / record,
                if held < rows.saturating_mul(record) {
                    ": truncated"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok((names, rows, reader))
}

/// Refuses a header longer than NumPy reads (before `npyz` allocates room for it): the magic
/// string, the version, then the header's length (2 bytes in version 1, 4 after).
pub(crate) fn check_header_length(path: &Path, reader: &mut impl std::io::BufRead) -> Result<()> {
    let start = reader.fill_buf().map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let length = match start {
        [0x93, b'N', b'U', b'M', b'P', b'Y', 1, _, a, b, ..] => {
            usize::from(u16::from_le_bytes([*a, *b]))
        }
        [0x93, b'N', b'U', b'M', b'P', b'Y', 2 | 3, _, a, b, c, d, ..] => {
            u32::from_le_bytes([*a, *b, *c, *d]) as usize
        }
        [0x93, b'N', b'U', b'M', b'P', b'Y', ..] => return Ok(()), // npyz names what is wrong
        _ => {
            return Err(format_error(
                path,
                "not a NumPy .npy file (no \\x93NUMPY at its start)",
            ));
        }
    };
    if length > MAX_HEADER_BYTES {
        return Err(format_error(
            path,
            format!("header of {length} bytes (NumPy reads at most {MAX_HEADER_BYTES})"),
        ));
    }
    Ok(())
}

/// The column names of a `.npy` table.
///
/// # Errors
/// An unreadable file; one that is not a structured array of float64 fields.
pub fn column_names(path: &Path) -> Result<Vec<String>> {
    Ok(open(path)?.0)
}

impl NpyRows {
    /// Opens `path`: its column names and the rows.
    ///
    /// # Errors
    /// As [`column_names`].
    pub fn open(path: &Path) -> Result<(Vec<String>, Self)> {
        let (names, rows, reader) = open(path)?;
        let width = names.len();
        Ok((
            names,
            Self {
                path: path.into(),
                reader,
                rows,
                row: 0,
                record: vec![0; 8 * width],
            },
        ))
    }

    /// The next row's columns `wanted` (indices in the file, with their names) into `out`, and
    /// its 1-based row number; `None` after the header's number of rows.
    ///
    /// # Errors
    /// A file shorter than its header says; a value that is not finite (row and column named).
    pub fn next_row(
        &mut self,
        wanted: &[(usize, String)],
        out: &mut [f64],
    ) -> Result<Option<usize>> {
        if self.row as u64 >= self.rows {
            return Ok(None);
        }
        self.row += 1;
        if let Err(e) = self.reader.read_exact(&mut self.record) {
            return Err(if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format_error(
                    &self.path,
                    format!(
                        "the file ends in row {} of the {} its header gives (truncated)",
                        self.row, self.rows
                    ),
                )
            } else {
                Error::Io {
                    path: self.path.clone(),
                    source: e,
                }
            });
        }
        for ((k, name), slot) in wanted.iter().zip(out.iter_mut()) {
            let bytes: [u8; 8] = self.record[8 * k..8 * k + 8]
                .try_into()
                .expect("eight bytes a field");
            let v = f64::from_le_bytes(bytes);
            if !v.is_finite() {
                return Err(Error::CsvValue {
                    file: self.path.clone(),
                    row: self.row,
                    column: name.clone(),
                    message: format!("{v} is not a finite number"),
                });
            }
            *slot = v;
        }
        Ok(Some(self.row))
    }
}
