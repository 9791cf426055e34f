//! Writing a table to a file in the format its name gives, atomically ([`Table::write`]).
use std::io::Write;
use std::path::Path;

use super::{AtomicFile, write_atomically};
use crate::TableFormat;
use crate::description::Description;
use crate::error::Result;
use crate::table::{Table, check_column_names, check_finite_from};

impl Table {
    /// Writes the table in the format its path's extension names ([`TableFormat::written`]:
    /// Parquet for `.parquet`, NumPy for `.npy` and `.npz`, a bag for `.mcap`, CSV for `.csv`,
    /// `.txt` or no extension), atomically.
    ///
    /// # Errors
    /// A name of another format; a value that is not finite; [`crate::error::Error::Io`] naming the file.
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
        let mut file = AtomicFile::create(path)?;
        file.begin_table(&self.columns, description)?;
        file.write_table_rows(&self.data)?;
        file.commit()
    }

    /// Writes the table as CSV with a header row, atomically (temporary file, then rename),
    /// described by its kind ([`Self::write`]).
    ///
    /// # Errors
    /// [`crate::error::Error::Io`] naming the file.
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
}
