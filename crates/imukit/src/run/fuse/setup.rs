//! How the filter fuses: its model (frame, Earth, noise, the receiver's accuracy, the aids'),
//! its policy (gate, covariance interval, rest, smoothing, stances) and the settings it takes
//! from a scenario or a part's figures.
use imu_core::AccelSign;
use imu_core::aiding::PositionNoise;
use imu_core::fusion::process_noise::{FLICKER_FLOOR, eskf_noise};
use imu_core::fusion::{EskfNoise, FixErrorModel, InitialSigma, SensorErrorSigma};

use super::FuseModel;
use crate::error::{Error, RequestOption, Result, refused};
use crate::io::conventions::NavFrameName;

/// How to fuse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseSetup {
    /// Navigation frame of the tables.
    pub nav_frame: NavFrameName,
    /// `None`: the flat Earth; on the WGS-84 Earth its gravity model (the fixes are then
    /// geodetic, see [`GNSS_EARTH_COLUMNS`](crate::io::columns::GNSS_EARTH_COLUMNS)).
    pub earth: Option<imu_core::earth::GravityModel>,
    /// Sign of the accelerometer columns.
    pub accel_sign: AccelSign,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// The IMU's noise as the filter models it.
    pub noise: EskfNoise,
    /// Initial uncertainty.
    pub initial_sigma: InitialSigma,
    /// The part's own bias figures (accelerometer m/s², gyroscope rad/s): its constant bias and
    /// bias-instability floor in quadrature, per worst axis. A static alignment states its
    /// accuracy from them (the filter's `initial_sigma` keeps wider floors for parts that give
    /// no figure).
    pub part_bias: [f64; 2],
    /// GNSS position one-sigma (x, y, z of the frame), m: white fixes' own, or the stationary
    /// deviation of correlated ones.
    pub gnss_position_sigma_m: [f64; 3],
    /// How the fixes' position errors evolve (the receiver's `[gnss]` model), when it is
    /// stated. Correlated in time — MATLAB's decay factor `k` in (0, 1) per fix, or a
    /// Gauss–Markov correlation time — they become filter states
    /// (`imu_core::fusion::fix_errors`) of stationary one-sigma `gnss_position_sigma_m`, each
    /// fix then told only a white part of [`FIX_WHITE_SIGMA_M`] (or its own accuracy columns):
    /// MATLAB's process from its first fix, a Gauss–Markov one in its stationary state. A decay
    /// factor of 0 or 1, or no process stated (`None`): white fixes.
    pub gnss_position_noise: Option<PositionNoise>,
    /// GNSS velocity one-sigma per axis, m/s (`None`: position only).
    pub gnss_velocity_sigma_m_s: Option<f64>,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// The receiver's latency, s: a fix stamped `t` was valid at `t − latency` (`[gnss]
    /// latency_s`); the filter compares it with its state predicted back that far.
    pub gnss_latency_s: f64,
    /// The innovation gate of the fixes.
    pub gate: Gate,
    /// Ground-vehicle and barometer aiding (all off by default).
    pub aiding: AidingSetup,
    /// Estimate the IMU's scale-factor, misalignment and g-sensitivity errors: 36 error states
    /// instead of 15 (see `imu_core::fusion::sensor_errors`), starting from
    /// `sensor_error_sigma`; the estimate gains [`sensor_error_columns`](super::sensor_error_columns). Off by default.
    pub estimate_sensor_errors: bool,
    /// Whether the part's error figures are its own (a scenario's, a preset's, a parameter
    /// file's); `false` for a part learnt from the log, whose bias and matrix figures are an
    /// unknown part's stand-ins: its sensor errors are then estimated only when asked.
    pub figures_known: bool,
    /// Their initial one-sigma: the part's own figures (`axes_misalignment_pct`,
    /// `acceleration_bias`; worst entry), at least [`MIN_SENSOR_ERROR_SIGMA`] and
    /// [`MIN_G_SENSITIVITY_SIGMA`].
    pub sensor_error_sigma: SensorErrorSigma,
    /// The vehicle stands still for the IMU's first `rest_s` seconds: the filter is told so
    /// at every sample there (zero velocity within [`REST_VELOCITY_SIGMA_M_S`], zero angular
    /// rate within one sample's gyroscope noise), which calibrates the gyroscope biases
    /// before the vehicle moves. 0 (the default): no rest.
    pub rest_s: f64,
    /// Find the rest at the start from the readings instead (`imu_core::stillness`, with the
    /// part's white noise); `rest_s` is then replaced by what is found.
    pub detect_rest: bool,
    /// Smooth the estimate forward–backward (`imu_core::fusion::smoother`): the output is the
    /// smoothed estimate and its one-sigma.
    pub smooth: bool,
    /// Zero-velocity updates wherever the readings show a stance (a foot-mounted IMU): the SHOE
    /// detector (`imu_core::stillness::detect_stance`) with the part's noise, the gyroscope's
    /// mean over the rest at the start taken off; zero velocity and zero rate at each stance
    /// sample, as at rest.
    pub zupt: bool,
    /// The covariance is propagated once per this interval and at every update, s (0: every
    /// IMU sample); see `Eskf::with_covariance_interval`. The one-sigma columns then hold the
    /// covariance of the last step.
    pub covariance_interval_s: f64,
    /// The bound of the fixes' noise scaling from their innovations, in variance (see
    /// `run::fuse::adapt`; 1, the default: the stated accuracy always). Off by default: the
    /// innovations cannot tell a receiver worse than stated from an IMU worse than modelled,
    /// and scaling the fixes for the IMU's fault would hide it (a consumer part without its
    /// sensor-error states is then never reset to the fixes, its one-sigma grown instead).
    /// [`DEFAULT_MAX_FIX_NOISE_SCALE`](super::DEFAULT_MAX_FIX_NOISE_SCALE) is the bound a front
    /// end's switch turns it on with.
    pub max_fix_noise_scale: f64,
}

