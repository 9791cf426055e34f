//! Monte Carlo perturbations of sensor parameters, as MATLAB's `perturbations` offers: each run
//! replaces a parameter by a draw from a distribution (independently per axis for 3-vector
//! parameters), from a stream seeded by (seed, run), so a run's parameters do not depend on how
//! many runs there are or which thread computes them.
//!
//! ```toml
//! [[imu.perturbations]]
//! parameter = "gyroscope.constant_bias_rad_s"
//! distribution = "normal"            # "truncated-normal", "uniform", "selection"
//! mean = 0.0
//! std = 0.01
//! # truncated-normal: mean, std, lower, upper; uniform: lower, upper;
//! # selection: values = [...], probabilities = [...] (equal when left out)
//! ```
use crate::sensor::SensorParams;
use rand_core::{Rng, SeedableRng};
use rand_distr::{Distribution as _, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::io::params::{ImuParams, Sensor};

/// A perturbation as written in a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerturbationSpec {
    /// `sensor.key`, e.g. `gyroscope.constant_bias_rad_s` (imukit's keys).
    pub parameter: String,
    /// `normal`, `truncated-normal`, `uniform` or `selection`.
    pub distribution: DistributionName,
    /// Mean (normal, truncated normal).
    pub mean: Option<f64>,
    /// Standard deviation (normal, truncated normal).
    pub std: Option<f64>,
    /// Lower bound (uniform, truncated normal).
    pub lower: Option<f64>,
    /// Upper bound (uniform, truncated normal).
    pub upper: Option<f64>,
    /// Candidates (selection).
    pub values: Option<Vec<f64>>,
    /// Their probabilities (selection; equal when left out).
    pub probabilities: Option<Vec<f64>>,
}

/// A distribution as a scenario names it; its parameters are the perturbation's other keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DistributionName {
    /// `mean`, `std`.
    Normal,
    /// `mean`, `std`, `lower`, `upper`.
    TruncatedNormal,
    /// `lower`, `upper`.
    Uniform,
    /// `values` (and `probabilities`).
    Selection,
}

/// A distribution to draw a parameter from.
#[derive(Clone, Debug, PartialEq)]
pub enum Distribution {
    /// N(mean, std²).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
    },
    /// N(mean, std²) restricted to [lower, upper] (by rejection).
    TruncatedNormal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// U(lower, upper).
    Uniform {
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// One of `values` with cumulative probabilities `cumulative`.
    Selection {
        /// Candidates.
        values: Vec<f64>,
        /// Cumulative probabilities, last = 1.
        cumulative: Vec<f64>,
    },
}

/// Which parameter a perturbation replaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Field {
    MeasurementRange,
    Resolution,
    ConstantBias,
    NoiseDensity,
    BiasInstability,
    RandomWalk,
    TemperatureBias,
    TemperatureScaleFactor,
    AccelerationBias,
}

/// A resolved perturbation.
#[derive(Clone, Debug, PartialEq)]
pub struct Perturbation {
    sensor: Sensor,
    field: Field,
    name: String,
    distribution: Distribution,
}

fn need(v: Option<f64>, field: &str, what: &str) -> Result<f64> {
    match v {
        Some(x) if x.is_finite() => Ok(x),
        Some(x) => Err(invalid(field, format!("{what} must be finite, got {x}"))),
        None => Err(invalid(field, format!("needs {what}"))),
    }
}

impl Perturbation {
    /// Resolves a written perturbation; `index` numbers it in messages.
    ///
    /// # Errors
    /// Unknown parameters or distributions, missing or invalid distribution parameters.
    pub fn from_spec(spec: &PerturbationSpec, index: usize) -> Result<Self> {
        let at = format!("imu.perturbations[{index}]");
        let (sensor, field) = target_of(&spec.parameter, &at)?;
        let distribution = distribution_of(spec, &at)?;
        Ok(Self {
            sensor,
            field,
            name: spec.parameter.clone(),
            distribution,
        })
    }

