//! One validated sensor triad and its drifting state.
use crate::math;
use crate::sensor::{
    BiasInstabilityModel, FilterBuffer, InlineBuffer, NoiseSource, NoiseType, ParamError,
    SensorParams,
};

/// Largest number of first-order sections of the flicker bias-instability model.
pub const MAX_FLICKER_SECTIONS: usize = 16;
/// Filter memory held inline per axis: the flicker cascade's, or a filter's up to this order
/// (longer filters keep theirs in the [`FilterBuffer`]).
const INLINE_STATE: usize = 2 * MAX_FLICKER_SECTIONS;

/// The bias-instability generator, ready to step.
#[derive(Clone, Debug, PartialEq)]
#[allow(
    clippy::large_enum_variant,
    reason = "built once per model and stepped in place; boxing would need a heap"
)]
enum BiasFilter<B: FilterBuffer> {
    /// A first-order `filter([b₀, b₁], [1, a₁], ·)` (MATLAB's default and Gauss–Markov),
    /// unrolled: the hot path.
    FirstOrder { b0: f64, b1: f64, a1: f64 },
    /// MATLAB `filter(b, a, ·)`, coefficients normalised by a₀ and padded with zeros to the
    /// same length, transposed direct form II.
    Iir { b: B, a: B },
    /// Cascade of `(1 − ζ z⁻¹)/(1 − φ z⁻¹)` sections times a gain (flicker noise).
    Cascade {
        zero: [f64; MAX_FLICKER_SECTIONS],
        pole: [f64; MAX_FLICKER_SECTIONS],
        sections: usize,
        gain: f64,
    },
}

/// `values / scale`, padded with zeros to `len` (≤ `B::CAPACITY`, as
/// [`FilterCoefficients`](crate::sensor::FilterCoefficients) checked; empty otherwise).
fn normalised<B: FilterBuffer>(values: &[f64], scale: f64, len: usize) -> B {
    let mut padded = B::zeros(len).unwrap_or_default();
    for (o, v) in padded.as_mut_slice().iter_mut().zip(values) {
        *o = v / scale;
    }
    padded
}

impl<B: FilterBuffer> BiasFilter<B> {
    /// True when every coefficient is a finite number.
    fn is_finite(&self) -> bool {
        match self {
            Self::FirstOrder { b0, b1, a1 } => [b0, b1, a1].iter().all(|v| v.is_finite()),
            Self::Iir { b, a } => b
                .as_slice()
                .iter()
                .chain(a.as_slice())
                .all(|v| v.is_finite()),
            Self::Cascade {
                zero, pole, gain, ..
            } => zero.iter().chain(pole).all(|v| v.is_finite()) && gain.is_finite(),
        }
    }

    fn new(model: &BiasInstabilityModel<B>, sample_rate_hz: f64) -> Self {
        match model {
            BiasInstabilityModel::Filter(c) => {
                let (num, den) = (c.numerator(), c.denominator());
                let len = num.len().max(den.len());
                if len == 2 {
                    let at = |v: &[f64], k: usize| v.get(k).map_or(0.0, |x| x / den[0]);
                    Self::FirstOrder {
                        b0: at(num, 0),
                        b1: at(num, 1),
                        a1: at(den, 1),
                    }
                } else {
                    Self::Iir {
                        b: normalised(num, den[0], len),
                        a: normalised(den, den[0], len),
                    }
                }
            }
            BiasInstabilityModel::Flicker {
                tau_min_s,
                tau_max_s,
            } => flicker(*tau_min_s, *tau_max_s, sample_rate_hz),
            BiasInstabilityModel::GaussMarkov { correlation_time_s } => {
                let phi = math::exp(-1.0 / (sample_rate_hz * correlation_time_s));
                Self::FirstOrder {
                    b0: math::sqrt(1.0 - phi * phi),
                    b1: 0.0,
                    a1: -phi,
                }
            }
        }
    }

