//! The one error type of the std layer: every variant says what and where.
use std::path::PathBuf;

use imu_core::KinematicsError;
use imu_core::allan::AllanError;
use imu_core::fusion::EskfError;
use imu_core::fusion::align::AlignError;
use imu_core::orientation::OrientError;
use imu_core::sensor::{ImuParamError, ParamError};
use imu_core::strapdown::StrapdownError;
use imu_core::strapdown::planar::PlanarError;

/// An option of a job's request, as the library names it in a refusal ([`Error::Request`]):
/// one name per option, which the front ends turn into their own without matching strings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RequestOption {
    /// The sample rate a file is written for.
    RateHz,
    /// The threads a run may use.
    Threads,
    /// Whether an orientation filter uses the file's magnetometer.
    UseMagnetometer,
    /// Whether a run is smoothed after the fact.
    Smooth,
    /// The Earth a job navigates on.
    Earth,
    /// The filter's initial state (a truth row).
    Initial,
    /// The one-sigma of the vehicle constraints.
    NhcSigma,
    /// The rest at the start of a run.
    RestS,
    /// How the filter finds its initial attitude (an alignment).
    Align,
    /// The interval between the filter's covariance steps.
    CovarianceInterval,
    /// A receiver's horizontal position one-sigma.
    GnssHorizontalAccuracy,
    /// A receiver's vertical position one-sigma.
    GnssVerticalAccuracy,
    /// A receiver's velocity one-sigma.
    GnssVelocityAccuracy,
    /// A receiver's position-error decay factor (MATLAB's).
    GnssDecayFactor,
    /// A receiver's position-error correlation time.
    GnssCorrelationTime,
    /// A receiver's latency.
    GnssLatency,
    /// The antenna's lever arm.
    GnssLeverArm,
    /// The navigation frame (`ned`, `enu`).
    NavFrame,
    /// The sign convention of the accelerometer readings.
    AccelSign,
    /// The constant gravity's magnitude.
    Gravity,
    /// The gravity model on the WGS-84 Earth.
    EarthGravity,
    /// The vertical channel on the WGS-84 Earth.
    Vertical,
    /// The time constant of the baro-damped vertical channel.
    BaroTimeConstant,
    /// The integration substeps per sample.
    Substeps,
    /// Barometer readings beside the IMU's.
    Barometer,
    /// The starting position.
    Position0,
    /// The starting velocity.
    Velocity0,
    /// The starting attitude as a quaternion (on the command line, from the `--init` file).
    Quaternion0,
    /// The starting attitude as Euler angles.
    Euler0,
    /// The starting heading of planar dead reckoning.
    Heading0,
    /// The starting latitude.
    Lat0,
    /// The starting longitude.
    Lon0,
    /// The starting height.
    Height0,
    /// The start of the time window, after the first sample.
    StartS,
    /// The end of the time window, after the first sample.
    EndS,
    /// The IMU's topic in a bag written.
    BagTopic,
    /// The frame id of the IMU's messages in a bag written.
    BagFrameId,
    /// The stamp of time 0 in a bag written.
    BagStart,
    /// The user-equivalent range error that scales a fix's HDOP.
    GnssUere,
    /// The IMU part the filter is tuned for (a preset or a parameter file).
    Imu,
    /// The scenario that made the data.
    Scenario,
    /// The length of a spectrum's segments.
    SegmentS,
}

impl RequestOption {
    /// Every option.
    pub const ALL: [Self; 42] = [
        Self::RateHz,
        Self::Threads,
        Self::UseMagnetometer,
        Self::Smooth,
        Self::Earth,
        Self::Initial,
        Self::NhcSigma,
        Self::RestS,
        Self::Align,
        Self::CovarianceInterval,
        Self::GnssHorizontalAccuracy,
        Self::GnssVerticalAccuracy,
        Self::GnssVelocityAccuracy,
        Self::GnssDecayFactor,
        Self::GnssCorrelationTime,
        Self::GnssLatency,
        Self::GnssLeverArm,
        Self::NavFrame,
        Self::AccelSign,
        Self::Gravity,
        Self::EarthGravity,
        Self::Vertical,
        Self::BaroTimeConstant,
        Self::Substeps,
        Self::Barometer,
        Self::Position0,
        Self::Velocity0,
        Self::Quaternion0,
        Self::Euler0,
        Self::Heading0,
        Self::Lat0,
        Self::Lon0,
        Self::Height0,
        Self::StartS,
        Self::EndS,
        Self::BagTopic,
        Self::BagFrameId,
        Self::BagStart,
        Self::GnssUere,
        Self::Imu,
        Self::Scenario,
        Self::SegmentS,
    ];

