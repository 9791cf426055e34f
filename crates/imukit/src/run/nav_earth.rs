//! The Earth a table is navigated on, as the library's jobs see it: the one place where the
//! flat Earth and WGS-84 differ for `integrate` and `fuse` — how a front end's start becomes a
//! state, which columns a position fills and what a GNSS fix table holds. The navigation is the
//! core's, generic over [`EarthModel`]; both Earths run in the data's own frame (ENU with FLU
//! body axes, NED with FRD).
use imu_core::earth::{EarthModel, FlatEarth, Geodetic, GravityModel, MAX_LATITUDE_RAD, Wgs84};
use imu_core::strapdown::NavState;
use imu_core::{Body, Ecef, Enu, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::columns::{GEODETIC_COLUMNS, GNSS_COLUMNS, GNSS_EARTH_COLUMNS, NAV_COLUMNS};
use crate::io::conventions::NavFrameName;
use crate::run::navigate::{InitialState, euler_unwrapped};

/// The widest navigation row: [`NAV_COLUMNS`] and a geodetic position.
pub(crate) const MAX_NAV_WIDTH: usize = NAV_COLUMNS.len() + GEODETIC_COLUMNS.len();

/// What the library's jobs need of an Earth beyond the core's [`EarthModel`].
pub(crate) trait NavEarth: EarthModel {
    /// The columns a position fills after [`NAV_COLUMNS`]: none on the flat Earth, where the
    /// plane coordinates are the position; `lat_rad, lon_rad, height_m` on WGS-84.
    const POSITION_COLUMNS: &'static [&'static str];
    /// The columns of a GNSS fix table: time, position, velocity.
    const GNSS_COLUMNS: &'static [&'static str; 7];
    /// What completes the refusal of a fix table without them.
    const GNSS_HINT: &'static str;
    /// Where the output's plane coordinates (`pos_*`) are measured from.
    type Origin: Copy;

    /// The start's position and the plane's origin from a front end's initial state.
    ///
    /// # Errors
    /// A start that does not say where it is on this Earth.
    fn start_position(initial: &InitialState) -> Result<(Self::Position, Self::Origin)>;
    /// The plane's origin for a start at `position` (an alignment's, from a fix).
    fn origin_at(position: &Self::Position) -> Self::Origin;
    /// The plane coordinates of `position`, m.
    fn plane_m(position: &Self::Position, origin: &Self::Origin) -> [f64; 3];
    /// A fix's position from its table values, `None` outside the Earth's domain.
    fn fix_position(values: [f64; 3]) -> Option<Self::Position>;
    /// A fix's velocity in the navigation frame from its table values.
    fn fix_velocity(values: [f64; 3]) -> Vec3<Self::Frame>;
}

impl<N: NavFrame> NavEarth for FlatEarth<N> {
    const POSITION_COLUMNS: &'static [&'static str] = &[];
    const GNSS_COLUMNS: &'static [&'static str; 7] = &GNSS_COLUMNS;
    const GNSS_HINT: &'static str = "";
    type Origin = ();

    fn start_position(initial: &InitialState) -> Result<(Vec3<N>, ())> {
        Ok((Vec3::from_array(initial.position_m), ()))
    }
    fn origin_at(_position: &Vec3<N>) {}
    fn plane_m(position: &Vec3<N>, _origin: &()) -> [f64; 3] {
        position.to_array()
    }
    fn fix_position(values: [f64; 3]) -> Option<Vec3<N>> {
        Some(Vec3::from_array(values))
    }
    fn fix_velocity(values: [f64; 3]) -> Vec3<N> {
        Vec3::from_array(values)
    }
}

impl<N: NavFrame> NavEarth for Wgs84<N> {
    const POSITION_COLUMNS: &'static [&'static str] = &GEODETIC_COLUMNS;
    const GNSS_COLUMNS: &'static [&'static str; 7] = &GNSS_EARTH_COLUMNS;
    const GNSS_HINT: &'static str = " (fixes on the WGS-84 Earth are geodetic)";
    type Origin = Plane<N>;

    fn start_position(initial: &InitialState) -> Result<(Geodetic, Plane<N>)> {
        let position = initial.geodetic.ok_or_else(|| {
            invalid(
                "initial state",
                "--earth wgs84 needs the starting latitude, longitude and height: a truth file \
                 with lat_rad, lon_rad, height_m (from a scenario with earth = \"wgs84\"), or \
                 lat0_deg, lon0_deg, height0_m",
            )
        })?;
        Ok((
            position,
            Plane::at(&plane_origin::<N>(initial.position_m, &position)),
        ))
    }
    fn origin_at(position: &Geodetic) -> Plane<N> {
        Plane::at(position)
    }
    fn plane_m(position: &Geodetic, plane: &Plane<N>) -> [f64; 3] {
        plane
            .c_te
            .apply(position.to_ecef() - plane.origin_ecef_m)
            .to_array()
    }
    fn fix_position([lat, lon, h]: [f64; 3]) -> Option<Geodetic> {
        (lat.abs() <= MAX_LATITUDE_RAD && lon.is_finite() && h.is_finite()).then_some(Geodetic {
            latitude_rad: lat,
            longitude_rad: lon,
            height_m: h,
        })
    }
    fn fix_velocity(values: [f64; 3]) -> Vec3<N> {
        // The fix tables give the ground velocity north, east, down whatever the frame.
        N::from_ned_axes(Vec3::<Ned>::from_array(values))
    }
}

