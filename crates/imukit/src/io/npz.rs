//! Tables as NumPy `.npz` archives (the `zip` crate for the archive, `npyz` for each member's
//! header): one member per column, `<column>.npy`, a one-dimensional float64 array — what
//! `numpy.savez(path, **columns)` writes, so `np.load("imu.npz")["accel_x_m_s2"]` is a column
//! and `pd.DataFrame(dict(np.load("imu.npz")))` the table. Members are stored, not compressed
//! (as `numpy.savez` does); `numpy.savez_compressed` archives (deflate) are read too.
//!
//! Rows arrive a chunk at a time and members are written a column at a time, so the writer
//! keeps a block of rows in memory and moves full blocks, column after column, to an unnamed
//! temporary file beside the output (deleted by the system however the command ends); when the
//! table ends each column is copied from there into its member. Memory stays flat however long
//! the table. Reading loads the whole table (as `numpy.load` does), each member's size checked
//! against the archive before anything is allocated.
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use npyz::{NpyHeader, WriterBuilder};
use zip::CompressionMethod;
use zip::write::SimpleFileOptions;

use crate::error::{Error, Result};
use crate::io::npy::{MAX_HEADER_BYTES, float64};
use crate::io::output::OutputFile;
use crate::io::table::Table;

/// Bytes of rows a writer keeps in memory before moving them to its temporary file.
const BLOCK_BYTES: usize = 8 << 20;

/// The largest factor by which deflate expands data (1032:1): a member declaring more is
/// refused before it is read.
const MAX_DEFLATE_RATIO: u64 = 1032;

fn format_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::CsvFormat {
        file: path.into(),
        message: format!(".npz: {e}"),
    }
}

/// A `.npz` table being written: rows buffered a block at a time, full blocks moved to a
/// temporary file column by column, the archive made when the table ends.
#[derive(Debug)]
pub struct NpzSink {
    path: PathBuf,
    columns: Vec<String>,
    /// The block being filled, column by column.
    block: Vec<Vec<f64>>,
    block_rows: usize,
    /// The moved blocks: each block's rows, its columns one after another.
    spill: BufWriter<File>,
    blocks: Vec<usize>,
}

impl NpzSink {
    /// A sink for `columns` of the archive at `path` (its temporary file made in the same
    /// folder).
    ///
    /// # Errors
    /// The file system's refusal, naming the file.
    pub fn create(path: &Path, columns: &[String]) -> Result<Self> {
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let spill = tempfile::tempfile_in(&folder).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let block_rows = (BLOCK_BYTES / (8 * columns.len().max(1))).max(1);
        Ok(Self {
            path: path.into(),
            columns: columns.to_vec(),
            block: vec![Vec::with_capacity(block_rows); columns.len()],
            block_rows,
            spill: BufWriter::new(spill),
            blocks: Vec::new(),
        })
    }

