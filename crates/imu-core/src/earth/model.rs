//! What a navigation frame on a given Earth supplies to the strapdown and the error-state
//! filter: [`EarthModel`], implemented by the flat Earth ([`FlatEarth`]: constant gravity, a
//! frame that does not turn) and by WGS-84 ([`Wgs84`]: normal gravity, the Earth and transport
//! rates, geodetic coordinates), each in ENU or NED. The navigation algorithms are written once
//! against the trait; a further Earth (a sphere, another ellipsoid) is one implementation.
//!
//! A position is held as three coordinates ([`EarthModel::Position`] converts): metres of the
//! local-level frame on the flat Earth, latitude, longitude (rad) and height (m) on WGS-84. The
//! navigation equations in the frame `n` of the model, with `ω_in = ω_ie + ω_en`:
//! `q̇_nb = ½ q_nb ⊗ (0, ω_ib^b) − ½ (0, ω_in^n) ⊗ q_nb`,
//! `v̇ = C_nb f^b + g^n − (2 ω_ie^n + ω_en^n) × v`, `ċ = ` [`EarthModel::position_rate`]`(c, v)`.
use core::marker::PhantomData;

use crate::earth::gravity::GravityModel;
use crate::earth::rates::{MAX_LATITUDE_RAD, earth_rate_ned, geodetic_rates, transport_rate_ned};
use crate::earth::wgs84::{Geodetic, OMEGA_IE_RAD_S};
use crate::frame::Ned;
use crate::math;
use crate::nav_frame::NavFrame;
use crate::vector::Vec3;

/// Gravity and the frame's rotation at one position and velocity, resolved in the navigation
/// frame `F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthTerms<F> {
    /// Gravity `g^n` (gravitation plus the centrifugal term of the Earth's rotation), m/s².
    pub gravity_m_s2: Vec3<F>,
    /// The Earth's rotation rate `ω_ie^n`, rad/s.
    pub earth_rate_rad_s: Vec3<F>,
    /// The transport rate `ω_en^n` (the turning of local level as the vehicle moves), rad/s.
    pub transport_rate_rad_s: Vec3<F>,
}

/// The error model's couplings through the Earth (Groves 2nd ed. §14.2.4, position error in
/// metres of the navigation frame): `δv̇ += G δp − [(2ω_ie + ω_en)×] δv`,
/// `φ̇ += −[ω_in×] φ − P δp − V δv`, row-major 3 × 3 blocks in the navigation frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorCouplings {
    /// `G = ∂g/∂p`: the gravity gradient's vertical term (the vertical channel's instability).
    pub gravity_gradient: [[f64; 3]; 3],
    /// `∂ω_in/∂p`: the frame rate's change with position.
    pub rate_by_position: [[f64; 3]; 3],
    /// `∂ω_en/∂v`: the transport rate's change with velocity (closes the Schuler loop).
    pub rate_by_velocity: [[f64; 3]; 3],
}

/// A navigation frame on an Earth: what the strapdown and the filter need of it.
pub trait EarthModel: Copy + core::fmt::Debug + PartialEq + Send + Sync + 'static {
    /// The local-level navigation frame ([`crate::Enu`] or [`crate::Ned`]).
    type Frame: NavFrame;
    /// A position on this Earth.
    type Position: Copy + core::fmt::Debug + Default + PartialEq;
    /// Whether the navigation frame turns (Earth rate, transport rate) and gravity varies with
    /// position; `false` lets the algorithms skip those terms (they are zero or constant).
    const ROTATING: bool;

    /// The three coordinates of a position.
    fn coordinates(position: &Self::Position) -> [f64; 3];
    /// The position of three coordinates.
    fn position(coordinates: [f64; 3]) -> Self::Position;
    /// Gravity and the frame rates at coordinates `c` and velocity `v`.
    fn terms(&self, c: &[f64; 3], v: &Vec3<Self::Frame>) -> EarthTerms<Self::Frame>;
    /// The coordinates' time derivative for velocity `v`.
    fn position_rate(&self, c: &[f64; 3], v: &Vec3<Self::Frame>) -> [f64; 3];
    /// Whether the navigation frame is defined at `c` (WGS-84's NED refuses the poles).
    fn in_domain(&self, c: &[f64; 3]) -> bool;
    /// The canonical coordinates of `c` (longitude wrapped into (−π, π] on WGS-84).
    fn wrap(&self, c: [f64; 3]) -> [f64; 3] {
        c
    }
    /// The height above the reference surface at `c`, m, and `∂c₂/∂h` (+1 when the third
    /// coordinate counts up, −1 when down).
    fn height_m(&self, c: &[f64; 3]) -> (f64, f64);
    /// The radius of curvature the vertical channel's gravity gradient `2g/R` uses, m
    /// (infinite on the flat Earth).
    fn radius_m(&self, c: &[f64; 3]) -> f64;
    /// The displacement from `from` to `to` in metres of the navigation frame at `from`.
    fn displacement_m(&self, from: &[f64; 3], to: &[f64; 3]) -> Vec3<Self::Frame>;
    /// `c` moved by `d` metres of the navigation frame (the inverse of
    /// [`Self::displacement_m`] to first order).
    fn offset(&self, c: &[f64; 3], d: &Vec3<Self::Frame>) -> [f64; 3];
    /// The error model's couplings at `c`, velocity `v` (`None` when the frame does not turn).
    fn couplings(&self, c: &[f64; 3], v: &Vec3<Self::Frame>) -> Option<ErrorCouplings>;
}

