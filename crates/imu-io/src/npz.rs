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
use crate::npy::{MAX_HEADER_BYTES, float64};
use crate::table::Table;
use crate::writeback::OutputFile;

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

/// The most an archive's members may expand, all together, once they hold more than
/// [`RATIO_FREE_BYTES`]: float64 measurements deflate by a few times, a constant column by up to
/// deflate's 1032; a whole table a hundred times smaller than its values is a decompression bomb.
pub const MAX_ARCHIVE_RATIO: u64 = 100;

/// Archives up to this size of values (64 MiB) are read whatever their ratio.
pub const RATIO_FREE_BYTES: u64 = 64 << 20;

/// Every column of a `.npz` archive as a table, the members' order the columns' order.
///
/// Before a value is read, the archive's directory is checked: no member named twice, each
/// member's stored size within the file, its declared size within what its compression can
/// give (stored: its stored size; deflate: 1032 times it), the members together within the
/// memory limit of in-memory work ([`crate::memory::max_memory_bytes`]) and, beyond 64
/// MiB, within [`MAX_ARCHIVE_RATIO`] times what they store. Each member's values go straight to
/// their place in the table (one copy in memory), and its CRC-32 is checked when it ends.
///
/// # Errors
/// An unreadable archive; a member that is not a one-dimensional float64 array, that declares
/// more than the archive can hold, holds more or less than its header says, or fails its CRC;
/// a member twice; columns of different lengths; no rows; a table beyond the limits above;
/// a value that is not finite (row and column named).
pub fn read_table(path: &Path) -> Result<Table> {
    let (file, file_bytes) = crate::open_with_length(path)?;
    let mut archive =
        zip::ZipArchive::new(BufReader::new(file)).map_err(|e| format_error(path, e))?;
    if archive.has_duplicate_names() {
        return Err(format_error(
            path,
            "a member appears twice (NumPy refuses such an archive; which one is meant?)",
        ));
    }
    check_sizes(&mut archive, path, file_bytes)?;
    let width = archive.len();
    let mut names: Vec<String> = Vec::with_capacity(width);
    let mut table = Table::new(&[]);
    let mut rows = 0usize;
    for k in 0..width {
        let mut member = archive.by_index(k).map_err(|e| format_error(path, e))?;
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
        let mut reader = BufReader::new(&mut member);
        crate::npy::check_header_length(path, &mut reader)?;
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
        // Within the checked total, so the table's room can be made.
        let n = usize::try_from(n).map_err(|_| bad(format!("{n} values")))?;
        if k == 0 {
            rows = n;
            table.data = vec![0.0; rows * width];
        } else if n != rows {
            return Err(bad(format!(
                "{n} values, but column {} has {rows}: the columns of a table are equally long",
                names[0]
            )));
        }
        read_column(&mut reader, &mut table.data, (k, width), &bad)?;
        // To the member's end: nothing may follow the values, and the end checks the CRC-32.
        let mut rest = [0u8; 64];
        match reader.read(&mut rest) {
            Ok(0) => {}
            Ok(_) => return Err(bad(format!("more bytes than its {rows} values"))),
            Err(e) => return Err(bad(format!("damaged ({e})"))),
        }
        names.push(name.to_string());
    }
    if rows == 0 {
        return Err(format_error(path, "no rows (or no columns)"));
    }
    table.columns = names;
    crate::table::check_finite_from(&table.columns, &table.data, &path.display().to_string(), 1)?;
    Ok(table)
}

/// Refuses an archive whose members declare more than it can hold, more than the memory limit
/// allows, or expand too far (a decompression bomb), before anything is read.
fn check_sizes<R: Read + std::io::Seek>(
    archive: &mut zip::ZipArchive<R>,
    path: &Path,
    file_bytes: u64,
) -> Result<()> {
    let (mut total, mut stored_total) = (0u64, 0u64);
    for i in 0..archive.len() {
        let member = archive.by_index_raw(i).map_err(|e| format_error(path, e))?;
        let name = String::from_utf8_lossy(member.name_raw()).into_owned();
        let (declared, stored) = (member.size(), member.compressed_size());
        let limit = match member.compression() {
            CompressionMethod::Stored => stored,
            _ => stored.saturating_mul(MAX_DEFLATE_RATIO),
        };
        if stored > file_bytes || declared > limit {
            return Err(format_error(
                path,
                format!(
                    "member {name} declares {declared} bytes from {stored} stored in a file of \
                     {file_bytes} (not a valid archive)"
                ),
            ));
        }
        total = total.saturating_add(declared);
        stored_total = stored_total.saturating_add(stored);
    }
    let limit = crate::memory::max_memory_bytes();
    #[allow(clippy::cast_precision_loss)]
    if total as f64 > limit {
        return Err(format_error(
            path,
            format!(
                "its members hold {total} bytes, more than the memory limit of {:.1} GB (a .npz \
                 table is read whole: write a larger one as .parquet or .npy, read row by row, \
                 or raise the limit with IMUKIT_MAX_MEMORY_GB)",
                limit / 1e9
            ),
        ));
    }
    if total > RATIO_FREE_BYTES && total / stored_total.max(1) > MAX_ARCHIVE_RATIO {
        return Err(format_error(
            path,
            format!(
                "its members expand {stored_total} stored bytes into {total}, more than \
                 {MAX_ARCHIVE_RATIO} times: not a table of measurements (a decompression bomb?)"
            ),
        ));
    }
    Ok(())
}

/// Reads column `k` of a table `width` columns wide from `reader` into `data`, a block at a
/// time, each value to its place in its row; `bad` names what went wrong.
fn read_column(
    reader: &mut impl Read,
    data: &mut [f64],
    (k, width): (usize, usize),
    bad: &impl Fn(String) -> Error,
) -> Result<()> {
    let rows = data.len() / width.max(1);
    let mut block = vec![0u8; 8 * 8192];
    let mut row = 0;
    while row < rows {
        let take = (rows - row).min(8192);
        let bytes = &mut block[..8 * take];
        reader
            .read_exact(bytes)
            .map_err(|e| bad(format!("ends before its {rows} values ({e})")))?;
        for (j, b) in bytes.chunks_exact(8).enumerate() {
            let v = f64::from_le_bytes(b.try_into().expect("eight bytes"));
            data[(row + j) * width + k] = v;
        }
        row += take;
    }
    Ok(())
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
