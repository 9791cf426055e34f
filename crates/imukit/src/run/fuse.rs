//! Loosely coupled INS/GNSS fusion for the CLI and Python: the core's error-state filter
//! ([`imu_core::fusion::eskf`]) over an IMU table (rates) and a GNSS table, on the flat Earth or
//! WGS-84 (fixes then geodetic), in the data's own frame (`run::nav_earth`).
//! Odometer, barometer and the constraints aid it alike on both (`fuse_aids`).
//!
//! Output: [`FUSE_COLUMNS`] — the navigation columns of `integrate`, the one-sigma of position,
//! velocity and attitude (navigation-frame axes), and the bias estimates (body axes) — then on
//! WGS-84 `lat_rad, lon_rad, height_m`, one row per IMU sample. A fix is applied at the first IMU
//! sample at or after its stamp (fixes are taken at IMU samples in imukit's simulations, so
//! exactly there).
use crate::io::columns::{FIX_ACCURACY_COLUMNS, FUSE_COLUMNS};
use imu_core::fusion::align::{self, PartFigures};
use imu_core::fusion::process_noise::{FLICKER_FLOOR, eskf_noise};
use imu_core::fusion::smoother::{ErrorVector, rts_backward};
use imu_core::fusion::{
    BASE_STATES, Eskf, EskfError, EskfNoise, EskfState, FULL_STATES, GnssFix, InitialSigma,
    SensorErrorEstimate, SensorErrorSigma, corrected_state,
};
use imu_core::strapdown::NavState;
use imu_core::{AccelSign, Body, Vec3};

use crate::io::columns::{ACCEL_COLUMNS, GYRO_COLUMNS, NAV_COLUMNS};

use crate::choice::{Choice, display_as_name};
use crate::error::{Error, Result, invalid};
use crate::io::conventions::{EarthName, NavFrameName};
use crate::io::table::Table;
use crate::run::fuse_aids::AidStreams;
use crate::run::nav_earth::{self, EarthJob, NavEarth, on_earth};
use crate::run::navigate::InitialState;

/// The columns a fused estimate gains when the filter estimates the IMU's scale-factor,
/// misalignment and g-sensitivity errors ([`FuseSetup::estimate_sensor_errors`]): for the
/// accelerometer then the gyroscope, row by row, a diagonal entry of `M` as
/// `<triad>_scale_factor_<axis>` and an off-diagonal one as `<triad>_misalignment_<row><column>`
/// (fractions: the reading is `(I + M) x + b`), then the gyroscopes' g-sensitivity
/// `gyro_g_sensitivity_<axis>_rad_s_per_m_s2`, then the same names with `_sigma` for their
/// one-sigma (before the unit).
#[must_use]
pub fn sensor_error_columns() -> Vec<String> {
    let axes = ["x", "y", "z"];
    // (name, unit suffix)
    let mut names: Vec<(String, &str)> = ["accel", "gyro"]
        .iter()
        .flat_map(|triad| {
            (0..9).map(move |k| {
                let (r, c) = (k / 3, k % 3);
                if r == c {
                    (format!("{triad}_scale_factor_{}", axes[r]), "")
                } else {
                    (format!("{triad}_misalignment_{}{}", axes[r], axes[c]), "")
                }
            })
        })
        .collect();
    names.extend(axes.map(|a| (format!("gyro_g_sensitivity_{a}"), "_rad_s_per_m_s2")));
    let values = names.iter().map(|(n, u)| format!("{n}{u}"));
    let sigmas = names.iter().map(|(n, u)| format!("{n}_sigma{u}"));
    values.chain(sigmas).collect()
}

/// The column names of a fused estimate: `base` and, with the sensor matrices,
/// [`sensor_error_columns`].
fn fused_columns(base: &[&str], sensor_errors: bool) -> Vec<String> {
    let mut columns: Vec<String> = base.iter().map(|c| (*c).to_string()).collect();
    if sensor_errors {
        columns.extend(sensor_error_columns());
    }
    columns
}

/// Appends the sensor errors' estimates and one-sigmas (`sigmas`: the 21 states in order) to
/// `row`.
fn push_sensor_errors(row: &mut Vec<f64>, estimate: &SensorErrorEstimate, sigmas: &[f64]) {
    for m in [&estimate.accel, &estimate.gyro] {
        for r in m {
            row.extend_from_slice(r);
        }
    }
    row.extend_from_slice(&estimate.gyro_g_sensitivity);
    row.extend_from_slice(sigmas);
}

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
    /// GNSS position one-sigma (x, y, z of the frame), m.
    pub gnss_position_sigma_m: [f64; 3],
    /// GNSS velocity one-sigma per axis, m/s (`None`: position only).
    pub gnss_velocity_sigma_m_s: Option<f64>,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// The receiver's latency, s: a fix stamped `t` was valid at `t − latency` (`[gnss]
    /// latency_s`); the filter compares it with its state predicted back that far.
    pub gnss_latency_s: f64,
    /// Innovation gate: NIS above this chi-square value is rejected (`f64::INFINITY`: off).
    pub gate: f64,
    /// Ground-vehicle and barometer aiding (all off by default).
    pub aiding: AidingSetup,
    /// Estimate the IMU's scale-factor, misalignment and g-sensitivity errors: 36 error states
    /// instead of 15 (see `imu_core::fusion::sensor_errors`), starting from
    /// `sensor_error_sigma`; the estimate gains [`sensor_error_columns`]. Off by default.
    pub estimate_sensor_errors: bool,
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
}

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

/// The least initial one-sigma of a scale-factor or misalignment entry the filter estimates
/// (a fraction: 100 ppm), for parts whose parameters state none.
pub const MIN_SENSOR_ERROR_SIGMA: f64 = 1e-4;

/// The least initial one-sigma of the gyroscopes' g-sensitivity the filter estimates,
/// (rad/s)/(m/s²) (about 0.001 °/s per g).
pub const MIN_G_SENSITIVITY_SIGMA: f64 = 1e-6;

/// One-sigma of the zero-velocity update at rest, m/s.
pub const REST_VELOCITY_SIGMA_M_S: f64 = 1e-3;

/// Rate of the non-holonomic constraints when no odometer paces them, Hz.
pub const NHC_RATE_HZ: f64 = 10.0;

/// Aid readings beside the IMU and GNSS tables.
#[derive(Clone, Copy, Debug, Default)]
pub struct AidTables<'a> {
    /// Odometer readings (`t_s, speed_m_s`, from `imukit simulate --odometer`).
    pub odometer: Option<&'a Table>,
    /// Barometer readings (`t_s, baro_height_m`, from `imukit simulate --baro`).
    pub baro: Option<&'a Table>,
}

/// What a fusion did besides its table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseSummary {
    /// Updates applied (fixes and aid readings).
    pub updates: usize,
    /// Updates rejected by the gate.
    pub rejected: usize,
    /// Resets to the fixes after [`MAX_REJECTED_IN_A_ROW`] of them were rejected in a row.
    pub resets: usize,
    /// The rest at the start the filter used, s (given, or found in the readings).
    pub rest_s: f64,
    /// Whether that rest was found in the readings ([`FuseSetup::detect_rest`]).
    pub rest_detected: bool,
    /// Whether the sensor-error states were estimated (36 states).
    pub sensor_errors: bool,
    /// Samples taken as stances by the zero-velocity detector ([`FuseSetup::zupt`]).
    pub stance_samples: usize,
}

