//! Loosely coupled INS/GNSS fusion for the CLI and Python: the core's error-state filter
//! ([`imu_core::fusion::eskf`]) over an IMU table (rates) and a GNSS table, on the flat Earth or
//! WGS-84 (fixes then geodetic), in the data's own frame (`run::nav_earth`).
//! Odometer, barometer and the constraints aid it alike on both (`aids`).
//!
//! Output: [`FUSE_COLUMNS`](crate::io::columns::FUSE_COLUMNS) — the navigation columns of
//! `integrate`, the one-sigma of position, velocity and attitude (navigation-frame axes), and
//! the bias estimates (body axes) — then on WGS-84 `lat_rad, lon_rad, height_m`, one row per IMU
//! sample. A fix is applied at the first IMU sample at or after its stamp (fixes are taken at
//! IMU samples in imukit's simulations, so exactly there).
//!
//! One room per concept: the request and the start ([`FuseRequest`], [`Start`]), the filter's
//! setup and model ([`FuseSetup`], [`PartModel`]), the inputs read and checked, the detectors
//! (rest, stances), the start's alignment, the recovery from lost fixes, the run itself
//! (`filter`: a short sequence of named steps), the rows, the smoothing, the aids.
mod adapt;
pub(crate) mod aids;
mod detect;
mod filter;
mod inputs;
mod model;
mod recovery;
mod request;
mod rows;
mod setup;
mod smooth;
mod start;

pub use adapt::{ADAPT_WINDOW, DEFAULT_MAX_FIX_NOISE_SCALE};
pub use detect::{
    Detection, FEW_STANCES, MAX_STANCE_GAP_S, QUIET_WINDOW_S, REST_START_SPEED_M_S, REST_WINDOW_S,
    STANCE_FALSE_ALARM, STANCE_VELOCITY_SIGMA_M_S, STANCE_WINDOW_S, StanceThreshold, learnt_noise,
    longest_without_stance, stance_gap_message, stance_samples,
};
pub use model::{FuseModel, LEARNT_BASE_PRESET, Part, PartModel};
pub(crate) use recovery::filter_refusal;
pub use recovery::{MAX_REJECTED_IN_A_ROW, MAX_RESETS_IN_A_ROW};
pub use request::{AlignName, FuseRequest, STATIC_ALIGN_S, Start};
pub use rows::{RESETS_COLUMN, sensor_error_columns};
pub use setup::{
    AidingSetup, CHI2_99_9_6DOF, DEFAULT_COVARIANCE_INTERVAL_S, DEFAULT_NHC_SIGMA_M_S,
    FIX_WHITE_SIGMA_M, FuseSetup, G_SENSITIVITY_STATES_FROM, Gate, MIN_G_SENSITIVITY_SIGMA,
    MIN_SENSOR_ERROR_SIGMA, NHC_RATE_HZ, OdometerModel, REST_VELOCITY_SIGMA_M_S,
    SENSOR_ERROR_STATES_FROM,
};
pub use smooth::SMOOTHING_GAP_S;
pub use start::{ALIGN_ATTITUDE_ALLOWANCE_RAD, ALIGN_MIN_SPEED_M_S, gnss_alignment_sigma};

use imu_core::fusion::{BASE_STATES, FIX_ERROR_STATES, FULL_STATES};

use crate::error::{Result, invalid};
use crate::io::table::Table;
use crate::run::nav_earth::{EarthJob, NavEarth, on_earth};
use crate::run::navigate::InitialState;

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
    /// Whether the sensor-error states were estimated (36 or 39 states).
    pub sensor_errors: bool,
    /// The fixes' correlated error the filter estimated (18 or 39 states), as modelled.
    pub fix_errors: Option<imu_core::fusion::FixErrorModel>,
    /// The filter's error states: 15, 18, 36 or 39.
    pub states: usize,
    /// The variance factor of the fixes' noise at the end, from their innovations (1: as
    /// stated; [`FuseSetup::max_fix_noise_scale`]).
    pub fix_noise_scale: f64,
    /// Samples taken as stances by the zero-velocity detector ([`FuseSetup::zupt`]).
    pub stance_samples: usize,
    /// The IMU's rows that repeated the row before exactly, dropped
    /// ([`crate::io::rows::Repeats`]).
    pub repeats: crate::io::rows::Repeats,
    /// The longest stretch without a stance after the rest at the start, `(start, length)`, s
    /// from the first sample ([`longest_without_stance`]; `None` without `--zupt`).
    pub stance_gap: Option<(f64, f64)>,
    /// The stance detector's threshold (`None` without `--zupt`).
    pub stance_threshold: Option<StanceThreshold>,
    /// What the detectors tested the readings against: the noise learnt from the log's quiet
    /// stretches, or the part's (`None`: no detector ran, or too few samples to tell).
    pub detection: Option<Detection>,
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
        const FIXES: usize = FIX_ERROR_STATES;
        match (
            self.setup.estimate_sensor_errors,
            self.setup.correlated_fixes(),
        ) {
            (false, false) => filter::fuse_on::<E, BASE_STATES>(earth, self),
            (false, true) => filter::fuse_on::<E, { BASE_STATES + FIXES }>(earth, self),
            (true, false) => filter::fuse_on::<E, FULL_STATES>(earth, self),
            (true, true) => filter::fuse_on::<E, { FULL_STATES + FIXES }>(earth, self),
        }
    }
}
