//! Tables as Apache Parquet files (Apache Arrow's `parquet` crate): one float64 column per
//! table column, named as in the CSV contract, Snappy-compressed, rows in row groups of
//! [`ROW_GROUP`]; what made the file (the scenario, the navigation frame, the command) in the
//! file's key-value metadata. Chosen by the output path's extension (`.parquet`), written as
//! every output is: under a temporary name, renamed into place when complete. Read back bit for
//! bit (float64 stays float64), by imukit and by pyarrow, pandas and polars.
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::Arc;

use arrow_array::{Array, ArrayRef, Float64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::basic::{Compression, Encoding};
use parquet::file::metadata::{KeyValue, ParquetMetaData};
use parquet::file::properties::WriterProperties;

use crate::description::Description;
use crate::error::{Error, Result};
use crate::table::Table;
use crate::writeback::OutputFile;

/// Rows per row group (and per write): memory stays flat however long the table.
pub const ROW_GROUP: usize = 65_536;

fn format_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::CsvFormat {
        file: path.into(),
        message: format!("Parquet: {e}"),
    }
}

/// A Parquet table being written row group by row group (the rows buffered column by column
/// until a group is full).
pub struct ParquetSink {
    writer: ArrowWriter<BufWriter<OutputFile>>,
    schema: Arc<Schema>,
    columns: Vec<Vec<f64>>,
    path: std::path::PathBuf,
}

impl std::fmt::Debug for ParquetSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetSink")
            .field("path", &self.path)
            .field("columns", &self.schema.fields().len())
            .finish_non_exhaustive()
    }
}

impl ParquetSink {
    /// A sink writing `columns` into `writer` (the file at `path`), with `metadata` as
    /// key-value pairs.
    ///
    /// # Errors
    /// The Parquet writer's refusal, naming the file.
    pub fn create(
        writer: BufWriter<OutputFile>,
        path: &Path,
        columns: &[String],
        metadata: &[(String, String)],
    ) -> Result<Self> {
        let path = path.to_path_buf();
        // The metadata both in the Arrow schema (pyarrow, pandas and polars show it there) and
        // in the file's key-value pairs.
        let schema = Arc::new(Schema::new_with_metadata(
            columns
                .iter()
                .map(|c| Field::new(c, DataType::Float64, false))
                .collect::<Vec<_>>(),
            metadata
                .iter()
                .cloned()
                .collect::<std::collections::HashMap<String, String>>(),
        ));
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            // Measured values rarely repeat: a dictionary costs a hash per value and is
            // dropped once it fills; plain float64 pages are written at once.
            .set_dictionary_enabled(false)
            // The bytes of each place gathered together (all first bytes, then all second
            // bytes, ...): the exponents and leading digits of float64 measurements repeat, so
            // Snappy finds them. 10⁶ samples of the comparison's formula job: truth 165 → 85
            // MB, readings 67 → 61 MB, written in 0.73 instead of 0.83 s. pyarrow, pandas and
            // polars read it (tests); Snappy is kept as the codec every reader has.
            .set_encoding(parquet::basic::Encoding::BYTE_STREAM_SPLIT)
            .set_key_value_metadata(Some(
                metadata
                    .iter()
                    .map(|(k, v)| KeyValue::new(k.clone(), v.clone()))
                    .collect(),
            ))
            .build();
        let writer = ArrowWriter::try_new(writer, Arc::clone(&schema), Some(props))
            .map_err(|e| format_error(&path, e))?;
        Ok(Self {
            writer,
            columns: vec![Vec::with_capacity(ROW_GROUP); columns.len()],
            schema,
            path,
        })
    }