/// The fused estimate's last column: the resets to the fixes so far (a step at each).
pub const RESETS_COLUMN: &str = "gnss_resets";

/// Where the filter starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start<'a> {
    /// At the first IMU sample, in this state (a truth row).
    State(&'a InitialState),
    /// Without truth: at the first GNSS fix whose horizontal speed is at least
    /// [`ALIGN_MIN_SPEED_M_S`], with position and velocity from the fix and the attitude of a
    /// vehicle moving nose first (heading and pitch along the fix's velocity, roll 0), each
    /// with its stated one-sigma (see [`gnss_alignment_sigma`]); the estimate begins there.
    AlignGnss,
    /// Without truth, at rest, on the WGS-84 Earth: levelling from the mean specific force and
    /// gyrocompassing from the mean body rate (the Earth rate's horizontal part points north)
    /// over the first `duration_s`, position from the fixes; the estimate begins at its end.
    /// Refused on the flat Earth, whose model has no Earth rate.
    AlignStatic {
        /// How long the vehicle stands still at the start, s.
        duration_s: f64,
    },
}

/// How long `--align static` averages, s.
pub const STATIC_ALIGN_S: f64 = 60.0;

/// An alignment by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlignName {
    /// [`Start::AlignGnss`].
    #[default]
    Gnss,
    /// [`Start::AlignStatic`] over [`STATIC_ALIGN_S`].
    Static,
}

impl Choice for AlignName {
    const WHAT: &'static str = "alignment";
    const NAMES: &'static [(&'static str, Self)] =
        &[("gnss", Self::Gnss), ("static", Self::Static)];
}

display_as_name!(AlignName);

impl From<AlignName> for Start<'_> {
    fn from(a: AlignName) -> Self {
        match a {
            AlignName::Gnss => Self::AlignGnss,
            AlignName::Static => Self::AlignStatic {
                duration_s: STATIC_ALIGN_S,
            },
        }
    }
}

/// A fusion as a front end states it, beside the scenario that gives the filter its model;
/// checked once, in [`FuseRequest::setup`], whose errors name the fields as written here
/// (`initial`, `align`, `earth`, `nhc_sigma_m_s`, `covariance_interval_s`, `rest_s`). Its
/// [`Default`] is every front end's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseRequest<'a> {
    /// Where the filter starts: a truth row…
    pub initial: Option<&'a InitialState>,
    /// …or an alignment (exactly one of the two).
    pub align: Option<AlignName>,
    /// The Earth the user expects; the scenario decides, so a different one is refused.
    pub earth: Option<EarthName>,
    /// The innovation gate ([`FuseSetup::gate`]) on.
    pub gate: bool,
    /// Non-holonomic constraints' one-sigma, m/s (`None`: off).
    pub nhc_sigma_m_s: Option<f64>,
    /// The covariance interval, s (`None`: [`DEFAULT_COVARIANCE_INTERVAL_S`]).
    pub covariance_interval_s: Option<f64>,
    /// Estimate the sensor errors (36 states); `None`: when the part warrants it
    /// ([`FuseSetup::warrants_sensor_errors`]).
    pub sensor_errors: Option<bool>,
    /// Seconds at rest at the start (`None`: found in the readings; `Some(0.0)`: no rest).
    pub rest_s: Option<f64>,
    /// Smooth the estimate forward–backward ([`FuseSetup::smooth`]).
    pub smooth: bool,
    /// Zero-velocity updates at stances ([`FuseSetup::zupt`]).
    pub zupt: bool,
}

impl Default for FuseRequest<'_> {
    fn default() -> Self {
        Self {
            initial: None,
            align: None,
            earth: None,
            gate: true,
            nhc_sigma_m_s: None,
            covariance_interval_s: None,
            sensor_errors: None,
            rest_s: None,
            smooth: false,
            zupt: false,
        }
    }
}

impl<'a> FuseRequest<'a> {
    /// The fields an error of [`Self::setup`] or of the fusion it sets up may name.
    pub const FIELDS: [&'static str; 6] = [
        "initial",
        "align",
        "earth",
        "nhc_sigma_m_s",
        "covariance_interval_s",
        "rest_s",
    ];

    /// The filter's setup from `scenario` and this request, and where it starts.
    ///
    /// # Errors
    /// Both starts or neither (field `initial`), an Earth other than the scenario's (field
    /// `earth`), and as [`FuseSetup::from_scenario`].
    pub fn setup(&self, scenario: &crate::Scenario) -> Result<(FuseSetup, Start<'a>)> {
        self.apply(FuseSetup::from_scenario(scenario)?)
    }

    /// This request applied to the filter's model `setup` (from a scenario or a
    /// [`PartModel`]), and where it starts.
    ///
    /// # Errors
    /// Both starts or neither (field `initial`), an Earth other than the model's (field
    /// `earth`).
    pub fn apply(&self, mut setup: FuseSetup) -> Result<(FuseSetup, Start<'a>)> {
        let start = match (self.initial, self.align) {
            (Some(s), None) => Start::State(s),
            (None, Some(a)) => a.into(),
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "initial",
                    "give the initial state or an alignment, not both",
                ));
            }
            (None, None) => {
                return Err(invalid(
                    "initial",
                    "the filter needs a start: the initial state (a truth row) or the alignment \
                     \"gnss\"",
                ));
            }
        };
        let earth = if setup.earth.is_some() {
            EarthName::Wgs84
        } else {
            EarthName::Flat
        };
        if let Some(e) = self.earth
            && e != earth
        {
            return Err(invalid(
                "earth",
                format!(
                    "\"{e}\": the filter's model (the scenario's, or the data's) is on the \
                     {earth} Earth"
                ),
            ));
        }
        if !self.gate {
            setup.gate = f64::INFINITY;
        }
        setup.aiding.nhc_sigma_m_s = self.nhc_sigma_m_s;
        if let Some(s) = self.covariance_interval_s {
            setup.covariance_interval_s = s;
        }
        setup.estimate_sensor_errors = self
            .sensor_errors
            .unwrap_or_else(|| setup.warrants_sensor_errors());
        match self.rest_s {
            Some(s) => {
                setup.rest_s = s;
                setup.detect_rest = false;
            }
            None => setup.detect_rest = true,
        }
        setup.smooth = self.smooth;
        setup.zupt = self.zupt;
        Ok((setup, start))
    }
}

/// The horizontal speed from which a GNSS velocity gives the heading, m/s.
pub const ALIGN_MIN_SPEED_M_S: f64 = 3.0;

/// One-sigma the alignment from GNSS allows for a vehicle's nose pointing off its velocity
/// (sideslip, angle of attack) and for its roll, rad.
pub const ALIGN_ATTITUDE_ALLOWANCE_RAD: [f64; 2] = [0.02, 0.05];