    /// One step of the filter on the three axes, each with its own memory.
    #[inline(always)]
    fn step3(&self, x: [f64; 3], z: &mut [FilterMemory<B>; 3]) -> [f64; 3] {
        match *self {
            // The general recursion unrolled for order 1, the same operations in the same order.
            Self::FirstOrder { b0, b1, a1 } => {
                let mut y = [0.0; 3];
                for i in 0..3 {
                    let z0 = &mut z[i].inline[0];
                    y[i] = b0 * x[i] + *z0;
                    *z0 = b1 * x[i] + 0.0 - a1 * y[i];
                }
                y
            }
            Self::Cascade {
                ref zero,
                ref pole,
                sections,
                gain,
            } => {
                [0, 1, 2].map(|i| cascade_step(zero, pole, sections, x[i], &mut z[i].inline) * gain)
            }
            Self::Iir { ref b, ref a } => iir_step3(b.as_slice(), a.as_slice(), x, z),
        }
    }
}

/// [`iir_step`] on the three axes, each with its own memory. Kept out of line with it: the
/// first-order and flicker paths are the hot ones, and inlining this arm there slowed the
/// flicker path by 15 %.
#[inline(never)]
fn iir_step3<B: FilterBuffer>(
    b: &[f64],
    a: &[f64],
    x: [f64; 3],
    z: &mut [FilterMemory<B>; 3],
) -> [f64; 3] {
    [0, 1, 2].map(|i| iir_step(b, a, x[i], z[i].iir(b.len())))
}

/// One step of `filter(b, a, ·)` in transposed direct form II (`b`, `a` of equal length,
/// `a₀ = 1`) with memory `z` (`len − 1` values; a shorter memory shortens the filter, which
/// [`FilterMemory::iir`] never gives).
#[inline]
fn iir_step(b: &[f64], a: &[f64], x: f64, z: &mut [f64]) -> f64 {
    let n = b.len().min(a.len()).min(z.len() + 1);
    if n == 0 {
        return 0.0;
    }
    let y = b[0] * x + if n > 1 { z[0] } else { 0.0 };
    for k in 1..n {
        let next = if k + 1 < n { z[k] } else { 0.0 };
        z[k - 1] = b[k] * x + next - a[k] * y;
    }
    y
}

/// One step of the flicker cascade (without its gain) on the inline memory: inputs in
/// `z[..16]`, outputs in `z[16..]`.
#[inline]
fn cascade_step(
    zero: &[f64; MAX_FLICKER_SECTIONS],
    pole: &[f64; MAX_FLICKER_SECTIONS],
    sections: usize,
    x: f64,
    z: &mut [f64; INLINE_STATE],
) -> f64 {
    let mut v = x;
    for i in 0..sections.min(MAX_FLICKER_SECTIONS) {
        let y = v - zero[i] * z[i] + pole[i] * z[MAX_FLICKER_SECTIONS + i];
        z[i] = v;
        z[MAX_FLICKER_SECTIONS + i] = y;
        v = y;
    }
    v
}

/// One axis's bias-instability filter memory: the flicker cascade's, or a filter's (inline up to
/// order 32, in the buffer beyond).
#[derive(Clone, Debug, Default, PartialEq)]
struct FilterMemory<B: FilterBuffer> {
    inline: [f64; INLINE_STATE],
    long: B,
}

impl<B: FilterBuffer> FilterMemory<B> {
    /// The memory of a filter with `len` coefficients: inline when it fits, else the buffer,
    /// sized (zeroed) on first use.
    #[inline]
    fn iir(&mut self, len: usize) -> &mut [f64] {
        let needed = len.saturating_sub(1);
        if needed <= INLINE_STATE {
            return &mut self.inline[..needed];
        }
        if self.long.as_slice().len() != needed {
            self.long = B::zeros(needed).unwrap_or_default();
        }
        self.long.as_mut_slice()
    }
}

