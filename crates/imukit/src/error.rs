//! The one error type of the std layer: every variant says what and where.
use std::path::PathBuf;

use imu_core::KinematicsError;

use crate::motion::expr::ExprError;

/// Why a scenario could not be read or run.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A scenario file (TOML or JSON) that does not parse or has wrong keys or values.
    #[error("{origin}: {message}")]
    Scenario {
        /// The file, or "scenario" for an in-memory one.
        origin: String,
        /// The parser's message (it names the key and, for files, the line).
        message: String,
    },
    /// A scenario key with an invalid value.
    #[error("{field}: {message}")]
    Invalid {
        /// Dotted key, e.g. `trajectory.order`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// An expression that does not parse.
    #[error("{field}: {source}")]
    Expression {
        /// Dotted key of the expression, e.g. `trajectory.position_m[1]`.
        field: String,
        /// The parse error with its column.
        source: ExprError,
    },
    /// A bad value in a CSV file.
    #[error("{}, row {row}, column {column}: {message}", file.display())]
    CsvValue {
        /// The file.
        file: PathBuf,
        /// 1-based line number (the header is row 1).
        row: usize,
        /// Column name.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// A CSV file that is malformed (unequal row lengths, truncated, not UTF-8, empty).
    #[error("{}: {message}", file.display())]
    CsvFormat {
        /// The file.
        file: PathBuf,
        /// What is wrong (with its row where known).
        message: String,
    },
    /// Required CSV columns are absent.
    #[error("{}: missing column(s) {}{hint}", file.display(), missing.join(", "))]
    MissingColumns {
        /// The file.
        file: PathBuf,
        /// Column names not found in the header.
        missing: Vec<String>,
        /// What else would do.
        hint: String,
    },
    /// The kinematics refused the input.
    #[error("{context}: {source}")]
    Kinematics {
        /// Where (file or trajectory), and the time of the sample when known.
        context: String,
        /// The core's error, with its sample index.
        source: KinematicsError,
    },
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> Error {
    Error::Invalid {
        field: field.into(),
        message: message.into(),
    }
}
