//! Error parameters of one sensor triad, as a user writes them (SI units, per axis).

use crate::sensor::ParamError;

pub use crate::signal::{FilterBuffer, InlineBuffer, MAX_FILTER_COEFFICIENTS};

/// Power spectral density convention of `noise_density` and `random_walk`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseType {
    /// Bandwidth `fs`: the datasheet / IEEE-952 / Kalibr convention (imukit's default).
    #[default]
    SingleSided,
    /// Bandwidth `fs/2`: MATLAB's default.
    DoubleSided,
}

impl NoiseType {
    /// The densities' bandwidth as a share of the sample rate: 1 (single-sided) or ½
    /// (double-sided). White noise of density `N` has the per-sample deviation
    /// `N·√(share·fs)`, a random walk of density `K` the step `K/√(share·fs)`.
    #[must_use]
    pub const fn bandwidth_share(self) -> f64 {
        match self {
            Self::SingleSided => 1.0,
            Self::DoubleSided => 0.5,
        }
    }
}

/// Numerator and denominator of the bias-instability filter (MATLAB `filter(Num, Den, x)`).
#[derive(Clone, Debug, PartialEq)]
pub struct FilterCoefficients<B: FilterBuffer = InlineBuffer> {
    numerator: B,
    denominator: B,
}

impl<B: FilterBuffer> Default for FilterCoefficients<B> {
    /// MATLAB's default: `Num = [1]`, `Den = [1, −0.5]`.
    fn default() -> Self {
        Self::matlab_default()
    }
}

impl<B: FilterBuffer> FilterCoefficients<B> {
    /// MATLAB's default: `Num = [1]`, `Den = [1, −0.5]`.
    #[must_use]
    pub fn matlab_default() -> Self {
        Self {
            numerator: B::from_slice(&[1.0]).unwrap_or_default(),
            denominator: B::from_slice(&[1.0, -0.5]).unwrap_or_default(),
        }
    }

    /// Coefficients `numerator` (b₀ … b_m) and `denominator` (a₀ … a_n), a₀ ≠ 0, each list at
    /// most [`FilterBuffer::CAPACITY`] long.
    ///
    /// # Errors
    /// Empty or too long lists, non-finite values, a₀ = 0.
    pub fn new(numerator: &[f64], denominator: &[f64]) -> Result<Self, ParamError> {
        if numerator.is_empty() || denominator.is_empty() {
            return Err(ParamError::BadFilter {
                reason: "at least one numerator and one denominator coefficient needed",
            });
        }
        let longest = numerator.len().max(denominator.len());
        if longest > B::CAPACITY {
            return Err(ParamError::TooManyCoefficients {
                len: longest,
                max: B::CAPACITY,
            });
        }
        if let Some(index) = numerator
            .iter()
            .chain(denominator)
            .position(|c| !c.is_finite())
        {
            return Err(ParamError::NotFinite {
                field: "bias_instability_coefficients",
                index,
            });
        }
        if denominator[0] == 0.0 {
            return Err(ParamError::BadFilter {
                reason: "the leading denominator coefficient must not be 0",
            });
        }
        let too_long = || ParamError::TooManyCoefficients {
            len: longest,
            max: B::CAPACITY,
        };
        Ok(Self {
            numerator: B::from_slice(numerator).ok_or_else(too_long)?,
            denominator: B::from_slice(denominator).ok_or_else(too_long)?,
        })
    }

    /// The numerator coefficients.
    #[must_use]
    pub fn numerator(&self) -> &[f64] {
        self.numerator.as_slice()
    }

    /// The denominator coefficients.
    #[must_use]
    pub fn denominator(&self) -> &[f64] {
        self.denominator.as_slice()
    }
}

/// How the bias-instability drift is generated from `BiasInstability·n`.
#[derive(Clone, Debug, PartialEq)]
pub enum BiasInstabilityModel<B: FilterBuffer = InlineBuffer> {
    /// MATLAB's `filter(Num, Den, ·)` (default `Num = [1]`, `Den = [1, −0.5]`). Note that this
    /// default is an AR(1) process with a 2-sample correlation: under Allan analysis it looks like
    /// extra white noise, not a flat floor.
    Filter(FilterCoefficients<B>),
    /// Flicker (1/f) noise whose Allan deviation is `0.664·BiasInstability` for τ between
    /// `tau_min_s` and `tau_max_s` (the datasheet's bias-instability floor), from a cascade of
    /// first-order pole-zero sections (two per decade) driven by one normal per axis.
    Flicker {
        /// Shortest τ of the floor, s (> 0).
        tau_min_s: f64,
        /// Longest τ of the floor, s (> `tau_min_s`).
        tau_max_s: f64,
    },
    /// First-order Gauss–Markov with the given correlation time (gnss-ins-sim style): steady-state
    /// standard deviation `BiasInstability`, `x_k = φ x_{k−1} + √(1−φ²)·B·n`, `φ = e^{−1/(fs·T)}`.
    GaussMarkov {
        /// Correlation time, s (> 0).
        correlation_time_s: f64,
    },
}