    fn draw(&self, rng: &mut Xoshiro256PlusPlus) -> f64 {
        let uniform = |rng: &mut Xoshiro256PlusPlus| {
            (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
        };
        match &self.distribution {
            Distribution::Normal { mean, std } => {
                let n: f64 = StandardNormal.sample(rng);
                mean + std * n
            }
            Distribution::TruncatedNormal {
                mean,
                std,
                lower,
                upper,
            } => {
                for _ in 0..10_000 {
                    let n: f64 = StandardNormal.sample(rng);
                    let x = mean + std * n;
                    if (*lower..=*upper).contains(&x) {
                        return x;
                    }
                }
                mean.clamp(*lower, *upper)
            }
            Distribution::Uniform { lower, upper } => lower + (upper - lower) * uniform(rng),
            Distribution::Selection { values, cumulative } => {
                let u = uniform(rng);
                let k = cumulative
                    .iter()
                    .position(|c| u < *c)
                    .unwrap_or(values.len() - 1);
                values[k]
            }
        }
    }

    fn apply(&self, p: &mut SensorParams, rng: &mut Xoshiro256PlusPlus) {
        let mut three = || [self.draw(rng), self.draw(rng), self.draw(rng)];
        match self.field {
            Field::MeasurementRange => p.measurement_range = self.draw(rng),
            Field::Resolution => p.resolution = self.draw(rng),
            Field::ConstantBias => p.constant_bias = three(),
            Field::NoiseDensity => p.noise_density = three(),
            Field::BiasInstability => p.bias_instability = three(),
            Field::RandomWalk => p.random_walk = three(),
            Field::TemperatureBias => p.temperature_bias = three(),
            Field::TemperatureScaleFactor => p.temperature_scale_factor_pct = three(),
            Field::AccelerationBias => p.acceleration_bias = three(),
        }
    }
}

/// The sensor and the field `parameter` (`sensor.field`) names; `at` locates it in messages.
fn target_of(parameter: &str, at: &str) -> Result<(Sensor, Field)> {
    let (sensor_key, key) = parameter.split_once('.').ok_or_else(|| {
        invalid(
            format!("{at}.parameter"),
            "expected sensor.parameter, e.g. gyroscope.constant_bias_rad_s",
        )
    })?;
    let sensor = Sensor::ALL
        .into_iter()
        .find(|s| s.key() == sensor_key)
        .ok_or_else(|| {
            invalid(
                format!("{at}.parameter"),
                format!("unknown sensor \"{sensor_key}\" (accelerometer, gyroscope, magnetometer)"),
            )
        })?;
    let u = sensor.unit();
    let fields = [
        (format!("measurement_range_{u}"), Field::MeasurementRange),
        (format!("resolution_{u}"), Field::Resolution),
        (format!("constant_bias_{u}"), Field::ConstantBias),
        (format!("noise_density_{u}_per_rt_hz"), Field::NoiseDensity),
        (format!("bias_instability_{u}"), Field::BiasInstability),
        (format!("random_walk_{u}_rt_hz"), Field::RandomWalk),
        (
            format!("temperature_bias_{u}_per_c"),
            Field::TemperatureBias,
        ),
        (
            "temperature_scale_factor_pct_per_c".to_string(),
            Field::TemperatureScaleFactor,
        ),
        (
            "acceleration_bias_rad_s_per_m_s2".to_string(),
            Field::AccelerationBias,
        ),
    ];
    let field = fields
        .iter()
        .filter(|(_, f)| *f != Field::AccelerationBias || sensor == Sensor::Gyroscope)
        .find(|(n, _)| n == key)
        .map(|(_, f)| *f)
        .ok_or_else(|| {
            let known: Vec<&str> = fields.iter().map(|(n, _)| n.as_str()).collect();
            invalid(
                format!("{at}.parameter"),
                format!(
                    "cannot perturb \"{key}\" (perturbable: {})",
                    known.join(", ")
                ),
            )
        })?;
    Ok((sensor, field))
}

/// The distribution `spec` describes, its parameters checked; `at` locates it in messages.
fn distribution_of(spec: &PerturbationSpec, at: &str) -> Result<Distribution> {
    let f = |name: &str| format!("{at}.{name}");
    let distribution = match spec.distribution {
        DistributionName::Normal => Distribution::Normal {
            mean: need(spec.mean, &f("mean"), "mean")?,
            std: need(spec.std, &f("std"), "std")?,
        },
        DistributionName::TruncatedNormal => Distribution::TruncatedNormal {
            mean: need(spec.mean, &f("mean"), "mean")?,
            std: need(spec.std, &f("std"), "std")?,
            lower: need(spec.lower, &f("lower"), "lower")?,
            upper: need(spec.upper, &f("upper"), "upper")?,
        },
        DistributionName::Uniform => Distribution::Uniform {
            lower: need(spec.lower, &f("lower"), "lower")?,
            upper: need(spec.upper, &f("upper"), "upper")?,
        },
        DistributionName::Selection => {
            let values = spec
                .values
                .clone()
                .ok_or_else(|| invalid(f("values"), "needs values"))?;
            if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
                return Err(invalid(f("values"), "needs at least one finite value"));
            }
            let p = spec
                .probabilities
                .clone()
                .unwrap_or_else(|| vec![1.0 / values.len() as f64; values.len()]);
            if p.len() != values.len() || p.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(invalid(f("probabilities"), "one probability ≥ 0 per value"));
            }
            let total: f64 = p.iter().sum();
            if (total - 1.0).abs() > 1e-9 {
                return Err(invalid(
                    f("probabilities"),
                    format!("must add up to 1, add up to {total}"),
                ));
            }
            let mut acc = 0.0;
            let cumulative = p.iter().map(|x| {
                acc += x;
                acc / total
            });
            Distribution::Selection {
                values,
                cumulative: cumulative.collect(),
            }
        }
    };
    match distribution {
        Distribution::Normal { std, .. } | Distribution::TruncatedNormal { std, .. }
            if std < 0.0 =>
        {
            return Err(invalid(f("std"), "must be ≥ 0"));
        }
        Distribution::TruncatedNormal { lower, upper, .. }
        | Distribution::Uniform { lower, upper }
            if lower > upper =>
        {
            return Err(invalid(f("lower"), "must not exceed upper"));
        }
        _ => {}
    }
    Ok(distribution)
}