    /// Appends row-major `data` (rows of the schema's width), flushing full row groups.
    ///
    /// # Errors
    /// The Parquet writer's refusal, naming the file.
    pub fn write(&mut self, data: &[f64]) -> Result<()> {
        let width = self.columns.len().max(1);
        for row in data.chunks_exact(width) {
            for (c, v) in self.columns.iter_mut().zip(row) {
                c.push(*v);
            }
            if self.columns[0].len() >= ROW_GROUP {
                self.flush()?;
            }
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<()> {
        if self.columns.first().is_none_or(Vec::is_empty) {
            return Ok(());
        }
        // Each column's buffer becomes its Arrow array without a copy, and comes back once the
        // group is written, emptied for the next: the system allocator gave each group's fresh
        // buffers back to the system and faulted them in again (29 600 page faults for 10⁶
        // rows of ten columns, against 700 for `.npy`).
        let arrays: Vec<Float64Array> = self
            .columns
            .iter_mut()
            .map(|c| Float64Array::from(std::mem::take(c)))
            .collect();
        let batch = RecordBatch::try_new(
            Arc::clone(&self.schema),
            arrays
                .iter()
                .map(|a| Arc::new(a.clone()) as ArrayRef)
                .collect(),
        )
        .map_err(|e| format_error(&self.path, e))?;
        let written = self
            .writer
            .write(&batch)
            .and_then(|()| self.writer.flush())
            .map_err(|e| format_error(&self.path, e));
        drop(batch);
        for (column, array) in self.columns.iter_mut().zip(arrays) {
            // The writer keeps no reference to the values once they are encoded; were one kept,
            // the column would simply grow a new buffer.
            if let Ok(mut buffer) = array.into_parts().1.into_inner().into_vec::<f64>() {
                buffer.clear();
                *column = buffer;
            }
        }
        written
    }

    /// Writes what is buffered and the footer, and gives the writer back.
    ///
    /// # Errors
    /// The Parquet writer's refusal, naming the file.
    pub fn finish(mut self) -> Result<BufWriter<OutputFile>> {
        self.flush()?;
        self.writer
            .into_inner()
            .map_err(|e| format_error(&self.path, e))
    }
}

/// Writes `table` as a Parquet file at `path` (named `.parquet`) with `description` in its
/// metadata, atomically
/// ([`Table::write`]'s binary path); every value must be
/// finite (refused, naming row and column, before the file is made).
///
/// # Errors
/// A value that is not finite; the writer's or the file system's refusal, naming the file.
pub fn write_table(table: &Table, path: &Path, description: &Description) -> Result<()> {
    table.write_binary(path, description)
}

/// A Parquet file's key-value metadata.
///
/// # Errors
/// An unreadable or malformed file.
pub fn read_metadata(path: &Path) -> Result<Vec<(String, String)>> {
    let builder = builder(path)?;
    Ok(builder
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .map(|kv| {
            kv.iter()
                .map(|k| (k.key.clone(), k.value.clone().unwrap_or_default()))
                .collect()
        })
        .unwrap_or_default())
}

/// A reader of the file at `path`, its metadata checked ([`check_metadata`]); a panic of the
/// Parquet crate on a damaged file is an error naming it ([`contain`]).
fn builder(path: &Path) -> Result<ParquetRecordBatchReaderBuilder<File>> {
    let (file, file_bytes) = crate::open_with_length(path)?;
    contain(path, || {
        let builder =
            ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| format_error(path, e))?;
        check_metadata(path, builder.metadata(), file_bytes)?;
        Ok(builder)
    })
}

/// The encodings imukit's float64 columns may have: plain values, split bytes, and a dictionary
/// (with its indices' run-length encoding) as other writers make them, and the old bit-packed
/// levels some writers still list.
#[allow(deprecated)]
const ENCODINGS: [Encoding; 6] = [
    Encoding::PLAIN,
    Encoding::BYTE_STREAM_SPLIT,
    Encoding::RLE,
    Encoding::RLE_DICTIONARY,
    Encoding::PLAIN_DICTIONARY,
    Encoding::BIT_PACKED,
];

/// Checks a file's metadata before any page is read: every column chunk's offsets and length
/// within the file, counts not negative and within the row group's, a codec this build reads
/// (uncompressed or Snappy), known encodings, and each column named once.
fn check_metadata(path: &Path, metadata: &ParquetMetaData, file_bytes: u64) -> Result<()> {
    let bad = |what: String| format_error(path, format!("damaged metadata: {what}"));
    let schema = metadata.file_metadata().schema_descr();
    let mut seen = std::collections::HashSet::new();
    for c in schema.columns() {
        if !seen.insert(c.name()) {
            return Err(format_error(
                path,
                format!("column {} appears twice", c.name()),
            ));
        }
    }
    for (g, group) in metadata.row_groups().iter().enumerate() {
        let rows = group.num_rows();
        if rows < 0 {
            return Err(bad(format!("row group {g} has {rows} rows")));
        }
        for chunk in group.columns() {
            let name = chunk.column_descr().name();
            let here = |what: String| bad(format!("row group {g}, column {name}: {what}"));
            let start = chunk
                .dictionary_page_offset()
                .unwrap_or_else(|| chunk.data_page_offset());
            let length = chunk.compressed_size();
            let inside = u64::try_from(start).ok().zip(u64::try_from(length).ok());
            if inside.is_none_or(|(s, l)| s.saturating_add(l) > file_bytes)
                || chunk.data_page_offset() < 0
            {
                return Err(here(format!(
                    "{length} bytes from byte {start}, outside the file's {file_bytes}"
                )));
            }
            // A flat column has a value (or a null) in every row.
            let flat = chunk.column_descr().max_rep_level() == 0;
            if chunk.num_values() < 0 || (flat && chunk.num_values() != rows) {
                return Err(here(format!(
                    "{} values in {rows} rows",
                    chunk.num_values()
                )));
            }
            if chunk.uncompressed_size() < 0 {
                return Err(here(format!(
                    "{} bytes uncompressed",
                    chunk.uncompressed_size()
                )));
            }
            if !matches!(
                chunk.compression(),
                Compression::UNCOMPRESSED | Compression::SNAPPY
            ) {
                return Err(here(format!(
                    "compressed with {} (imukit reads uncompressed and Snappy Parquet)",
                    chunk.compression()
                )));
            }
            // Pages stored as they are take the room their values do.
            if chunk.compression() == Compression::UNCOMPRESSED
                && chunk.compressed_size() != chunk.uncompressed_size()
            {
                return Err(here(format!(
                    "said to be uncompressed, but {} bytes hold {} of pages",
                    chunk.compressed_size(),
                    chunk.uncompressed_size()
                )));
            }
            if let Some(e) = chunk.encodings().find(|e| !ENCODINGS.contains(e)) {
                return Err(here(format!("encoding {e} (not one of a float64 column)")));
            }
        }
    }
    Ok(())
}

/// Runs `read` on the file at `path`, a panic inside the Parquet crate (a damaged file it does
/// not refuse cleanly) turned into an error naming the file: the last line behind
/// [`check_metadata`], so that no file can end the process.
fn contain<T>(path: &Path, read: impl FnOnce() -> Result<T>) -> Result<T> {
    crate::contained(read).unwrap_or_else(|message| {
        Err(format_error(
            path,
            format!("damaged file (the Parquet reader failed: {message})"),
        ))
    })
}

/// Every column of a Parquet table: float64 columns without nulls, finite values (a column of
/// another type, a null or a value that is not finite is refused with its column and row).
///
/// # Errors
/// As above; an unreadable or malformed file; a file without rows.
pub fn read_table(path: &Path) -> Result<Table> {
    let builder = builder(path)?;
    let names = float64_names(path, builder.schema())?;
    contain(path, || read_batches(path, builder, names))
}

fn read_batches(
    path: &Path,
    builder: ParquetRecordBatchReaderBuilder<File>,
    names: Vec<String>,
) -> Result<Table> {
    let reader = builder.build().map_err(|e| format_error(path, e))?;
    let names_ref: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut table = Table::new(&names_ref);
    let mut rows_before = 0usize;
    for batch in reader {
        let batch = batch.map_err(|e| format_error(path, e))?;
        let columns: Vec<&Float64Array> = batch
            .columns()
            .iter()
            .map(|c| {
                c.as_any()
                    .downcast_ref::<Float64Array>()
                    .expect("float64 columns, checked in the schema")
            })
            .collect();
        for (name, c) in names.iter().zip(&columns) {
            if let Some(i) = (0..c.len()).find(|&i| c.is_null(i)) {
                return Err(format_error(
                    path,
                    format!(
                        "row {}, column {name}: no value (null)",
                        rows_before + i + 1
                    ),
                ));
            }
        }
        table.data.reserve(batch.num_rows() * names.len());
        for i in 0..batch.num_rows() {
            for c in &columns {
                table.data.push(c.value(i));
            }
        }
        rows_before += batch.num_rows();
    }
    if table.rows() == 0 {
        return Err(format_error(path, "no rows"));
    }
    let width = names.len();
    if let Some(k) = table.data.iter().position(|v| !v.is_finite()) {
        return Err(format_error(
            path,
            format!(
                "row {}, column {}: {} is not a finite number",
                k / width + 1,
                names[k % width],
                table.data[k]
            ),
        ));
    }
    Ok(table)
}

/// The column names of a Parquet table (refused: a column that is not float64).
///
/// # Errors
/// An unreadable or malformed file; a column of another type.
pub fn column_names(path: &Path) -> Result<Vec<String>> {
    let builder = builder(path)?;
    float64_names(path, builder.schema())
}

fn float64_names(path: &Path, schema: &Schema) -> Result<Vec<String>> {
    if let Some(f) = schema
        .fields()
        .iter()
        .find(|f| f.data_type() != &DataType::Float64)
    {
        return Err(format_error(
            path,
            format!(
                "column {} is {}, not float64 (imukit's tables are numbers)",
                f.name(),
                f.data_type()
            ),
        ));
    }
    Ok(schema.fields().iter().map(|f| f.name().clone()).collect())
}

/// A Parquet table read row by row, a row group's batch at a time (memory does not grow with
/// the file).
pub struct ParquetRows {
    path: std::path::PathBuf,
    reader: parquet::arrow::arrow_reader::ParquetRecordBatchReader,
    batch: Vec<Float64Array>,
    next: usize,
    row: usize,
}

impl std::fmt::Debug for ParquetRows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetRows")
            .field("path", &self.path)
            .field("row", &self.row)
            .finish_non_exhaustive()
    }
}