/// The flat Earth: a local-level frame `N` that does not turn, constant gravity along its
/// vertical, positions in metres of `N`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatEarth<N> {
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    frame: PhantomData<N>,
}

impl<N: NavFrame> FlatEarth<N> {
    /// A flat Earth with gravity `gravity_m_s2`.
    #[must_use]
    pub fn new(gravity_m_s2: f64) -> Self {
        Self {
            gravity_m_s2,
            frame: PhantomData,
        }
    }
}

impl<N: NavFrame> Default for FlatEarth<N> {
    fn default() -> Self {
        Self::new(crate::frame::DEFAULT_GRAVITY_M_S2)
    }
}

impl<N: NavFrame> EarthModel for FlatEarth<N> {
    type Frame = N;
    type Position = Vec3<N>;
    const ROTATING: bool = false;

    #[inline]
    fn coordinates(position: &Vec3<N>) -> [f64; 3] {
        position.to_array()
    }
    #[inline]
    fn position(coordinates: [f64; 3]) -> Vec3<N> {
        Vec3::from_array(coordinates)
    }
    #[inline]
    fn terms(&self, _c: &[f64; 3], _v: &Vec3<N>) -> EarthTerms<N> {
        EarthTerms {
            gravity_m_s2: N::gravity(self.gravity_m_s2),
            earth_rate_rad_s: Vec3::zeros(),
            transport_rate_rad_s: Vec3::zeros(),
        }
    }
    #[inline]
    fn position_rate(&self, _c: &[f64; 3], v: &Vec3<N>) -> [f64; 3] {
        v.to_array()
    }
    #[inline]
    fn in_domain(&self, _c: &[f64; 3]) -> bool {
        true
    }
    #[inline]
    fn height_m(&self, c: &[f64; 3]) -> (f64, f64) {
        (N::Z_UP * c[2], N::Z_UP)
    }
    #[inline]
    fn radius_m(&self, _c: &[f64; 3]) -> f64 {
        f64::INFINITY
    }
    #[inline]
    fn displacement_m(&self, from: &[f64; 3], to: &[f64; 3]) -> Vec3<N> {
        Vec3::from_array(*to) - Vec3::from_array(*from)
    }
    #[inline]
    fn offset(&self, c: &[f64; 3], d: &Vec3<N>) -> [f64; 3] {
        (Vec3::<N>::from_array(*c) + *d).to_array()
    }
    #[inline]
    fn couplings(&self, _c: &[f64; 3], _v: &Vec3<N>) -> Option<ErrorCouplings> {
        None
    }
}

/// The rotating WGS-84 Earth: geodetic positions, normal (or constant) gravity along the
/// ellipsoid normal, the Earth and transport rates; navigation in the local-level frame `N`
/// (NED, or ENU with the same equations re-resolved). The frame is refused beyond ±89.9°
/// ([`MAX_LATITUDE_RAD`]), where the transport rate's `tan φ` grows without bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wgs84<N> {
    /// The gravity model.
    pub gravity: GravityModel,
    frame: PhantomData<N>,
}

impl<N: NavFrame> Wgs84<N> {
    /// WGS-84 with `gravity`.
    #[must_use]
    pub fn new(gravity: GravityModel) -> Self {
        Self {
            gravity,
            frame: PhantomData,
        }
    }
}

impl<N: NavFrame> Default for Wgs84<N> {
    #[inline]
    fn default() -> Self {
        Self::new(GravityModel::Normal)
    }
}

#[inline]
fn geodetic(c: &[f64; 3]) -> Geodetic {
    Geodetic {
        latitude_rad: c[0],
        longitude_rad: c[1],
        height_m: c[2],
    }
}

/// An angle difference wrapped to (−π, π].
pub(crate) fn wrap_pi(a: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    let d = a - two_pi * math::round(a / two_pi);
    if d <= -core::f64::consts::PI {
        d + two_pi
    } else {
        d
    }
}

fn matrix_from_ned<N: NavFrame>(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    // Rows and columns re-resolved: M_N = T M T⁻¹ for the axis change T (a signed permutation).
    let rows: [Vec3<N>; 3] =
        core::array::from_fn(|j| N::from_ned_axes(Vec3::<Ned>::new(m[0][j], m[1][j], m[2][j])));
    let t: [[f64; 3]; 3] =
        core::array::from_fn(|i| core::array::from_fn(|j| rows[j].to_array()[i]));
    core::array::from_fn(|i| N::from_ned_axes(Vec3::<Ned>::from_array(t[i])).to_array())
}

