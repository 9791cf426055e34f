//! One validated sensor triad and its drifting state.
use crate::math;
use crate::sensor::{MAX_FILTER_COEFFICIENTS, NoiseSource, NoiseType, ParamError, SensorParams};

const FILTER_STATE: usize = MAX_FILTER_COEFFICIENTS - 1;

/// The conditions of one sample that the error model depends on besides the true value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Sensor temperature, °C.
    pub temperature_c: f64,
    /// Acceleration that the gyroscope's AccelerationBias multiplies (m/s²); ignored by sensors
    /// whose `acceleration_bias` is zero.
    pub acceleration_m_s2: [f64; 3],
}

impl Default for Environment {
    fn default() -> Self {
        Self {
            temperature_c: 25.0,
            acceleration_m_s2: [0.0; 3],
        }
    }
}

/// What drifts over time: the bias-instability filter state and the random-walk value, per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorState {
    filter: [[f64; FILTER_STATE]; 3],
    random_walk: [f64; 3],
}

impl Default for SensorState {
    fn default() -> Self {
        Self {
            filter: [[0.0; FILTER_STATE]; 3],
            random_walk: [0.0; 3],
        }
    }
}

impl SensorState {
    /// The current random-walk value per axis.
    #[must_use]
    pub fn random_walk(&self) -> [f64; 3] {
        self.random_walk
    }
}

/// A validated error model of one triad at a fixed sample rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorModel {
    misalignment: [[f64; 3]; 3],
    bias: [f64; 3],
    white_sigma: [f64; 3],
    bias_instability: [f64; 3],
    b: [f64; MAX_FILTER_COEFFICIENTS],
    a: [f64; MAX_FILTER_COEFFICIENTS],
    filter_len: usize,
    random_walk_sigma: [f64; 3],
    temperature_bias: [f64; 3],
    temperature_scale: [f64; 3],
    acceleration_bias: [f64; 3],
    range: f64,
    resolution: f64,
}

impl SensorModel {
    /// Validates `params` and precomputes the model for `sample_rate_hz`.
    ///
    /// # Errors
    /// [`ParamError`] naming the field (see [`SensorParams::validate`]) or the sample rate.
    pub fn new(params: &SensorParams, sample_rate_hz: f64) -> Result<Self, ParamError> {
        params.validate()?;
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(ParamError::NotPositive {
                field: "sample_rate_hz",
                value: sample_rate_hz,
            });
        }
        let bandwidth = match params.noise_type {
            NoiseType::SingleSided => sample_rate_hz,
            NoiseType::DoubleSided => sample_rate_hz / 2.0,
        };
        let root = math::sqrt(bandwidth);
        let coeffs = params.bias_instability_coefficients;
        let (num, den) = (coeffs.numerator(), coeffs.denominator());
        let a0 = den[0];
        let mut b = [0.0; MAX_FILTER_COEFFICIENTS];
        let mut a = [0.0; MAX_FILTER_COEFFICIENTS];
        for (k, c) in num.iter().enumerate() {
            b[k] = c / a0;
        }
        for (k, c) in den.iter().enumerate() {
            a[k] = c / a0;
        }
        Ok(Self {
            misalignment: params
                .axes_misalignment_pct
                .map(|row| row.map(|m| m / 100.0)),
            bias: params.constant_bias,
            white_sigma: params.noise_density.map(|n| n * root),
            bias_instability: params.bias_instability,
            b,
            a,
            filter_len: num.len().max(den.len()),
            random_walk_sigma: params.random_walk.map(|k| k / root),
            temperature_bias: params.temperature_bias,
            temperature_scale: params.temperature_scale_factor_pct.map(|s| s / 100.0),
            acceleration_bias: params.acceleration_bias,
            range: params.measurement_range,
            resolution: params.resolution,
        })
    }

    /// One reading from the ideal input `u` (sensor frame); advances `state`; draws exactly nine
    /// standard normals from `noise` (bias instability ×3, white ×3, random walk ×3).
    pub fn measure(
        &self,
        u: [f64; 3],
        env: &Environment,
        state: &mut SensorState,
        noise: &mut impl NoiseSource,
    ) -> [f64; 3] {
        let n_bi: [f64; 3] = core::array::from_fn(|_| noise.standard_normal());
        let n_white: [f64; 3] = core::array::from_fn(|_| noise.standard_normal());
        let n_rw: [f64; 3] = core::array::from_fn(|_| noise.standard_normal());
        let dt_c = env.temperature_c - 25.0;
        core::array::from_fn(|i| {
            let m = &self.misalignment[i];
            let bulk = m[0] * u[0] + m[1] * u[1] + m[2] * u[2] + self.bias[i];
            let instability =
                self.filter_step(self.bias_instability[i] * n_bi[i], &mut state.filter[i]);
            state.random_walk[i] += self.random_walk_sigma[i] * n_rw[i];
            let drift = instability + self.white_sigma[i] * n_white[i] + state.random_walk[i];
            let environment = dt_c * self.temperature_bias[i]
                + self.acceleration_bias[i] * env.acceleration_m_s2[i];
            let y = (1.0 + dt_c * self.temperature_scale[i]) * (bulk + drift + environment);
            self.quantise(self.saturate(y))
        })
    }

    /// One step of MATLAB `filter(b, a, x)` in transposed direct form II (persistent state `z`).
    fn filter_step(&self, x: f64, z: &mut [f64; FILTER_STATE]) -> f64 {
        let n = self.filter_len;
        let y = self.b[0] * x + if n > 1 { z[0] } else { 0.0 };
        for k in 1..n {
            let next = if k + 1 < n { z[k] } else { 0.0 };
            z[k - 1] = self.b[k] * x + next - self.a[k] * y;
        }
        y
    }

    fn saturate(&self, y: f64) -> f64 {
        if y > self.range {
            self.range
        } else if y < -self.range {
            -self.range
        } else {
            y
        }
    }

    fn quantise(&self, y: f64) -> f64 {
        if self.resolution > 0.0 {
            self.resolution * math::round(y / self.resolution)
        } else {
            y
        }
    }
}
