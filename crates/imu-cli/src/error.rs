//! The command line's error type: every library, figure and I/O error a command can meet, with
//! the exit code a script can test.
use imu_plot::PlotError;

/// What went wrong, for the user; `Display` says what and where.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Input or I/O errors from the library (a request's option named by its flag: see the
    /// `From` conversion).
    #[error(transparent)]
    Library(imukit::Error),
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

impl From<imukit::Error> for CliError {
    /// The library's error, a refused request option named by the flag that sets it.
    fn from(e: imukit::Error) -> Self {
        Self::Library(e.naming_options(imukit::error::RequestOption::flag))
    }
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

/// The flag that sets a library request field named as a string: the field's name with `-` for
/// `_` (`gravity_m_s2` → `--gravity-m-s2`; Python's keywords are the fields' own names). The
/// options whose flag is spelt otherwise are refused as [`imukit::Error::Request`], which
/// carries its flag.
#[must_use]
pub fn flag(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// A library refusal of a request field, named by its flag.
#[must_use]
pub fn by_flag(e: imukit::Error) -> imukit::Error {
    match e {
        imukit::Error::Invalid { field, message } => imukit::Error::Invalid {
            field: flag(&field),
            message,
        },
        // A refused request option is named by its flag in `CliError`'s conversion.
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

#[cfg(test)]
mod tests {
    use imukit::error::RequestOption;

    use super::CliError;

    #[test]
    fn a_refused_request_option_is_named_by_its_flag_and_a_file_key_is_left() {
        let named = |e: imukit::Error| match CliError::from(e) {
            CliError::Library(imukit::Error::Invalid { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        for (option, flag) in [
            (RequestOption::Threads, "--threads"),
            (RequestOption::UseMagnetometer, "--no-mag"),
            (RequestOption::Initial, "--init"),
            (RequestOption::Align, "--align"),
            (RequestOption::GnssLeverArm, "--gnss-lever-arm-m"),
        ] {
            assert_eq!(named(imukit::error::refused(option, "m")), flag);
        }
        let key = imukit::Error::Invalid {
            field: "imu.gyroscope.NoiseDensity".into(),
            message: "m".into(),
        };
        assert_eq!(named(key), "imu.gyroscope.NoiseDensity");
    }
}