/// The generator of run `run` (`None`: the single run of `imukit simulate` without `--runs`)
/// on the stream `salt` of `seed`: streams of different salts are independent.
fn run_stream(seed: u64, run: Option<u64>, salt: u64) -> Xoshiro256PlusPlus {
    let mut z = (seed ^ salt) ^ run.map_or(u64::MAX, |r| r.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Xoshiro256PlusPlus::seed_from_u64(z ^ (z >> 31))
}

/// A part of the same type as `base`, drawn for `run` — what a Monte Carlo over parts (an
/// outage study) simulates instead of one part in every run: each axis's constant bias, each
/// entry of the axes' scale-factor and misalignment errors (`axes_misalignment_pct` about
/// `100·I`) and each axis's gyroscope g-sensitivity from `N(0, s²)`, `s` the magnitude `base`
/// gives that axis or entry (the datasheet's figure taken as one-sigma; 0 stays 0). The
/// accelerometer and the gyroscope are drawn (the magnetometer is left as given), from a
/// stream of (`seed`, `run`) of its own.
///
/// # Errors
/// A draw that makes a parameter invalid, named with the run.
pub fn drawn_part(base: &ImuParams, seed: u64, run: Option<u64>) -> Result<ImuParams> {
    const SALT: u64 = 0x5041_5254_4452_4157;
    let mut rng = run_stream(seed, run, SALT);
    let mut normal = |s: f64| {
        let n: f64 = StandardNormal.sample(&mut rng);
        s * n
    };
    let mut out = base.clone();
    for sensor in [Sensor::Accelerometer, Sensor::Gyroscope] {
        let p = out.get_mut(sensor);
        p.constant_bias = p.constant_bias.map(|b| normal(b.abs()));
        for (r, row) in p.axes_misalignment_pct.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                let nominal = if r == c { 100.0 } else { 0.0 };
                *v = nominal + normal((*v - nominal).abs());
            }
        }
        if sensor == Sensor::Gyroscope {
            p.acceleration_bias = p.acceleration_bias.map(|k| normal(k.abs()));
        }
        p.validate().map_err(|e| {
            let which = run.map_or_else(|| "the run".to_string(), |r| format!("run {r}"));
            invalid(
                format!("drawn part ({})", sensor.key()),
                format!("{which}: the draw is invalid: {e}"),
            )
        })?;
    }
    Ok(out)
}

/// The parameters of a run: `base` with every perturbation drawn from the stream of
/// (`seed`, `run`) — `run = None` is the single run of `imukit simulate` without `--runs`.
///
/// # Errors
/// A draw that makes a parameter invalid (e.g. a negative density), with run and parameter.
pub fn perturbed(
    base: &ImuParams,
    perturbations: &[Perturbation],
    seed: u64,
    run: Option<u64>,
) -> Result<ImuParams> {
    if perturbations.is_empty() {
        return Ok(base.clone());
    }
    const SALT: u64 = 0x5045_5254_5552_4221;
    let mut rng = run_stream(seed, run, SALT);
    let mut out = base.clone();
    for p in perturbations {
        let params = out.get_mut(p.sensor);
        p.apply(params, &mut rng);
        params.validate().map_err(|e| {
            let which = run.map_or_else(|| "the run".to_string(), |r| format!("run {r}"));
            invalid(
                format!("imu.perturbations ({})", p.name),
                format!("{which}: the draw is invalid: {e}"),
            )
        })?;
    }
    Ok(out)
}