/// Which fixes (and aid readings) the filter takes: the core's [`Gate`].
pub use imu_core::fusion::gate::Gate;

/// The covariance interval [`FuseSetup::from_scenario`] chooses, s: 20 Hz, four times less
/// work than every sample at 100 Hz, and the same NEES to three digits in the consistency test
/// (covariance at 10 Hz there).
pub const DEFAULT_COVARIANCE_INTERVAL_S: f64 = 0.05;

/// How the filter uses aids besides GNSS: one-sigmas of what it is told; `None` is off.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AidingSetup {
    /// Odometer forward speed, white one-sigma, m/s; a scale-factor error `k` (fraction) is
    /// added as `|k·v|` in quadrature (the filter does not estimate it).
    pub odometer: Option<OdometerModel>,
    /// Non-holonomic constraints: the body's lateral and vertical velocity are 0 within this
    /// one-sigma, m/s, applied with every odometer reading or, without an odometer, at
    /// [`NHC_RATE_HZ`].
    pub nhc_sigma_m_s: Option<f64>,
    /// Barometric height: white one-sigma, m (a constant bias is not estimated).
    pub baro_sigma_m: Option<f64>,
}

/// The odometer as the filter models it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometerModel {
    /// White noise one-sigma, m/s.
    pub noise_m_s: f64,
    /// Scale-factor error, fraction.
    pub scale_factor_error: f64,
}

/// The white part of a correlated fix's error the filter is told when the fixes carry no
/// accuracy of their own, m: MATLAB's processes have none, and a filter told none would have
/// nothing between its state and the fix but the fix-error states.
pub const FIX_WHITE_SIGMA_M: f64 = 1e-3;

/// The least initial one-sigma of a scale-factor or misalignment entry the filter estimates
/// (a fraction: 100 ppm), for parts whose parameters state none.
pub const MIN_SENSOR_ERROR_SIGMA: f64 = 1e-4;

