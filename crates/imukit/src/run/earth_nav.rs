//! 3D strapdown on the WGS-84 Earth for the CLI and Python (`--earth wgs84`): the core's
//! local-NED mechanization ([`imu_core::strapdown`] on [`imu_core::earth::Wgs84`]) with Earth rate, transport rate,
//! Coriolis and normal gravity, fed from an IMU table and reported as the flat navigation is.
//!
//! Output: [`EARTH_NAV_COLUMNS`], the navigation columns of the flat integration (`pos_*` in
//! the tangent plane at the origin of the starting truth, `vel_*` and the attitude in the
//! local-level frame at each position, axes and body convention of the chosen frame) and
//! `lat_rad, lon_rad, height_m`.
use imu_core::earth::{Geodetic, GravityModel, Wgs84};
use imu_core::strapdown::{
    NavState, StrapdownOptions, VerticalChannel, strapdown_increments, strapdown_rates_rk4,
};
use imu_core::{Body, Ecef, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::table::{
    ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS, Table, concat_columns,
};
use crate::run::navigate::{
    GEODETIC_COLUMNS, InitialState, NAV_COLUMNS, NavScheme, NavSetup, euler_unwrapped,
};
use crate::scenario::earth::frd_to_body;

/// The navigation state on WGS-84 in local NED.
pub(crate) type EarthNavState = NavState<Wgs84<Ned>>;

/// Navigation output on the Earth: [`NAV_COLUMNS`] then the geodetic position.
pub const EARTH_NAV_COLUMNS: [&str; 17] = concat_columns(NAV_COLUMNS, GEODETIC_COLUMNS);

/// The barometric height column the baro-damped vertical channel reads from the IMU table.
pub const BARO_COLUMN: &str = "baro_height_m";

/// How the Earth mechanization runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthNav {
    /// The vertical channel.
    pub vertical: VerticalChannel,
    /// Gravity.
    pub gravity: GravityModel,
}

/// The tangent plane whose coordinates are the `pos_*` columns: the origin `o` with
/// `r(o) + C_et(o) p = r₁` for the first sample's plane coordinates `p` and position `r₁`
/// (solved by fixed-point iteration; the plane's axes turn by |p|/R between iterates).
fn plane_origin<N: NavFrame>(position_m: [f64; 3], at: &Geodetic) -> Geodetic {
    let p = Vec3::<N>::from_array(position_m);
    let r1 = at.to_ecef();
    let mut origin = *at;
    for _ in 0..8 {
        let c_et: Rotation<N, Ecef> = N::from_ned().inverse().then(&origin.ned_to_ecef());
        match Geodetic::from_ecef(r1 - c_et.apply(p)) {
            Some(o) => origin = o,
            None => break,
        }
    }
    origin
}

/// The starting state in NED/FRD from a front end's [`InitialState`] (frame `N`).
pub(crate) fn start<N: NavFrame>(
    initial: &InitialState,
    t0: f64,
) -> Result<(EarthNavState, Geodetic)> {
    let position = initial.geodetic.ok_or_else(|| {
        invalid(
            "initial state",
            "--earth wgs84 needs the starting latitude, longitude and height: a truth file with \
             lat_rad, lon_rad, height_m (from a scenario with earth = \"wgs84\"), or lat0_deg, \
             lon0_deg, height0_m",
        )
    })?;
    let attitude = Rotation::<Body, N>::from_wxyz(initial.quaternion).ok_or_else(|| {
        invalid(
            "initial state",
            "the quaternion has zero norm or is not finite",
        )
    })?;
    let from_ned = N::from_ned();
    let state = EarthNavState {
        t_s: t0,
        attitude: frd_to_body::<N>().then(&attitude).then(&from_ned.inverse()),
        velocity_m_s: from_ned
            .inverse()
            .apply(Vec3::<N>::from_array(initial.velocity_m_s)),
        position,
    };
    Ok((state, plane_origin::<N>(initial.position_m, &position)))
}