/// The one-sigma of a start aligned from a GNSS fix of velocity `v` (attitude by
/// [`imu_core::fusion::align::moving`]): position the fix's plus the lever arm's length (the
/// antenna's offset is not yet known in the navigation frame), velocity the fix's, heading and
/// pitch `σ_v/|v_h|` and [`ALIGN_ATTITUDE_ALLOWANCE_RAD`]`[0]` in quadrature, roll
/// [`ALIGN_ATTITUDE_ALLOWANCE_RAD`]`[1]` (roll about the heading and pitch across it, turned onto
/// the frame's horizontal axes), biases as `setup` has them.
#[must_use]
pub fn gnss_alignment_sigma(v: [f64; 3], setup: &FuseSetup) -> InitialSigma {
    let horizontal = v[0].hypot(v[1]);
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    let lever = setup.lever_arm_m.iter().map(|l| l * l).sum::<f64>().sqrt();
    let pos_sigma = setup
        .gnss_position_sigma_m
        .iter()
        .fold(0.0_f64, |a, b| a.max(*b));
    let angle = (vel_sigma / horizontal)
        .atan()
        .hypot(ALIGN_ATTITUDE_ALLOWANCE_RAD[0]);
    // Roll is about the heading, pitch across it: on the frame's horizontal axes, the diagonal
    // of σ_r² u uᵀ + σ_p² u⊥ u⊥ᵀ for the heading's unit vector u (the same in ENU and NED).
    let roll = ALIGN_ATTITUDE_ALLOWANCE_RAD[1];
    let (cos, sin) = (v[0] / horizontal, v[1] / horizontal);
    let tilt = |along: f64, across: f64| (roll * along).hypot(angle * across);
    InitialSigma {
        position_m: pos_sigma + lever,
        velocity_m_s: vel_sigma,
        attitude_rad: [tilt(cos, sin), tilt(sin, cos), angle],
        ..setup.initial_sigma
    }
}

/// Fuses `imu` (rates) with `gnss` ([`GNSS_COLUMNS`](crate::io::columns::GNSS_COLUMNS)) from `initial`;
/// a `gnss` table without columns is no fixes (the IMU and the other aids alone).
///
/// # Errors
/// Missing columns, GNSS times that do not increase or fall outside the IMU's span, the
/// filter's refusals (the sample or update named), a divergence.
pub fn fuse(
    imu: &Table,
    gnss: &Table,
    initial: &InitialState,
    setup: &FuseSetup,
) -> Result<(Table, FuseSummary)> {
    fuse_with(
        imu,
        gnss,
        AidTables::default(),
        Start::State(initial),
        setup,
    )
}

/// [`fuse`] with odometer and barometer readings: each table given is used with its model in
/// `setup.aiding` (a table without a model is refused, not ignored); the non-holonomic
/// constraints are used when `setup.aiding.nhc_sigma_m_s` is set.
///
/// # Errors
/// As [`fuse`]; an aid table without its columns or with times that do not increase or fall
/// outside the IMU's span (`odometer data, row …`); an aid table without its model.
pub fn fuse_with(
    imu: &Table,
    gnss: &Table,
    aids: AidTables<'_>,
    start: Start<'_>,
    setup: &FuseSetup,
) -> Result<(Table, FuseSummary)> {
    let (table, _, summary) = Fuse {
        imu,
        gnss,
        aids,
        start,
        setup,
        keep_filtered: false,
    }
    .on_its_earth()?;
    Ok((table, summary))
}

/// [`fuse_with`] smoothed forward–backward ([`FuseSetup::smooth`] whatever `setup` says), with
/// the forward filter's own table from the same pass: `(filtered, smoothed, summary)`, for
/// those who compare the two without running the filter twice.
///
/// # Errors
/// As [`fuse_with`].
pub fn fuse_filtered_and_smoothed(
    imu: &Table,
    gnss: &Table,
    aids: AidTables<'_>,
    start: Start<'_>,
    setup: &FuseSetup,
) -> Result<(Table, Table, FuseSummary)> {
    let setup = FuseSetup {
        smooth: true,
        ..*setup
    };
    let (smoothed, filtered, summary) = Fuse {
        imu,
        gnss,
        aids,
        start,
        setup: &setup,
        keep_filtered: true,
    }
    .on_its_earth()?;
    let filtered = filtered.ok_or_else(|| invalid("fuse", "the filtered table was not kept"))?;
    Ok((filtered, smoothed, summary))
}

/// [`fuse_with`] as an [`EarthJob`].
struct Fuse<'a> {
    imu: &'a Table,
    gnss: &'a Table,
    aids: AidTables<'a>,
    start: Start<'a>,
    setup: &'a FuseSetup,
    /// Smoothing, also write the forward filter's rows into a table of their own.
    keep_filtered: bool,
}

impl Fuse<'_> {
    /// Runs the fusion on the Earth and in the frame its setup names.
    fn on_its_earth(self) -> Result<(Table, Option<Table>, FuseSummary)> {
        let (frame, earth, gravity) = (
            self.setup.nav_frame,
            self.setup.earth,
            self.setup.gravity_m_s2,
        );
        on_earth(frame, earth, gravity, self)
    }
}

impl EarthJob for Fuse<'_> {
    type Output = Result<(Table, Option<Table>, FuseSummary)>;

    fn run<E: NavEarth>(self, earth: E) -> Self::Output {
        if self.setup.estimate_sensor_errors {
            fuse_on::<E, FULL_STATES>(earth, self)
        } else {
            fuse_on::<E, BASE_STATES>(earth, self)
        }
    }
}

/// GNSS stamps: finite, increasing, inside the IMU's span `[t0, t1]` (the row named), and not
/// more frequent on average than the IMU's `samples` (fixes are applied at IMU samples).
fn check_fix_times(g_t: &[f64], (t0, t1): (f64, f64), samples: usize) -> Result<()> {
    for (k, &tk) in g_t.iter().enumerate() {
        if !tk.is_finite() || (k > 0 && tk <= g_t[k - 1]) {
            return Err(invalid(
                "GNSS data",
                format!("row {}: times must be finite and increase", k + 2),
            ));
        }
        if tk < t0 || tk > t1 {
            return Err(invalid(
                "GNSS data",
                format!(
                    "row {}: time {tk} s is outside the IMU's span [{t0}, {t1}] s",
                    k + 2
                ),
            ));
        }
    }
    if let (Some(&first), Some(&last)) = (g_t.first(), g_t.last())
        && g_t.len() > 1
        && samples > 1
    {
        let (fix_dt, imu_dt) = (
            (last - first) / (g_t.len() - 1) as f64,
            (t1 - t0) / (samples - 1) as f64,
        );
        if fix_dt < imu_dt {
            return Err(invalid(
                "GNSS data",
                format!(
                    "fixes come every {fix_dt} s, more often than the IMU's samples (every \
                     {imu_dt} s): the filter applies fixes at IMU samples, so the IMU must be the \
                     faster sensor"
                ),
            ));
        }
    }
    Ok(())
}

/// The filter's refusal of reading `index` (0-based) of `what` (`GNSS`, `odometer`, …) as an
/// error naming its row: a divergence as [`Error::Diverged`], bad input as invalid data.
pub(crate) fn filter_refusal(what: &str, index: usize, e: EskfError) -> Error {
    let (context, row) = (format!("{what} data"), index + 2);
    match e {
        EskfError::Diverged { .. } => Error::Diverged {
            context,
            message: format!("row {row}: {e}"),
        },
        source => Error::Filter {
            context,
            row: Some(row),
            source,
        },
    }
}