/// The least initial one-sigma of the gyroscopes' g-sensitivity the filter estimates,
/// (rad/s)/(m/s²) (about 0.001 °/s per g).
pub const MIN_G_SENSITIVITY_SIGMA: f64 = 1e-6;

/// One-sigma of the zero-velocity update at rest, m/s.
pub const REST_VELOCITY_SIGMA_M_S: f64 = 1e-3;

/// The non-holonomic constraints' one-sigma when a front end turns them on without one, m/s
/// (`--nhc` alone): a car's sideways and vertical body velocity, slip and suspension included.
pub const DEFAULT_NHC_SIGMA_M_S: f64 = 0.1;

/// Rate of the non-holonomic constraints when no odometer paces them, Hz.
pub const NHC_RATE_HZ: f64 = 10.0;

/// The refusal of `setup`'s covariance interval.
pub(super) fn covariance_interval_refusal(setup: &FuseSetup) -> Error {
    refused(
        RequestOption::CovarianceInterval,
        format!(
            "must be a finite number ≥ 0 (s), got {}",
            setup.covariance_interval_s
        ),
    )
}

/// The initial one-sigma of a triad's scale-factor and misalignment entries from its
/// `axes_misalignment_pct` (`100 (I + M)`): the largest `|Mᵢᵢ|` and the largest `|Mᵢⱼ|`, each
/// at least [`MIN_SENSOR_ERROR_SIGMA`].
fn matrix_sigma(p: &crate::sensor::SensorParams) -> (f64, f64) {
    let a = &p.axes_misalignment_pct;
    let (mut scale, mut cross) = (0.0_f64, 0.0_f64);
    for (r, row) in a.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            if r == c {
                scale = scale.max((v / 100.0 - 1.0).abs());
            } else {
                cross = cross.max((v / 100.0).abs());
            }
        }
    }
    (
        scale.max(MIN_SENSOR_ERROR_SIGMA),
        cross.max(MIN_SENSOR_ERROR_SIGMA),
    )
}

/// The scale-factor or misalignment one-sigma (a fraction: 0.5 %) from which a part's errors
/// are estimated by default: a 0.5 % scale-factor error turns a 90° turn into 8 mrad of
/// heading. Consumer parts' 1–2 % cross-axis sensitivity is above it; the tactical and
/// industrial presets' 0.1 % and less are below.
pub const SENSOR_ERROR_STATES_FROM: f64 = 5e-3;

/// The gyroscope g-sensitivity, (rad/s)/(m/s²), from which a part's errors are estimated by
/// default (about 0.06 °/s per g: a car's 0.3 g of braking then reads as 30 °/h).
pub const G_SENSITIVITY_STATES_FROM: f64 = 1e-5;

impl FuseSetup {
    /// The factor that turns the accelerometer columns into specific force (−1 for MATLAB's
    /// sign).
    #[must_use]
    pub fn specific_force_factor(&self) -> f64 {
        match self.accel_sign {
            AccelSign::SpecificForce => 1.0,
            AccelSign::Matlab => -1.0,
        }
    }

    /// The fixes' correlated error as the filter models it, for fixes every `fix_interval_s`
    /// (the decay factor is per fix): `None` for white fixes
    /// ([`FuseSetup::gnss_position_noise`]) or an interval that is not positive.
    #[must_use]
    pub fn fix_error_model(&self, fix_interval_s: f64) -> Option<FixErrorModel> {
        match self.gnss_position_noise? {
            PositionNoise::DecayFactor(k) => {
                FixErrorModel::from_decay_factor(k, fix_interval_s, self.gnss_position_sigma_m)
            }
            PositionNoise::GaussMarkov { correlation_time_s } => {
                FixErrorModel::stationary(correlation_time_s, self.gnss_position_sigma_m)
            }
        }
    }

