//! A scenario on the WGS-84 Earth (`earth = "wgs84"`): the trajectory is given in the local
//! tangent plane at `origin` (metres along the scenario's frame axes, ENU or NED, attitude
//! relative to those axes) and carried exactly through ECEF onto the ellipsoid; truth is then
//! reported in the local-level frame at each position and the IMU senses the Earth rate,
//! transport rate, Coriolis force and normal gravity ([`imu_core::earth`]).
//!
//! The tangent plane is not the ellipsoid: a path level in the plane climbs away from the
//! ellipsoid (8 m after 10 km), and its local-level attitude turns with the transport rate.
//! Columns keep their meaning: `pos_*` are the tangent-plane coordinates, `vel_*`/`acc_*` the
//! ground velocity in the local-level frame at the position and the derivative of its
//! components, the attitude is relative to that frame, `omega_*` is the attitude rate
//! `ω_nb^b`; `lat_rad, lon_rad, height_m` and `ecef_*_m` are added.
use imu_core::earth::ideal::EcefKinematics;
use imu_core::earth::{EarthMount, EarthTruth, Geodetic, GravityModel, MagneticModel};
use imu_core::ideal::IdealReading;
use imu_core::{Body, Ecef, EulerZyx, NavFrame, Ned, Rotation, Truth, Vec3};

use crate::error::{Result, invalid};
use crate::io::columns::{EARTH_TRUTH_COLUMNS, TRUTH_COLUMNS};
use crate::io::table::{Table, truth_row};

/// The Earth a scenario runs on.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum EarthSetup {
    /// A flat, non-rotating Earth with constant gravity along the frame's vertical (MATLAB
    /// imuSensor's world; the default).
    #[default]
    Flat,
    /// The rotating WGS-84 ellipsoid, the trajectory in the tangent plane at the origin (boxed:
    /// it carries the magnetic model's coefficients).
    Wgs84(Box<TangentPlane>),
}

impl EarthSetup {
    /// The truth table's columns on this Earth: [`TRUTH_COLUMNS`], then on the WGS-84 Earth
    /// [`EARTH_TRUTH_COLUMNS`].
    #[must_use]
    pub fn truth_columns(&self) -> Vec<&'static str> {
        match self {
            Self::Flat => TRUTH_COLUMNS.to_vec(),
            Self::Wgs84(_) => earth_truth_columns(),
        }
    }
}

/// [`TRUTH_COLUMNS`], then [`EARTH_TRUTH_COLUMNS`]: the truth table on the WGS-84 Earth.
fn earth_truth_columns() -> Vec<&'static str> {
    TRUTH_COLUMNS
        .iter()
        .chain(&EARTH_TRUTH_COLUMNS)
        .copied()
        .collect()
}

/// The tangent plane at a point of the WGS-84 ellipsoid, the gravity model and the magnetic
/// field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentPlane {
    /// Where the plane touches: its axes are the local NED (or ENU) axes there.
    pub origin: Geodetic,
    /// Normal gravity, or a constant when the scenario sets `gravity_m_s2`.
    pub gravity: GravityModel,
    /// The World Magnetic Model and the date, or `None` for the constant field of the IMU.
    pub magnetic: Option<MagneticEnvironment>,
}

/// A magnetic model and the decimal year at `t = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticEnvironment {
    /// The model.
    pub model: MagneticModel,
    /// Decimal year at `t = 0`.
    pub year_at_start: f64,
}

/// Seconds in a decimal year of the magnetic model's clock (the mean Gregorian year).
const SECONDS_PER_YEAR: f64 = 365.2425 * 86_400.0;

impl MagneticEnvironment {
    /// The field at `earth`'s position and time, local NED, µT.
    ///
    /// # Errors
    /// The model's refusal (a height outside −1 km … 850 km, a time past its validity), with
    /// the time.
    pub fn field_ned_ut(&self, earth: &EarthTruth) -> Result<Vec3<Ned>> {
        let year = self.year_at_start + earth.t_s / SECONDS_PER_YEAR;
        self.model
            .field_ned_nt(&earth.position, year)
            .map(|f| f * 1e-3)
            .map_err(|e| invalid("magnetic_model", format!("at t = {} s: {e}", earth.t_s)))
    }
}