/// What a fusion reads: IMU times and rates (the frame's body convention, as in the table),
/// GNSS stamps, positions (three columns) and velocities, checked.
struct FusionInputs {
    t: Vec<f64>,
    f: Vec<[f64; 3]>,
    w: Vec<[f64; 3]>,
    g_t: Vec<f64>,
    g_p: Vec<[f64; 3]>,
    /// The fixes' velocities (zeros where they have none).
    g_v: Vec<[f64; 3]>,
    /// What the fixes give of their velocity.
    velocities: FixVelocity,
    /// Each fix's own horizontal and vertical one-sigma ([`FIX_ACCURACY_COLUMNS`]), if the
    /// table gives them.
    accuracy: Option<Vec<[f64; 2]>>,
}

/// What a table of fixes gives of the velocity, by its columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FixVelocity {
    /// No velocity column: positions only (a `NavSatFix`, an NMEA `GGA`).
    None,
    /// The two horizontal columns only (NMEA's speed and course over ground): the vertical one
    /// is not known.
    Horizontal,
    /// All three.
    Full,
}

/// The one-sigma given to a vertical velocity the fixes do not know, m/s: no information.
const UNKNOWN_VELOCITY_SIGMA_M_S: f64 = 1e4;

impl FusionInputs {
    /// Reads `imu` (rates) and `gnss` (`columns`: `t_s`, three position and three velocity
    /// columns, the velocity's optional, or its vertical one alone; `hint` follows the list of
    /// missing ones)
    /// and checks the stamps ([`check_fix_times`]).
    ///
    /// # Errors
    /// Missing columns, named; the stamps' refusals.
    fn read(
        imu: &Table,
        gnss: &Table,
        columns: &[&str; 7],
        hint: &str,
        accuracy: [f64; 2],
    ) -> Result<Self> {
        let t = imu
            .column("t_s")
            .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
        let (Some(f), Some(w)) = (imu.triples(&ACCEL_COLUMNS), imu.triples(&GYRO_COLUMNS)) else {
            return Err(invalid(
                "IMU data",
                "fusion needs rates: accel_x/y/z_m_s2 and gyro_x/y/z_rad_s",
            ));
        };
        if t.len() < 2 {
            return Err(invalid(
                "IMU data",
                format!("{} rows: fusion needs at least two samples", t.len()),
            ));
        }
        let has = |c: &&str| gnss.columns.iter().any(|h| h == c);
        if gnss.columns.is_empty() {
            // No fixes at all (a table without columns): the IMU and the other aids alone.
            return Ok(Self {
                t,
                f,
                w,
                g_t: Vec::new(),
                g_p: Vec::new(),
                g_v: Vec::new(),
                velocities: FixVelocity::None,
                accuracy: None,
            });
        }
        // Positions only when none of the velocity's columns is there; the horizontal velocity
        // alone when the vertical one is missing.
        let velocities = match (columns[4..6].iter().any(has), has(&columns[6])) {
            (false, false) => FixVelocity::None,
            (true, false) => FixVelocity::Horizontal,
            _ => FixVelocity::Full,
        };
        let needed = match velocities {
            FixVelocity::None => &columns[..4],
            FixVelocity::Horizontal => &columns[..6],
            FixVelocity::Full => &columns[..],
        };
        let missing: Vec<&str> = needed.iter().copied().filter(|c| !has(c)).collect();
        if !missing.is_empty() {
            return Err(invalid(
                "GNSS data",
                format!("missing column(s) {}{hint}", missing.join(", ")),
            ));
        }
        let g_t = gnss.column("t_s").unwrap_or_default();
        let g_p = gnss
            .triples(&[columns[1], columns[2], columns[3]])
            .unwrap_or_default();
        let g_v = match velocities {
            FixVelocity::Full => gnss.triples(&[columns[4], columns[5], columns[6]]),
            FixVelocity::Horizontal => gnss
                .column(columns[4])
                .zip(gnss.column(columns[5]))
                .map(|(a, b)| a.into_iter().zip(b).map(|(x, y)| [x, y, 0.0]).collect()),
            FixVelocity::None => None,
        }
        .unwrap_or_else(|| vec![[0.0; 3]; g_t.len()]);
        check_fix_times(&g_t, (t[0], t[t.len() - 1]), t.len())?;
        let accuracy = fix_accuracy(gnss, accuracy)?;
        Ok(Self {
            t,
            f,
            w,
            g_t,
            g_p,
            g_v,
            velocities,
            accuracy,
        })
    }