/// Designs the flicker cascade: poles and zeros alternate, log-spaced two per decade between
/// `f_lo = 0.02/τ_max` and `f_hi = min(fs/4, 20/τ_min)` (continuous-time, mapped by `z = e^{sT}`),
/// so `|H|² ∝ 1/f` in between; the gain makes the two-sided PSD of the output for input `B·n`
/// equal `B²/(2πf)`, whose Allan deviation is `√(2 ln 2/π)·B ≈ 0.664·B` (IEEE 952, Annex C).
fn flicker<B: FilterBuffer>(tau_min_s: f64, tau_max_s: f64, fs: f64) -> BiasFilter<B> {
    let two_pi = 2.0 * core::f64::consts::PI;
    let f_hi = (fs / 4.0).min(20.0 / tau_min_s);
    let f_lo = (0.02 / tau_max_s).min(f_hi / 10.0);
    let ratio = f_hi / f_lo;
    let sections = (math::ceil(2.0 * math::ln(ratio) / math::ln(10.0)) as usize)
        .clamp(1, MAX_FLICKER_SECTIONS);
    let r = math::powf(ratio, 1.0 / sections as f64);
    let mut zero = [0.0; MAX_FLICKER_SECTIONS];
    let mut pole = [0.0; MAX_FLICKER_SECTIONS];
    for i in 0..sections {
        let p = f_lo * math::powf(r, i as f64);
        pole[i] = math::exp(-two_pi * p / fs);
        zero[i] = math::exp(-two_pi * p * math::sqrt(r) / fs);
    }
    // |H(e^{jω})|² of the cascade, with 1 − cos ω written as 2 sin²(ω/2) for precision.
    let h2 = |f: f64| {
        let s = math::sin(core::f64::consts::PI * f / fs);
        let s2 = 2.0 * s * s;
        (0..sections).fold(1.0, |acc, i| {
            let (q, p) = (zero[i], pole[i]);
            acc * ((1.0 - q) * (1.0 - q) + 2.0 * q * s2) / ((1.0 - p) * (1.0 - p) + 2.0 * p * s2)
        })
    };
    const POINTS: usize = 48;
    let (a, b) = (math::ln(f_lo * r), math::ln(f_hi / r));
    let mean_log_gain2 = (0..POINTS)
        .map(|j| {
            let f = math::exp(a + (b - a) * j as f64 / (POINTS - 1) as f64);
            math::ln(fs / (two_pi * f * h2(f)))
        })
        .sum::<f64>()
        / POINTS as f64;
    BiasFilter::Cascade {
        zero,
        pole,
        sections,
        gain: math::sqrt(math::exp(mean_log_gain2)),
    }
}

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
#[derive(Clone, Debug, PartialEq)]
pub struct SensorState<B: FilterBuffer = InlineBuffer> {
    filter: [FilterMemory<B>; 3],
    random_walk: [f64; 3],
    quantization_residual: [f64; 3],
}

impl<B: FilterBuffer> Default for SensorState<B> {
    fn default() -> Self {
        Self {
            filter: Default::default(),
            random_walk: [0.0; 3],
            quantization_residual: [0.0; 3],
        }
    }
}

impl<B: FilterBuffer> SensorState<B> {
    /// The current random-walk value per axis.
    #[must_use]
    pub fn random_walk(&self) -> [f64; 3] {
        self.random_walk
    }
}

/// A validated error model of one triad at a fixed sample rate.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel<B: FilterBuffer = InlineBuffer> {
    misalignment: [[f64; 3]; 3],
    bias: [f64; 3],
    white_sigma: [f64; 3],
    bias_instability: [f64; 3],
    bias_filter: BiasFilter<B>,
    random_walk_sigma: [f64; 3],
    temperature_bias: [f64; 3],
    temperature_scale: [f64; 3],
    acceleration_bias: [f64; 3],
    range: f64,
    resolution: f64,
    quantization_carry: bool,
}

