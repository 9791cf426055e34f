//! The World Magnetic Model (WMM2025): the Earth's main magnetic field at a geodetic position
//! and a time, in local NED, by spherical-harmonic synthesis to degree 12 in double precision.
//!
//! The method of the WMM technical report (NOAA NCEI / BGS, "The US/UK World Magnetic Model for
//! 2025-2030"): geodetic → geocentric spherical coordinates, Gauss coefficients advanced
//! linearly from the epoch, Schmidt semi-normalised associated Legendre functions by their
//! standard recursions,
//! `X' = −Σ (a/r)^{n+2} Σ (g cos mλ + h sin mλ) dP_n^m/dφ'`,
//! `Y' = (1/cos φ') Σ (a/r)^{n+2} Σ m (g sin mλ − h cos mλ) P_n^m`,
//! `Z' = −Σ (n+1) (a/r)^{n+2} Σ (g cos mλ + h sin mλ) P_n^m`,
//! then rotated by `φ' − φ` back to the geodetic north and down. The coefficients are NOAA's
//! (`wmm2025.cof`, public domain). The Rust crate `world_magnetic_model` evaluates the same model
//! in single precision and by whole days, which misses the official test values' printed
//! 0.1 nT by up to 0.1 nT; imukit needs the model to the printed digit.
use crate::earth::wgs84::{E2, Geodetic};
use crate::frame::Ned;
use crate::math;
use crate::vector::Vec3;

/// Largest degree of the model.
pub const DEGREE: usize = 12;
/// Coefficients per set: `n = 1..=12`, `m = 0..=n`.
const COEFFICIENTS: usize = DEGREE * (DEGREE + 3) / 2;
/// Geomagnetic reference radius `a`, m.
pub const REFERENCE_RADIUS_M: f64 = 6_371_200.0;
/// Lowest height above the ellipsoid the model is meant for, m.
pub const MIN_HEIGHT_M: f64 = -1_000.0;
/// Highest height above the ellipsoid the model is meant for, m.
pub const MAX_HEIGHT_M: f64 = 850_000.0;

/// A spherical-harmonic main-field model with linear secular variation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticModel {
    name: &'static str,
    epoch_year: f64,
    valid_until_year: f64,
    g: [f64; COEFFICIENTS],
    h: [f64; COEFFICIENTS],
    g_dot: [f64; COEFFICIENTS],
    h_dot: [f64; COEFFICIENTS],
}

/// Why the model cannot give a field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WmmError {
    /// The time is outside the model's validity.
    OutsideValidity {
        /// The decimal year asked for.
        year: f64,
        /// The model's first valid year.
        from: f64,
        /// The year it expires.
        until: f64,
    },
    /// The height is outside −1 km … 850 km.
    Height {
        /// The height, m.
        height_m: f64,
    },
    /// A position or time that is not a finite number.
    NotFinite,
}

impl core::fmt::Display for WmmError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::OutsideValidity { year, from, until } => write!(
                f,
                "the World Magnetic Model is valid from {from:.1} to {until:.1}, asked for {year:.3}"
            ),
            Self::Height { height_m } => write!(
                f,
                "the World Magnetic Model is meant for heights from -1 km to 850 km, asked for {:.3} km",
                height_m / 1000.0
            ),
            Self::NotFinite => write!(f, "the position or time is not a finite number"),
        }
    }
}

impl core::error::Error for WmmError {}

/// Index of `(n, m)` in the coefficient arrays.
const fn index(n: usize, m: usize) -> usize {
    n * (n + 1) / 2 - 1 + m
}

impl MagneticModel {
    /// WMM2025 (epoch 2025.0, valid to 2030.0), from NOAA's coefficient file.
    #[must_use]
    pub fn wmm2025() -> Self {
        Self::from_cof("WMM2025", 2025.0, 2030.0, include_str!("wmm2025.cof"))
    }

    /// Reads a coefficient table of lines `n m g h g_dot h_dot` (`#` lines are comments).
    fn from_cof(name: &'static str, epoch_year: f64, valid_until_year: f64, text: &str) -> Self {
        let mut model = Self {
            name,
            epoch_year,
            valid_until_year,
            g: [0.0; COEFFICIENTS],
            h: [0.0; COEFFICIENTS],
            g_dot: [0.0; COEFFICIENTS],
            h_dot: [0.0; COEFFICIENTS],
        };
        for line in text.lines().filter(|l| !l.trim_start().starts_with('#')) {
            let mut parts = line.split_whitespace();
            let mut int = || parts.next().and_then(|p| p.parse::<usize>().ok());
            let (Some(n), Some(m)) = (int(), int()) else {
                continue;
            };
            let mut values = [0.0; 4];
            for v in &mut values {
                *v = parts.next().and_then(|p| p.parse().ok()).unwrap_or(0.0);
            }
            if (1..=DEGREE).contains(&n) && m <= n {
                let k = index(n, m);
                [model.g[k], model.h[k], model.g_dot[k], model.h_dot[k]] = values;
            }
        }
        model
    }

