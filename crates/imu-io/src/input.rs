//! A file to read and how to read it: the column map of a vendor's CSV (`--map`, Python's
//! `map_path=`/`map_json=`), the topics and clock of a ROS bag (`--topic`, `--receive-time`) and
//! the part's calibration applied to its readings (`--calibration`).
//!
//! They travel with the path as one argument, [`Input`], to every reader of that file: a job
//! that reads an input twice (its header, then its rows) reads it the same way both times, and
//! nothing is kept between calls, so what one caller (or thread) asks for never changes what
//! another reads. A plain path is an [`Input`] read as it is (`From<&Path>`).
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::calibration::CalibrationFile;
use crate::column_map::ColumnMap;

/// Which time a message of a bag is read at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Clock {
    /// Its header's stamp: when the data were taken (the default).
    #[default]
    Header,
    /// When the recorder received it (the bag's log time): for drivers whose header stamps
    /// are missing or wrong.
    Receive,
}

/// What to read from a bag: its topics (all when empty) and at which time.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    /// The topics to choose among (the command line's `--topic`, Python's `topic=`).
    pub topics: Vec<String>,
    /// Whose stamps (`--receive-time`, Python's `receive_time=`).
    pub clock: Clock,
}

/// A file to read, with how to read it.
#[derive(Clone, Debug, Default)]
pub struct Input {
    path: PathBuf,
    map: Option<Arc<ColumnMap>>,
    selection: Selection,
    calibration: Option<Arc<CalibrationFile>>,
}

impl Input {
    /// The file at `path`, read as it is: a CSV file by its header, a bag's topics all offered
    /// at their header stamps.
    #[must_use]
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            ..Self::default()
        }
    }

    /// Read through `map` (a vendor's CSV: which field is which imukit column, in which unit and
    /// axes).
    #[must_use]
    pub fn with_map(mut self, map: ColumnMap) -> Self {
        self.map = Some(Arc::new(map));
        self
    }

    /// Read with the readings corrected by `calibration` (each sensor's three columns, after
    /// any column map).
    #[must_use]
    pub fn with_calibration(mut self, calibration: CalibrationFile) -> Self {
        self.calibration = Some(Arc::new(calibration));
        self
    }

    /// The calibration its readings are corrected by, if any.
    #[must_use]
    pub fn calibration(&self) -> Option<&CalibrationFile> {
        self.calibration.as_deref()
    }

    /// Read with `selection`: a bag's topics to choose among and whose stamps.
    #[must_use]
    pub fn with_selection(mut self, selection: Selection) -> Self {
        self.selection = selection;
        self
    }

    /// The file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The column map it is read through, if any.
    #[must_use]
    pub fn map(&self) -> Option<&ColumnMap> {
        self.map.as_deref()
    }

    /// What to read from it when it is a bag.
    #[must_use]
    pub fn selection(&self) -> &Selection {
        &self.selection
    }
}

/// An input is its path wherever a path is asked for (a message, an output check, a
/// description), as a `PathBuf` is.
impl std::ops::Deref for Input {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for Input {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl From<&Path> for Input {
    fn from(path: &Path) -> Self {
        Self::new(path)
    }
}

impl From<&PathBuf> for Input {
    fn from(path: &PathBuf) -> Self {
        Self::new(path)
    }
}

impl From<PathBuf> for Input {
    fn from(path: PathBuf) -> Self {
        Self::new(path)
    }
}

impl From<&Input> for Input {
    fn from(input: &Input) -> Self {
        input.clone()
    }
}
