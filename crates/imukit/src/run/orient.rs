//! Orientation filters by name with `key=value` settings, run over IMU CSV files (streamed) —
//! the layer under `imukit orient` and the Python filter classes. The filters themselves are
//! the core's ([`imu_core::orientation`]).
use std::path::Path;

use imu_core::orientation::{
    Complementary, Ecompass, Estimate, FilterInput, KalmanFilter, KalmanParams, Madgwick, Mahony,
    OrientError, OrientationFilter, RobustFilter, RobustParams, RobustStatus,
};
use imu_core::{AccelSign, Body, Enu, NavFrame, Ned, Rotation};

use crate::choice::{Choice, display_as_name};
use crate::error::{Result, invalid};
use crate::io::description::{Described, Description};
use crate::io::output::AtomicFile;
use crate::io::rows::{Gaps, SampleClock, TimeWindow, TimedRows};
use crate::io::schema::TableKind;
use crate::io::table::{ACCEL_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS};
use crate::run::navigate::euler_unwrapped;
use crate::scenario::{AccelSignName, NavFrameName};

/// Columns of an orientation output: time, `q_nb` (scalar first), z-y-x Euler angles (yaw
/// unwrapped).
pub const ORIENT_COLUMNS: [&str; 8] = [
    "t_s",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
];

/// What the robust filter adds to [`ORIENT_COLUMNS`]: its gyroscope bias estimate and its
/// flags (1 or 0): at rest (the bias was learnt), accelerometer rejected, magnetic disturbance.
pub const ROBUST_COLUMNS: [&str; 6] = [
    "gyro_bias_x_rad_s",
    "gyro_bias_y_rad_s",
    "gyro_bias_z_rad_s",
    "at_rest",
    "accel_rejected",
    "mag_disturbed",
];

/// The robust filter's status as the values of [`ROBUST_COLUMNS`].
#[must_use]
pub fn robust_row(s: &RobustStatus) -> [f64; 6] {
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let [x, y, z] = s.gyro_bias_rad_s;
    [
        x,
        y,
        z,
        flag(s.at_rest),
        flag(s.accel_rejected),
        flag(s.mag_disturbed),
    ]
}

/// The filters, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FilterKind {
    /// imukit's own filter, the default: gyroscope bias learnt at rest only, accelerometer and
    /// magnetometer readings that are not gravity and north rejected and flagged
    /// (`imu_core::orientation::robust`).
    #[default]
    Robust,
    /// MATLAB `imufilter`: accelerometer + gyroscope Kalman filter.
    ImuFilter,
    /// MATLAB `ahrsfilter`: + magnetometer.
    AhrsFilter,
    /// MATLAB `ecompass`: accelerometer + magnetometer, sample by sample.
    Ecompass,
    /// Madgwick's gradient-descent filter.
    Madgwick,
    /// Mahony's complementary filter.
    Mahony,
    /// MATLAB `complementaryFilter`.
    Complementary,
}

impl Choice for FilterKind {
    const WHAT: &'static str = "filter";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("robust", Self::Robust),
        ("imufilter", Self::ImuFilter),
        ("ahrsfilter", Self::AhrsFilter),
        ("ecompass", Self::Ecompass),
        ("madgwick", Self::Madgwick),
        ("mahony", Self::Mahony),
        ("complementary", Self::Complementary),
    ];
}

impl FilterKind {
    /// Whether the filter must have a magnetometer (`Some(true)`), must not (`Some(false)`),
    /// or uses one when there is one (`None`).
    #[must_use]
    pub fn magnetometer(self) -> Option<bool> {
        match self {
            Self::AhrsFilter | Self::Ecompass => Some(true),
            Self::ImuFilter => Some(false),
            Self::Robust | Self::Madgwick | Self::Mahony | Self::Complementary => None,
        }
    }

    /// The settings the filter takes (MATLAB property names; matched without case or `_`).
    #[must_use]
    pub fn settings(self) -> Vec<&'static str> {
        match self {
            Self::ImuFilter => KALMAN_SETTINGS.to_vec(),
            Self::AhrsFilter => [KALMAN_SETTINGS.as_slice(), &MAGNETIC_SETTINGS].concat(),
            // The e-compass has no memory; the rate is accepted for uniformity.
            Self::Ecompass => vec!["SampleRate"],
            Self::Madgwick => vec!["SampleRate", "Beta"],
            Self::Mahony => vec!["SampleRate", "Kp", "Ki"],
            Self::Complementary => vec!["SampleRate", "AccelerometerGain", "MagnetometerGain"],
            Self::Robust => ROBUST_SETTINGS.to_vec(),
        }
    }
}