    /// Whether the fixes' errors are correlated in time, so that the filter carries them as
    /// states ([`FuseSetup::fix_error_model`]).
    #[must_use]
    pub fn correlated_fixes(&self) -> bool {
        self.fix_error_model(1.0).is_some()
    }

    /// Whether the part's own scale-factor, misalignment or g-sensitivity figures are large
    /// enough ([`SENSOR_ERROR_STATES_FROM`], [`G_SENSITIVITY_STATES_FROM`]) that the filter
    /// should estimate them: what `fuse` does when not told (never for figures that are not
    /// the part's own, [`FuseSetup::figures_known`]).
    #[must_use]
    pub fn warrants_sensor_errors(&self) -> bool {
        let e = &self.sensor_error_sigma;
        let matrices = [
            e.accel_scale_factor,
            e.accel_misalignment,
            e.gyro_scale_factor,
            e.gyro_misalignment,
        ]
        .iter()
        .any(|s| *s >= SENSOR_ERROR_STATES_FROM);
        self.figures_known && (matrices || e.gyro_g_sensitivity >= G_SENSITIVITY_STATES_FROM)
    }

    /// The filter for data simulated by `scenario`: its frame, accelerometer sign, gravity, the
    /// IMU's noise (white and drift PSDs, `imu_core::fusion::process_noise`) and the `[gnss]`
    /// receiver's accuracy, error process and lever arm (the fixes' stationary deviation,
    /// `σ √(2/(1 + k))` for MATLAB's decay factor `k`; correlated fixes' errors as filter
    /// states when `[gnss]` states its process, [`FuseSetup::gnss_position_noise`]). Initial uncertainty: position as the fixes, 0.1 m/s,
    /// 0.01 rad of tilt and 0.05 rad of heading, and the parts' constant biases (at least
    /// 0.01 m/s² and 1e-4 rad/s). Aids: the `[odometer]` noise and scale-factor error, the
    /// `[baro]` noise with its bias in quadrature (neither estimated); the non-holonomic
    /// constraints stay off (a scenario does not say its vehicle is on wheels). The covariance
    /// is stepped every [`DEFAULT_COVARIANCE_INTERVAL_S`].
    ///
    /// # Errors
    /// A scenario without `[gnss]`.
    pub fn from_scenario(scenario: &crate::Scenario) -> Result<Self> {
        let gnss = scenario.gnss.as_ref().ok_or_else(|| {
            refused(
                RequestOption::Scenario,
                "has no [gnss] receiver: the filter takes the fixes' accuracy from it",
            )
        })?;
        Ok(Self::from_model(&FuseModel {
            nav_frame: scenario.nav_frame,
            earth: match &scenario.earth {
                crate::scenario::EarthSetup::Flat => None,
                crate::scenario::EarthSetup::Wgs84(plane) => Some(plane.gravity),
            },
            accel_sign: scenario.imu.accel_sign,
            gravity_m_s2: scenario.gravity_m_s2,
            imu: &scenario.imu.sensors.params,
            sample_rate_hz: scenario.sample_rate_hz,
            gnss: &gnss.params,
            gnss_process_stated: gnss.process_stated,
            lever_arm_m: gnss.lever_arm_m,
            gnss_latency_s: gnss.latency_s,
            odometer: scenario.odometer.map(|o| OdometerModel {
                noise_m_s: o.error.noise,
                scale_factor_error: o.error.constant,
            }),
            baro_sigma_m: scenario.baro.map(|b| b.error.noise.hypot(b.error.constant)),
        }))
    }

