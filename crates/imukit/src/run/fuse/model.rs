//! What the filter's model is made of, from a scenario or stated apart from any: a part by a
//! preset's name or a parameter file, the receiver's accuracies.
use imu_core::AccelSign;

use super::{FuseSetup, OdometerModel};
use crate::error::Data;
use crate::error::{Result, invalid};
use crate::io::conventions::NavFrameName;
use crate::io::table::Table;

/// What the filter's model is made of, from a scenario ([`FuseSetup::from_scenario`]) or
/// stated apart from any ([`PartModel`]): the data's frame, Earth, gravity and accelerometer
/// sign, the part's error figures at the data's sample rate, and the aids' accuracies.
#[derive(Clone, Copy, Debug)]
pub struct FuseModel<'a> {
    /// Navigation frame of the tables.
    pub nav_frame: NavFrameName,
    /// `None`: the flat Earth; on the WGS-84 Earth its gravity model.
    pub earth: Option<imu_core::earth::GravityModel>,
    /// Sign of the accelerometer columns.
    pub accel_sign: AccelSign,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// The part's error figures.
    pub imu: &'a crate::io::params::ImuParams,
    /// The data's sample rate, Hz (a double-sided density's bandwidth).
    pub sample_rate_hz: f64,
    /// The receiver's accuracies and noise model.
    pub gnss: &'a imu_core::aiding::GnssParams,
    /// Whether the receiver's error process (decay factor or correlation time) is stated, not
    /// a default: only then are correlated fixes modelled as such
    /// ([`FuseSetup::gnss_position_noise`]); a receiver of unknown process is taken as white.
    pub gnss_process_stated: bool,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// The receiver's latency, s.
    pub gnss_latency_s: f64,
    /// The odometer's model (`None`: none).
    pub odometer: Option<OdometerModel>,
    /// The barometer's one-sigma, m (`None`: none).
    pub baro_sigma_m: Option<f64>,
}

/// A part: a built-in preset by its name, a parameter file, or what the log itself shows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Part {
    /// A preset's name (`imukit presets`).
    Preset(String),
    /// A parameter file (imukit TOML or JSON, MATLAB `loadparams` JSON).
    File(std::path::PathBuf),
    /// No data sheet: the white noise learnt from the log's quiet stretches
    /// ([`learnt_noise`](super::learnt_noise)); the rest — bias stability and constant bias —
    /// as an unknown consumer part's, [`LEARNT_BASE_PRESET`]'s figures (wide enough that the
    /// filter learns the biases at rest and at stances).
    Learnt,
}

/// The preset whose bias figures stand for an unknown part's ([`Part::Learnt`]): the least
/// stable consumer part among the presets.
pub const LEARNT_BASE_PRESET: &str = "mpu-6050";

impl Default for Part {
    fn default() -> Self {
        Self::Preset(String::new())
    }
}

impl Part {
    /// What a front end's one argument names (`--imu PRESET|FILE`, Python's `imu=`): a file when
    /// it has an extension or exists, else a preset's name.
    #[must_use]
    pub fn named(name: &str) -> Self {
        let path = std::path::Path::new(name);
        if path.extension().is_some() || path.exists() {
            Self::File(path.to_path_buf())
        } else {
            Self::Preset(name.to_string())
        }
    }
}

/// The filter's model apart from any scenario: the part by a preset's name or a parameter
/// file (`imukit fuse --imu stim300`, `--imu part.toml`), the GNSS receiver as `[gnss]` keys
/// (`--gnss-horizontal-accuracy-m` …; MATLAB's defaults for the rest), the data's frame and
/// Earth from the inputs' descriptions ([`PartModel::setup`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartModel {
    /// The part.
    pub imu: Part,
    /// The part in a MATLAB file of several.
    pub part: Option<String>,
    /// The receiver (its rate is not used).
    pub gnss: crate::scenario::gnss::GnssSpec,
}

