//! The command line's error type: every library, figure and I/O error a command can meet, with
//! the exit code a script can test.
use imu_plot::PlotError;

/// What went wrong, for the user; `Display` says what and where.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Input or I/O errors from the library.
    #[error(transparent)]
    Library(#[from] imukit::Error),
    /// A figure or animation could not be made.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// Other I/O errors (creating folders, writing text).
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
}

impl CliError {
    /// Exit code: 74 for I/O problems, 65 for bad input data (sysexits.h).
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Library(imukit::Error::Io { .. }) | Self::Io { .. } => 74,
            Self::Plot(p) if p.is_io() => 74,
            Self::Library(_) | Self::Plot(_) => 65,
        }
    }
}

/// The request fields whose flag is not the field's name with `-` for `_`.
const FLAGS: [(&str, &str); 4] = [
    ("initial", "--init"),
    ("nhc_sigma_m_s", "--nhc"),
    ("gate", "--no-gate"),
    ("use_magnetometer", "--no-mag"),
];

/// The flag that sets a library request field: the table `FLAGS`, else the field's name with `-` for
/// `_` (`gravity_m_s2` → `--gravity-m-s2`). Python's keywords are the fields' own names.
#[must_use]
pub fn flag(field: &str) -> String {
    FLAGS.iter().find(|(f, _)| *f == field).map_or_else(
        || format!("--{}", field.replace('_', "-")),
        |(_, flag)| (*flag).to_string(),
    )
}

/// A library refusal of a request field, named by its flag.
#[must_use]
pub fn by_flag(e: imukit::Error) -> imukit::Error {
    match e {
        imukit::Error::Invalid { field, message } => imukit::Error::Invalid {
            field: flag(&field),
            message,
        },
        other => other,
    }
}

/// A figure's refusal of an option, named by its flag.
#[must_use]
pub fn plot_by_flag(e: PlotError) -> PlotError {
    match e {
        PlotError::Invalid { field, message } => PlotError::Invalid {
            field: flag(&field),
            message,
        },
        other => other,
    }
}
