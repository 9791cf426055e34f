//! One validated sensor triad and its drifting state.
use crate::math;
use crate::sensor::{
    BiasInstabilityModel, FilterBuffer, InlineBuffer, NoiseSource, ParamError, SensorParams,
};
use crate::signal::iir_step;

/// Largest number of first-order sections of the flicker bias-instability model.
pub const MAX_FLICKER_SECTIONS: usize = 16;
/// Filter memory held inline per axis: the flicker cascade's, or a filter's up to this order
/// (longer filters keep theirs in the [`FilterBuffer`]).
const INLINE_STATE: usize = 2 * MAX_FLICKER_SECTIONS;

/// A triad's three axis values in four lanes, the fourth a spare that parameters and state keep
/// at zero. The model's arithmetic is written lane by lane over it, so that one vector
/// instruction does an operation on all three axes: the same IEEE operations, in the same order,
/// on each axis as a per-axis loop, so the same numbers bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
struct Axes([f64; 4]);

impl Axes {
    #[inline(always)]
    fn of(v: [f64; 3]) -> Self {
        Self([v[0], v[1], v[2], 0.0])
    }
    #[inline(always)]
    fn xyz(self) -> [f64; 3] {
        [self.0[0], self.0[1], self.0[2]]
    }
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self([v; 4])
    }
}