/// Integrates an IMU table (rates or increments, frame `N`'s body convention) on the Earth.
///
/// # Errors
/// Missing columns (both layouts named; `baro_height_m` for the baro channel), an initial state
/// without a geodetic position, the core's refusals (with the sample), non-finite results.
pub(crate) fn integrate_earth_in<N: NavFrame>(
    imu: &Table,
    t: &[f64],
    initial: &InitialState,
    setup: &NavSetup,
    earth: &EarthNav,
) -> Result<Table> {
    let (s0, origin) = start::<N>(initial, t.first().copied().unwrap_or(0.0))?;
    let options = StrapdownOptions {
        vertical: earth.vertical,
        ..setup.options
    };
    let model = Wgs84::new(earth.gravity);
    let baro = match earth.vertical {
        VerticalChannel::Baro { .. } => Some(imu.column(BARO_COLUMN).ok_or_else(|| {
            invalid(
                "IMU data",
                format!("the baro vertical channel needs a {BARO_COLUMN} column"),
            )
        })?),
        _ => None,
    };
    let to_frd = frd_to_body::<N>().inverse();
    let sign = match setup.accel_sign {
        imu_core::AccelSign::SpecificForce => 1.0,
        imu_core::AccelSign::Matlab => -1.0,
    };
    // Body axes of N's convention → FRD, accelerometer sign → specific force.
    let frd = |v: Vec<[f64; 3]>, s: f64| -> Vec<[f64; 3]> {
        v.into_iter()
            .map(|a| to_frd.apply(Vec3::from_array(a.map(|x| s * x))).to_array())
            .collect()
    };
    let mut out = vec![EarthNavState::default(); t.len()];
    let corrections = setup.options.coning || setup.options.sculling;
    let result = if let (Some(f), Some(w)) =
        (imu.triples(&ACCEL_COLUMNS), imu.triples(&GYRO_COLUMNS))
    {
        let (f, w) = (frd(f, sign), frd(w, 1.0));
        match setup.scheme.for_input(true, corrections) {
            NavScheme::Rk4 { substeps } => strapdown_rates_rk4(
                model,
                t,
                &w,
                &f,
                baro.as_deref(),
                s0,
                options,
                substeps,
                &mut out,
            ),
            _ => {
                // The trapezoid of rates as increments, as the flat scheme does.
                let (dth, dv) = trapezoid(t, &w, &f);
                strapdown_increments(model, t, &dth, &dv, baro.as_deref(), s0, options, &mut out)
            }
        }
    } else if let (Some(dv), Some(dth)) = (imu.triples(&DV_COLUMNS), imu.triples(&DTHETA_COLUMNS)) {
        if setup.scheme.for_input(false, corrections) != NavScheme::ConingSculling {
            return Err(invalid(
                "IMU data",
                "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
            ));
        }
        let (dv, dth) = (frd(dv, sign), frd(dth, 1.0));
        strapdown_increments(model, t, &dth, &dv, baro.as_deref(), s0, options, &mut out)
    } else {
        return Err(invalid(
            "IMU data",
            "needs accel_x/y/z_m_s2 and gyro_x/y/z_rad_s (rates) or dv_x/y/z_m_s and dtheta_x/y/z_rad (increments)",
        ));
    };
    result.map_err(|source| crate::Error::Strapdown {
        context: "IMU data".into(),
        source,
    })?;
    Ok(table::<N>(&out, &origin))
}

/// Increments from rate samples by the trapezoid (entry 0 unused).
fn trapezoid(t: &[f64], w: &[[f64; 3]], f: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut dth = vec![[0.0; 3]; t.len()];
    let mut dv = vec![[0.0; 3]; t.len()];
    for k in 1..t.len() {
        let h = 0.5 * (t[k] - t[k - 1]);
        dth[k] = std::array::from_fn(|i| h * (w[k - 1][i] + w[k][i]));
        dv[k] = std::array::from_fn(|i| h * (f[k - 1][i] + f[k][i]));
    }
    (dth, dv)
}

/// The output rows in frame `N`.
fn table<N: NavFrame>(states: &[EarthNavState], origin: &Geodetic) -> Table {
    let mut table = Table::new(&EARTH_NAV_COLUMNS);
    let mut last_yaw = None;
    for s in states {
        table.push_row(&row::<N>(s, origin, &mut last_yaw));
    }
    table
}