    /// The filter's setup from its model ([`FuseModel`]): noise from the part's densities at
    /// the sample rate, initial uncertainty from its biases and the fixes' accuracy, the
    /// GNSS one-sigmas from the receiver's accuracies (MATLAB's decay factor's steady share) and
    /// its error process,
    /// the gate at 99.9 %, the covariance every [`DEFAULT_COVARIANCE_INTERVAL_S`].
    #[must_use]
    pub fn from_model(m: &FuseModel<'_>) -> Self {
        let p = m.imu;
        let noise = eskf_noise(&p.accelerometer, &p.gyroscope, m.sample_rate_hz);
        let g = m.gnss;
        let scale = match g.position_noise {
            PositionNoise::DecayFactor(k) => FixErrorModel::decay_factor_sigma_ratio(k),
            PositionNoise::GaussMarkov { .. } => 1.0,
        };
        // A zero accuracy (exact fixes) still needs a little trust in the model.
        let floor = |s: f64| s.max(1e-3);
        let (h, v) = (
            floor(g.horizontal_accuracy_m * scale),
            floor(g.vertical_accuracy_m * scale),
        );
        let max_abs = |v: [f64; 3]| v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let (accel_scale_factor, accel_misalignment) = matrix_sigma(&p.accelerometer);
        let (gyro_scale_factor, gyro_misalignment) = matrix_sigma(&p.gyroscope);
        Self {
            nav_frame: m.nav_frame,
            earth: m.earth,
            accel_sign: m.accel_sign,
            gravity_m_s2: m.gravity_m_s2,
            noise,
            initial_sigma: InitialSigma {
                position_m: h.max(v),
                velocity_m_s: 0.1,
                attitude_rad: [0.01, 0.01, 0.05],
                accel_bias_m_s2: max_abs(p.accelerometer.constant_bias).max(0.01),
                gyro_bias_rad_s: max_abs(p.gyroscope.constant_bias).max(1e-4),
            },
            part_bias: [
                max_abs(p.accelerometer.constant_bias)
                    .hypot(FLICKER_FLOOR * max_abs(p.accelerometer.bias_instability)),
                max_abs(p.gyroscope.constant_bias)
                    .hypot(FLICKER_FLOOR * max_abs(p.gyroscope.bias_instability)),
            ],
            gnss_position_sigma_m: [h, h, v],
            gnss_position_noise: m.gnss_process_stated.then_some(g.position_noise),
            gnss_velocity_sigma_m_s: Some(floor(g.velocity_accuracy_m_s)),
            lever_arm_m: m.lever_arm_m,
            gnss_latency_s: m.gnss_latency_s,
            gate: Gate::ChiSquare(CHI2_99_9_6DOF),
            aiding: AidingSetup {
                odometer: m.odometer,
                nhc_sigma_m_s: None,
                baro_sigma_m: m.baro_sigma_m,
            },
            covariance_interval_s: DEFAULT_COVARIANCE_INTERVAL_S,
            max_fix_noise_scale: 1.0,
            estimate_sensor_errors: false,
            figures_known: true,
            sensor_error_sigma: SensorErrorSigma {
                accel_scale_factor,
                accel_misalignment,
                gyro_scale_factor,
                gyro_misalignment,
                gyro_g_sensitivity: max_abs(p.gyroscope.acceleration_bias)
                    .max(MIN_G_SENSITIVITY_SIGMA),
            },
            rest_s: 0.0,
            detect_rest: false,
            smooth: false,
            zupt: false,
        }
    }
}

impl FuseSetup {
    /// What an estimate made with this setup holds ([`crate::io::description::Description`]):
    /// a fused table in the setup's frame, on its Earth, with its gravity.
    #[must_use]
    pub fn description(&self) -> crate::io::description::Description {
        crate::io::description::Description::of_navigation(
            crate::io::schema::TableKind::Fused,
            self.nav_frame,
            self.earth,
            self.gravity_m_s2,
        )
    }
}

/// The default innovation gate of a position-and-velocity fix: the chi-square 99.9 % quantile
/// with 6 degrees of freedom (a good fix is rejected once in a thousand).
pub const CHI2_99_9_6DOF: f64 = imu_core::fusion::gate::CHI2_99_9[5];