macro_rules! lanewise {
    ($trait:ident, $method:ident, $op:tt) => {
        impl core::ops::$trait for Axes {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                let (a, b) = (self.0, o.0);
                Self([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
        impl core::ops::$trait<f64> for Axes {
            type Output = Self;
            #[inline(always)]
            fn $method(self, k: f64) -> Self {
                self.$method(Axes::splat(k))
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

/// [`math::round`] on each lane.
#[inline(always)]
fn round_lanes(x: Axes) -> Axes {
    Axes(x.0.map(math::round))
}

/// `y` limited to `±range` (NaN passes), on each lane.
#[inline(always)]
fn saturate_lanes(y: Axes, range: f64) -> Axes {
    Axes(y.0.map(|v| {
        let v = if v < -range { -range } else { v };
        if v > range { range } else { v }
    }))
}

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

    /// One step of the filter on the three axes, each with its own memory: `first_order`'s for
    /// the first-order filter, `z`'s for the others.
    #[inline(always)]
    fn step3(&self, x: Axes, first_order: &mut Axes, z: &mut [FilterMemory<B>; 3]) -> Axes {
        match *self {
            // The general recursion unrolled for order 1, the same operations in the same order:
            // `y = b₀x + z`, `z = b₁x + 0 − a₁y`, the three axes at once.
            Self::FirstOrder { b0, b1, a1 } => {
                let y = x * b0 + *first_order;
                *first_order = x * b1 + 0.0 - y * a1;
                y
            }
            Self::Cascade {
                ref zero,
                ref pole,
                sections,
                gain,
            } => {
                let x = x.xyz();
                Axes::of(
                    [0, 1, 2]
                        .map(|i| cascade_step(zero, pole, sections, x[i], &mut z[i].inline) * gain),
                )
            }
            Self::Iir { ref b, ref a } => {
                Axes::of(iir_step3(b.as_slice(), a.as_slice(), x.xyz(), z))
            }
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
/// so `|H|² ∝ 1/f` in between, and a last pole at `f_hi` ends the band; the gain makes the two-sided PSD of the output for input `B·n`
/// equal `B²/(2πf)`, whose Allan deviation is `√(2 ln 2/π)·B ≈ 0.664·B` (IEEE 952, Annex C).
fn flicker<B: FilterBuffer>(tau_min_s: f64, tau_max_s: f64, fs: f64) -> BiasFilter<B> {
    let two_pi = 2.0 * core::f64::consts::PI;
    let f_hi = (fs / 4.0).min(20.0 / tau_min_s);
    let f_lo = (0.02 / tau_max_s).min(f_hi / 10.0);
    let ratio = f_hi / f_lo;
    let pairs = (math::ceil(2.0 * math::ln(ratio) / math::ln(10.0)) as usize)
        .clamp(1, MAX_FLICKER_SECTIONS - 1);
    let r = math::powf(ratio, 1.0 / pairs as f64);
    let mut zero = [0.0; MAX_FLICKER_SECTIONS];
    let mut pole = [0.0; MAX_FLICKER_SECTIONS];
    for i in 0..pairs {
        let p = f_lo * math::powf(r, i as f64);
        pole[i] = math::exp(-two_pi * p / fs);
        zero[i] = math::exp(-two_pi * p * math::sqrt(r) / fs);
    }
    // A last pole at f_hi, with no zero after it: above the band the spectrum falls instead of
    // flattening into white noise that would add to the part's own.
    pole[pairs] = math::exp(-two_pi * f_hi / fs);
    let sections = pairs + 1;
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

/// The sensing element's memoryless nonlinearity of one triad: each axis reads
/// `u + K₂u² + |u|·ε/2 + k·a²` of its input `u` and the acceleration `a` along it (the
/// [`Environment`]'s), before the error model's misalignment, bias and noise — and, in a part
/// with a signal chain, before the chain, at its internal rate, which is where vibration
/// rectifies into a bias ([`SensorParams::scale_factor_nonlinearity`],
/// [`SensorParams::scale_factor_asymmetry_pct`], [`SensorParams::acceleration_squared_bias`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Nonlinearity {
    square: [f64; 3],
    half_asymmetry: [f64; 3],
    acceleration_squared: [f64; 3],
}

impl Nonlinearity {
    /// The terms of `params`; `None` when all are zero (the reading is then `u` itself).
    #[must_use]
    pub fn of<B: FilterBuffer>(params: &SensorParams<B>) -> Option<Self> {
        let n = Self {
            square: params.scale_factor_nonlinearity,
            half_asymmetry: params.scale_factor_asymmetry_pct.map(|e| e / 200.0),
            acceleration_squared: params.acceleration_squared_bias,
        };
        (n != Self::default()).then_some(n)
    }

    /// What the element makes of input `u` under acceleration `acceleration` (per axis).
    #[inline]
    #[must_use]
    pub fn apply(&self, u: [f64; 3], acceleration: [f64; 3]) -> [f64; 3] {
        core::array::from_fn(|i| {
            let (x, a) = (u[i], acceleration[i]);
            x + self.square[i] * x * x
                + self.half_asymmetry[i] * math::abs(x)
                + self.acceleration_squared[i] * a * a
        })
    }
}

/// What drifts over time: the bias-instability filter state and the random-walk value, per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorState<B: FilterBuffer = InlineBuffer> {
    /// The general filters' and the flicker cascade's memory, per axis.
    filter: [FilterMemory<B>; 3],
    /// The first-order filter's memory (its one value per axis).
    first_order: Axes,
    random_walk: Axes,
    quantization_residual: Axes,
}

impl<B: FilterBuffer> Default for SensorState<B> {
    fn default() -> Self {
        Self {
            filter: Default::default(),
            first_order: Axes::default(),
            random_walk: Axes::default(),
            quantization_residual: Axes::default(),
        }
    }
}

impl<B: FilterBuffer> SensorState<B> {
    /// The current random-walk value per axis.
    #[must_use]
    pub fn random_walk(&self) -> [f64; 3] {
        self.random_walk.xyz()
    }
}

/// A validated error model of one triad at a fixed sample rate.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel<B: FilterBuffer = InlineBuffer> {
    /// The misalignment matrix's columns (`misalignment_columns[j].0[i]` is row `i`, column `j`).
    misalignment_columns: [Axes; 3],
    bias: Axes,
    white_sigma: Axes,
    bias_instability: Axes,
    bias_filter: BiasFilter<B>,
    random_walk_sigma: Axes,
    temperature_bias: Axes,
    temperature_scale: Axes,
    acceleration_bias: Axes,
    nonlinearity: Option<Nonlinearity>,
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
        let bandwidth = sample_rate_hz * params.noise_type.bandwidth_share();
        let root = math::sqrt(bandwidth);
        let misalignment = params
            .axes_misalignment_pct
            .map(|row| row.map(|m| m / 100.0));
        let model = Self {
            misalignment_columns: [0, 1, 2].map(|j| Axes::of(misalignment.map(|row| row[j]))),
            bias: Axes::of(params.constant_bias),
            white_sigma: Axes::of(params.noise_density.map(|n| n * root)),
            bias_instability: Axes::of(params.bias_instability),
            bias_filter: BiasFilter::new(&params.bias_instability_model, sample_rate_hz),
            random_walk_sigma: Axes::of(params.random_walk.map(|k| k / root)),
            temperature_bias: Axes::of(params.temperature_bias),
            temperature_scale: Axes::of(params.temperature_scale_factor_pct.map(|s| s / 100.0)),
            acceleration_bias: Axes::of(params.acceleration_bias),
            nonlinearity: Nonlinearity::of(params),
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
        if let Some(e) = overflow("noise_density", &model.white_sigma.xyz())
            .or_else(|| overflow("random_walk", &model.random_walk_sigma.xyz()))
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

    /// Takes the sensing element's nonlinearity out of the model (a signal chain applies it at
    /// its internal rate, before its filter); the model then reads its input as it is.
    pub fn take_nonlinearity(&mut self) -> Option<Nonlinearity> {
        self.nonlinearity.take()
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
        let n_bi = Axes([normals[0], normals[1], normals[2], 0.0]);
        let n_white = Axes([normals[3], normals[4], normals[5], 0.0]);
        let n_rw = Axes([normals[6], normals[7], normals[8], 0.0]);
        let dt_c = env.temperature_c - 25.0;
        let u = match &self.nonlinearity {
            Some(n) => n.apply(u, env.acceleration_m_s2),
            None => u,
        };
        // `M u + b`, each row's sum in the order `m₀u₀ + m₁u₁ + m₂u₂ + b`.
        let [c0, c1, c2] = self.misalignment_columns;
        let y = c0 * u[0] + c1 * u[1] + c2 * u[2] + self.bias;
        let instability = self.bias_filter.step3(
            self.bias_instability * n_bi,
            &mut state.first_order,
            &mut state.filter,
        );
        state.random_walk = state.random_walk + self.random_walk_sigma * n_rw;
        let drift = instability + self.white_sigma * n_white + state.random_walk;
        let environment =
            self.temperature_bias * dt_c + self.acceleration_bias * Axes::of(env.acceleration_m_s2);
        let scale = self.temperature_scale * dt_c + 1.0;
        let y = saturate_lanes(scale * (y + drift + environment), self.range);
        if self.resolution > 0.0 {
            let r = self.resolution;
            if self.quantization_carry {
                let carried = y + state.quantization_residual;
                let q = round_lanes(carried / r) * r;
                state.quantization_residual = carried - q;
                q.xyz()
            } else {
                (round_lanes(y / r) * r).xyz()
            }
        } else {
            y.xyz()
        }
    }
}