    /// The model's name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The years the model is valid for, `[epoch, expiry)`.
    #[must_use]
    pub fn validity(&self) -> (f64, f64) {
        (self.epoch_year, self.valid_until_year)
    }

    /// The main field at `position` and the decimal year `year`, local NED (north X, east Y,
    /// down Z), nT.
    ///
    /// # Errors
    /// A year outside the model's validity, a height outside −1 km … 850 km, non-finite input.
    pub fn field_ned_nt(&self, position: &Geodetic, year: f64) -> Result<Vec3<Ned>, WmmError> {
        let finite = [
            position.latitude_rad,
            position.longitude_rad,
            position.height_m,
            year,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite {
            return Err(WmmError::NotFinite);
        }
        if !(self.epoch_year..self.valid_until_year).contains(&year) {
            return Err(WmmError::OutsideValidity {
                year,
                from: self.epoch_year,
                until: self.valid_until_year,
            });
        }
        if !(MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&position.height_m) {
            return Err(WmmError::Height {
                height_m: position.height_m,
            });
        }
        let dt = year - self.epoch_year;
        // Geodetic → geocentric spherical (WMM report eq. 7): radius r and latitude φ'.
        let (sp, cp) = (
            math::sin(position.latitude_rad),
            math::cos(position.latitude_rad),
        );
        let (_, r_e) = position.radii_m();
        let p = (r_e + position.height_m) * cp;
        let z = (r_e * (1.0 - E2) + position.height_m) * sp;
        let r = math::sqrt(p * p + z * z);
        let (mu, s) = (z / r, p / r); // sin φ', cos φ'
        // Schmidt semi-normalised P_n^m(sin φ') and dP_n^m/dφ', by the standard recursions.
        let mut pnm = [[0.0; DEGREE + 1]; DEGREE + 1];
        let mut dpnm = [[0.0; DEGREE + 1]; DEGREE + 1];
        pnm[0][0] = 1.0;
        for n in 1..=DEGREE {
            let nf = n as f64;
            for m in 0..=n {
                let mf = m as f64;
                if m == n {
                    let k = math::sqrt((2.0 * nf - 1.0) / (2.0 * nf));
                    let k = if n == 1 { 1.0 } else { k };
                    pnm[n][n] = k * s * pnm[n - 1][n - 1];
                    dpnm[n][n] = k * (s * dpnm[n - 1][n - 1] - mu * pnm[n - 1][n - 1]);
                } else {
                    let a = 2.0 * nf - 1.0;
                    let b = if n >= 2 && m <= n - 2 {
                        math::sqrt((nf - 1.0) * (nf - 1.0) - mf * mf)
                    } else {
                        0.0
                    };
                    let c = math::sqrt(nf * nf - mf * mf);
                    let (p2, dp2) = if n >= 2 && m <= n - 2 {
                        (pnm[n - 2][m], dpnm[n - 2][m])
                    } else {
                        (0.0, 0.0)
                    };
                    pnm[n][m] = (a * mu * pnm[n - 1][m] - b * p2) / c;
                    dpnm[n][m] = (a * (mu * dpnm[n - 1][m] + s * pnm[n - 1][m]) - b * dp2) / c;
                }
            }
        }
        let lambda = position.longitude_rad;
        let (mut x, mut y, mut zf) = (0.0, 0.0, 0.0);
        let ratio = REFERENCE_RADIUS_M / r;
        let mut power = ratio * ratio;
        for n in 1..=DEGREE {
            power *= ratio; // (a/r)^{n+2}
            let nf = n as f64;
            for m in 0..=n {
                let k = index(n, m);
                let g = self.g[k] + dt * self.g_dot[k];
                let h = self.h[k] + dt * self.h_dot[k];
                let (sm, cm) = (math::sin(m as f64 * lambda), math::cos(m as f64 * lambda));
                let gc = g * cm + h * sm;
                x -= power * gc * dpnm[n][m];
                y += power * m as f64 * (g * sm - h * cm) * pnm[n][m];
                zf -= (nf + 1.0) * power * gc * pnm[n][m];
            }
        }
        y /= s;
        // Back to geodetic axes: rotate by ψ = φ' − φ about east.
        let psi = math::atan2(mu, s) - position.latitude_rad;
        let (sps, cps) = (math::sin(psi), math::cos(psi));
        Ok(Vec3::new(x * cps - zf * sps, y, x * sps + zf * cps))
    }
}