/// Settings of the robust filter (`RobustParams`; angles in rad, times in s).
const ROBUST_SETTINGS: [&str; 15] = [
    "SampleRate",
    "Gravity",
    "AccelerometerTimeConstant",
    "MagnetometerTimeConstant",
    "RestTimeConstant",
    "RestGyroscopeThreshold",
    "RestAccelerometerThreshold",
    "RestMinimumTime",
    "BiasTimeConstant",
    "AccelerationRejection",
    "AccelerationRejectionAngle",
    "RecoveryTime",
    "MagneticRejection",
    "DipRejection",
    "MagneticRecoveryTime",
];

/// Settings of both Kalman filters.
const KALMAN_SETTINGS: [&str; 9] = [
    "SampleRate",
    "DecimationFactor",
    "AccelerometerNoise",
    "GyroscopeNoise",
    "GyroscopeDriftNoise",
    "LinearAccelerationNoise",
    "LinearAccelerationDecayFactor",
    "InitialProcessNoiseScale",
    "Gravity",
];

/// Settings of the AHRS filter's magnetometer.
const MAGNETIC_SETTINGS: [&str; 4] = [
    "MagnetometerNoise",
    "MagneticDisturbanceNoise",
    "MagneticDisturbanceDecayFactor",
    "ExpectedMagneticFieldStrength",
];

/// The conventions an orientation run follows where a front end names neither the frame nor
/// the accelerometer sign: imukit's unless asked, from every front end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Conventions {
    /// imukit's, as in every other command: ENU (FLU body axes), accelerometers reading
    /// specific force (`+g` up at rest).
    #[default]
    Imukit,
    /// MATLAB's Navigation Toolbox: NED (FRD body axes), accelerometers in MATLAB's sign
    /// (gravity minus acceleration: `+g` down at rest).
    Matlab,
}

impl Choice for Conventions {
    const WHAT: &'static str = "conventions";
    const NAMES: &'static [(&'static str, Self)] =
        &[("imukit", Self::Imukit), ("matlab", Self::Matlab)];
}

display_as_name!(FilterKind, Conventions);

impl Conventions {
    /// The navigation frame.
    #[must_use]
    pub fn nav_frame(self) -> NavFrameName {
        match self {
            Self::Imukit => NavFrameName::ENU,
            Self::Matlab => NavFrameName::NED,
        }
    }

    /// The accelerometer sign, by its name.
    #[must_use]
    pub fn accel_sign_name(self) -> AccelSignName {
        match self {
            Self::Imukit => AccelSignName::SpecificForce,
            Self::Matlab => AccelSignName::Matlab,
        }
    }

    /// The accelerometer sign.
    #[must_use]
    pub fn accel_sign(self) -> AccelSign {
        match self {
            Self::Imukit => AccelSign::SpecificForce,
            Self::Matlab => AccelSign::Matlab,
        }
    }
}

/// The frame and accelerometer sign of an orientation run: each as chosen, else the
/// conventions'.
#[must_use]
pub fn frame_and_sign(
    conventions: Conventions,
    nav_frame: Option<NavFrameName>,
    accel_sign: Option<AccelSignName>,
) -> (NavFrameName, AccelSign) {
    (
        nav_frame.unwrap_or(conventions.nav_frame()),
        accel_sign.map_or(conventions.accel_sign(), AccelSign::from),
    )
}

/// An orientation run as a front end states it: the filter, the conventions, the frame and
/// sign when they override the conventions, and settings by MATLAB's property names; checked
/// once, in [`OrientRequest::resolve`], whose errors name a setting.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OrientRequest {
    /// The filter.
    pub filter: FilterKind,
    /// The conventions the frame and the sign follow unless given.
    pub conventions: Conventions,
    /// The navigation frame (`None`: the conventions').
    pub nav_frame: Option<NavFrameName>,
    /// The accelerometer sign (`None`: the conventions').
    pub accel_sign: Option<AccelSignName>,
    /// `(name, value)` settings.
    pub settings: Vec<(String, f64)>,
    /// `false`: a 9-axis input run as 6D, its magnetometer columns ignored (`--no-mag`); `true`
    /// (the default): the magnetometer used when the filter may use one and the input has it.
    pub use_magnetometer: bool,
}

