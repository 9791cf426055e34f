//! Orientation filters by name with `key=value` settings, run over IMU CSV files (streamed) —
//! the layer under `imukit orient` and the Python filter classes. The filters themselves are
//! the core's ([`imu_core::orientation`]).
use imu_core::orientation::{
    Complementary, Ecompass, Estimate, FilterInput, KalmanFilter, KalmanParams, Madgwick, Mahony,
    OrientError, OrientationFilter, RobustFilter, RobustParams, RobustStatus,
};
use imu_core::{AccelSign, NavFrame};

use crate::choice::{Choice, display_as_name};
use crate::error::{Result, invalid};
use crate::io::conventions::{AccelSignName, NavFrameName};
use crate::io::described::Described;

/// The robust filter's status as the values of [`crate::io::columns::ROBUST_COLUMNS`].
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
    /// imukit's own filter, the default: inclination from the accelerometer low-passed in an
    /// almost inertial frame, heading from the magnetometer unless a magnet is near, gyroscope
    /// bias learnt at rest and in motion (`imu_core::orientation::robust`).
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

    /// The settings the filter takes (MATLAB property names; matched without case or `_`):
    /// those [`Self::setting_defaults`] gives a default.
    #[must_use]
    pub fn settings(self) -> Vec<&'static str> {
        let magnetometer = self.magnetometer().unwrap_or(false);
        self.setting_defaults(magnetometer)
            .into_iter()
            .map(|(name, _)| name)
            .collect()
    }
}

impl FilterKind {
    /// Each setting's default, with a magnetometer or without (Madgwick's gain depends on it):
    /// the one place the filters, the command line and Python take them from. `SampleRate` is
    /// the rate of a filter built without data (MATLAB's 100 Hz; the command line runs at the
    /// data's own rate unless given one).
    #[must_use]
    pub fn setting_defaults(self, magnetometer: bool) -> Vec<(&'static str, f64)> {
        let k = KalmanParams::default();
        let rate = ("SampleRate", k.sample_rate_hz);
        match self {
            Self::ImuFilter | Self::AhrsFilter => {
                #[allow(clippy::cast_precision_loss)]
                let mut d = vec![
                    rate,
                    ("DecimationFactor", k.decimation as f64),
                    ("AccelerometerNoise", k.accelerometer_noise),
                    ("GyroscopeNoise", k.gyroscope_noise),
                    ("GyroscopeDriftNoise", k.gyroscope_drift_noise),
                    ("LinearAccelerationNoise", k.linear_acceleration_noise),
                    ("LinearAccelerationDecayFactor", k.linear_acceleration_decay),
                    ("InitialProcessNoiseScale", 1.0),
                    ("Gravity", k.gravity_m_s2),
                ];
                if self == Self::AhrsFilter {
                    d.extend([
                        ("MagnetometerNoise", k.magnetometer_noise),
                        ("MagneticDisturbanceNoise", k.magnetic_disturbance_noise),
                        (
                            "MagneticDisturbanceDecayFactor",
                            k.magnetic_disturbance_decay,
                        ),
                        (
                            "ExpectedMagneticFieldStrength",
                            k.expected_magnetic_field_ut,
                        ),
                    ]);
                }
                d
            }
            Self::Ecompass => vec![rate],
            Self::Madgwick => vec![
                rate,
                (
                    "Beta",
                    if magnetometer {
                        MADGWICK_BETA_9D
                    } else {
                        MADGWICK_BETA_6D
                    },
                ),
            ],
            Self::Mahony => vec![rate, ("Kp", MAHONY_KP), ("Ki", MAHONY_KI)],
            Self::Complementary => vec![
                rate,
                ("AccelerometerGain", COMPLEMENTARY_GAIN),
                ("MagnetometerGain", COMPLEMENTARY_GAIN),
            ],
            Self::Robust => {
                let mut p = RobustParams::default();
                p.settings_mut()
                    .into_iter()
                    .map(|(name, v)| (name, *v))
                    .collect()
            }
        }
    }
}

/// Madgwick's gain without a magnetometer, rad/s (his paper's 6-axis figure).
pub const MADGWICK_BETA_6D: f64 = 0.033;

/// Madgwick's gain with a magnetometer, rad/s (his paper's 9-axis figure).
pub const MADGWICK_BETA_9D: f64 = 0.041;

/// Mahony's proportional gain (ahrs' default).
pub const MAHONY_KP: f64 = 1.0;

/// Mahony's integral gain (ahrs' default).
pub const MAHONY_KI: f64 = 0.3;

/// MATLAB `complementaryFilter`'s accelerometer and magnetometer gain.
pub const COMPLEMENTARY_GAIN: f64 = 0.01;

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
    /// The whole run smoothed after the fact (the robust filter's forward and backward passes,
    /// `imu_core::orientation::robust::smooth`), not filtered as it comes.
    pub smooth: bool,
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
            nav_frame: described.known(
                crate::error::RequestOption::NavFrame,
                self.nav_frame,
                |d| d.nav_frame,
            )?,
            accel_sign: described.known(
                crate::error::RequestOption::AccelSign,
                self.accel_sign,
                |d| d.accel_sign,
            )?,
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
        spec.smooth = self.smooth;
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
    /// Smooth the whole run (the robust filter only).
    pub smooth: bool,
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
            smooth: false,
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
                let beta = self.setting("Beta")?.unwrap_or(if mag {
                    MADGWICK_BETA_9D
                } else {
                    MADGWICK_BETA_6D
                });
                AnyFilter::Madgwick(Madgwick::new(rate, beta, mag, sign).map_err(refused)?)
            }
            FilterKind::Mahony => {
                let kp = self.setting("Kp")?.unwrap_or(MAHONY_KP);
                let ki = self.setting("Ki")?.unwrap_or(MAHONY_KI);
                AnyFilter::Mahony(Mahony::new(rate, kp, ki, mag, sign).map_err(refused)?)
            }
            FilterKind::Robust => {
                let mut p = RobustParams {
                    sample_rate_hz: rate,
                    accel_sign: sign,
                    magnetometer: mag,
                    ..RobustParams::default()
                };
                for (name, field) in p.settings_mut() {
                    if name == "SampleRate" {
                        continue; // the filter's rate, set above
                    }
                    if let Some(v) = self.setting(name)? {
                        *field = v;
                    }
                }
                AnyFilter::Robust(RobustFilter::new(p).map_err(refused)?)
            }
            FilterKind::Complementary => {
                let ka = self
                    .setting("AccelerometerGain")?
                    .unwrap_or(COMPLEMENTARY_GAIN);
                let km = self
                    .setting("MagnetometerGain")?
                    .unwrap_or(COMPLEMENTARY_GAIN);
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

mod csv;
mod rows;

pub use csv::{OrientSummary, orient_csv, orient_row};
pub use rows::{Estimates, ecompass_rows, quaternion_distances, run_rows, smooth_rows};
