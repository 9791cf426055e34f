//! The WGS-84 ellipsoid: constants, radii of curvature, geodetic ↔ ECEF, and the local NED axes.
//!
//! Constants from NIMA TR8350.2 (3rd ed., 2000), tables 3.1 and 3.3. The inverse transform is
//! Vermeille's closed form (H. Vermeille, "An analytical method to transform geocentric into
//! geodetic coordinates", J. Geodesy 85, 2011), exact for every point farther than about 43 km
//! from the Earth's centre, i.e. anywhere a vehicle can be.
use crate::frame::{Ecef, Ned};
use crate::math;
use crate::rotation::Rotation;
use crate::vector::Vec3;

/// Semi-major axis `a`, m.
pub const A_M: f64 = 6_378_137.0;
/// Flattening `f = 1/298.257223563`.
pub const F: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared `e² = f(2 − f)`.
pub const E2: f64 = F * (2.0 - F);
/// Semi-minor axis `b = a(1 − f)`, m.
pub const B_M: f64 = A_M * (1.0 - F);
/// Angular velocity of the Earth `ω_ie`, rad/s.
pub const OMEGA_IE_RAD_S: f64 = 7.292_115e-5;
/// Earth's gravitational constant `GM` (atmosphere included), m³/s².
pub const GM_M3_S2: f64 = 3.986_004_418e14;

/// Geodetic coordinates on WGS-84.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Geodetic {
    /// Geodetic latitude φ, rad, in [−π/2, π/2].
    pub latitude_rad: f64,
    /// Longitude λ, rad, east positive.
    pub longitude_rad: f64,
    /// Height above the ellipsoid h, m.
    pub height_m: f64,
}

impl Geodetic {
    /// From degrees and metres.
    #[must_use]
    pub fn from_degrees(latitude_deg: f64, longitude_deg: f64, height_m: f64) -> Self {
        Self {
            latitude_rad: latitude_deg.to_radians(),
            longitude_rad: longitude_deg.to_radians(),
            height_m,
        }
    }

    /// Meridian radius of curvature `R_N = a(1 − e²)/(1 − e² sin²φ)^{3/2}` and prime-vertical
    /// radius `R_E = a/√(1 − e² sin²φ)`, m.
    #[inline]
    #[must_use]
    pub fn radii_m(&self) -> (f64, f64) {
        let s = math::sin(self.latitude_rad);
        let w = 1.0 - E2 * s * s;
        let r_e = A_M / math::sqrt(w);
        (r_e * (1.0 - E2) / w, r_e)
    }

    /// The ECEF position, m:
    /// `[(R_E + h) cos φ cos λ, (R_E + h) cos φ sin λ, (R_E(1 − e²) + h) sin φ]`.
    #[must_use]
    pub fn to_ecef(&self) -> Vec3<Ecef> {
        let (_, r_e) = self.radii_m();
        let (sp, cp) = (math::sin(self.latitude_rad), math::cos(self.latitude_rad));
        let (sl, cl) = (math::sin(self.longitude_rad), math::cos(self.longitude_rad));
        let h = self.height_m;
        Vec3::new(
            (r_e + h) * cp * cl,
            (r_e + h) * cp * sl,
            (r_e * (1.0 - E2) + h) * sp,
        )
    }

    /// The geodetic coordinates of an ECEF position (Vermeille 2011; longitude in (−π, π], 0 on
    /// the polar axis). `None` within about 43 km of the Earth's centre, where the closed form
    /// does not hold, and for non-finite input.
    #[must_use]
    pub fn from_ecef(r: Vec3<Ecef>) -> Option<Self> {
        let (x, y, z) = (r.x(), r.y(), r.z());
        let e4 = E2 * E2;
        let rho2 = x * x + y * y;
        let p = rho2 / (A_M * A_M);
        let q = (1.0 - E2) / (A_M * A_M) * z * z;
        let r6 = (p + q - e4) / 6.0;
        if !(r6 > 0.0 && r6.is_finite()) {
            return None;
        }
        let s = e4 * p * q / (4.0 * r6 * r6 * r6);
        let t = math::cbrt(1.0 + s + math::sqrt(s * (2.0 + s)));
        let u = r6 * (1.0 + t + 1.0 / t);
        let v = math::sqrt(u * u + e4 * q);
        let w = E2 * (u + v - q) / (2.0 * v);
        let k = math::sqrt(u + v + w * w) - w;
        let rho = math::sqrt(rho2);
        let d = k * rho / (k + E2);
        let dz = math::sqrt(d * d + z * z);
        let out = Self {
            latitude_rad: 2.0 * math::atan2(z, d + dz),
            longitude_rad: if rho2 > 0.0 {
                2.0 * math::atan2(y, x + rho)
            } else {
                0.0
            },
            height_m: (k + E2 - 1.0) / k * dz,
        };
        let finite = out.latitude_rad.is_finite()
            && out.longitude_rad.is_finite()
            && out.height_m.is_finite();
        finite.then_some(out)
    }

    /// The local NED axes at this point resolved in ECEF, `C_en` (NED → ECEF): its columns are
    /// north `[−sin φ cos λ, −sin φ sin λ, cos φ]`, east `[−sin λ, cos λ, 0]` and down
    /// `[−cos φ cos λ, −cos φ sin λ, −sin φ]`.
    #[must_use]
    pub fn ned_to_ecef(&self) -> Rotation<Ned, Ecef> {
        let (sp, cp) = (math::sin(self.latitude_rad), math::cos(self.latitude_rad));
        let (sl, cl) = (math::sin(self.longitude_rad), math::cos(self.longitude_rad));
        Rotation::from_dcm(&[
            [-sp * cl, -sl, -cp * cl],
            [-sp * sl, cl, -cp * sl],
            [cp, 0.0, -sp],
        ])
    }
}