impl OrientRequest {
    /// This request with the frame and the accelerometer sign, when not given, taken from the
    /// input's description (`described`); the conventions then fill only what neither says. A
    /// run simulated in NED is so estimated in NED, with the body axes the readings have.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `nav_frame` or `accel_sign` when the option contradicts
    /// the input's description.
    pub fn with_described(self, described: &Described) -> Result<Self> {
        Ok(Self {
            nav_frame: described.known("nav_frame", self.nav_frame, |d| d.nav_frame)?,
            accel_sign: described.known("accel_sign", self.accel_sign, |d| d.accel_sign)?,
            ..self
        })
    }

    /// The filter spec and the navigation frame.
    #[must_use]
    pub fn resolve(&self) -> (FilterSpec, NavFrameName) {
        let (nav, sign) = frame_and_sign(self.conventions, self.nav_frame, self.accel_sign);
        let mut spec = FilterSpec::new(self.filter, sign);
        spec.settings.clone_from(&self.settings);
        spec.use_magnetometer = self.use_magnetometer;
        (spec, nav)
    }
}

/// The refusal of a setting `kind` does not have, listing those it has.
fn unknown_setting(kind: FilterKind, name: &str) -> crate::Error {
    let known = kind.settings();
    invalid(
        name,
        format!(
            "unknown setting for {}; known: {}",
            kind.name(),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        ),
    )
}

/// The filters that run without a magnetometer, for messages.
const SIX_AXIS_FILTERS: &str = "robust, imufilter, madgwick, mahony or complementary";

/// A filter to build: which, with which sensors and accelerometer sign, and its settings.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSpec {
    /// Which filter.
    pub kind: FilterKind,
    /// Sign of the accelerometer readings.
    pub accel_sign: AccelSign,
    /// Whether magnetometer readings are fed (for the filters that may use one).
    pub magnetometer: bool,
    /// `false`: magnetometer columns of the input are ignored (6D from a 9-axis file).
    pub use_magnetometer: bool,
    /// `(name, value)` settings (see [`FilterKind::settings`]).
    pub settings: Vec<(String, f64)>,
    /// The diagonal of InitialProcessNoise (9 or 12 values), replacing the default.
    pub initial_process_noise: Option<Vec<f64>>,
}

fn key(name: &str) -> String {
    name.chars()
        .filter(|c| *c != '_')
        .flat_map(char::to_lowercase)
        .collect()
}

impl FilterSpec {
    /// A spec with no settings; the magnetometer as the filter requires (or none).
    #[must_use]
    pub fn new(kind: FilterKind, accel_sign: AccelSign) -> Self {
        Self {
            kind,
            accel_sign,
            magnetometer: kind.magnetometer().unwrap_or(false),
            use_magnetometer: true,
            settings: Vec::new(),
            initial_process_noise: None,
        }
    }