    fn io(&self, source: std::io::Error) -> Error {
        Error::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Appends row-major `data` (rows of the table's width).
    ///
    /// # Errors
    /// The file system's refusal, naming the file.
    pub fn write(&mut self, data: &[f64]) -> Result<()> {
        let width = self.columns.len().max(1);
        for row in data.chunks_exact(width) {
            for (c, v) in self.block.iter_mut().zip(row) {
                c.push(*v);
            }
            if self
                .block
                .first()
                .is_some_and(|c| c.len() >= self.block_rows)
            {
                self.move_block()?;
            }
        }
        Ok(())
    }

    fn move_block(&mut self) -> Result<()> {
        let rows = self.block.first().map_or(0, Vec::len);
        if rows == 0 {
            return Ok(());
        }
        let mut bytes = Vec::with_capacity(8 * rows);
        for c in &mut self.block {
            bytes.clear();
            bytes.extend(c.iter().flat_map(|v| v.to_le_bytes()));
            c.clear();
            if let Err(e) = self.spill.write_all(&bytes) {
                return Err(self.io(e));
            }
        }
        self.blocks.push(rows);
        Ok(())
    }

    /// Writes the archive into `out`: a member per column, each copied block by block from
    /// the temporary file.
    ///
    /// # Errors
    /// The file system's or the archive writer's refusal, naming the file.
    pub fn finish(mut self, out: BufWriter<OutputFile>) -> Result<BufWriter<OutputFile>> {
        self.move_block()?;
        let rows: usize = self.blocks.iter().sum();
        let mut spill = self.spill.into_inner().map_err(|e| Error::Io {
            path: self.path.clone(),
            source: e.into_error(),
        })?;
        let path = self.path;
        let io = |source| Error::Io {
            path: path.clone(),
            source,
        };
        let zip_error = |e: zip::result::ZipError| format_error(&path, e);
        let member_bytes = 8 * rows as u64 + MAX_HEADER_BYTES as u64;
        let options = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Stored)
            .large_file(member_bytes >= u64::from(u32::MAX));
        let mut zip = zip::ZipWriter::new(out);
        let mut buffer = Vec::new();
        for (k, name) in self.columns.iter().enumerate() {
            zip.start_file(format!("{name}.npy"), options)
                .map_err(zip_error)?;
            npyz::WriteOptions::new_header_only()
                .dtype(float64())
                .shape(&[rows as u64])
                .writer(&mut zip)
                .write_header_only()
                .map_err(io)?;
            // Column k of each block sits after the block's first k columns.
            let mut block_start = 0u64;
            for &n in &self.blocks {
                let offset = block_start + 8 * (k * n) as u64;
                buffer.resize(8 * n, 0);
                spill.seek(SeekFrom::Start(offset)).map_err(io)?;
                spill.read_exact(&mut buffer).map_err(io)?;
                zip.write_all(&buffer).map_err(io)?;
                block_start += 8 * (self.columns.len() * n) as u64;
            }
        }
        zip.finish().map_err(zip_error)
    }
}

/// Every column of a `.npz` archive as a table, the members' order the columns' order.
///
/// # Errors
/// An unreadable archive; a member that is not a one-dimensional float64 array, or that
/// declares more than the archive can hold; columns of different lengths; no rows; a value that
/// is not finite (row and column named).
pub fn read_table(path: &Path) -> Result<Table> {
    let file = File::open(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let mut archive =
        zip::ZipArchive::new(BufReader::new(file)).map_err(|e| format_error(path, e))?;
    let mut names = Vec::with_capacity(archive.len());
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(archive.len());
    for i in 0..archive.len() {
        let mut member = archive.by_index(i).map_err(|e| format_error(path, e))?;
        let member_name = member
            .name()
            .map_err(|e| format_error(path, e))?
            .into_owned();
        let Some(name) = member_name.strip_suffix(".npy") else {
            return Err(format_error(
                path,
                format!("member {member_name} is not an .npy array"),
            ));
        };
        let bad = |what: String| format_error(path, format!("member {member_name}: {what}"));
        let declared = member.size();
        let limit = match member.compression() {
            CompressionMethod::Stored => member.compressed_size(),
            _ => member.compressed_size().saturating_mul(MAX_DEFLATE_RATIO),
        };
        if declared > limit {
            return Err(bad(format!(
                "declares {declared} bytes from {} stored (not a valid archive)",
                member.compressed_size()
            )));
        }
        let mut reader = BufReader::new((&mut member).take(declared));
        crate::io::npy::check_header_length(path, &mut reader)?;
        let header = NpyHeader::from_reader(&mut reader).map_err(|e| bad(e.to_string()))?;
        if header.dtype() != float64() || header.shape().len() != 1 {
            return Err(bad(format!(
                "an array of {} with shape {:?}; a column is a one-dimensional float64 array",
                header.dtype().descr(),
                header.shape()
            )));
        }
        let n = header.shape()[0];
        if n.saturating_mul(8) > declared {
            return Err(bad(format!(
                "its header gives {n} values, more than its {declared} bytes hold"
            )));
        }
        let mut bytes = vec![0u8; 8 * n as usize];
        reader
            .read_exact(&mut bytes)
            .map_err(|e| bad(format!("ends before its {n} values (truncated: {e})")))?;
        let values: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("eight bytes")))
            .collect();
        if let Some(first) = columns.first()
            && first.len() != values.len()
        {
            return Err(bad(format!(
                "{} values, but column {} has {}: the columns of a table are equally long",
                values.len(),
                names[0],
                first.len()
            )));
        }
        if names.iter().any(|n| n == name) {
            return Err(bad(format!("column {name} appears twice")));
        }
        names.push(name.to_string());
        columns.push(values);
    }
    let rows = columns.first().map_or(0, Vec::len);
    if rows == 0 {
        return Err(format_error(path, "no rows (or no columns)"));
    }
    let names_ref: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut table = Table::new(&names_ref);
    table.data = (0..rows)
        .flat_map(|i| columns.iter().map(move |c| c[i]))
        .collect();
    crate::io::table::check_finite_from(
        &table.columns,
        &table.data,
        &path.display().to_string(),
        1,
    )?;
    Ok(table)
}

/// The column names of a `.npz` archive: its members' names without `.npy` (from the archive's
/// directory; the members themselves are checked when read).
///
/// # Errors
/// An unreadable archive; a member that is not an `.npy` array.
pub fn column_names(path: &Path) -> Result<Vec<String>> {
    let file = File::open(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let archive = zip::ZipArchive::new(BufReader::new(file)).map_err(|e| format_error(path, e))?;
    archive
        .file_names()
        .map(|m| {
            let m = m.map_err(|e| format_error(path, e))?;
            m.strip_suffix(".npy")
                .map(str::to_string)
                .ok_or_else(|| format_error(path, format!("member {m} is not an .npy array")))
        })
        .collect()
}
