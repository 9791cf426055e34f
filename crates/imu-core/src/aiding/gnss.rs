//! A GNSS receiver's errors, per fix, in local north, east, down.
//!
//! Position error per axis: MATLAB gpsSensor's first-order filter (its source, as MathWorks
//! staff quote it): `x_k = k x_{k−1} + σ √(2 (1 − k)) w_k`, `k` the `DecayFactor`, σ the
//! horizontal (north, east) or vertical (down) accuracy, `w_k` standard normal, starting from 0.
//! `k = 0` is white noise of standard deviation σ√2; as `k → 1` the stationary deviation
//! σ√(2/(1 + k)) → σ with a correlation time of `1/(1 − k)` fixes (MATLAB's default 0.999 at
//! 1 Hz: 17 minutes), and at `k = 1` the error stays 0. The alternative,
//! [`PositionNoise::GaussMarkov`], starts in its stationary state and keeps deviation σ with a
//! correlation time `T`: `x_k = φ x_{k−1} + σ √(1 − φ²) w_k`, `φ = e^{−Δt/T}`. Velocity error:
//! white, `σ_v` per axis. Six standard normals per fix, in the order position (N, E, D), then
//! velocity (N, E, D).
use crate::math;
use crate::sensor::NoiseSource;

/// How the position error evolves between fixes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PositionNoise {
    /// MATLAB gpsSensor's `DecayFactor` in [0, 1] (0.999 by default).
    DecayFactor(f64),
    /// First-order Gauss–Markov with this correlation time, s (> 0), stationary deviation σ.
    GaussMarkov {
        /// Correlation time, s.
        correlation_time_s: f64,
    },
}

/// A receiver's error parameters (MATLAB gpsSensor's names and defaults).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssParams {
    /// Fixes per second, Hz (1).
    pub rate_hz: f64,
    /// Horizontal position accuracy σ, m (1.6).
    pub horizontal_accuracy_m: f64,
    /// Vertical position accuracy σ, m (3).
    pub vertical_accuracy_m: f64,
    /// Velocity accuracy σ per axis, m/s (0.1).
    pub velocity_accuracy_m_s: f64,
    /// Position error process.
    pub position_noise: PositionNoise,
}

impl Default for GnssParams {
    fn default() -> Self {
        Self {
            rate_hz: 1.0,
            horizontal_accuracy_m: 1.6,
            vertical_accuracy_m: 3.0,
            velocity_accuracy_m_s: 0.1,
            position_noise: PositionNoise::DecayFactor(0.999),
        }
    }
}

/// One of [`GnssParams`]' parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GnssParam {
    /// [`GnssParams::rate_hz`].
    RateHz,
    /// [`GnssParams::horizontal_accuracy_m`].
    HorizontalAccuracy,
    /// [`GnssParams::vertical_accuracy_m`].
    VerticalAccuracy,
    /// [`GnssParams::velocity_accuracy_m_s`].
    VelocityAccuracy,
    /// [`PositionNoise::DecayFactor`].
    DecayFactor,
    /// [`PositionNoise::GaussMarkov`]'s correlation time.
    CorrelationTime,
}

impl GnssParam {
    /// The parameter's name with its unit, as files and requests spell it.
    #[must_use]
    pub const fn key(self) -> &'static str {
        match self {
            Self::RateHz => "rate_hz",
            Self::HorizontalAccuracy => "horizontal_accuracy_m",
            Self::VerticalAccuracy => "vertical_accuracy_m",
            Self::VelocityAccuracy => "velocity_accuracy_m_s",
            Self::DecayFactor => "decay_factor",
            Self::CorrelationTime => "correlation_time_s",
        }
    }
}

/// A parameter out of its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssError {
    /// The parameter.
    pub field: GnssParam,
    /// Its value.
    pub value: f64,
    /// What it must be.
    pub rule: &'static str,
}

impl core::fmt::Display for GnssError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} must be {}, got {}",
            self.field.key(),
            self.rule,
            self.value
        )
    }
}

impl core::error::Error for GnssError {}

/// The validated model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssModel {
    phi: f64,
    drive: [f64; 3],
    stationary: Option<[f64; 3]>,
    velocity_sigma: f64,
}

/// The position error carried between fixes, local NED, m.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GnssState {
    error_ned_m: [f64; 3],
    started: bool,
}

impl GnssModel {
    /// Validates `params`.
    ///
    /// # Errors
    /// [`GnssError`] naming the parameter (rate > 0, accuracies ≥ 0, decay factor in [0, 1],
    /// correlation time > 0, all finite).
    pub fn new(params: &GnssParams) -> Result<Self, GnssError> {
        let check = |field, value: f64, ok: bool, rule| {
            if ok && value.is_finite() {
                Ok(value)
            } else {
                Err(GnssError { field, value, rule })
            }
        };
        let rate = params.rate_hz;
        check(GnssParam::RateHz, rate, rate > 0.0, "a finite number > 0")?;
        let h = params.horizontal_accuracy_m;
        let v = params.vertical_accuracy_m;
        let s = params.velocity_accuracy_m_s;
        check(
            GnssParam::HorizontalAccuracy,
            h,
            h >= 0.0,
            "a finite number ≥ 0",
        )?;
        check(
            GnssParam::VerticalAccuracy,
            v,
            v >= 0.0,
            "a finite number ≥ 0",
        )?;
        check(
            GnssParam::VelocityAccuracy,
            s,
            s >= 0.0,
            "a finite number ≥ 0",
        )?;
        let sigma = [h, h, v];
        let (phi, drive, stationary) = match params.position_noise {
            PositionNoise::DecayFactor(k) => {
                check(
                    GnssParam::DecayFactor,
                    k,
                    (0.0..=1.0).contains(&k),
                    "within [0, 1]",
                )?;
                let scale = math::sqrt(2.0 * (1.0 - k));
                (k, sigma.map(|x| x * scale), None)
            }
            PositionNoise::GaussMarkov { correlation_time_s } => {
                let t = correlation_time_s;
                check(
                    GnssParam::CorrelationTime,
                    t,
                    t > 0.0,
                    "a finite number > 0",
                )?;
                let phi = math::exp(-1.0 / (rate * t));
                let scale = math::sqrt(1.0 - phi * phi);
                (phi, sigma.map(|x| x * scale), Some(sigma))
            }
        };
        Ok(Self {
            phi,
            drive,
            stationary,
            velocity_sigma: s,
        })
    }

    /// The errors of the next fix: position (N, E, D, m) and velocity (N, E, D, m/s).
    pub fn step(
        &self,
        state: &mut GnssState,
        noise: &mut impl NoiseSource,
    ) -> ([f64; 3], [f64; 3]) {
        let w: [f64; 6] = core::array::from_fn(|_| noise.standard_normal());
        let e = &mut state.error_ned_m;
        for i in 0..3 {
            e[i] = match (state.started, self.stationary) {
                (false, Some(sigma)) => sigma[i] * w[i],
                _ => self.phi * e[i] + self.drive[i] * w[i],
            };
        }
        state.started = true;
        (*e, [3, 4, 5].map(|i| self.velocity_sigma * w[i]))
    }
}