    /// Parses `key=value` settings (e.g. `GyroscopeNoise=7.6154e-7`).
    ///
    /// # Errors
    /// A setting without `=`, or a value that is not a number.
    pub fn parse_settings(kind: FilterKind, pairs: &[String]) -> Result<Vec<(String, f64)>> {
        let known = kind.settings();
        pairs
            .iter()
            .map(|p| {
                let (k, v) = p
                    .split_once('=')
                    .ok_or_else(|| invalid("--param", format!("{p:?} is not key=value")))?;
                let k = k.trim();
                // The key first: a setting the filter does not have is the mistake to name.
                if !known.iter().any(|n| key(n) == key(k)) {
                    return Err(unknown_setting(kind, k));
                }
                let value: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| invalid("--param", format!("{k}: {v:?} is not a number")))?;
                Ok((k.to_string(), value))
            })
            .collect()
    }

    /// The value of setting `name` (last one wins), after checking every setting is known.
    fn setting(&self, name: &str) -> Result<Option<f64>> {
        let known = self.kind.settings();
        for (k, _) in &self.settings {
            if !known.iter().any(|n| key(n) == key(k)) {
                return Err(unknown_setting(self.kind, k));
            }
        }
        Ok(self
            .settings
            .iter()
            .rev()
            .find(|(k, _)| key(k) == key(name))
            .map(|(_, v)| *v))
    }

    /// The sample rate: the `SampleRate` setting, else `data_rate_hz`.
    ///
    /// # Errors
    /// An unknown setting.
    pub fn sample_rate_hz(&self, data_rate_hz: f64) -> Result<f64> {
        Ok(self.fixed_rate_hz()?.unwrap_or(data_rate_hz))
    }

    /// The `SampleRate` setting: a fixed rate that replaces the samples' own intervals, as in
    /// MATLAB's filters (`None`: each sample over its own interval).
    ///
    /// # Errors
    /// An unknown setting.
    pub fn fixed_rate_hz(&self) -> Result<Option<f64>> {
        self.setting("SampleRate")
    }

    /// The Kalman parameters these settings give.
    fn kalman(&self, sample_rate_hz: f64) -> Result<KalmanParams> {
        let mut p = KalmanParams {
            sample_rate_hz,
            accel_sign: self.accel_sign,
            ..KalmanParams::default()
        };
        let set = |name: &str, field: &mut f64| -> Result<()> {
            if let Some(v) = self.setting(name)? {
                *field = v;
            }
            Ok(())
        };
        set("AccelerometerNoise", &mut p.accelerometer_noise)?;
        set("GyroscopeNoise", &mut p.gyroscope_noise)?;
        set("GyroscopeDriftNoise", &mut p.gyroscope_drift_noise)?;
        set("LinearAccelerationNoise", &mut p.linear_acceleration_noise)?;
        set(
            "LinearAccelerationDecayFactor",
            &mut p.linear_acceleration_decay,
        )?;
        set("MagnetometerNoise", &mut p.magnetometer_noise)?;
        set(
            "MagneticDisturbanceNoise",
            &mut p.magnetic_disturbance_noise,
        )?;
        set(
            "MagneticDisturbanceDecayFactor",
            &mut p.magnetic_disturbance_decay,
        )?;
        set(
            "ExpectedMagneticFieldStrength",
            &mut p.expected_magnetic_field_ut,
        )?;
        set("Gravity", &mut p.gravity_m_s2)?;
        if let Some(d) = self.setting("DecimationFactor")? {
            if !(d >= 1.0 && d.fract() == 0.0 && d <= 1e9) {
                return Err(invalid(
                    "DecimationFactor",
                    format!("{d} is not a whole number ≥ 1"),
                ));
            }
            p.decimation = d as usize;
        }
        if let Some(diag) = &self.initial_process_noise {
            let states = if self.kind == FilterKind::AhrsFilter {
                12
            } else {
                9
            };
            if diag.len() != states {
                return Err(invalid(
                    "InitialProcessNoise",
                    format!("needs {states} diagonal values, got {}", diag.len()),
                ));
            }
            p.initial_process_noise[..states].copy_from_slice(diag);
        }
        if let Some(s) = self.setting("InitialProcessNoiseScale")? {
            p.initial_process_noise = p.initial_process_noise.map(|v| v * s);
        }
        Ok(p)
    }

    /// The filter, at `sample_rate_hz` unless a `SampleRate` setting says otherwise.
    ///
    /// # Errors
    /// Unknown settings, invalid values (named), a magnetometer the filter cannot use.
    pub fn build<N: NavFrame>(&self, sample_rate_hz: f64) -> Result<AnyFilter<N>> {
        let rate = self.sample_rate_hz(sample_rate_hz)?;
        let refused = |source: imu_core::orientation::OrientError| crate::Error::Orientation {
            context: "filter".into(),
            source,
        };
        let (sign, mag) = (self.accel_sign, self.magnetometer);
        Ok(match self.kind {
            FilterKind::ImuFilter => {
                AnyFilter::Kalman(KalmanFilter::<N>::imu(self.kalman(rate)?).map_err(refused)?)
            }
            FilterKind::AhrsFilter => {
                AnyFilter::Kalman(KalmanFilter::<N>::ahrs(self.kalman(rate)?).map_err(refused)?)
            }
            FilterKind::Ecompass => AnyFilter::Ecompass(Ecompass { accel_sign: sign }),
            FilterKind::Madgwick => {
                let beta = self
                    .setting("Beta")?
                    .unwrap_or(if mag { 0.041 } else { 0.033 });
                AnyFilter::Madgwick(Madgwick::new(rate, beta, mag, sign).map_err(refused)?)
            }
            FilterKind::Mahony => {
                let kp = self.setting("Kp")?.unwrap_or(1.0);
                let ki = self.setting("Ki")?.unwrap_or(0.3);
                AnyFilter::Mahony(Mahony::new(rate, kp, ki, mag, sign).map_err(refused)?)
            }
            FilterKind::Robust => {
                let mut p = RobustParams {
                    sample_rate_hz: rate,
                    accel_sign: sign,
                    magnetometer: mag,
                    ..RobustParams::default()
                };
                for (name, field) in [
                    ("Gravity", &mut p.gravity_m_s2),
                    ("AccelerometerTimeConstant", &mut p.tau_accel_s),
                    ("MagnetometerTimeConstant", &mut p.tau_mag_s),
                    ("RestTimeConstant", &mut p.rest_tau_s),
                    ("RestGyroscopeThreshold", &mut p.rest_gyro_rad_s),
                    ("RestAccelerometerThreshold", &mut p.rest_accel_m_s2),
                    ("RestMinimumTime", &mut p.rest_min_s),
                    ("BiasTimeConstant", &mut p.bias_tau_s),
                    ("AccelerationRejection", &mut p.accel_rejection_g),
                    ("AccelerationRejectionAngle", &mut p.accel_rejection_rad),
                    ("RecoveryTime", &mut p.recovery_s),
                    ("MagneticRejection", &mut p.mag_rejection),
                    ("DipRejection", &mut p.dip_rejection_rad),
                    ("MagneticRecoveryTime", &mut p.mag_recovery_s),
                ] {
                    if let Some(v) = self.setting(name)? {
                        *field = v;
                    }
                }
                AnyFilter::Robust(RobustFilter::new(p).map_err(refused)?)
            }
            FilterKind::Complementary => {
                let ka = self.setting("AccelerometerGain")?.unwrap_or(0.01);
                let km = self.setting("MagnetometerGain")?.unwrap_or(0.01);
                AnyFilter::Complementary(
                    Complementary::new(rate, ka, km, mag, sign).map_err(refused)?,
                )
            }
        })
    }
}