/// A job generic over the Earth, run by [`on_earth`] on the one a front end chose.
pub(crate) trait EarthJob {
    /// What the job returns.
    type Output;
    /// Runs the job on `earth`.
    fn run<E: NavEarth>(self, earth: E) -> Self::Output;
}

/// Runs `job` in `frame` on the flat Earth with gravity `gravity_m_s2` (`earth` `None`), or on
/// WGS-84 with the gravity model `earth`.
pub(crate) fn on_earth<J: EarthJob>(
    frame: NavFrameName,
    earth: Option<GravityModel>,
    gravity_m_s2: f64,
    job: J,
) -> J::Output {
    match (frame, earth) {
        (NavFrameName::ENU, None) => job.run(FlatEarth::<Enu>::new(gravity_m_s2)),
        (NavFrameName::NED, None) => job.run(FlatEarth::<Ned>::new(gravity_m_s2)),
        (NavFrameName::ENU, Some(g)) => job.run(Wgs84::<Enu>::new(g)),
        (NavFrameName::NED, Some(g)) => job.run(Wgs84::<Ned>::new(g)),
    }
}

/// The tangent plane of the `pos_*` columns on WGS-84, with what each row's coordinates need
/// worked out once: the origin in ECEF and the turn from ECEF to the plane's axes (frame `N`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Plane<N> {
    origin_ecef_m: Vec3<Ecef>,
    c_te: Rotation<Ecef, N>,
}

impl<N: NavFrame> Plane<N> {
    /// The plane tangent at `origin`.
    fn at(origin: &Geodetic) -> Self {
        Self {
            origin_ecef_m: origin.to_ecef(),
            c_te: origin.ned_to_ecef().inverse().then(&N::from_ned()),
        }
    }
}

/// The origin of the tangent plane whose coordinates are the `pos_*` columns: the origin `o` with
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

/// The starting state on Earth `E` from a front end's initial state at time `t0`, and the
/// plane's origin.
///
/// # Errors
/// A quaternion of zero norm, a start without a position on this Earth.
pub(crate) fn start<E: NavEarth>(
    initial: &InitialState,
    t0: f64,
) -> Result<(NavState<E>, E::Origin)> {
    let attitude = Rotation::<Body, E::Frame>::from_wxyz(initial.quaternion).ok_or_else(|| {
        invalid(
            "initial state",
            "the quaternion has zero norm or is not finite",
        )
    })?;
    let (position, origin) = E::start_position(initial)?;
    Ok((
        NavState {
            t_s: t0,
            attitude,
            velocity_m_s: Vec3::from_array(initial.velocity_m_s),
            position,
        },
        origin,
    ))
}

/// The output columns of a navigation on Earth `E`: [`NAV_COLUMNS`] then its position's.
pub(crate) fn nav_columns<E: NavEarth>() -> Vec<&'static str> {
    NAV_COLUMNS
        .iter()
        .chain(E::POSITION_COLUMNS)
        .copied()
        .collect()
}

/// One navigation row of state `s` — [`NAV_COLUMNS`] then the Earth's position columns — in
/// the first `NAV_COLUMNS.len() + E::POSITION_COLUMNS.len()` entries; the yaw is unwrapped
/// against `last_yaw` (then updated).
pub(crate) fn nav_row<E: NavEarth>(
    s: &NavState<E>,
    origin: &E::Origin,
    last_yaw: &mut Option<f64>,
) -> [f64; MAX_NAV_WIDTH] {
    let [qw, qx, qy, qz] = s.attitude.to_wxyz();
    let e = euler_unwrapped(&s.attitude, last_yaw);
    let [px, py, pz] = E::plane_m(&s.position, origin);
    let [vx, vy, vz] = s.velocity_m_s.to_array();
    let mut row = [0.0; MAX_NAV_WIDTH];
    row[..NAV_COLUMNS.len()].copy_from_slice(&[
        s.t_s,
        px,
        py,
        pz,
        vx,
        vy,
        vz,
        qw,
        qx,
        qy,
        qz,
        e.yaw_rad,
        e.pitch_rad,
        e.roll_rad,
    ]);
    let extra = E::POSITION_COLUMNS.len();
    row[NAV_COLUMNS.len()..NAV_COLUMNS.len() + extra]
        .copy_from_slice(&E::coordinates(&s.position)[..extra]);
    row
}

/// The width of a navigation row on Earth `E`.
pub(crate) const fn nav_width<E: NavEarth>() -> usize {
    NAV_COLUMNS.len() + E::POSITION_COLUMNS.len()
}