impl ParquetRows {
    /// Opens `path`: its column names and the rows.
    ///
    /// # Errors
    /// As [`column_names`].
    pub fn open(path: &Path) -> Result<(Vec<String>, Self)> {
        let builder = builder(path)?;
        let names = float64_names(path, builder.schema())?;
        let reader = contain(path, || builder.build().map_err(|e| format_error(path, e)))?;
        Ok((
            names,
            Self {
                path: path.into(),
                reader,
                batch: Vec::new(),
                next: 0,
                row: 0,
            },
        ))
    }

    /// The next row's columns `wanted` (indices in the file, with their names) into `out`, and
    /// its 1-based row number; `None` at the end.
    ///
    /// # Errors
    /// A null or a value that is not finite (row and column named), a malformed file.
    pub fn next_row(
        &mut self,
        wanted: &[(usize, String)],
        out: &mut [f64],
    ) -> Result<Option<usize>> {
        while self.batch.first().is_none_or(|c| self.next >= c.len()) {
            let (reader, path) = (&mut self.reader, &self.path);
            let Some(batch) = contain(path, || Ok(reader.next()))? else {
                return Ok(None);
            };
            let batch = batch.map_err(|e| format_error(&self.path, e))?;
            self.batch = batch
                .columns()
                .iter()
                .map(|c| {
                    c.as_any()
                        .downcast_ref::<Float64Array>()
                        .expect("float64 columns, checked in the schema")
                        .clone()
                })
                .collect();
            self.next = 0;
            if self.batch.is_empty() {
                return Ok(None);
            }
        }
        self.row += 1;
        for ((k, name), slot) in wanted.iter().zip(out.iter_mut()) {
            let c = &self.batch[*k];
            let v = if c.is_null(self.next) {
                f64::NAN
            } else {
                c.value(self.next)
            };
            if !v.is_finite() {
                return Err(Error::CsvValue {
                    file: self.path.clone(),
                    row: self.row,
                    column: name.clone(),
                    message: format!("{v} is not a finite number (or no value)"),
                });
            }
            *slot = v;
        }
        self.next += 1;
        Ok(Some(self.row))
    }
}