impl<B: FilterBuffer> Default for BiasInstabilityModel<B> {
    fn default() -> Self {
        Self::Filter(FilterCoefficients::matlab_default())
    }
}

/// Error parameters of one triad (accelerometer, gyroscope or magnetometer), MATLAB's
/// `accelparams`/`gyroparams`/`magparams` fields in SI units of the measurand `[u]`
/// (m/s², rad/s or µT). The default is an ideal sensor.
///
/// `B` stores the bias-instability filter (see [`FilterBuffer`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SensorParams<B: FilterBuffer = InlineBuffer> {
    /// Saturation level, `[u]`, > 0 (may be infinite).
    pub measurement_range: f64,
    /// Quantisation step, `[u]`/LSB, ≥ 0 (0: none).
    pub resolution: f64,
    /// Constant bias, `[u]`.
    pub constant_bias: [f64; 3],
    /// Axes misalignment and scale, percent; `100·I` is perfect alignment.
    pub axes_misalignment_pct: [[f64; 3]; 3],
    /// White-noise density, `[u]/√Hz`, ≥ 0.
    pub noise_density: [f64; 3],
    /// Bias-instability input amplitude, `[u]`, ≥ 0.
    pub bias_instability: [f64; 3],
    /// How the bias instability is generated (MATLAB's filter by default).
    pub bias_instability_model: BiasInstabilityModel<B>,
    /// Random walk, `[u]·√Hz`, ≥ 0.
    pub random_walk: [f64; 3],
    /// PSD convention of `noise_density` and `random_walk`.
    pub noise_type: NoiseType,
    /// Bias per °C away from 25 °C, `[u]/°C`.
    pub temperature_bias: [f64; 3],
    /// Scale-factor error per °C away from 25 °C, %/°C, in [0, 100].
    pub temperature_scale_factor_pct: [f64; 3],
    /// Gyroscope only: bias per unit acceleration, `(rad/s)/(m/s²)`.
    pub acceleration_bias: [f64; 3],
    /// Second-order scale-factor nonlinearity `K₂`, `1/[u]`: each axis reads `u + K₂u²` of
    /// its input `u` (the sensing element's, before the signal chain and the misalignment), so
    /// a vibration of amplitude `A` along the axis rectifies into a bias `K₂A²/2`.
    pub scale_factor_nonlinearity: [f64; 3],
    /// Scale-factor asymmetry, percent, in [−100, 100]: the scale factor for positive inputs
    /// exceeds the one for negative inputs by this share of their mean (`u ± |u|·ε/2`), so a
    /// vibration of amplitude `A` rectifies into `εA/π`.
    pub scale_factor_asymmetry_pct: [f64; 3],
    /// Gyroscope only: bias per squared acceleration along the same axis (g²-sensitivity),
    /// `(rad/s)/(m/s²)²`, of the acceleration [`acceleration_bias`](Self::acceleration_bias)
    /// takes; a vibration of amplitude `A` rectifies into `kA²/2`.
    pub acceleration_squared_bias: [f64; 3],
    /// Carry each sample's quantisation residual into the next (sigma-delta style), so sums of
    /// readings track sums of inputs to within one LSB; off in MATLAB.
    pub quantization_carry: bool,
}

impl<B: FilterBuffer> Default for SensorParams<B> {
    fn default() -> Self {
        Self {
            measurement_range: f64::INFINITY,
            resolution: 0.0,
            constant_bias: [0.0; 3],
            axes_misalignment_pct: [[100.0, 0.0, 0.0], [0.0, 100.0, 0.0], [0.0, 0.0, 100.0]],
            noise_density: [0.0; 3],
            bias_instability: [0.0; 3],
            bias_instability_model: BiasInstabilityModel::default(),
            random_walk: [0.0; 3],
            noise_type: NoiseType::SingleSided,
            temperature_bias: [0.0; 3],
            temperature_scale_factor_pct: [0.0; 3],
            acceleration_bias: [0.0; 3],
            scale_factor_nonlinearity: [0.0; 3],
            scale_factor_asymmetry_pct: [0.0; 3],
            acceleration_squared_bias: [0.0; 3],
            quantization_carry: false,
        }
    }
}

impl<B: FilterBuffer> SensorParams<B> {
    /// MATLAB's scalar AxesMisalignment `s`: 100 on the diagonal, `s` elsewhere (percent).
    #[must_use]
    pub const fn misalignment_from_scalar(s: f64) -> [[f64; 3]; 3] {
        [[100.0, s, s], [s, 100.0, s], [s, s, 100.0]]
    }

