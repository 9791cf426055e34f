//! Parquet in a build without the `parquet` feature: every reader and writer refuses the file
//! by name, with the same signatures as the real ones (`parquet.rs`).
use std::io::BufWriter;
use std::path::Path;

use crate::description::Description;
use crate::error::{Result, invalid};
use crate::table::Table;
use crate::writeback::OutputFile;

fn refused(path: &Path) -> crate::Error {
    invalid(
        path.display().to_string(),
        "a Parquet file: this build of imu-io has no Parquet (its `parquet` feature is off)",
    )
}

/// A Parquet writer: none can be made in this build.
#[derive(Debug)]
pub enum ParquetSink {}

impl ParquetSink {
    /// Refuses the file.
    ///
    /// # Errors
    /// Always.
    pub fn create(
        _writer: BufWriter<OutputFile>,
        path: &Path,
        _columns: &[String],
        _metadata: &[(String, String)],
    ) -> Result<Self> {
        Err(refused(path))
    }

    /// Never called: no writer exists.
    ///
    /// # Errors
    /// None.
    pub fn write(&mut self, _data: &[f64]) -> Result<()> {
        match *self {}
    }

    /// Never called: no writer exists.
    ///
    /// # Errors
    /// None.
    pub fn finish(self) -> Result<BufWriter<OutputFile>> {
        match self {}
    }
}

/// Refuses the file.
///
/// # Errors
/// Always.
pub fn write_table(_table: &Table, path: &Path, _description: &Description) -> Result<()> {
    Err(refused(path))
}

/// Refuses the file.
///
/// # Errors
/// Always.
pub fn read_metadata(path: &Path) -> Result<Vec<(String, String)>> {
    Err(refused(path))
}

/// Refuses the file.
///
/// # Errors
/// Always.
pub fn read_table(path: &Path) -> Result<Table> {
    Err(refused(path))
}

/// Refuses the file.
///
/// # Errors
/// Always.
pub fn column_names(path: &Path) -> Result<Vec<String>> {
    Err(refused(path))
}

/// A Parquet file's rows: none can be opened in this build.
#[derive(Debug)]
pub enum ParquetRows {}

impl ParquetRows {
    /// Refuses the file.
    ///
    /// # Errors
    /// Always.
    pub fn open(path: &Path) -> Result<(Vec<String>, Self)> {
        Err(refused(path))
    }

    /// Never called: no reader exists.
    ///
    /// # Errors
    /// None.
    pub fn next_row(
        &mut self,
        _wanted: &[(usize, String)],
        _out: &mut [f64],
    ) -> Result<Option<usize>> {
        match *self {}
    }
}
