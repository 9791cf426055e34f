//! A barometric altimeter and a wheel odometer: the simplest aids, each a reading of one truth
//! quantity with a constant error and white noise.
//!
//! Barometer: `h_baro = h + b + σ_h w` (height above the reference, m). Odometer: the forward
//! speed of the body with a scale-factor error, `s = (1 + k) v_x + σ_s w` (m/s).
use crate::sensor::NoiseSource;

/// A barometer's or an odometer's error: a constant (bias or scale-factor error) and white noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimpleAid {
    /// Bias, m (barometer), or scale-factor error, fraction (odometer).
    pub constant: f64,
    /// White-noise one-sigma per reading (m or m/s).
    pub noise: f64,
}

impl SimpleAid {
    /// The barometer's reading of height `height_m`.
    pub fn baro(&self, height_m: f64, noise: &mut impl NoiseSource) -> f64 {
        height_m + self.constant + self.noise * noise.standard_normal()
    }

    /// The odometer's reading of forward speed `speed_m_s`.
    pub fn odometer(&self, speed_m_s: f64, noise: &mut impl NoiseSource) -> f64 {
        (1.0 + self.constant) * speed_m_s + self.noise * noise.standard_normal()
    }
}