/// One output row in frame `N`: [`EARTH_NAV_COLUMNS`] of state `s`, positions in the tangent
/// plane at `origin`, the yaw unwrapped from the previous row's.
pub(crate) fn row<N: NavFrame>(
    s: &EarthNavState,
    origin: &Geodetic,
    last_yaw: &mut Option<f64>,
) -> [f64; 17] {
    let from_ned = N::from_ned();
    let to_body = frd_to_body::<N>();
    let c_te: Rotation<Ecef, N> = origin.ned_to_ecef().inverse().then(&from_ned);
    let attitude: Rotation<Body, N> = to_body.inverse().then(&s.attitude).then(&from_ned);
    let e = euler_unwrapped(&attitude, last_yaw);
    let p = c_te
        .apply(s.position.to_ecef() - origin.to_ecef())
        .to_array();
    let v = from_ned.apply(s.velocity_m_s).to_array();
    let q = attitude.to_wxyz();
    let g = &s.position;
    [
        s.t_s,
        p[0],
        p[1],
        p[2],
        v[0],
        v[1],
        v[2],
        q[0],
        q[1],
        q[2],
        q[3],
        e.yaw_rad,
        e.pitch_rad,
        e.roll_rad,
        g.latitude_rad,
        g.longitude_rad,
        g.height_m,
    ]
}

/// Reads an IMU CSV file whole, refused before reading when it could exceed the memory budget
/// of [`check_in_memory`](crate::scenario::check_in_memory) with what the Earth navigation keeps
/// per sample.
///
/// # Errors
/// The budget, and the reader's errors naming file, row and column.
pub fn read_whole(input: &std::path::Path) -> Result<Table> {
    let bytes = std::fs::metadata(input)
        .map_err(|source| crate::Error::Io {
            path: input.into(),
            source,
        })?
        .len();
    // A CSV value takes at least 2 bytes; each becomes a number in the table, and about 30
    // numbers per row come out (the states and the table).
    let rows_at_most = usize::try_from(bytes / 14).unwrap_or(usize::MAX);
    crate::scenario::check_in_memory(rows_at_most, 8 * 7 * 2 + 8 * 17 * 2, "IMU data")?;
    crate::io::table::read_table(input)
}

/// Integrates the IMU CSV `input` on the Earth into `out` (read whole, within the memory budget
/// of [`check_in_memory`](crate::scenario::check_in_memory); `out` appears only when complete).
///
/// # Errors
/// As [`crate::run::navigate::integrate`], and I/O errors naming the file.
pub(crate) fn integrate_earth_csv(
    input: &std::path::Path,
    initial: &InitialState,
    setup: &NavSetup,
    out: &std::path::Path,
) -> Result<crate::run::navigate::NavSummary> {
    let imu = read_whole(input)?;
    let nav = crate::run::navigate::integrate(&imu, initial, setup)?;
    let rates = ACCEL_COLUMNS
        .iter()
        .chain(&GYRO_COLUMNS)
        .all(|c| imu.columns.iter().any(|h| h == c));
    let corrections = setup.options.coning || setup.options.sculling;
    nav.write(out)?;
    let last = |c: &str| nav.column(c).and_then(|v| v.last().copied()).unwrap_or(0.0);
    Ok(crate::run::navigate::NavSummary {
        rows: nav.rows(),
        scheme: setup.scheme.for_input(rates, corrections),
        end_position_m: [last("pos_x_m"), last("pos_y_m"), last("pos_z_m")],
    })
}

/// `imu` with a [`BARO_COLUMN`] taken from barometer readings `baro` (`t_s, baro_height_m`,
/// as `imukit simulate --baro` writes): each IMU sample gets the last reading at or before it
/// (the first reading before the first one).
///
/// # Errors
/// Missing columns, times that do not increase or fall outside the IMU's span, values that are
/// not finite, an empty file.
pub fn with_baro_column(imu: &Table, baro: &Table) -> Result<Table> {
    let t = imu
        .column("t_s")
        .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else {
        return Err(invalid("IMU data", "has no rows"));
    };
    // The same rule as the fusion's aids: finite, increasing, within the IMU's span.
    let (tb, hb) = crate::run::fuse_aids::aid_series(baro, "barometer", BARO_COLUMN, (t0, t1))?;
    if tb.is_empty() {
        return Err(invalid("barometer data", "has no readings"));
    }
    let mut columns: Vec<&str> = imu.columns.iter().map(String::as_str).collect();
    if columns.contains(&BARO_COLUMN) {
        return Err(invalid(
            "IMU data",
            format!("already has a {BARO_COLUMN} column; give the barometer once"),
        ));
    }
    columns.push(BARO_COLUMN);
    let mut out = Table::new(&columns);
    let width = imu.columns.len();
    let mut k = 0;
    for (i, ti) in t.iter().enumerate() {
        while k + 1 < tb.len() && tb[k + 1] <= *ti {
            k += 1;
        }
        let mut row = imu.data[i * width..(i + 1) * width].to_vec();
        row.push(hb[k]);
        out.push_row(&row);
    }
    Ok(out)
}
