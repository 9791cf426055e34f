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
    /// A figure or animation could not be made (a refused option named by its flag: see the
    /// `From` conversion).
    #[error(transparent)]
    Plot(PlotError),
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

impl From<PlotError> for CliError {
    /// The figure's error, a refused option named by the flag that sets it.
    fn from(e: PlotError) -> Self {
        match e {
            PlotError::Option { option, message } => Self::Plot(PlotError::Invalid {
                field: option.flag().into(),
                message,
            }),
            PlotError::Data(e) => Self::from(e),
            other => Self::Plot(other),
        }
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
            assert_eq!(named(imukit::error::refused(option, "m")).to_string(), flag);
        }
        let key = imukit::Error::Invalid {
            field: "imu.gyroscope.NoiseDensity".into(),
            message: "m".into(),
        };
        assert_eq!(named(key).to_string(), "imu.gyroscope.NoiseDensity");
    }

    /// Every long flag of every command (aliases included).
    fn flags() -> std::collections::BTreeSet<String> {
        fn walk(c: &clap::Command, out: &mut std::collections::BTreeSet<String>) {
            for a in c.get_arguments() {
                out.extend(
                    a.get_long_and_visible_aliases()
                        .into_iter()
                        .flatten()
                        .map(|l| format!("--{l}")),
                );
            }
            for s in c.get_subcommands() {
                walk(s, out);
            }
        }
        let mut out = std::collections::BTreeSet::new();
        walk(
            &<crate::cli::Cli as clap::CommandFactory>::command(),
            &mut out,
        );
        out
    }

    #[test]
    fn every_typed_option_is_named_by_a_flag_the_command_line_has() {
        let flags = flags();
        for option in RequestOption::ALL {
            assert!(
                flags.contains(option.flag()),
                "{option:?}: {}",
                option.flag()
            );
        }
        for option in imu_plot::FigureOption::ALL {
            assert!(
                flags.contains(option.flag()),
                "{option:?}: {}",
                option.flag()
            );
        }
        // A flag not there is noticed.
        assert!(!flags.contains("--no-such-flag"));
    }

    #[test]
    fn a_refused_figure_option_is_named_by_its_flag() {
        let e = CliError::from(imu_plot::PlotError::Option {
            option: imu_plot::FigureOption::Body,
            message: "m".into(),
        });
        assert_eq!(e.to_string(), "--body-m: m");
        assert_eq!(e.exit_code(), 65);
    }
}
