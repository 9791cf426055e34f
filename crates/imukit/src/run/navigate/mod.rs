//! 3D strapdown for the CLI and Python, and errors of an estimate against truth.
//!
//! IMU input: rates (`accel_*_m_s2`, `gyro_*_rad_s`, turned into increments by the trapezoid) or
//! increments (`dv_*_m_s`, `dtheta_*_rad`). The accelerometer columns must hold specific force
//! (imukit's default sign); data in MATLAB's sign is flipped with `accel_sign = matlab`.
//! Navigation output has the truth columns the integrator estimates: `t_s, pos_*, vel_*, q_*,
//! yaw_rad, pitch_rad, roll_rad`, and on the WGS-84 Earth `lat_rad, lon_rad, height_m` (`pos_*`
//! then in the tangent plane at the origin of the starting truth, velocity and attitude in the
//! local-level frame at each position). Both Earths run in the data's own frame through
//! `run::nav_earth`.
//!
//! One room per concept: the request and its defaults ([`NavRequest`], [`NavSetup`]), the
//! initial state ([`InitialState`], from a truth row or a reference on the Earth), the
//! integration of a whole table ([`integrate`]) and the streamed one of a file
//! ([`integrate_csv`]).
mod initial;
mod request;
mod stream;

pub use initial::InitialState;
pub use request::{
    DEFAULT_BARO_TIME_CONSTANT_S, DEFAULT_RK4_SUBSTEPS, MAX_RK4_SUBSTEPS, NavAsked, NavRequest,
    NavScheme, NavSetup, SchemeName, VerticalName,
};
use stream::NEEDS_READINGS;
pub use stream::{NavSummary, integrate_csv, read_whole, with_baro_column};

use imu_core::earth::GravityModel;
use imu_core::strapdown::{
    NavState, StrapdownOptions, VerticalChannel, strapdown_increments, strapdown_rates,
    strapdown_rates_rk4,
};
use imu_core::{AccelSign, NavFrame, Rotation};

use crate::error::Data;
use crate::io::columns::{ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS};

use crate::error::{Result, invalid};
use crate::io::rows::check_increasing;
use crate::io::table::Table;
use crate::run::nav_earth::{self, EarthJob, NavEarth, on_earth};
/// Integrates an IMU table (rates or increments) from `initial`.
///
/// # Errors
/// Missing columns (both layouts named; `baro_height_m` for the baro channel), invalid initial
/// quaternion, an initial state without a geodetic position on the WGS-84 Earth, non-finite
/// values or non-increasing times (sample index named).
pub fn integrate(imu: &Table, initial: &InitialState, setup: &NavSetup) -> Result<Table> {
    let nav = with_earth(
        setup,
        Integrate {
            imu,
            initial,
            setup,
        },
    )?;
    nav.check_finite("navigation")?;
    Ok(nav)
}

/// How the Earth mechanization runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthNav {
    /// The vertical channel.
    pub vertical: VerticalChannel,
    /// Gravity.
    pub gravity: GravityModel,
}

/// The barometric height column the baro-damped vertical channel reads from the IMU table.
pub const BARO_COLUMN: &str = "baro_height_m";

/// The strapdown options of `setup`, with the vertical channel of WGS-84.
fn strapdown_options(setup: &NavSetup) -> StrapdownOptions {
    StrapdownOptions {
        vertical: setup
            .earth
            .map_or(VerticalChannel::Free, |earth| earth.vertical),
        ..setup.options
    }
}

/// Runs `job` on the Earth and in the frame of `setup`.
fn with_earth<J: EarthJob>(setup: &NavSetup, job: J) -> J::Output {
    on_earth(
        setup.nav_frame,
        setup.earth.map(|e| e.gravity),
        setup.gravity_m_s2,
        job,
    )
}

/// [`integrate`] as an [`EarthJob`].
struct Integrate<'a> {
    imu: &'a Table,
    initial: &'a InitialState,
    setup: &'a NavSetup,
}

impl EarthJob for Integrate<'_> {
    type Output = Result<Table>;

    fn run<E: NavEarth>(self, earth: E) -> Result<Table> {
        let Self {
            imu,
            initial,
            setup,
        } = self;
        let options = strapdown_options(setup);
        let t = imu
            .column("t_s")
            .ok_or_else(|| invalid(Data::Imu, "missing column t_s"))?;
        check_increasing(&t, Data::Imu, 2)?;
        let (s0, origin) = nav_earth::start::<E>(initial, t.first().copied().unwrap_or(0.0))?;
        let baro = match options.vertical {
            VerticalChannel::Baro { .. } => Some(imu.column(BARO_COLUMN).ok_or_else(|| {
                invalid(
                    Data::Imu,
                    format!("the baro vertical channel needs a {BARO_COLUMN} column"),
                )
            })?),
            _ => None,
        };
        let baro = baro.as_deref();
        let flip = |v: Vec<[f64; 3]>| match setup.accel_sign {
            AccelSign::SpecificForce => v,
            AccelSign::Matlab => v.into_iter().map(|a| a.map(|x| -x)).collect(),
        };
        let mut out = vec![NavState::<E>::default(); t.len()];
        let corrections = options.coning || options.sculling;
        let result =
            if let (Some(f), Some(w)) = (imu.triples(&ACCEL_COLUMNS), imu.triples(&GYRO_COLUMNS)) {
                let f = flip(f);
                match setup.scheme.for_input(true, corrections) {
                    NavScheme::ConingSculling => {
                        strapdown_rates(earth, &t, &w, &f, baro, s0, options, &mut out)
                    }
                    NavScheme::Rk4 { substeps } => strapdown_rates_rk4(
                        earth, &t, &w, &f, baro, s0, options, substeps, &mut out,
                    ),
                    NavScheme::Auto { .. } => unreachable!("for_input chooses a concrete scheme"),
                }
            } else if let (Some(dv), Some(dth)) =
                (imu.triples(&DV_COLUMNS), imu.triples(&DTHETA_COLUMNS))
            {
                if setup.scheme.for_input(false, corrections) != NavScheme::ConingSculling {
                    return Err(invalid(
                        Data::Imu,
                        "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
                    ));
                }
                strapdown_increments(earth, &t, &dth, &flip(dv), baro, s0, options, &mut out)
            } else {
                return Err(invalid(Data::Imu, NEEDS_READINGS));
            };
        result.map_err(|source| crate::Error::Strapdown {
            context: Data::Imu.label().into(),
            source,
        })?;
        let mut table = Table::new(&nav_earth::nav_columns::<E>());
        let width = nav_earth::nav_width::<E>();
        let mut last_yaw: Option<f64> = None;
        for s in &out {
            table.push_row(&nav_earth::nav_row(s, &origin, &mut last_yaw)[..width]);
        }
        Ok(table)
    }
}

/// The z-y-x Euler angles of `r` with the yaw unwrapped against `last_yaw` (then updated).
pub(crate) fn euler_unwrapped<N: NavFrame>(
    r: &Rotation<imu_core::Body, N>,
    last_yaw: &mut Option<f64>,
) -> imu_core::EulerZyx {
    let mut e = r.to_euler();
    if let Some(y) = *last_yaw {
        let tau = std::f64::consts::TAU;
        e.yaw_rad += tau * ((y - e.yaw_rad) / tau).round();
    }
    *last_yaw = Some(e.yaw_rad);
    e
}

type Emit<'a, E> = dyn FnMut(NavState<E>) -> Result<()> + 'a;