impl PartModel {
    /// [`PartModel::setup`] for the IMU table `imu`, at its median sample rate; for
    /// [`Part::Learnt`], the white noise learnt from the table's quiet stretches.
    ///
    /// # Errors
    /// As [`PartModel::setup`]; fewer than two samples with increasing times; for
    /// [`Part::Learnt`], a log without enough quiet stretches to learn from.
    pub fn setup_for(
        &self,
        nav: &crate::run::navigate::NavSetup,
        accel_sign: Option<AccelSign>,
        imu: &Table,
    ) -> Result<FuseSetup> {
        let t = imu.column("t_s").unwrap_or_default();
        let median = crate::io::rows::Gaps::of_times(&t, 0).median_s;
        if median.is_nan() || median <= 0.0 {
            return Err(invalid(
                Data::Imu,
                "needs at least two samples with increasing t_s (the sample rate sets the noise)",
            ));
        }
        if self.imu != Part::Learnt {
            return self.setup(nav, accel_sign, 1.0 / median);
        }
        let base = Self {
            imu: Part::Preset(LEARNT_BASE_PRESET.into()),
            ..self.clone()
        };
        let mut setup = base.setup(nav, accel_sign, 1.0 / median)?;
        let (Some(f), Some(w)) = (
            imu.triples(&crate::io::columns::ACCEL_COLUMNS),
            imu.triples(&crate::io::columns::GYRO_COLUMNS),
        ) else {
            return Err(invalid(
                Data::Imu,
                "needs accel_* and gyro_* columns to learn the sensor's noise from",
            ));
        };
        let quiet = super::learnt_noise(&f, &w, median, setup.gravity_m_s2).ok_or_else(|| {
            invalid(
                Data::Imu,
                format!(
                    "the log has too few quiet stretches ({} blocks of {} s still) to learn its \
                     sensor's noise from: name the part (a preset or a parameter file)",
                    imu_core::stillness::MIN_QUIET_BLOCKS,
                    super::QUIET_WINDOW_S
                ),
            )
        })?;
        // Per-sample standard deviations back to densities at this rate.
        setup.noise.accel_psd = quiet.noise.accel * median.sqrt();
        setup.noise.gyro_psd = quiet.noise.gyro * median.sqrt();
        setup.figures_known = false;
        Ok(setup)
    }

    /// The filter's setup for data in the frame, Earth and sign of `nav` (the accelerometer
    /// sign, when `accel_sign` is `None`, the part's profile's) sampled at `sample_rate_hz`.
    ///
    /// # Errors
    /// An unknown preset, an unreadable or invalid parameter file, GNSS keys out of range (named
    /// `gnss.…`).
    pub fn setup(
        &self,
        nav: &crate::run::navigate::NavSetup,
        accel_sign: Option<AccelSign>,
        sample_rate_hz: f64,
    ) -> Result<FuseSetup> {
        let (preset, params) = match &self.imu {
            Part::Preset(name) => (Some(name.clone()), None),
            Part::File(path) => (None, Some(path.clone())),
            Part::Learnt => {
                return Err(crate::error::refused(
                    crate::error::RequestOption::Imu,
                    "a part learnt from the log needs the log: PartModel::setup_for",
                ));
            }
        };
        let spec = crate::scenario::ImuSpec {
            preset,
            params,
            part: self.part.clone(),
            ..crate::scenario::ImuSpec::default()
        };
        let sensors =
            crate::scenario::sensors::SensorSetup::resolve(&spec, std::path::Path::new("."))?;
        let (gnss, latency_s, lever_arm_m) = self.gnss.for_filter()?;
        Ok(FuseSetup::from_model(&FuseModel {
            nav_frame: nav.nav_frame,
            earth: nav.earth.map(|e| e.gravity),
            accel_sign: accel_sign.unwrap_or(sensors.profile.accel_sign()),
            gravity_m_s2: nav.gravity_m_s2,
            imu: &sensors.params,
            sample_rate_hz,
            gnss: &gnss,
            gnss_process_stated: self.gnss.process_stated(),
            lever_arm_m,
            gnss_latency_s: latency_s,
            odometer: None,
            baro_sigma_m: None,
        }))
    }
}

impl PartModel {
    /// [`PartModel::setup_for`] on data whose frame, Earth, gravity and accelerometer sign are
    /// what the user gave (`asked`), else what the inputs' descriptions say (`described`), else
    /// the conventions asked for, else the library's defaults (the sign: the part's profile's).
    ///
    /// # Errors
    /// An option that contradicts an input's description, or two inputs that disagree (the
    /// setting named); as [`PartModel::setup_for`].
    pub fn setup_described(
        &self,
        asked: &crate::run::navigate::NavAsked,
        described: &crate::io::described::Described,
        imu: &Table,
    ) -> Result<FuseSetup> {
        let nav = crate::run::navigate::NavRequest::default()
            .with_described(asked, described)?
            .setup()?;
        self.setup_for(&nav, asked.accel_sign_of(described)?, imu)
    }
}