impl<N: NavFrame> EarthModel for Wgs84<N> {
    type Frame = N;
    type Position = Geodetic;
    const ROTATING: bool = true;

    #[inline]
    fn coordinates(p: &Geodetic) -> [f64; 3] {
        [p.latitude_rad, p.longitude_rad, p.height_m]
    }
    #[inline]
    fn position(c: [f64; 3]) -> Geodetic {
        geodetic(&c)
    }
    #[inline]
    fn terms(&self, c: &[f64; 3], v: &Vec3<N>) -> EarthTerms<N> {
        let p = geodetic(c);
        let v_ned = N::to_ned_axes(*v);
        EarthTerms {
            gravity_m_s2: N::from_ned_axes(Vec3::new(0.0, 0.0, self.gravity.magnitude_m_s2(&p))),
            earth_rate_rad_s: N::from_ned_axes(earth_rate_ned(&p)),
            transport_rate_rad_s: N::from_ned_axes(transport_rate_ned(&p, v_ned)),
        }
    }
    #[inline]
    fn position_rate(&self, c: &[f64; 3], v: &Vec3<N>) -> [f64; 3] {
        geodetic_rates(&geodetic(c), N::to_ned_axes(*v))
    }
    #[inline]
    fn in_domain(&self, c: &[f64; 3]) -> bool {
        c[0].is_finite() && math::abs(c[0]) <= MAX_LATITUDE_RAD
    }
    #[inline]
    fn wrap(&self, mut c: [f64; 3]) -> [f64; 3] {
        let pi = core::f64::consts::PI;
        if c[1] > pi || c[1] <= -pi {
            c[1] -= 2.0 * pi * math::round(c[1] / (2.0 * pi));
        }
        c
    }
    #[inline]
    fn height_m(&self, c: &[f64; 3]) -> (f64, f64) {
        (c[2], 1.0)
    }
    #[inline]
    fn radius_m(&self, c: &[f64; 3]) -> f64 {
        let (r_n, r_e) = geodetic(c).radii_m();
        math::sqrt(r_n * r_e)
    }
    #[inline]
    fn displacement_m(&self, from: &[f64; 3], to: &[f64; 3]) -> Vec3<N> {
        let (r_n, r_e) = geodetic(from).radii_m();
        N::from_ned_axes(Vec3::new(
            (to[0] - from[0]) * (r_n + from[2]),
            wrap_pi(to[1] - from[1]) * (r_e + from[2]) * math::cos(from[0]),
            -(to[2] - from[2]),
        ))
    }
    #[inline]
    fn offset(&self, c: &[f64; 3], d: &Vec3<N>) -> [f64; 3] {
        let d = N::to_ned_axes(*d);
        let (r_n, r_e) = geodetic(c).radii_m();
        [
            c[0] + d.x() / (r_n + c[2]),
            c[1] + d.y() / ((r_e + c[2]) * math::cos(c[0])),
            c[2] - d.z(),
        ]
    }
    #[inline]
    fn couplings(&self, c: &[f64; 3], _v: &Vec3<N>) -> Option<ErrorCouplings> {
        let p = geodetic(c);
        let (r_n, r_e) = p.radii_m();
        let (rho_n, rho_e) = (r_n + p.height_m, r_e + p.height_m);
        let gamma = self.gravity.magnitude_m_s2(&p);
        let r = math::sqrt(r_n * r_e) + p.height_m;
        let (sin_l, cos_l) = (math::sin(p.latitude_rad), math::cos(p.latitude_rad));
        let tan_l = sin_l / cos_l;
        // NED: the gravity model's error is vertical only (the horizontal Schuler feedback
        // comes from the tilt the transport rate's error makes; a horizontal gradient as well
        // would double it).
        let mut gravity_gradient = [[0.0; 3]; 3];
        gravity_gradient[2][2] = 2.0 * gamma / r;
        // ∂ω_ie/∂p_N = ∂ω_ie/∂φ / (R_N + h).
        let mut rate_by_position = [[0.0; 3]; 3];
        rate_by_position[0][0] = -OMEGA_IE_RAD_S * sin_l / rho_n;
        rate_by_position[2][0] = -OMEGA_IE_RAD_S * cos_l / rho_n;
        let mut rate_by_velocity = [[0.0; 3]; 3];
        rate_by_velocity[0][1] = 1.0 / rho_e;
        rate_by_velocity[1][0] = -1.0 / rho_n;
        rate_by_velocity[2][1] = -tan_l / rho_e;
        Some(ErrorCouplings {
            gravity_gradient: matrix_from_ned::<N>(gravity_gradient),
            rate_by_position: matrix_from_ned::<N>(rate_by_position),
            rate_by_velocity: matrix_from_ned::<N>(rate_by_velocity),
        })
    }
}