impl TangentPlane {
    /// Checks the origin: latitude within ±89.9° (the local NED frame is not used nearer the
    /// poles), every value finite, the height within 1000 km of the ellipsoid.
    ///
    /// # Errors
    /// The field out of range, named (`origin.latitude_deg`, …).
    pub fn new(origin: Geodetic, gravity: GravityModel) -> Result<Self> {
        let lat = origin.latitude_rad.to_degrees();
        if !(lat.is_finite() && lat.abs() <= imu_core::earth::MAX_LATITUDE_RAD.to_degrees()) {
            return Err(invalid(
                "origin.latitude_deg",
                format!(
                    "must be within ±89.9° (the local NED frame is not used at the poles), got {lat}"
                ),
            ));
        }
        let lon = origin.longitude_rad.to_degrees();
        if !(lon.is_finite() && lon.abs() <= 180.0) {
            return Err(invalid(
                "origin.longitude_deg",
                format!("must be within ±180°, got {lon}"),
            ));
        }
        if !(origin.height_m.is_finite() && origin.height_m.abs() <= 1e6) {
            return Err(invalid(
                "origin.height_m",
                format!(
                    "must be within ±1000 km of the ellipsoid, got {}",
                    origin.height_m
                ),
            ));
        }
        Ok(Self {
            origin,
            gravity,
            magnetic: None,
        })
    }

    /// The coordinates of `p` in the plane, axes of `frame`, m.
    #[must_use]
    pub fn plane_coordinates(
        &self,
        p: &Geodetic,
        frame: crate::io::conventions::NavFrameName,
    ) -> [f64; 3] {
        let d = p.to_ecef() - self.origin.to_ecef();
        match frame {
            crate::io::conventions::NavFrameName::ENU => self
                .plane_to_ecef::<imu_core::Enu>()
                .inverse()
                .apply(d)
                .to_array(),
            crate::io::conventions::NavFrameName::NED => self
                .plane_to_ecef::<imu_core::Ned>()
                .inverse()
                .apply(d)
                .to_array(),
        }
    }

    /// Geodetic samples (`[φ, λ, h]`, attitude relative to the local level) placed in the plane:
    /// positions in plane coordinates, attitudes as quaternions relative to the plane's axes
    /// (`C_tb = C_t,local(φ, λ) C_local,b`), axes of `frame`. The finite differences then run
    /// in the plane, where the motion is smooth.
    ///
    /// # Errors
    /// A latitude beyond ±89.9° or a value that is not finite, with its row.
    pub fn place_samples(
        &self,
        path: &mut crate::motion::SampledPath,
        frame: crate::io::conventions::NavFrameName,
    ) -> Result<()> {
        match frame {
            crate::io::conventions::NavFrameName::ENU => self.place_in::<imu_core::Enu>(path),
            crate::io::conventions::NavFrameName::NED => self.place_in::<imu_core::Ned>(path),
        }
    }

    fn place_in<N: NavFrame>(&self, path: &mut crate::motion::SampledPath) -> Result<()> {
        use crate::motion::sampled::SampledAttitudeData;
        let c_te = self.plane_to_ecef::<N>().inverse();
        let r0 = self.origin.to_ecef();
        let mut quaternions = Vec::with_capacity(path.position_m.len());
        for (k, p) in path.position_m.iter_mut().enumerate() {
            let [lat, lon, h] = *p;
            if !(lat.abs() <= imu_core::earth::MAX_LATITUDE_RAD && lon.is_finite() && h.is_finite())
            {
                return Err(invalid(
                    &path.origin,
                    format!(
                        "row {}: latitude {lat} rad, longitude {lon} rad, height {h} m: the latitude must be within ±89.9° and every value finite",
                        k + path.first_row
                    ),
                ));
            }
            let g = Geodetic {
                latitude_rad: lat,
                longitude_rad: lon,
                height_m: h,
            };
            *p = c_te.apply(g.to_ecef() - r0).to_array();
            // Local level of N's convention at the sample, in the plane's axes.
            let local: Rotation<N, N> = N::from_ned().inverse().then(&g.ned_to_ecef()).then(&c_te);
            let body: Option<Rotation<Body, N>> = match &path.attitude {
                SampledAttitudeData::Euler(e) => Some(Rotation::from_euler(e[k])),
                SampledAttitudeData::Quaternion(q) => {
                    Some(Rotation::from_wxyz(q[k]).ok_or_else(|| {
                        invalid(
                            &path.origin,
                            format!(
                                "row {}: the quaternion has zero norm or is not finite",
                                k + path.first_row
                            ),
                        )
                    })?)
                }
                SampledAttitudeData::Tangent => None,
            };
            if let Some(b) = body {
                quaternions.push(b.then(&local).to_wxyz());
            }
        }
        if !matches!(path.attitude, SampledAttitudeData::Tangent) {
            path.attitude = SampledAttitudeData::Quaternion(quaternions);
        }
        path.geodetic = false;
        Ok(())
    }

    /// The tangent-plane axes of `N` resolved in ECEF.
    fn plane_to_ecef<N: NavFrame>(&self) -> Rotation<N, Ecef> {
        N::from_ned().inverse().then(&self.origin.ned_to_ecef())
    }