/// Any of the filters, by value (copyable, so a batch can be undone on error; the Kalman
/// variant's 700 bytes are copied once per batch, not per sample).
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum AnyFilter<N: NavFrame> {
    /// `imufilter` or `ahrsfilter`.
    Kalman(KalmanFilter<N>),
    /// `ecompass`.
    Ecompass(Ecompass),
    /// Madgwick.
    Madgwick(Madgwick),
    /// Mahony.
    Mahony(Mahony),
    /// `complementaryFilter`.
    Complementary(Complementary),
    /// imukit's robust filter.
    Robust(RobustFilter),
}

impl<N: NavFrame> AnyFilter<N> {
    /// Samples per estimate: MATLAB's `DecimationFactor` for `imufilter`/`ahrsfilter`, else 1.
    #[must_use]
    pub fn decimation(&self) -> usize {
        match self {
            Self::Kalman(f) => f.params().decimation,
            _ => 1,
        }
    }

    /// The robust filter's bias estimate and flags after the last sample (`None` for the
    /// others).
    #[must_use]
    pub fn status(&self) -> Option<RobustStatus> {
        match self {
            Self::Robust(f) => Some(f.status()),
            _ => None,
        }
    }
}

impl<N: NavFrame> OrientationFilter<N> for AnyFilter<N> {
    fn update(
        &mut self,
        input: &FilterInput,
    ) -> std::result::Result<Option<Estimate<N>>, OrientError> {
        match self {
            Self::Kalman(f) => f.update(input),
            Self::Ecompass(f) => f.update(input),
            Self::Madgwick(f) => f.update(input),
            Self::Mahony(f) => f.update(input),
            Self::Complementary(f) => f.update(input),
            Self::Robust(f) => f.update(input),
        }
    }

    fn reset(&mut self) {
        match self {
            Self::Kalman(f) => f.reset(),
            Self::Ecompass(f) => OrientationFilter::<N>::reset(f),
            Self::Madgwick(f) => OrientationFilter::<N>::reset(f),
            Self::Mahony(f) => OrientationFilter::<N>::reset(f),
            Self::Complementary(f) => OrientationFilter::<N>::reset(f),
            Self::Robust(f) => OrientationFilter::<N>::reset(f),
        }
    }
}

/// One orientation output row in [`ORIENT_COLUMNS`] order (yaw unwrapped against `last_yaw`).
#[must_use]
pub fn orient_row<N: NavFrame>(
    t_s: f64,
    q: &Rotation<Body, N>,
    last_yaw: &mut Option<f64>,
) -> [f64; 8] {
    let [w, x, y, z] = q.to_wxyz();
    let e = euler_unwrapped(q, last_yaw);
    [t_s, w, x, y, z, e.yaw_rad, e.pitch_rad, e.roll_rad]
}