    /// The option's name in the library's requests and in Python's keywords.
    #[must_use]
    pub const fn key(self) -> &'static str {
        match self {
            Self::RateHz => "rate_hz",
            Self::Threads => "threads",
            Self::UseMagnetometer => "use_magnetometer",
            Self::Smooth => "smooth",
            Self::Earth => "earth",
            Self::Initial => "initial",
            Self::NhcSigma => "nhc_sigma_m_s",
            Self::RestS => "rest_s",
            Self::Align => "align",
            Self::CovarianceInterval => "covariance_interval_s",
            Self::GnssHorizontalAccuracy => "gnss_horizontal_accuracy_m",
            Self::GnssVerticalAccuracy => "gnss_vertical_accuracy_m",
            Self::GnssVelocityAccuracy => "gnss_velocity_accuracy_m_s",
            Self::GnssDecayFactor => "gnss_decay_factor",
            Self::GnssCorrelationTime => "gnss_correlation_time_s",
            Self::GnssLatency => "gnss_latency_s",
            Self::GnssLeverArm => "gnss_lever_arm_m",
            Self::NavFrame => "nav_frame",
            Self::AccelSign => "accel_sign",
            Self::Gravity => "gravity_m_s2",
            Self::EarthGravity => "earth_gravity",
            Self::Vertical => "vertical",
            Self::BaroTimeConstant => "baro_time_constant_s",
            Self::Substeps => "substeps",
            Self::Barometer => "baro",
            Self::Position0 => "position0_m",
            Self::Velocity0 => "velocity0_m_s",
            Self::Quaternion0 => "quaternion0",
            Self::Euler0 => "euler0_rad",
            Self::Heading0 => "heading0_rad",
            Self::Lat0 => "lat0_deg",
            Self::Lon0 => "lon0_deg",
            Self::Height0 => "height0_m",
            Self::StartS => "start_s",
            Self::EndS => "end_s",
            Self::BagTopic => "bag_topic",
            Self::BagFrameId => "bag_frame_id",
            Self::BagStart => "bag_start_s",
            Self::GnssUere => "gnss_uere_m",
            Self::Imu => "imu",
            Self::Scenario => "scenario",
            Self::SegmentS => "segment_s",
        }
    }

    /// The command line's flag that sets the option.
    #[must_use]
    pub const fn flag(self) -> &'static str {
        match self {
            Self::RateHz => "--rate-hz",
            Self::Threads => "--threads",
            Self::UseMagnetometer => "--no-mag",
            Self::Smooth => "--smooth",
            Self::Earth => "--earth",
            Self::Initial => "--init",
            Self::NhcSigma => "--nhc",
            Self::RestS => "--rest-s",
            Self::Align => "--align",
            Self::CovarianceInterval => "--covariance-interval-s",
            Self::GnssHorizontalAccuracy => "--gnss-horizontal-accuracy-m",
            Self::GnssVerticalAccuracy => "--gnss-vertical-accuracy-m",
            Self::GnssVelocityAccuracy => "--gnss-velocity-accuracy-m-s",
            Self::GnssDecayFactor => "--gnss-decay-factor",
            Self::GnssCorrelationTime => "--gnss-correlation-time-s",
            Self::GnssLatency => "--gnss-latency-s",
            Self::GnssLeverArm => "--gnss-lever-arm-m",
            Self::NavFrame => "--nav-frame",
            Self::AccelSign => "--accel-sign",
            Self::Gravity => "--gravity-m-s2",
            Self::EarthGravity => "--earth-gravity",
            Self::Vertical => "--vertical",
            Self::BaroTimeConstant => "--baro-time-constant-s",
            Self::Substeps => "--substeps",
            Self::Barometer => "--baro",
            Self::Position0 => "--position0-m",
            Self::Velocity0 => "--velocity0-m-s",
            Self::Quaternion0 => "--init",
            Self::Euler0 => "--euler0-rad",
            Self::Heading0 => "--heading0-rad",
            Self::Lat0 => "--lat0-deg",
            Self::Lon0 => "--lon0-deg",
            Self::Height0 => "--height0-m",
            Self::StartS => "--start-s",
            Self::EndS => "--end-s",
            Self::BagTopic => "--bag-topic",
            Self::BagFrameId => "--bag-frame-id",
            Self::BagStart => "--bag-start-s",
            Self::GnssUere => "--gnss-uere-m",
            Self::Imu => "--imu",
            Self::Scenario => "--scenario",
            Self::SegmentS => "--segment-s",
        }
    }
}

