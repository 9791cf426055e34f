//! Gravity on the WGS-84 Earth: normal gravity (Somigliana with the height correction) or a
//! constant, along the ellipsoid normal (local down).
//!
//! NIMA TR8350.2 (3rd ed., 2000): eq. 4-1, `γ₀(φ) = γ_e (1 + k sin²φ)/√(1 − e² sin²φ)`, and
//! eq. 4-3, `γ(φ, h) = γ₀ [1 − (2/a)(1 + f + m − 2f sin²φ) h + (3/a²) h²]` with
//! `m = ω_ie² a² b / GM`. Gravity here is gravitation plus the centrifugal acceleration of the
//! Earth's rotation, which is what a specific-force equation in the rotating frame subtracts.
//! Its small deflection from the ellipsoid normal at height (below 1e-6 rad for aircraft
//! heights) is neglected: `g^n = [0, 0, γ]` in NED.
use crate::earth::wgs84::{A_M, B_M, E2, F, GM_M3_S2, Geodetic, OMEGA_IE_RAD_S};
use crate::math;

/// Normal gravity on the equator `γ_e`, m/s² (TR8350.2 table 3.4).
pub const GAMMA_EQUATOR_M_S2: f64 = 9.780_325_335_9;
/// Somigliana's constant `k` (TR8350.2 table 3.4).
pub const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;
/// `m = ω_ie² a² b / GM` (TR8350.2 table 3.4: 0.00344978650684).
pub const M_RATIO: f64 = OMEGA_IE_RAD_S * OMEGA_IE_RAD_S * A_M * A_M * B_M / GM_M3_S2;

/// Normal gravity magnitude `γ(φ, h)`, m/s² (TR8350.2 eq. 4-1 and 4-3).
#[inline]
#[must_use]
pub fn normal_gravity_m_s2(position: &Geodetic) -> f64 {
    let s2 = {
        let s = math::sin(position.latitude_rad);
        s * s
    };
    let gamma0 = GAMMA_EQUATOR_M_S2 * (1.0 + SOMIGLIANA_K * s2) / math::sqrt(1.0 - E2 * s2);
    let h = position.height_m;
    gamma0 * (1.0 - 2.0 / A_M * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 / (A_M * A_M) * h * h)
}

/// Which gravity the Earth model uses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum GravityModel {
    /// WGS-84 normal gravity `γ(φ, h)` (the default).
    #[default]
    Normal,
    /// A constant magnitude, m/s², along local down (for comparisons with the flat model).
    Constant(f64),
}

impl GravityModel {
    /// The gravity magnitude at `position`, m/s².
    #[inline]
    #[must_use]
    pub fn magnitude_m_s2(&self, position: &Geodetic) -> f64 {
        match *self {
            Self::Normal => normal_gravity_m_s2(position),
            Self::Constant(g) => g,
        }
    }
}