/// What [`orient_csv`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct OrientSummary {
    /// Rows read.
    pub samples: usize,
    /// Rows written (fewer with decimation).
    pub rows: usize,
    /// Samples at the end that do not fill a decimation block, so give no estimate (0 without
    /// decimation; MATLAB's filters refuse such a call, a file is read whole instead).
    pub unfinished: usize,
    /// The sample rate: the `SampleRate` setting, or the median rate of the file, Hz.
    pub sample_rate_hz: f64,
    /// Whether each sample was integrated over its own interval (no `SampleRate` setting) or
    /// at the fixed `SampleRate`, as MATLAB's filters do.
    pub per_sample: bool,
    /// The gaps in the sample times, integrated across.
    pub gaps: Gaps,
    /// What the user should know about the run (a magnetometer the filter ignores).
    pub warnings: Vec<String>,
}

/// Runs the filter `spec` over the IMU CSV `input` (`accel_*`, `gyro_*` and, when used,
/// `mag_*` columns) into `out` ([`ORIENT_COLUMNS`]), streamed; `out` appears only when complete.
/// The sample rate is `SampleRate` if set, else the median interval of the first
/// [`GAP_WINDOW`](crate::io::rows::GAP_WINDOW) rows'. Whether the magnetometer is used follows the filter, or for those
/// that may use one, whether the file has `mag_*` columns (`spec.magnetometer` is set
/// accordingly). Only the rows of `window` are filtered.
///
/// # Errors
/// Missing columns, bad cells (file, row, column), times that do not increase, the filter's
/// refusals with the row, I/O errors.
pub fn orient_csv(
    input: &Path,
    spec: &FilterSpec,
    nav: NavFrameName,
    window: TimeWindow,
    out: &Path,
) -> Result<OrientSummary> {
    match nav {
        NavFrameName::ENU => orient_csv_in::<Enu>(input, spec, nav, window, out),
        NavFrameName::NED => orient_csv_in::<Ned>(input, spec, nav, window, out),
    }
}

fn orient_csv_in<N: NavFrame>(
    input: &Path,
    spec: &FilterSpec,
    nav: NavFrameName,
    window: TimeWindow,
    out: &Path,
) -> Result<OrientSummary> {
    let header = crate::io::table::read_header(input)?;
    let has = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
    let mut spec = spec.clone();
    // A filter that may use a magnetometer uses one when the file has it; a file with only some
    // of the mag_* columns is a mistake to name, not a reason to drop the magnetometer silently.
    let some_mag = MAG_COLUMNS.iter().any(|c| header.iter().any(|h| h == c));
    let name = spec.kind.name();
    let mut warnings = Vec::new();
    spec.magnetometer = match (spec.kind.magnetometer(), spec.use_magnetometer) {
        (Some(true), false) => {
            return Err(invalid(
                "use_magnetometer",
                format!("the {name} filter needs a magnetometer; for 6D use {SIX_AXIS_FILTERS}"),
            ));
        }
        (Some(true), true) => true,
        (Some(false), _) => {
            if some_mag && spec.use_magnetometer {
                warnings.push(format!(
                    "{}: the {name} filter uses no magnetometer: the file's mag_* columns are \
                     ignored and the heading is not held (robust, ahrsfilter, madgwick, mahony \
                     and complementary use them; --no-mag says you mean 6D)",
                    input.display()
                ));
            }
            false
        }
        (None, use_it) => some_mag && use_it,
    };
    if spec.magnetometer && !has(&MAG_COLUMNS) {
        let missing = MAG_COLUMNS
            .iter()
            .filter(|c| !header.iter().any(|h| h == *c))
            .map(|c| (*c).to_string())
            .collect();
        let hint = if some_mag {
            format!(
                "; the {name} filter uses all three magnetometer columns when the file has any \
                 (--no-mag ignores them)"
            )
        } else {
            format!(
                "; the {name} filter needs a magnetometer and this file has none: for 6D use \
                 {SIX_AXIS_FILTERS}"
            )
        };
        return Err(crate::Error::MissingColumns {
            file: input.into(),
            missing,
            hint,
        });
    }
    let gyro = spec.kind != FilterKind::Ecompass;
    let mut columns = vec!["t_s"];
    columns.extend(ACCEL_COLUMNS);
    if gyro {
        columns.extend(GYRO_COLUMNS);
    }
    if spec.magnetometer {
        columns.extend(MAG_COLUMNS);
    }
    let hint = format!(
        "; the {} filter needs t_s, accel_*{}{}",
        spec.kind.name(),
        if gyro { ", gyro_*" } else { "" },
        if spec.magnetometer { ", mag_*" } else { "" }
    );
    let mut rows = TimedRows::open(input, &columns, &hint)?.within(window);
    let data_rate = rows.median_interval().map_or(f64::NAN, |m| 1.0 / m);
    let rate = spec.sample_rate_hz(data_rate)?;
    let per_sample = spec.fixed_rate_hz()?.is_none();
    if !(rate.is_finite() && rate > 0.0) {
        return Err(invalid(
            "SampleRate",
            "cannot be taken from a single row: give SampleRate=…",
        ));
    }
    let mut filter = spec.build::<N>(rate)?;
    let mut file = AtomicFile::create(out)?;
    let robust = spec.kind == FilterKind::Robust;
    let out_columns: Vec<String> = ORIENT_COLUMNS
        .iter()
        .chain(if robust { &ROBUST_COLUMNS[..] } else { &[] })
        .map(|c| (*c).to_string())
        .collect();
    file.begin_table(
        &out_columns,
        &Description {
            nav_frame: Some(nav),
            ..Description::of_kind(TableKind::Orientation)
        },
    )?;
    let (mut samples, mut written, mut last_yaw) = (0usize, 0usize, None);
    let mut r = vec![0.0; columns.len()];
    while rows.next_row(&mut r)? {
        let three = |k: usize| [r[k], r[k + 1], r[k + 2]];
        let sample = FilterInput {
            accel_m_s2: three(1),
            gyro_rad_s: if gyro { three(4) } else { [0.0; 3] },
            mag_ut: if spec.magnetometer {
                three(if gyro { 7 } else { 4 })
            } else {
                [0.0; 3]
            },
            interval_s: rows.interval().filter(|_| per_sample),
        };
        let estimate = filter
            .update(&sample)
            .map_err(|e| invalid("IMU data", format!("row {}: {e}", rows.last_row())))?;
        if let Some(est) = estimate {
            let row = orient_row(r[0], &est.orientation, &mut last_yaw);
            match filter.status() {
                Some(status) => file.write_row(&[&row[..], &robust_row(&status)].concat())?,
                None => file.write_row(&row)?,
            }
            written += 1;
        }
        samples += 1;
    }
    file.commit()?;
    Ok(OrientSummary {
        samples,
        rows: written,
        unfinished: samples - written * filter.decimation(),
        sample_rate_hz: rate,
        per_sample,
        gaps: rows.gaps(),
        warnings,
    })
}