    /// The IMU's span `[t₀, t₁]`, s.
    fn span(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// For the alignment from GNSS: the first fix `k` at [`ALIGN_MIN_SPEED_M_S`] or more, the
    /// IMU sample `i0` it is applied at, and its age there (latency included), s.
    ///
    /// # Errors
    /// No fix that fast.
    fn first_fix_at_speed(&self, latency_s: f64) -> Result<(usize, usize, f64)> {
        if self.velocities == FixVelocity::None {
            return Err(invalid(
                "GNSS data",
                "the fixes have no velocity (vel_* columns): the heading cannot be taken from \
                 GNSS velocity (give the initial state, or --align static on the WGS-84 Earth)",
            ));
        }
        let k = self
            .g_v
            .iter()
            .position(|v| v[0].hypot(v[1]) >= ALIGN_MIN_SPEED_M_S)
            .ok_or_else(|| {
                invalid(
                    "GNSS data",
                    format!(
                        "no fix with a horizontal speed of {ALIGN_MIN_SPEED_M_S} m/s or more: the \
                         heading cannot be taken from GNSS velocity (give the initial state \
                         instead)"
                    ),
                )
            })?;
        let t = &self.t;
        let i0 = t.partition_point(|&ti| ti < self.g_t[k]).min(t.len() - 1);
        Ok((k, i0, t[i0] - self.g_t[k] + latency_s))
    }
}

/// A fix table's own accuracy ([`FIX_ACCURACY_COLUMNS`]; where one of the two is missing,
/// `setup`'s for it), each value a positive finite number; `None` without either column.
///
/// # Errors
/// A value that is not positive and finite (its row).
fn fix_accuracy(gnss: &Table, setup: [f64; 2]) -> Result<Option<Vec<[f64; 2]>>> {
    let columns = FIX_ACCURACY_COLUMNS.map(|c| gnss.column(c));
    if columns.iter().all(Option::is_none) {
        return Ok(None);
    }
    let rows = gnss.rows();
    let [h, v] = [0, 1].map(|k| columns[k].clone().unwrap_or_else(|| vec![setup[k]; rows]));
    for (k, (a, b)) in h.iter().zip(&v).enumerate() {
        if !(a.is_finite() && b.is_finite() && *a > 0.0 && *b > 0.0) {
            return Err(invalid(
                "GNSS data",
                format!(
                    "row {}: the fix's accuracy must be positive and finite, got {a} m and {b} m",
                    k + 2
                ),
            ));
        }
    }
    Ok(Some(h.into_iter().zip(v).map(|(a, b)| [a, b]).collect()))
}

/// Resets after which the fixes are still rejected, one after another, before the fusion is
/// a divergence: the filter could not be brought back to them.
pub const MAX_RESETS_IN_A_ROW: usize = 3;

/// The fixes' acceptance, counted: rejected one after another, and the resets to them.
#[derive(Debug, Default)]
struct Acceptance {
    /// Fixes rejected since the last accepted one (or reset).
    rejected_in_a_row: usize,
    /// Resets since the last accepted fix.
    resets_in_a_row: usize,
    /// Resets in all.
    resets: usize,
}

impl Acceptance {
    /// Counts fix `index`'s outcome; `true` when it is the [`MAX_REJECTED_IN_A_ROW`]th rejected
    /// in a row: the filter is to be reset to it.
    ///
    /// # Errors
    /// The filter's refusal ([`filter_refusal`]); a divergence: as many fixes rejected in a row
    /// again after [`MAX_RESETS_IN_A_ROW`] resets.
    fn count(
        &mut self,
        outcome: std::result::Result<imu_core::fusion::UpdateOutcome, EskfError>,
        index: usize,
        gate: f64,
    ) -> Result<bool> {
        let outcome = outcome.map_err(|e| filter_refusal("GNSS", index, e))?;
        if outcome.accepted {
            self.rejected_in_a_row = 0;
            self.resets_in_a_row = 0;
            return Ok(false);
        }
        self.rejected_in_a_row += 1;
        if self.rejected_in_a_row < MAX_REJECTED_IN_A_ROW {
            return Ok(false);
        }
        if self.resets_in_a_row >= MAX_RESETS_IN_A_ROW {
            return Err(Error::Diverged {
                context: "GNSS data".into(),
                message: format!(
                    "row {}: {MAX_REJECTED_IN_A_ROW} fixes in a row rejected by the innovation \
                     gate (the last with NIS {:.1} against {gate:.1}) after {MAX_RESETS_IN_A_ROW} \
                     resets to the fixes: the fixes have jumped, the data are in another frame \
                     or with another accelerometer sign than the filter was told (nav_frame, \
                     accel_sign), or the IMU is not the one described; nothing is written",
                    index + 2,
                    outcome.nis
                ),
            });
        }
        self.rejected_in_a_row = 0;
        self.resets_in_a_row += 1;
        self.resets += 1;
        Ok(true)
    }
}

/// The GNSS speed above which a vehicle is not at rest for the static alignment, m/s.
const STATIC_SPEED_M_S: f64 = 0.5;

fn fuse_on<E: NavEarth, const S: usize>(
    earth: E,
    job: Fuse<'_>,
) -> Result<(Table, Option<Table>, FuseSummary)> {
    let Fuse {
        imu,
        gnss,
        aids,
        start,
        setup,
        keep_filtered,
    } = job;
    let [h, _, v] = setup.gnss_position_sigma_m;
    let inputs = FusionInputs::read(imu, gnss, E::GNSS_COLUMNS, E::GNSS_HINT, [h, v])?;
    let FusionInputs {
        t,
        f,
        w,
        g_t,
        g_p,
        g_v,
        velocities,
        accuracy,
    } = &inputs;
    let (t0, t1) = inputs.span();
    let found;
    let setup = if setup.detect_rest {
        let moving_at_start = match start {
            Start::State(initial) => {
                let v = initial.velocity_m_s;
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() > REST_START_SPEED_M_S
            }
            // Aligned from a fix at speed: the vehicle moves.
            Start::AlignGnss => true,
            Start::AlignStatic { .. } => false,
        };
        let readings_still = if moving_at_start {
            0.0
        } else {
            detected_rest_s(t, f, w, setup)
        };
        // Steady motion in a straight line reads like rest: a fix moving faster than 5σ of its
        // velocity before the rest's end overrules the readings (no rest at all: the readings
        // could not tell it from motion).
        let moves_at = (*velocities != FixVelocity::None)
            .then(|| {
                let limit = 5.0 * setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
                g_t.iter().zip(g_v).find(|(_, v)| {
                    let vertical = if *velocities == FixVelocity::Full {
                        v[2]
                    } else {
                        0.0
                    };
                    (v[0] * v[0] + v[1] * v[1] + vertical * vertical).sqrt() > limit
                })
            })
            .flatten()
            .map_or(f64::INFINITY, |(tk, _)| tk - t0);
        found = FuseSetup {
            rest_s: if moves_at < readings_still {
                0.0
            } else {
                readings_still
            },
            ..*setup
        };
        &found
    } else {
        setup
    };
    let mut aid_streams = AidStreams::new(aids, setup, (t0, t1), t.len())?;
    let stances = if setup.zupt {
        let stance = stance_samples(t, f, w, setup);
        let count = stance.iter().filter(|s| **s).count();
        aid_streams.set_stance(stance);
        count
    } else {
        0
    };
    let fixes = g_p
        .iter()
        .enumerate()
        .map(|(k, &p)| {
            E::fix_position(p).ok_or_else(|| {
                invalid(
                    "GNSS data",
                    format!(
                        "row {}: the latitude must be within ±89.9° and the longitude and height \
                         finite",
                        k + 2
                    ),
                )
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let fix_velocity: Vec<Vec3<E::Frame>> = g_v.iter().map(|&v| E::fix_velocity(v)).collect();
    let sign = match setup.accel_sign {
        AccelSign::SpecificForce => 1.0,
        AccelSign::Matlab => -1.0,
    };
    // The first IMU sample, state, plane origin and one-sigma; fixes before `next_fix` used.
    let (first, s0, origin, sigma, mut next_fix) = match start {
        Start::State(initial) => {
            let (s, origin) = nav_earth::start::<E>(initial, t0)?;
            (0, s, origin, setup.initial_sigma, 0)
        }
        Start::AlignStatic { .. } if !E::ROTATING => {
            return Err(invalid(
                "align",
                "\"static\": on the flat Earth the gyroscopes cannot find north (the flat model \
                 has no Earth rate); a static alignment needs a scenario on the WGS-84 Earth — \
                 use \"gnss\" (heading from the first fix at speed) or give the initial state",
            ));
        }
        Start::AlignStatic { duration_s } => {
            let i0 = t.partition_point(|&ti| ti < t0 + duration_s);
            if i0 < 2 || i0 >= t.len() {
                return Err(invalid(
                    "align",
                    format!(
                        "\"static\" averages the first {duration_s} s at rest: the IMU data must \
                         last longer"
                    ),
                ));
            }
            let used = g_t.partition_point(|&x| x <= t[i0]);
            if used == 0 {
                return Err(invalid(
                    "GNSS data",
                    format!(
                        "no fix in the first {duration_s} s: the static alignment takes its \
                         position from the fixes"
                    ),
                ));
            }
            if let Some(k) = (0..used).find(|&k| {
                let v = g_v[k];
                v[0].hypot(v[1]).hypot(v[2]) > STATIC_SPEED_M_S
            }) {
                return Err(invalid(
                    "GNSS data",
                    format!(
                        "row {}: the vehicle moves ({:.2} m/s) during the static alignment's first \
                         {duration_s} s",
                        k + 2,
                        g_v[k][0].hypot(g_v[k][1]).hypot(g_v[k][2])
                    ),
                ));
            }
            let mean = |v: &[[f64; 3]], s: f64| -> [f64; 3] {
                let sum = v[..i0]
                    .iter()
                    .fold([0.0; 3], |a, x| [0, 1, 2].map(|j| a[j] + x[j]));
                sum.map(|x| s * (x / i0 as f64))
            };
            let position = fixes[used - 1];
            let part = PartFigures {
                accel_bias_m_s2: setup.part_bias[0],
                gyro_bias_rad_s: setup.part_bias[1],
                accel_psd: setup.noise.accel_psd,
                gyro_psd: setup.noise.gyro_psd,
            };
            let aligned = align::at_rest(
                &earth,
                &position,
                mean(f, sign),
                mean(w, 1.0),
                t[i0] - t0,
                &part,
            )
            .map_err(|source| Error::Align {
                field: "align".into(),
                source,
            })?;
            let sigma = InitialSigma {
                position_m: setup
                    .gnss_position_sigma_m
                    .iter()
                    .fold(0.0_f64, |a, b| a.max(*b)),
                velocity_m_s: 0.05,
                attitude_rad: [
                    aligned.tilt_sigma_rad,
                    aligned.tilt_sigma_rad,
                    aligned.heading_sigma_rad,
                ],
                // What the averages took for the attitude stays a bias the filter must learn.
                accel_bias_m_s2: part.accel_bias_m_s2.max(1e-6),
                gyro_bias_rad_s: part.gyro_bias_rad_s.max(1e-9),
            };
            let s = NavState {
                t_s: t[i0],
                attitude: aligned.attitude,
                velocity_m_s: Vec3::zeros(),
                position,
            };
            (i0, s, E::origin_at(&position), sigma, used)
        }
        Start::AlignGnss => {
            let (k, i0, age) = inputs.first_fix_at_speed(setup.gnss_latency_s)?;
            let v = fix_velocity[k];
            // The fix was valid `age` before sample i0: moved on by its velocity.
            let position = E::position(earth.offset(&E::coordinates(&fixes[k]), &(v * age)));
            let s = NavState {
                t_s: t[i0],
                attitude: align::moving(&v),
                velocity_m_s: v,
                position,
            };
            let sigma = gnss_alignment_sigma(v.to_array(), setup);
            (i0, s, E::origin_at(&position), sigma, k + 1)
        }
    };
    let s0 = NavState {
        t_s: t[first],
        ..s0
    };
    aid_streams.start_at(t[first]);
    let filter_error = |context: &str, source: EskfError| Error::Filter {
        context: context.into(),
        row: None,
        source,
    };
    let start = EskfState {
        nav: s0,
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    };
    let filter = Eskf::<E, S>::new(earth, &start, &sigma, setup.noise)
        .map_err(|e| filter_error("filter", e))?
        .with_covariance_interval(setup.covariance_interval_s)
        .map_err(|_| covariance_interval_refusal(setup))?;
    let filter = if S == FULL_STATES {
        filter
            .with_sensor_error_sigma(&setup.sensor_error_sigma)
            .map_err(|e| filter_error("sensor_error_sigma", e))?
    } else {
        filter
    };
    let mut filter = if setup.smooth {
        filter
            .with_smoothing(SMOOTHING_GAP_S)
            .map_err(|e| filter_error("smooth", e))?
    } else {
        filter
    };
    // What the backward pass needs: the epochs, and each sample's filtered state.
    let mut epochs = crate::run::epochs::PackedEpochs::<S>::new();
    let mut filtered: Vec<(EskfState<E>, SensorErrorEstimate, usize)> = Vec::new();
    let lever = Vec3::<Body>::from_array(setup.lever_arm_m);
    let vel_sigma = setup.gnss_velocity_sigma_m_s.unwrap_or(1.0);
    // The third axis is the vertical in either frame (up in ENU, down in NED).
    let vertical_sigma = if *velocities == FixVelocity::Horizontal {
        UNKNOWN_VELOCITY_SIGMA_M_S
    } else {
        vel_sigma
    };
    let mut columns: Vec<&str> = FUSE_COLUMNS.to_vec();
    columns.extend(E::POSITION_COLUMNS);
    let mut columns = fused_columns(&columns, S == FULL_STATES);
    columns.push(RESETS_COLUMN.to_string());
    let mut table = Table {
        columns,
        data: Vec::new(),
    };
    let mut filtered_table = (setup.smooth && keep_filtered).then(|| Table {
        columns: table.columns.clone(),
        data: Vec::new(),
    });
    let mut acceptance = Acceptance::default();
    let mut last_yaw = None;
    let mut row = Vec::with_capacity(table.columns.len());
    for i in first..t.len() {
        filter
            .propagate(t[i], w[i], f[i].map(|x| sign * x))
            .map_err(|e| filter_error("IMU data", e))?;
        while next_fix < g_t.len() && g_t[next_fix] <= t[i] {
            let fix = GnssFix::<E> {
                position: fixes[next_fix],
                velocity_m_s: setup
                    .gnss_velocity_sigma_m_s
                    .filter(|_| *velocities != FixVelocity::None)
                    .map(|_| fix_velocity[next_fix]),
                lever_arm_m: lever,
                position_sigma_m: accuracy.as_ref().map_or(setup.gnss_position_sigma_m, |a| {
                    let [h, v] = a[next_fix];
                    [h, h, v]
                }),
                velocity_sigma_m_s: [vel_sigma, vel_sigma, vertical_sigma],
                // Valid at its stamp minus the latency; applied at this IMU sample.
                age_s: t[i] - g_t[next_fix] + setup.gnss_latency_s,
            };
            if acceptance.count(filter.update_gnss(&fix, setup.gate), next_fix, setup.gate)? {
                // Lost: back to the fix, the heading along its velocity when the vehicle moves.
                let heading = fix.velocity_m_s.and_then(|v| {
                    let speed = v.x().hypot(v.y());
                    (speed >= ALIGN_MIN_SPEED_M_S).then(|| {
                        (vel_sigma / speed)
                            .atan()
                            .hypot(ALIGN_ATTITUDE_ALLOWANCE_RAD[0])
                    })
                });
                filter
                    .reset_to_gnss(&fix, heading)
                    .map_err(|e| filter_refusal("GNSS", next_fix, e))?;
            }
            next_fix += 1;
        }
        aid_streams.apply(&mut filter, t[i], i)?;
        let s = filter.state();
        if setup.smooth {
            while let Some(e) = filter.take_epoch() {
                epochs.push(&e);
            }
            let errors = filter.sensor_errors();
            filtered.push((s, errors, acceptance.resets));
            if let Some(kept) = filtered_table.as_mut() {
                push_fused_row(
                    kept,
                    &mut row,
                    (&s, &errors, &filter.sigmas()),
                    (&origin, &mut last_yaw),
                    acceptance.resets,
                );
            }
            continue;
        }
        let sig = filter.sigmas();
        push_fused_row(
            &mut table,
            &mut row,
            (&s, &filter.sensor_errors(), &sig),
            (&origin, &mut last_yaw),
            acceptance.resets,
        );
    }
    if setup.smooth {
        filter.finish_smoothing();
        while let Some(e) = filter.take_epoch() {
            epochs.push(&e);
        }
        smoothed_rows::<E, S>(
            filter.earth(),
            &epochs,
            &filtered,
            &t[first..],
            (&mut table, &mut row),
            &origin,
        );
    }
    table.check_finite("fused navigation")?;
    if let Some(kept) = &filtered_table {
        kept.check_finite("fused navigation")?;
    }
    let (updates, rejected) = filter.update_counts();
    Ok((
        table,
        filtered_table,
        FuseSummary {
            updates,
            rejected,
            resets: acceptance.resets,
            rest_s: setup.rest_s,
            rest_detected: setup.detect_rest,
            sensor_errors: setup.estimate_sensor_errors,
            stance_samples: stances,
        },
    ))
}

/// The longest propagation without an epoch the smoother keeps, s: the spacing of its estimate
/// through an outage (between epochs the correction is interpolated linearly).
pub const SMOOTHING_GAP_S: f64 = 0.5;

/// Appends one row of the fused table: the state `s` (with the sensor errors and one-sigmas
/// `sig`), in the frame of `origin`, the yaw unwrapped against the last, the resets so far.
fn push_fused_row<E: NavEarth, const S: usize>(
    table: &mut Table,
    row: &mut Vec<f64>,
    (s, errors, sig): (&EskfState<E>, &SensorErrorEstimate, &[f64; S]),
    (origin, last_yaw): (&E::Origin, &mut Option<f64>),
    resets: usize,
) {
    let (nav_width, base) = (nav_earth::nav_width::<E>(), NAV_COLUMNS.len());
    let nav = nav_earth::nav_row(&s.nav, origin, last_yaw);
    row.clear();
    row.extend_from_slice(&nav[..base]);
    row.extend_from_slice(&sig[..9]);
    row.extend_from_slice(&s.accel_bias_m_s2);
    row.extend_from_slice(&s.gyro_bias_rad_s);
    row.extend_from_slice(&sig[9..15]);
    row.extend_from_slice(&nav[base..nav_width]);
    if S == FULL_STATES {
        push_sensor_errors(row, errors, &sig[15..]);
    }
    #[allow(clippy::cast_precision_loss)]
    row.push(resets as f64);
    table.push_row(row);
}

/// The smoothed table: the backward pass over `epochs`, each sample's filtered state
/// (`filtered`, at times `t`) corrected by the smoothed correction interpolated between the
/// epochs around it (none across a reset), its one-sigma likewise.
fn smoothed_rows<E: NavEarth, const S: usize>(
    earth: &E,
    epochs: &crate::run::epochs::PackedEpochs<S>,
    filtered: &[(EskfState<E>, SensorErrorEstimate, usize)],
    t: &[f64],
    (table, row): (&mut Table, &mut Vec<f64>),
    origin: &E::Origin,
) {
    let n = epochs.len();
    let mut smoothed = vec![ErrorVector::<S>::zeros(); n];
    let mut variance = vec![ErrorVector::<S>::zeros(); n];
    rts_backward(epochs, |j, dx, p| {
        smoothed[j] = *dx;
        variance[j] = p.diagonal();
    });
    let mut last_yaw = None;
    let mut j = 0;
    for (i, (state, errors, resets)) in filtered.iter().enumerate() {
        let ti = t[i];
        while j + 1 < n && epochs.t_s(j + 1) <= ti {
            j += 1;
        }
        let (dx, var) = if j + 1 < n && !epochs.reset(j + 1) && epochs.t_s(j) <= ti {
            let span = epochs.t_s(j + 1) - epochs.t_s(j);
            let w = if span > 0.0 {
                (ti - epochs.t_s(j)) / span
            } else {
                0.0
            };
            let end = epochs.correction(j + 1) + smoothed[j + 1];
            (
                smoothed[j] * (1.0 - w) + end * w,
                variance[j] * (1.0 - w) + variance[j + 1] * w,
            )
        } else if j < n && epochs.t_s(j) <= ti {
            (smoothed[j], variance[j])
        } else {
            (ErrorVector::<S>::zeros(), ErrorVector::<S>::zeros())
        };
        let s = corrected_state(earth, state, dx.as_slice());
        let mut e = *errors;
        if S == FULL_STATES {
            for k in 0..9 {
                e.accel[k / 3][k % 3] += dx[15 + k];
                e.gyro[k / 3][k % 3] += dx[24 + k];
            }
            for k in 0..3 {
                e.gyro_g_sensitivity[k] += dx[33 + k];
            }
        }
        let sig: [f64; S] = core::array::from_fn(|k| var[k].max(0.0).sqrt());
        push_fused_row(table, row, (&s, &e, &sig), (origin, &mut last_yaw), *resets);
    }
}

/// One-sigma of the zero-velocity update at a stance on the move, m/s (OpenShoe's figure).
pub const STANCE_VELOCITY_SIGMA_M_S: f64 = 0.01;

/// Window of the stance detector, s (Skog et al. use 3 to 5 samples at 100 Hz and more).
pub const STANCE_WINDOW_S: f64 = 0.05;

/// False-alarm probability of the stance detector per sample.
pub const STANCE_FALSE_ALARM: f64 = 1e-3;

/// The samples of readings `f`, `w` (specific force and rate, times `t`) that are stances
/// ([`FuseSetup::zupt`]), as the fusion finds them.
pub fn stance_samples(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> Vec<bool> {
    use imu_core::stillness::{detect_stance, shoe_threshold};
    let mut stance = vec![false; t.len()];
    let Some((interval, noise)) = reading_noise(t, setup) else {
        return stance;
    };
    // The rest's mean rate is the bias the detector's zero-rate test must not see.
    let rest = t.partition_point(|&x| x < t[0] + setup.rest_s);
    let bias = if rest > 0 {
        [0, 1, 2].map(|k| w[..rest].iter().map(|x| x[k]).sum::<f64>() / rest as f64)
    } else {
        [0.0; 3]
    };
    let gyro: Vec<[f64; 3]> = w
        .iter()
        .map(|x| [x[0] - bias[0], x[1] - bias[1], x[2] - bias[2]])
        .collect();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((STANCE_WINDOW_S / interval).round() as usize).max(3);
    detect_stance(
        f,
        &gyro,
        setup.gravity_m_s2,
        noise,
        window,
        shoe_threshold(window, STANCE_FALSE_ALARM),
        &mut stance,
    );
    stance
}

/// Block length of the rest detector, s.
pub const REST_WINDOW_S: f64 = 0.5;

/// A start faster than this, m/s, is not at rest: no rest is looked for.
pub const REST_START_SPEED_M_S: f64 = 0.1;

/// The rest at the start of readings `f`, `w` at times `t`, s ([`imu_core::stillness`] with the
/// part's white noise per sample and blocks of [`REST_WINDOW_S`]).
fn detected_rest_s(t: &[f64], f: &[[f64; 3]], w: &[[f64; 3]], setup: &FuseSetup) -> f64 {
    let Some((interval, noise)) = reading_noise(t, setup) else {
        return 0.0;
    };
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let window = ((REST_WINDOW_S / interval).round() as usize).max(2);
    let still = imu_core::stillness::initial_rest(f, w, noise, window);
    if still == 0 { 0.0 } else { t[still] - t[0] }
}

/// The mean interval of the times `t` and the part's white noise over one such interval, the
/// stillness tests' noise; `None` for fewer than three samples or times that do not advance.
fn reading_noise(t: &[f64], setup: &FuseSetup) -> Option<(f64, imu_core::stillness::ReadingNoise)> {
    let n = t.len();
    if n < 3 {
        return None;
    }
    let interval = (t[n - 1] - t[0]) / (n - 1) as f64;
    if interval.is_nan() || interval <= 0.0 {
        return None;
    }
    let per_sample = |psd: f64| psd / interval.sqrt();
    Some((
        interval,
        imu_core::stillness::ReadingNoise {
            accel: per_sample(setup.noise.accel_psd),
            gyro: per_sample(setup.noise.gyro_psd),
        },
    ))
}

/// The refusal of `setup`'s covariance interval.
fn covariance_interval_refusal(setup: &FuseSetup) -> Error {
    invalid(
        "covariance_interval_s",
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
    /// Whether the part's scale-factor, misalignment or g-sensitivity figures are large enough
    /// ([`SENSOR_ERROR_STATES_FROM`], [`G_SENSITIVITY_STATES_FROM`]) that the filter should
    /// estimate them: what `fuse` does when not told.
    #[must_use]
    pub fn warrants_sensor_errors(&self) -> bool {
        let e = &self.sensor_error_sigma;
        [
            e.accel_scale_factor,
            e.accel_misalignment,
            e.gyro_scale_factor,
            e.gyro_misalignment,
        ]
        .iter()
        .any(|s| *s >= SENSOR_ERROR_STATES_FROM)
            || e.gyro_g_sensitivity >= G_SENSITIVITY_STATES_FROM
    }

    /// The filter for data simulated by `scenario`: its frame, accelerometer sign, gravity, the
    /// IMU's noise (white and drift PSDs, `imu_core::fusion::process_noise`) and the `[gnss]` receiver's accuracy and lever arm (the fixes'
    /// stationary deviation, `σ √(2/(1 + k))` for MATLAB's decay factor `k`, as white noise; the
    /// filter assumes uncorrelated fixes). Initial uncertainty: position as the fixes, 0.1 m/s,
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
            invalid(
                "scenario",
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
    /// GNSS one-sigmas from the receiver's accuracies (MATLAB's decay factor's steady share),
    /// the gate at 99.9 %, the covariance every [`DEFAULT_COVARIANCE_INTERVAL_S`].
    #[must_use]
    pub fn from_model(m: &FuseModel<'_>) -> Self {
        use imu_core::aiding::PositionNoise;
        let p = m.imu;
        let noise = eskf_noise(&p.accelerometer, &p.gyroscope, m.sample_rate_hz);
        let g = m.gnss;
        let scale = match g.position_noise {
            PositionNoise::DecayFactor(k) => (2.0 / (1.0 + k)).sqrt(),
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
            gnss_velocity_sigma_m_s: Some(floor(g.velocity_accuracy_m_s)),
            lever_arm_m: m.lever_arm_m,
            gnss_latency_s: m.gnss_latency_s,
            gate: CHI2_99_9_6DOF,
            aiding: AidingSetup {
                odometer: m.odometer,
                nhc_sigma_m_s: None,
                baro_sigma_m: m.baro_sigma_m,
            },
            covariance_interval_s: DEFAULT_COVARIANCE_INTERVAL_S,
            estimate_sensor_errors: false,
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
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// The receiver's latency, s.
    pub gnss_latency_s: f64,
    /// The odometer's model (`None`: none).
    pub odometer: Option<OdometerModel>,
    /// The barometer's one-sigma, m (`None`: none).
    pub baro_sigma_m: Option<f64>,
}

/// The filter's model apart from any scenario: the part by a preset's name or a parameter
/// file (`imukit fuse --imu stim300`, `--imu part.toml`), the GNSS receiver as `[gnss]` keys
/// (`--gnss-horizontal-accuracy-m` …; MATLAB's defaults for the rest), the data's frame and
/// Earth from the inputs' descriptions ([`PartModel::setup`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartModel {
    /// A preset's name, or the path of a parameter file (imukit TOML, MATLAB JSON).
    pub imu: String,
    /// The part in a MATLAB file of several.
    pub part: Option<String>,
    /// The receiver (its rate is not used).
    pub gnss: crate::scenario::gnss::GnssSpec,
}

impl PartModel {
    /// [`PartModel::setup`] for the IMU table `imu`, at its median sample rate.
    ///
    /// # Errors
    /// As [`PartModel::setup`]; fewer than two samples with increasing times.
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
                "IMU data",
                "needs at least two samples with increasing t_s (the sample rate sets the noise)",
            ));
        }
        self.setup(nav, accel_sign, 1.0 / median)
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
        let path = std::path::Path::new(&self.imu);
        let is_file = path.extension().is_some() || path.exists();
        let spec = crate::scenario::ImuSpec {
            preset: (!is_file).then(|| self.imu.clone()),
            params: is_file.then(|| path.to_path_buf()),
            part: self.part.clone(),
            ..crate::scenario::ImuSpec::default()
        };
        let sensors =
            crate::scenario::sensors::SensorSetup::resolve(&spec, std::path::Path::new("."))?;
        // A simulated receiver may be exact; a filter told so gates away every real fix.
        for (field, value) in [
            (
                "gnss.horizontal_accuracy_m",
                self.gnss.horizontal_accuracy_m,
            ),
            ("gnss.vertical_accuracy_m", self.gnss.vertical_accuracy_m),
            (
                "gnss.velocity_accuracy_m_s",
                self.gnss.velocity_accuracy_m_s,
            ),
        ] {
            if let Some(v) = value
                && !(v.is_finite() && v > 0.0)
            {
                return Err(invalid(
                    field,
                    format!(
                        "must be a one-sigma above 0 for the filter, got {v} (no receiver is \
                         exact: a filter told so rejects its fixes)"
                    ),
                ));
            }
        }
        let gnss = self.gnss.params()?;
        Ok(FuseSetup::from_model(&FuseModel {
            nav_frame: nav.nav_frame,
            earth: nav.earth.map(|e| e.gravity),
            accel_sign: accel_sign.unwrap_or(sensors.profile.accel_sign()),
            gravity_m_s2: nav.gravity_m_s2,
            imu: &sensors.params,
            sample_rate_hz,
            gnss: &gnss,
            lever_arm_m: crate::scenario::resolve::finite_vec(
                "gnss.lever_arm_m",
                self.gnss.lever_arm_m.unwrap_or([0.0; 3]),
            )?,
            gnss_latency_s: self.gnss.latency_s.unwrap_or(0.0),
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
        described: &crate::io::description::Described,
        imu: &Table,
    ) -> Result<FuseSetup> {
        let nav = crate::run::navigate::NavRequest::default()
            .with_described(asked, described)?
            .setup()?;
        self.setup_for(&nav, asked.accel_sign_of(described)?, imu)
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

/// Fixes rejected one after another before the filter is reset to the last of them
/// ([`Eskf::reset_to_gnss`](imu_core::fusion::Eskf::reset_to_gnss)).
pub const MAX_REJECTED_IN_A_ROW: usize = 10;

/// The default innovation gate of a position-and-velocity fix: the chi-square 99.9 % quantile
/// with 6 degrees of freedom (a good fix is rejected once in a thousand).
pub const CHI2_99_9_6DOF: f64 = imu_core::fusion::gate::CHI2_99_9[5];