impl<B: FilterBuffer> SensorModel<B> {
    /// Validates `params` and precomputes the model for `sample_rate_hz`.
    ///
    /// # Errors
    /// [`ParamError`] naming the field (see [`SensorParams::validate`]) or the sample rate.
    pub fn new(params: &SensorParams<B>, sample_rate_hz: f64) -> Result<Self, ParamError> {
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
        let model = Self {
            misalignment: params
                .axes_misalignment_pct
                .map(|row| row.map(|m| m / 100.0)),
            bias: params.constant_bias,
            white_sigma: params.noise_density.map(|n| n * root),
            bias_instability: params.bias_instability,
            bias_filter: BiasFilter::new(&params.bias_instability_model, sample_rate_hz),
            random_walk_sigma: params.random_walk.map(|k| k / root),
            temperature_bias: params.temperature_bias,
            temperature_scale: params.temperature_scale_factor_pct.map(|s| s / 100.0),
            acceleration_bias: params.acceleration_bias,
            range: params.measurement_range,
            resolution: params.resolution,
            quantization_carry: params.quantization_carry,
        };
        // Parameters valid on their own can still overflow once scaled to the sample rate.
        let overflow = |field, values: &[f64; 3]| {
            values
                .iter()
                .position(|v| !v.is_finite())
                .map(|index| ParamError::Overflow { field, index })
        };
        if let Some(e) = overflow("noise_density", &model.white_sigma)
            .or_else(|| overflow("random_walk", &model.random_walk_sigma))
        {
            return Err(e);
        }
        if !model.bias_filter.is_finite() {
            return Err(ParamError::Overflow {
                field: match params.bias_instability_model {
                    BiasInstabilityModel::Filter(_) => "bias_instability_coefficients",
                    BiasInstabilityModel::Flicker { .. } => "bias_instability_flicker_tau_s",
                    BiasInstabilityModel::GaussMarkov { .. } => {
                        "bias_instability_correlation_time_s"
                    }
                },
                index: 0,
            });
        }
        Ok(model)
    }

    /// One reading from the ideal input `u` (sensor frame); advances `state`; draws exactly nine
    /// standard normals from `noise` (bias instability ×3, white ×3, random walk ×3).
    #[inline]
    pub fn measure(
        &self,
        u: [f64; 3],
        env: &Environment,
        state: &mut SensorState<B>,
        noise: &mut impl NoiseSource,
    ) -> [f64; 3] {
        let mut normals = [0.0; 9];
        noise.fill_standard_normal(&mut normals);
        self.measure_drawn(u, env, state, &normals)
    }

    /// [`Self::measure`] with the sample's nine standard normals already drawn, in the order
    /// `measure` draws them.
    ///
    /// Written as index loops over the axes, stage by stage: the iterator and closure forms of
    /// the same arithmetic measured 1.5× slower here (they change what the compiler inlines).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    pub fn measure_drawn(
        &self,
        u: [f64; 3],
        env: &Environment,
        state: &mut SensorState<B>,
        normals: &[f64; 9],
    ) -> [f64; 3] {
        let n_bi = [normals[0], normals[1], normals[2]];
        let n_white = [normals[3], normals[4], normals[5]];
        let n_rw = [normals[6], normals[7], normals[8]];
        let dt_c = env.temperature_c - 25.0;
        let mut y = [0.0; 3];
        for i in 0..3 {
            let m = &self.misalignment[i];
            y[i] = m[0] * u[0] + m[1] * u[1] + m[2] * u[2] + self.bias[i];
        }
        let instability = self.bias_filter.step3(
            [0, 1, 2].map(|i| self.bias_instability[i] * n_bi[i]),
            &mut state.filter,
        );
        for i in 0..3 {
            state.random_walk[i] += self.random_walk_sigma[i] * n_rw[i];
            let drift = instability[i] + self.white_sigma[i] * n_white[i] + state.random_walk[i];
            let environment = dt_c * self.temperature_bias[i]
                + self.acceleration_bias[i] * env.acceleration_m_s2[i];
            y[i] = self
                .saturate((1.0 + dt_c * self.temperature_scale[i]) * (y[i] + drift + environment));
        }
        if self.quantization_carry && self.resolution > 0.0 {
            for i in 0..3 {
                let carried = y[i] + state.quantization_residual[i];
                y[i] = self.quantise(carried);
                state.quantization_residual[i] = carried - y[i];
            }
        } else {
            y = y.map(|v| self.quantise(v));
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
