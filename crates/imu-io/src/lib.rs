//! # imu-io — imukit's files and formats
//!
//! Everything imukit reads and writes, below the jobs that use it: the table ([`table`]) and
//! every column set and table kind ([`columns`], [`schema`]), the conventions a file names
//! ([`conventions`]), what a table holds, written into it ([`description`]); the formats, each
//! chosen by its path's extension ([`TableFormat`]): CSV, the EuRoC/TUM-VI ASL layout read by its
//! header ([`asl`]), a vendor's CSV through a column map ([`column_map`]), Parquet
//! ([`parquet`]), NumPy `.npy` and `.npz` ([`npy`], [`npz`]), the topics of a ROS bag ([`bag`]),
//! NMEA logs ([`nmea`]); a file to read with how to read it ([`Input`]: its column map, a bag's
//! topics and clock); outputs that leave no partial file ([`output`]); the time-checked row
//! reader of IMU files ([`rows`]); the part files: parameter files ([`params`]), data sheets
//! ([`datasheet`]), Kalibr's ([`kalibr`]), the built-in presets of real parts ([`presets`]),
//! datasheet units ([`units`]); typed values read from a tree of them ([`value_tree`]: a Python
//! dict's way in); the memory an in-memory read may take ([`memory`]); and the error type,
//! [`Error`], that names file, row, column or key.
//!
//! It imports nothing of the jobs (`imukit`), so the arrows between the two point one way.
//!
//! The heavy formats are cargo features, all on by default: `parquet`, `bags` (ROS bags) and
//! `nmea`. An embedder that leaves one out keeps every other format, and a file of the missing
//! one is refused by name.
#![forbid(unsafe_code)]
pub mod choice;
pub mod error;
pub mod sensor;

pub mod asl;
pub mod bag;
pub mod calibration;
pub mod chain;
pub mod column_map;
pub mod columns;
pub mod conventions;
pub mod datasheet;
pub mod described;
pub mod description;
pub mod input;
pub mod kalibr;
pub mod memory;
pub mod nmea;
pub mod npy;
pub mod npz;
pub mod output;
pub mod params;
#[cfg(feature = "parquet")]
pub mod parquet;
#[cfg(not(feature = "parquet"))]
#[path = "parquet_off.rs"]
pub mod parquet;
pub mod part_file;
pub mod plausible;
pub mod presets;
pub mod read;
pub mod rows;
pub mod schema;
pub mod table;
pub mod units;
pub mod value_tree;
pub mod writeback;

pub use error::{Error, Result};
pub use input::Input;
pub use table::Table;

use std::cell::Cell;
use std::path::Path;
use std::sync::Once;

/// Opens the file at `path` to read it, with its length in bytes (what a binary reader checks
/// declared sizes against before it allocates).
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub(crate) fn open_with_length(path: &Path) -> crate::Result<(std::fs::File, u64)> {
    let io = |source| crate::Error::Io {
        path: path.into(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let length = file.metadata().map_err(io)?.len();
    Ok((file, length))
}

thread_local! {
    /// True while this thread runs a reader under [`contained`].
    static CONTAINING: Cell<bool> = const { Cell::new(false) };
}

/// Runs `read`, a panic inside it returned as its message instead of unwinding further, and
/// printed by no panic hook: for third-party readers that may still panic on a damaged file
/// where imukit's own checks did not foresee it. A last line of defence, not a way of reading.
#[cfg_attr(not(any(feature = "parquet", feature = "bags")), allow(dead_code))]
pub(crate) fn contained<T>(read: impl FnOnce() -> T) -> std::result::Result<T, String> {
    static QUIET: Once = Once::new();
    QUIET.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CONTAINING.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = CONTAINING.with(|c| c.replace(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read));
    CONTAINING.with(|c| c.set(was));
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic".to_string())
    })
}

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
    /// An NMEA 0183 log ([`nmea`]): GNSS fixes.
    Nmea,
    /// A ROS bag ([`bag`]): a topic's table. ROS 2's MCAP file, its sqlite3 file (`.db3`) or
    /// a bag's folder (`metadata.yaml` beside its storage files), or a ROS 1 `.bag`.
    Mcap,
}

impl TableFormat {
    /// The format `path` names.
    #[must_use]
    pub fn of(path: &Path) -> Self {
        // A ROS 2 bag's folder: its metadata file and the storage files beside it.
        if path.is_dir() && path.join("metadata.yaml").is_file() {
            return Self::Mcap;
        }
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("parquet") {
            Self::Parquet
        } else if ext.eq_ignore_ascii_case("npy") {
            Self::Npy
        } else if ext.eq_ignore_ascii_case("npz") {
            Self::Npz
        } else if ext.eq_ignore_ascii_case("nmea") {
            Self::Nmea
        } else if ["mcap", "bag", "db3"]
            .iter()
            .any(|e| ext.eq_ignore_ascii_case(e))
        {
            Self::Mcap
        } else {
            Self::Csv
        }
    }

    /// The format a table is written in at `path`: CSV (`.csv`, `.txt`, or no extension: a
    /// device such as `/dev/stdout`), `.parquet`, `.npy`, `.npz`, or a ROS 2 bag as MCAP
    /// (`.mcap`). Any other name is refused before anything is written, rather than given CSV
    /// text under a name that promises another format (`.xlsx`, `.mat`, `.h5`), or MCAP bytes
    /// under a name ROS reads as another storage (`.db3`, `.bag`).
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `field` and the path, with the formats written.
    pub fn written(field: &str, path: &Path) -> crate::Result<Self> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let is = |e: &str| ext.eq_ignore_ascii_case(e);
        let format = Self::of(path);
        if is("db3") || is("bag") {
            return Err(crate::error::invalid(
                field,
                format!(
                    "{}: imukit writes ROS 2 bags as MCAP; name it .mcap (ROS 2 replays it; \
                     `rosbags-convert` makes a ROS 1 .bag of it)",
                    path.display()
                ),
            ));
        }
        let known = matches!(format, Self::Parquet | Self::Npy | Self::Npz | Self::Mcap)
            || ext.is_empty()
            || is("csv")
            || is("txt");
        if !known {
            return Err(crate::error::invalid(
                field,
                format!(
                    "{}: .{ext} is not a table format imukit writes (.csv, .parquet, .npy, .npz, \
                     .mcap)",
                    path.display()
                ),
            ));
        }
        Ok(format)
    }

    /// The number of a table's first row in the file as errors name it: 2 in a CSV file (its
    /// header is row 1), 1 in the binary formats.
    #[must_use]
    pub fn first_row(self) -> usize {
        match self {
            Self::Csv => 2,
            Self::Parquet | Self::Npy | Self::Npz | Self::Mcap | Self::Nmea => 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::contained;

    #[test]
    fn a_panic_in_a_contained_reader_is_its_message_and_the_thread_goes_on() {
        assert_eq!(contained(|| 7), Ok(7));
        let index = 5;
        let caught = contained(|| [1, 2, 3][index]);
        assert_eq!(
            caught,
            Err("index out of bounds: the len is 3 but the index is 5".to_string())
        );
        let text = contained(|| -> u8 { panic!("{} pages", 3) });
        assert_eq!(text, Err("3 pages".to_string()));
        // Outside it, panics are what they were (caught here by the test harness's own means).
        assert!(std::panic::catch_unwind(|| panic!("plain")).is_err());
    }
}