/// Estimates of a batch: `q_nb` (w, x, y, z) and the bias-corrected body rate per estimate.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Estimates {
    /// Orientations, one per estimate.
    pub quaternions: Vec<[f64; 4]>,
    /// Angular velocities, rad/s.
    pub angular_velocity_rad_s: Vec<[f64; 3]>,
    /// The robust filter's bias and flags per estimate ([`ROBUST_COLUMNS`]); empty for the
    /// others.
    pub status: Vec<[f64; 6]>,
}

/// Runs `filter` over rows of readings given as flat slices (three values per row):
/// accelerometer, gyroscope and magnetometer (`None` for sensors the filter does not use), and
/// their times `t_s` when known: each sample is then integrated over its own interval, the
/// first from the last time `clock` holds (else at the filter's sample rate).
/// The filter and the clock carry their state into the next call, so a run in chunks equals a
/// run whole; on an error both are left as they were before the call. As in MATLAB's `imufilter` and
/// `ahrsfilter`, each call takes whole decimation blocks: the row count must be a multiple of
/// the `DecimationFactor`.
///
/// # Errors
/// Slices of different lengths, a row count that is not a multiple of the decimation factor,
/// times that are not finite or do not increase, the filter's refusals naming the row index
/// (non-finite readings among them), and estimates that are not finite.
pub fn run_rows<N: NavFrame>(
    filter: &mut AnyFilter<N>,
    clock: &mut SampleClock,
    accel: &[f64],
    gyro: Option<&[f64]>,
    mag: Option<&[f64]>,
    t_s: Option<&[f64]>,
) -> Result<Estimates> {
    let n = accel.len() / 3;
    if let Some(t) = t_s.filter(|t| t.len() != n) {
        return Err(invalid(
            "t_s",
            format!("has {} times, the accelerometer {n} rows", t.len()),
        ));
    }
    let intervals = t_s.map(|t| clock.intervals(t)).transpose()?;
    for (name, s) in [("gyroscope", gyro), ("magnetometer", mag)] {
        if let Some(s) = s.filter(|s| s.len() != accel.len()) {
            return Err(invalid(
                name,
                format!("has {} rows, the accelerometer {n}", s.len() / 3),
            ));
        }
    }
    let decimation = filter.decimation();
    if !n.is_multiple_of(decimation) {
        return Err(invalid(
            "readings",
            format!(
                "{n} rows is not a multiple of DecimationFactor = {decimation} (each call takes \
                 whole blocks of {decimation} samples, as MATLAB's imufilter and ahrsfilter do)"
            ),
        ));
    }
    let mut working = *filter;
    let mut out = Estimates::default();
    let three = |s: Option<&[f64]>, i: usize| {
        s.map_or([0.0; 3], |s| [s[3 * i], s[3 * i + 1], s[3 * i + 2]])
    };
    for i in 0..n {
        let input = FilterInput {
            accel_m_s2: three(Some(accel), i),
            gyro_rad_s: three(gyro, i),
            mag_ut: three(mag, i),
            interval_s: intervals.as_ref().and_then(|d| d[i]),
        };
        let estimate = working
            .update(&input)
            .map_err(|e| invalid("readings", format!("row {i}: {e}")))?;
        if let Some(e) = estimate {
            let (q, w) = (e.orientation.to_wxyz(), e.angular_velocity_rad_s);
            if !q.iter().chain(&w).all(|v| v.is_finite()) {
                return Err(invalid(
                    "readings",
                    format!(
                        "row {i}: the estimate is not finite (readings too large for the filter, \
                         or a sample rate too small)"
                    ),
                ));
            }
            out.quaternions.push(q);
            out.angular_velocity_rad_s.push(w);
            if let Some(status) = working.status() {
                out.status.push(robust_row(&status));
            }
        }
    }
    *filter = working;
    clock.advance(t_s);
    Ok(out)
}