/// A refusal of the request option `option`.
pub fn refused(option: RequestOption, message: impl Into<String>) -> Error {
    Error::Request {
        option,
        message: message.into(),
    }
}

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
    /// A scenario (a Python dict, a JSON file) whose value at `field` does not fit its key.
    #[error("{origin}: {field}: {message}")]
    ScenarioKey {
        /// What the scenario is, e.g. "scenario dict".
        origin: String,
        /// Dotted key path, e.g. `imu.seed`; empty for the whole scenario.
        field: String,
        /// What does not fit.
        message: String,
    },
    /// A request's option refused, named by its typed name ([`RequestOption`]): each front end
    /// spells it its own way (Python's keyword, the command line's flag).
    #[error("{}: {message}", option.key())]
    Request {
        /// The option.
        option: RequestOption,
        /// What is wrong.
        message: String,
    },
    /// A scenario key with an invalid value.
    #[error("{field}: {message}")]
    Invalid {
        /// Dotted key, e.g. `trajectory.order`, or the input by what it holds.
        field: Subject,
        /// What is wrong.
        message: String,
    },
    /// An option given a name it does not take (see [`crate::choice::Choice`]).
    #[error("{field}: unknown {what} \"{value}\" ({})", choices.join(", "))]
    UnknownChoice {
        /// The request field, e.g. `nav_frame`.
        field: String,
        /// What is chosen, e.g. "navigation frame".
        what: &'static str,
        /// The name given.
        value: String,
        /// The names it takes.
        choices: Vec<&'static str>,
    },
    /// The Kalman filter refused its settings or a sample (not a divergence: see
    /// [`Error::Diverged`]).
    #[error("{context}: {}{source}", row.map(|r| format!("row {r}: ")).unwrap_or_default())]
    Filter {
        /// The input or setting, e.g. `IMU data`, `sensor_error_sigma`.
        context: Subject,
        /// The 1-based row of the input (the header is row 1), when a sample was refused.
        row: Option<usize>,
        /// The core's error.
        source: EskfError,
    },
    /// An alignment that could not be made: the start `start` (`static`, `level`) asked for by
    /// the request option [`RequestOption::Align`].
    #[error("{}: {}", RequestOption::Align.key(), align_message(start, source))]
    Align {
        /// The alignment asked for.
        start: &'static str,
        /// The core's error.
        source: AlignError,
    },
    /// A Kalman filter that lost its measurements (its covariance no longer positive definite,
    /// or fixes rejected one after another): the estimate is not written.
    #[error("{context}: {message}")]
    Diverged {
        /// The input where it was noticed, e.g. `GNSS data`.
        context: Subject,
        /// What happened.
        message: String,
    },
    /// An expression that does not parse.
    #[error("{field}: {source}")]
    Expression {
        /// Dotted key of the expression, e.g. `trajectory.position_m[1]`.
        field: String,
        /// The parse error with its column (imukit's expression parser's).
        source: Box<dyn std::error::Error + Send + Sync>,
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
    /// A result that is not a finite number: refused at the boundary, never written.
    #[error(
        "{what}, row {row}, column {column}: the result is {value}, not a finite number (an input or parameter is too large for it); nothing was written"
    )]
    NotFinite {
        /// The output (file or table).
        what: String,
        /// 1-based row (the header is row 1).
        row: usize,
        /// The column.
        column: String,
        /// The value (inf or NaN).
        value: f64,
    },
    /// A quaternion of zero norm or not finite, where an attitude was expected.
    #[error("{field} has zero norm or is not finite")]
    BadQuaternion {
        /// The argument and index, e.g. `quaternion[3]`.
        field: String,
    },
    /// A sensor parameter the core refused.
    #[error("{context}: {source}")]
    Param {
        /// The parameter table, e.g. `imu.gyroscope`.
        context: String,
        /// The core's error, naming the parameter.
        source: ParamError,
    },
    /// A sensor parameter refused at the sample rate of a model.
    #[error("{context}: {source}")]
    ImuParam {
        /// The IMU, e.g. `imu`.
        context: String,
        /// The core's error, naming the sensor and the parameter.
        source: ImuParamError,
    },
    /// The 3D strapdown refused the data.
    #[error("{context}: {source}")]
    Strapdown {
        /// The data, e.g. `IMU data`.
        context: String,
        /// The core's error, with its sample.
        source: StrapdownError,
    },
    /// Planar dead reckoning refused the data.
    #[error("{context}: {source}")]
    Planar {
        /// The data, e.g. `planar IMU`.
        context: String,
        /// The core's error, with its sample.
        source: PlanarError,
    },
    /// An orientation filter refused its settings or data.
    #[error("{context}: {source}")]
    Orientation {
        /// The filter or the data.
        context: String,
        /// The core's error.
        source: OrientError,
    },
    /// The Allan deviation refused a column.
    #[error("{context}: {source}")]
    Allan {
        /// The column.
        context: String,
        /// The core's error.
        source: AllanError,
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

/// Where an error points, as far as it knows: the scenario key or argument (`field`), the file,
/// the 1-based row (the header is row 1) and the column. Front ends show it to programs (Python's
/// `ImuError.field`, `.file`, `.row`, `.column`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// Dotted key or argument name, e.g. `imu.gyroscope.noise_density`.
    pub field: Option<String>,
    /// The file.
    pub file: Option<PathBuf>,
    /// The row in the file.
    pub row: Option<usize>,
    /// The column name.
    pub column: Option<String>,
}

