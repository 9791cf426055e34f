//! The rotation rates of the local NED frame: the Earth rate `ω_ie^n` and the transport rate
//! `ω_en^n` (the turning of local level as the vehicle moves over the curved Earth), with the
//! transport rate's time derivative for the lever-arm and angular-acceleration terms.
//!
//! `ω_ie^n = ω_ie [cos φ, 0, −sin φ]`;
//! `ω_en^n = [v_E/(R_E + h), −v_N/(R_N + h), −v_E tan φ/(R_E + h)]` (Groves, *Principles of GNSS,
//! Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., eq. 5.44), which with
//! `φ̇ = v_N/(R_N + h)`, `λ̇ = v_E/((R_E + h) cos φ)` is `[λ̇ cos φ, −φ̇, −λ̇ sin φ]`. The tan φ
//! term is why navigation in NED refuses the poles (|φ| > 89.9°, see [`MAX_LATITUDE_RAD`]).
use crate::earth::wgs84::{E2, Geodetic, OMEGA_IE_RAD_S};
use crate::frame::Ned;
use crate::math;
use crate::vector::Vec3;

/// The largest |latitude| at which the local NED frame is used, rad (89.9°): nearer the pole
/// the transport rate's `tan φ` and the longitude rate grow without bound.
pub const MAX_LATITUDE_RAD: f64 = 89.9 * core::f64::consts::PI / 180.0;

/// The Earth rate in local NED, rad/s.
#[inline]
#[must_use]
pub fn earth_rate_ned(position: &Geodetic) -> Vec3<Ned> {
    let phi = position.latitude_rad;
    Vec3::new(
        OMEGA_IE_RAD_S * math::cos(phi),
        0.0,
        -OMEGA_IE_RAD_S * math::sin(phi),
    )
}

/// The transport rate `ω_en^n`, rad/s, for the ground velocity `v^n` (NED, m/s).
#[inline]
#[must_use]
pub fn transport_rate_ned(position: &Geodetic, velocity_m_s: Vec3<Ned>) -> Vec3<Ned> {
    let (r_n, r_e) = position.radii_m();
    let (rho_n, rho_e) = (r_n + position.height_m, r_e + position.height_m);
    let (v_n, v_e) = (velocity_m_s.x(), velocity_m_s.y());
    Vec3::new(
        v_e / rho_e,
        -v_n / rho_n,
        -v_e * math::tan(position.latitude_rad) / rho_e,
    )
}

/// Rates of the geodetic coordinates for the ground velocity `v^n`:
/// `(φ̇, λ̇, ḣ) = (v_N/(R_N + h), v_E/((R_E + h) cos φ), −v_D)`, rad/s, rad/s, m/s.
#[inline]
#[must_use]
pub fn geodetic_rates(position: &Geodetic, velocity_m_s: Vec3<Ned>) -> [f64; 3] {
    let (r_n, r_e) = position.radii_m();
    let h = position.height_m;
    [
        velocity_m_s.x() / (r_n + h),
        velocity_m_s.y() / ((r_e + h) * math::cos(position.latitude_rad)),
        -velocity_m_s.z(),
    ]
}

/// The time derivative of [`transport_rate_ned`]'s components for the ground velocity `v^n` and
/// its component derivative `v̇^n` (NED), rad/s²: the chain rule through `φ̇`, `ḣ`, `dR/dφ`.
#[must_use]
pub fn transport_rate_derivative_ned(
    position: &Geodetic,
    velocity_m_s: Vec3<Ned>,
    acceleration_m_s2: Vec3<Ned>,
) -> Vec3<Ned> {
    let phi = position.latitude_rad;
    let (r_n, r_e) = position.radii_m();
    let (s, c) = (math::sin(phi), math::cos(phi));
    let w = 1.0 - E2 * s * s;
    // dR_E/dφ = R_E e² sin φ cos φ / w, dR_N/dφ = 3 R_N e² sin φ cos φ / w.
    let dr_e = r_e * E2 * s * c / w;
    let dr_n = 3.0 * r_n * E2 * s * c / w;
    let h = position.height_m;
    let (rho_n, rho_e) = (r_n + h, r_e + h);
    let (v_n, v_e, v_d) = (velocity_m_s.x(), velocity_m_s.y(), velocity_m_s.z());
    let (a_n, a_e) = (acceleration_m_s2.x(), acceleration_m_s2.y());
    let phi_dot = v_n / rho_n;
    let h_dot = -v_d;
    let rho_e_dot = dr_e * phi_dot + h_dot;
    let rho_n_dot = dr_n * phi_dot + h_dot;
    let t = math::tan(phi);
    Vec3::new(
        a_e / rho_e - v_e * rho_e_dot / (rho_e * rho_e),
        -a_n / rho_n + v_n * rho_n_dot / (rho_n * rho_n),
        -(a_e * t + v_e * phi_dot / (c * c)) / rho_e + v_e * t * rho_e_dot / (rho_e * rho_e),
    )
}