/// The e-compass of each row: accelerometer and magnetometer rows (three values each, flat) in
/// frame `nav`, with the accelerometer sign `accel_sign`; four values `q_nb` per row.
///
/// # Errors
/// Slices of different lengths; a row the e-compass refuses (parallel or zero vectors), named
/// by its index.
pub fn ecompass_rows(
    accel: &[f64],
    mag: &[f64],
    accel_sign: AccelSign,
    nav: NavFrameName,
) -> Result<Vec<f64>> {
    fn rows<N: NavFrame>(a: &[f64], m: &[f64], s: AccelSign) -> Result<Vec<f64>> {
        let mut out = Vec::with_capacity(a.len() / 3 * 4);
        for (i, (a, m)) in a.chunks_exact(3).zip(m.chunks_exact(3)).enumerate() {
            let q = imu_core::orientation::ecompass::<N>([a[0], a[1], a[2]], [m[0], m[1], m[2]], s)
                .map_err(|source| crate::Error::Orientation {
                    context: format!("row {i}"),
                    source,
                })?;
            out.extend(q.to_wxyz());
        }
        Ok(out)
    }
    if accel.len() != mag.len() {
        return Err(invalid(
            "mag",
            format!("has {} rows, accel {}", mag.len() / 3, accel.len() / 3),
        ));
    }
    match nav {
        NavFrameName::ENU => rows::<Enu>(accel, mag, accel_sign),
        NavFrameName::NED => rows::<Ned>(accel, mag, accel_sign),
    }
}

/// The quaternion distance (rad) between the rows of two flat lists of quaternions
/// `[w, x, y, z]` (four values per row).
///
/// # Errors
/// Lists of different lengths; a quaternion of zero norm or not finite, named `q1[i]`/`q2[i]`.
pub fn quaternion_distances(q1: &[f64], q2: &[f64]) -> Result<Vec<f64>> {
    if q1.len() != q2.len() {
        return Err(invalid(
            "q2",
            format!("has {} rows, q1 {}", q2.len() / 4, q1.len() / 4),
        ));
    }
    let rotation = |c: &[f64], name: &str, i: usize| {
        Rotation::<Body, Enu>::from_wxyz([c[0], c[1], c[2], c[3]]).ok_or_else(|| {
            crate::Error::BadQuaternion {
                field: format!("{name}[{i}]"),
            }
        })
    };
    q1.chunks_exact(4)
        .zip(q2.chunks_exact(4))
        .enumerate()
        .map(|(i, (a, b))| {
            Ok(imu_core::orientation::quaternion_distance(
                &rotation(a, "q1", i)?,
                &rotation(b, "q2", i)?,
            ))
        })
        .collect()
}