/// An input a job reads, by what it holds. A refusal about one names it by its label
/// ([`Data::label`], e.g. `IMU data`), and a front end that knows which file it came from
/// names the file instead ([`Error::data`], [`Error::relabelled`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Data {
    /// IMU readings.
    Imu,
    /// GNSS fixes.
    Gnss,
    /// Odometer readings.
    Odometer,
    /// Barometer readings.
    Barometer,
}

impl Data {
    /// Every kind.
    pub const ALL: [Self; 4] = [Self::Imu, Self::Gnss, Self::Odometer, Self::Barometer];

    /// How a refusal names it.
    #[must_use]
    pub const fn label(self) -> &'static str {
        match self {
            Self::Imu => "IMU data",
            Self::Gnss => "GNSS data",
            Self::Odometer => "odometer data",
            Self::Barometer => "barometer data",
        }
    }
}

/// What a refusal is about: an input by what it holds, or a key, option, file or argument by
/// its name. Shown as the name, or as the input's [`Data::label`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Subject {
    /// An input a job reads.
    Data(Data),
    /// A key, option, file or argument.
    Named(String),
}

impl core::fmt::Display for Subject {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Data(d) => f.write_str(d.label()),
            Self::Named(s) => f.write_str(s),
        }
    }
}

impl From<Data> for Subject {
    fn from(d: Data) -> Self {
        Self::Data(d)
    }
}

impl From<String> for Subject {
    fn from(s: String) -> Self {
        Self::Named(s)
    }
}

impl From<&str> for Subject {
    fn from(s: &str) -> Self {
        Self::Named(s.to_string())
    }
}

impl From<&String> for Subject {
    fn from(s: &String) -> Self {
        Self::Named(s.clone())
    }
}

impl Error {
    /// The input this refusal is about, when it is about one ([`Subject::Data`]).
    #[must_use]
    pub fn data(&self) -> Option<Data> {
        match self {
            Self::Invalid {
                field: Subject::Data(d),
                ..
            }
            | Self::Filter {
                context: Subject::Data(d),
                ..
            }
            | Self::Diverged {
                context: Subject::Data(d),
                ..
            } => Some(*d),
            _ => None,
        }
    }

    /// This refusal with the input it names called `name` instead (the file it came from); other
    /// refusals as they are.
    #[must_use]
    pub fn relabelled(self, name: String) -> Self {
        match self {
            Self::Invalid { message, .. } => Self::Invalid {
                field: name.into(),
                message,
            },
            Self::Filter { row, source, .. } => Self::Filter {
                context: name.into(),
                row,
                source,
            },
            Self::Diverged { message, .. } => Self::Diverged {
                context: name.into(),
                message,
            },
            other => other,
        }
    }

    /// This refusal of a value ([`Error::Invalid`], from a check shared with other keys) as a
    /// refusal of the request option `option`; other refusals as they are.
    #[must_use]
    pub fn of_option(self, option: RequestOption) -> Self {
        match self {
            Self::Invalid { message, .. } => Self::Request { option, message },
            other => other,
        }
    }