    /// MATLAB's 3-vector AxesMisalignment `[a, b, c]`:
    /// `[[100, b, c], [a, 100, c], [a, b, 100]]` (percent).
    #[must_use]
    pub const fn misalignment_from_vector(v: [f64; 3]) -> [[f64; 3]; 3] {
        let [a, b, c] = v;
        [[100.0, b, c], [a, 100.0, c], [a, b, 100.0]]
    }

    /// Checks every field as MATLAB does: densities, instability and random walk ≥ 0; range > 0
    /// (may be infinite); resolution ≥ 0; temperature scale factor in [0, 100]; no NaN anywhere.
    ///
    /// # Errors
    /// The first offending field, with its axis.
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.measurement_range.is_nan() || self.measurement_range <= 0.0 {
            return Err(ParamError::NotPositive {
                field: "measurement_range",
                value: self.measurement_range,
            });
        }
        if !self.resolution.is_finite() {
            return Err(ParamError::NotFinite {
                field: "resolution",
                index: 0,
            });
        }
        if self.resolution < 0.0 {
            return Err(ParamError::Negative {
                field: "resolution",
                index: 0,
                value: self.resolution,
            });
        }
        let finite = |field: &'static str, v: &[f64; 3]| match v.iter().position(|c| !c.is_finite())
        {
            Some(index) => Err(ParamError::NotFinite { field, index }),
            None => Ok(()),
        };
        let non_negative = |field: &'static str, v: &[f64; 3]| {
            finite(field, v)?;
            match v.iter().position(|c| *c < 0.0) {
                Some(index) => Err(ParamError::Negative {
                    field,
                    index,
                    value: v[index],
                }),
                None => Ok(()),
            }
        };
        finite("constant_bias", &self.constant_bias)?;
        for (r, row) in self.axes_misalignment_pct.iter().enumerate() {
            if let Some(k) = row.iter().position(|c| !c.is_finite()) {
                return Err(ParamError::NotFinite {
                    field: "axes_misalignment_pct",
                    index: 3 * r + k,
                });
            }
        }
        non_negative("noise_density", &self.noise_density)?;
        non_negative("bias_instability", &self.bias_instability)?;
        non_negative("random_walk", &self.random_walk)?;
        finite("temperature_bias", &self.temperature_bias)?;
        finite(
            "temperature_scale_factor_pct",
            &self.temperature_scale_factor_pct,
        )?;
        if let Some(index) = self
            .temperature_scale_factor_pct
            .iter()
            .position(|c| !(0.0..=100.0).contains(c))
        {
            let value = self.temperature_scale_factor_pct[index];
            return Err(ParamError::OutOfRange {
                field: "temperature_scale_factor_pct",
                index,
                value,
                min: 0.0,
                max: 100.0,
            });
        }
        finite("acceleration_bias", &self.acceleration_bias)?;
        finite("scale_factor_nonlinearity", &self.scale_factor_nonlinearity)?;
        finite("acceleration_squared_bias", &self.acceleration_squared_bias)?;
        finite(
            "scale_factor_asymmetry_pct",
            &self.scale_factor_asymmetry_pct,
        )?;
        if let Some(index) = self
            .scale_factor_asymmetry_pct
            .iter()
            .position(|c| !(-100.0..=100.0).contains(c))
        {
            return Err(ParamError::OutOfRange {
                field: "scale_factor_asymmetry_pct",
                index,
                value: self.scale_factor_asymmetry_pct[index],
                min: -100.0,
                max: 100.0,
            });
        }
        if let BiasInstabilityModel::GaussMarkov { correlation_time_s } =
            self.bias_instability_model
            && !(correlation_time_s.is_finite() && correlation_time_s > 0.0)
        {
            return Err(ParamError::NotPositive {
                field: "bias_instability_correlation_time_s",
                value: correlation_time_s,
            });
        }
        if let BiasInstabilityModel::Flicker {
            tau_min_s,
            tau_max_s,
        } = self.bias_instability_model
        {
            if !(tau_min_s.is_finite() && tau_min_s > 0.0) {
                return Err(ParamError::NotPositive {
                    field: "bias_instability_tau_min_s",
                    value: tau_min_s,
                });
            }
            if !(tau_max_s.is_finite() && tau_max_s > tau_min_s) {
                return Err(ParamError::OutOfRange {
                    field: "bias_instability_tau_max_s",
                    index: 0,
                    value: tau_max_s,
                    min: tau_min_s,
                    max: f64::INFINITY,
                });
            }
        }
        Ok(())
    }
}
