//! Files in and out: tables and CSV ([`table`]), tables as Parquet ([`parquet`]) and as NumPy
//! `.npy` and `.npz` ([`npy`], [`npz`]), each chosen by its path's extension ([`TableFormat`]), parameter
//! files ([`params`]), the built-in
//! presets of real parts ([`presets`]), datasheet units ([`units`]), the time-checked row
//! reader of IMU files ([`rows`]) and typed values read from a tree of them ([`value_tree`]:
//! a Python dict's way in).
pub mod npy;
pub mod npz;
pub mod output;
pub mod params;
pub mod parquet;
pub mod presets;
pub mod rows;
pub mod table;
pub mod units;
pub mod value_tree;

use std::path::Path;

/// The format of a table file, by its path's extension (any case): `.parquet`, `.npy`, `.npz`,
/// else CSV.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFormat {
    /// Comma-separated values with a header row (the default).
    Csv,
    /// Apache Parquet ([`parquet`]).
    Parquet,
    /// A NumPy structured array ([`npy`]).
    Npy,
    /// A NumPy archive of one array per column ([`npz`]).
    Npz,
}

impl TableFormat {
    /// The format `path` names.
    #[must_use]
    pub fn of(path: &Path) -> Self {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("parquet") {
            Self::Parquet
        } else if ext.eq_ignore_ascii_case("npy") {
            Self::Npy
        } else if ext.eq_ignore_ascii_case("npz") {
            Self::Npz
        } else {
            Self::Csv
        }
    }

    /// The number of a table's first row in the file as errors name it: 2 in a CSV file (its
    /// header is row 1), 1 in the binary formats.
    #[must_use]
    pub fn first_row(self) -> usize {
        match self {
            Self::Csv => 2,
            Self::Parquet | Self::Npy | Self::Npz => 1,
        }
    }
}