    /// This refusal, when it names a request option, as [`Error::Invalid`] of the option's
    /// name in a front end, `name(option)` (the command line's flag); other refusals as they are.
    #[must_use]
    pub fn naming_options(self, name: impl Fn(RequestOption) -> &'static str) -> Self {
        match self {
            Self::Request { option, message } => Self::Invalid {
                field: name(option).into(),
                message,
            },
            Self::Align { start, source } => Self::Invalid {
                field: name(RequestOption::Align).into(),
                message: align_message(start, &source),
            },
            other => other,
        }
    }

    /// Where the error points.
    #[must_use]
    pub fn location(&self) -> Location {
        let field = |f: &str| Location {
            field: Some(f.to_string()),
            ..Location::default()
        };
        let file = |f: &std::path::Path| Location {
            file: Some(f.to_path_buf()),
            ..Location::default()
        };
        match self {
            Self::Io { path, .. } => file(path),
            Self::Scenario { .. } => Location::default(),
            Self::Request { option, .. } => field(option.key()),
            Self::Align { .. } => field(RequestOption::Align.key()),
            Self::Invalid { field: f, .. } | Self::Diverged { context: f, .. } => {
                field(&f.to_string())
            }
            Self::ScenarioKey { field: f, .. }
            | Self::UnknownChoice { field: f, .. }
            | Self::Expression { field: f, .. }
            | Self::BadQuaternion { field: f } => field(f),
            Self::CsvValue {
                file: f,
                row,
                column,
                ..
            } => Location {
                file: Some(f.clone()),
                row: Some(*row),
                column: Some(column.clone()),
                field: None,
            },
            Self::CsvFormat { file: f, .. } => file(f),
            Self::Filter { context, row, .. } => Location {
                row: *row,
                ..field(&context.to_string())
            },
            Self::NotFinite {
                what, row, column, ..
            } => Location {
                field: Some(what.clone()),
                row: Some(*row),
                column: Some(column.clone()),
                file: None,
            },
            Self::MissingColumns {
                file: f, missing, ..
            } => Location {
                column: missing.first().cloned(),
                ..file(f)
            },
            Self::Param { context, source } => field(&format!("{context}.{}", source.field())),
            Self::ImuParam { context, source } => field(&format!(
                "{context}.{}.{}",
                source.sensor,
                source.source.field()
            )),
            Self::Kinematics { context, .. }
            | Self::Strapdown { context, .. }
            | Self::Planar { context, .. }
            | Self::Orientation { context, .. }
            | Self::Allan { context, .. } => field(context),
        }
    }
}

/// What to do instead when a static alignment fails.
/// Why the alignment `start` failed, with what to do instead.
fn align_message(start: &str, e: &AlignError) -> String {
    let hint = match e {
        AlignError::NoNorth { .. } => "; use \"gnss\" or give the initial state",
        AlignError::NotAtRest { .. } => "",
    };
    format!("\"{start}\": {e}{hint}")
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// [`Error::Invalid`]: the value of `field` (a key, an option, an argument) is wrong, `message`
/// says why.
pub fn invalid(field: impl Into<Subject>, message: impl Into<String>) -> Error {
    Error::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

#[cfg(test)]
mod data_tests {
    use super::*;

    #[test]
    fn a_refusal_about_an_input_is_named_by_the_file_a_front_end_knows() {
        for data in Data::ALL {
            let e = invalid(data, "row 3: times must increase");
            assert_eq!(e.data(), Some(data));
            assert_eq!(
                e.to_string(),
                format!("{}: row 3: times must increase", data.label())
            );
            // A key spelt like an input's label is a key: nothing is matched by its text.
            assert_eq!(invalid(data.label(), "m").data(), None);
            let renamed = e.relabelled("log.csv".into());
            assert_eq!(renamed.to_string(), "log.csv: row 3: times must increase");
            assert_eq!(renamed.data(), None);
        }
        // A request's field names no input.
        let e = invalid("rest_s", "must be ≥ 0");
        assert_eq!(e.data(), None);
        assert_eq!(e.relabelled("x".into()).to_string(), "x: must be ≥ 0");
        let io = Error::Scenario {
            origin: "s.toml".into(),
            message: "bad".into(),
        };
        assert_eq!(io.data(), None);
    }
}