    /// A tangent-plane truth sample (frame `N`, body axes of `N`'s convention) on the Earth.
    ///
    /// # Errors
    /// A position within 43 km of the Earth's centre, or beyond ±89.9° of latitude, named with
    /// its time.
    pub fn to_earth<N: NavFrame>(&self, s: &Truth<N>) -> Result<EarthTruth> {
        let c_et = self.plane_to_ecef::<N>();
        let to_frd = N::frd_to_body().inverse();
        let k = EcefKinematics {
            position_m: self.origin.to_ecef() + c_et.apply(s.position_m),
            velocity_m_s: c_et.apply(s.velocity_m_s),
            acceleration_m_s2: c_et.apply(s.acceleration_m_s2),
            attitude: N::frd_to_body().then(&s.attitude).then(&c_et),
            omega_eb_b_rad_s: to_frd.apply(s.omega_b_rad_s),
            alpha_eb_b_rad_s2: to_frd.apply(s.alpha_b_rad_s2),
        };
        let earth = EarthTruth::from_ecef(s.t_s, &k).ok_or_else(|| {
            invalid(
                "trajectory",
                format!("at t = {} s the position is not on the Earth (too near its centre or not finite)", s.t_s),
            )
        })?;
        if earth.position.latitude_rad.abs() > imu_core::earth::MAX_LATITUDE_RAD {
            return Err(invalid(
                "trajectory",
                format!(
                    "at t = {} s the latitude is {:.4}°, beyond ±89.9° where the local NED frame is not used",
                    s.t_s,
                    earth.position.latitude_rad.to_degrees()
                ),
            ));
        }
        Ok(earth)
    }

    /// The truth sample as reported in frame `N`: the tangent-plane position of `plane`, the
    /// rest in the local-level frame at the position (`N`'s axes and body convention).
    #[must_use]
    pub fn local<N: NavFrame>(plane: &Truth<N>, earth: &EarthTruth) -> Truth<N> {
        let from_ned = N::from_ned();
        let to_body = N::frd_to_body();
        let attitude = to_body.inverse().then(&earth.attitude).then(&from_ned);
        Truth {
            t_s: earth.t_s,
            position_m: plane.position_m,
            velocity_m_s: from_ned.apply(earth.velocity_m_s),
            acceleration_m_s2: from_ned.apply(earth.acceleration_m_s2),
            attitude,
            euler: unwrap_yaw(attitude.to_euler(), plane.euler),
            omega_b_rad_s: to_body.apply(earth.omega_nb_b_rad_s),
            alpha_b_rad_s2: to_body.apply(earth.alpha_nb_b_rad_s2),
        }
    }

    /// The columns [`EARTH_TRUTH_COLUMNS`] of a sample.
    #[must_use]
    pub fn earth_row(earth: &EarthTruth) -> [f64; 6] {
        let p = &earth.position;
        let r = p.to_ecef();
        [
            p.latitude_rad,
            p.longitude_rad,
            p.height_m,
            r.x(),
            r.y(),
            r.z(),
        ]
    }

    /// The ideal reading on the Earth in `N`'s body convention, for the lever arm (body axes
    /// of `N`'s convention, m) and the magnetic field in local NED (µT): the specific force
    /// (physical sign), the inertial rate `ω_ib^b` and the field in body axes.
    #[must_use]
    pub fn ideal<N: NavFrame>(
        &self,
        earth: &EarthTruth,
        lever_arm_m: Vec3<Body>,
        field_ned: Vec3<Ned>,
    ) -> IdealReading {
        let mount = EarthMount {
            lever_arm_m: N::frd_to_body().inverse().apply(lever_arm_m),
            accel_sign: imu_core::AccelSign::SpecificForce,
            gravity: self.gravity,
        };
        mount.read(earth, field_ned).to_body::<N>()
    }
}

/// A chunk of truth on the Earth as a table: [`crate::io::columns::TRUTH_COLUMNS`] of the local
/// samples, then [`EARTH_TRUTH_COLUMNS`].
#[must_use]
pub fn earth_truth_table<N: NavFrame>(local: &[Truth<N>], earth: &[EarthTruth]) -> Table {
    let names = earth_truth_columns();
    let mut t = Table::new(&names);
    t.data.reserve(local.len() * names.len());
    for (s, e) in local.iter().zip(earth) {
        t.data.extend_from_slice(&truth_row(s));
        t.data.extend_from_slice(&TangentPlane::earth_row(e));
    }
    t
}

/// Keeps yaw continuous with the tangent-plane yaw (which the trajectory unwrapped).
fn unwrap_yaw(e: EulerZyx, reference: EulerZyx) -> EulerZyx {
    let two_pi = 2.0 * std::f64::consts::PI;
    let yaw = e.yaw_rad + two_pi * ((reference.yaw_rad - e.yaw_rad) / two_pi).round();
    EulerZyx::new(yaw, e.pitch_rad, e.roll_rad)
}
