//! What a part's figures are: each term of the sensor error model as its data sheet states it —
//! the quoted figure, its unit, the statistic it is and the line it comes from — or marked as
//! not given.
//!
//! A parameter file may carry a `[datasheet.<sensor>]` table beside its `[<sensor>]` table (every
//! preset does):
//!
//! ```toml
//! [datasheet.gyroscope]
//! noise_density = { quoted = 0.15, unit = "°/√h", statistic = "typical", line = "Angular random walk 0.15 °/√h" }
//! bias_instability = { quoted = 0.5, unit = "°/h", statistic = "allan-minimum", line = "Bias instability 0.5 °/h" }
//! random_walk = "not given"
//! ```
//!
//! [`Datasheet::check`] turns every figure into the parameter the model takes by the one rule of
//! its statistic ([`Statistic`]) and compares it with the parameter the file sets; a term marked
//! `"not given"` must be left ideal. The model's terms mean:
//!
//! - a bias, scale-factor, misalignment, temperature or g-sensitivity figure is a spread across
//!   parts and runs: the model takes its **1σ** (a part at one standard deviation). A data sheet's
//!   1σ, rms or typical figure is that; a range or a maximum is a bound, not a statistic, and is
//!   refused;
//! - a noise figure (angle or velocity random walk, noise density, rate random walk) is the part's
//!   own coefficient: typical or maximum (then the model is a part at the bound);
//! - bias instability is quoted as the Allan-deviation minimum; the model's flicker coefficient
//!   is that minimum / 0.664 ([`crate::units::datasheet_bias_instability`]);
//! - range and resolution are the specification itself.
use std::collections::BTreeMap;

use crate::error::{Result, invalid};
use crate::params::{ImuParams, ParamValue, Sensor};
use crate::sensor::SensorParams;
use crate::units::{convert, datasheet_bias_instability};

/// The statistic a data sheet's figure is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Statistic {
    /// One standard deviation across parts or runs (`"1-sigma"`).
    OneSigma,
    /// Root mean square across parts or runs (`"rms"`), a 1σ for a zero-mean spread.
    Rms,
    /// The typical value (`"typical"`): the 1σ of the population, as vendors define it.
    Typical,
    /// A maximum (`"max"`): a bound.
    Max,
    /// A ± limit or range (`"range"`): a bound.
    Range,
    /// The minimum of the Allan deviation (`"allan-minimum"`).
    AllanMinimum,
    /// A specification met by construction: range, resolution (`"spec"`).
    Spec,
}

impl Statistic {
    const NAMES: [(&'static str, Self); 7] = [
        ("1-sigma", Self::OneSigma),
        ("rms", Self::Rms),
        ("typical", Self::Typical),
        ("max", Self::Max),
        ("range", Self::Range),
        ("allan-minimum", Self::AllanMinimum),
        ("spec", Self::Spec),
    ];

    fn parse(s: &str, field: &str) -> Result<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == s)
            .map(|(_, v)| *v)
            .ok_or_else(|| {
                let known: Vec<&str> = Self::NAMES.iter().map(|(n, _)| *n).collect();
                invalid(
                    field,
                    format!("unknown statistic \"{s}\" (known: {})", known.join(", ")),
                )
            })
    }

    /// The name as written in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("", |(n, _)| n)
    }
}

/// A term of the sensor error model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Term {
    /// Saturation.
    MeasurementRange,
    /// Quantisation step.
    Resolution,
    /// Turn-on (run-to-run) bias.
    ConstantBias,
    /// Scale-factor error: the diagonal of `axes_misalignment_pct` minus 100.
    ScaleFactor,
    /// Cross-axis misalignment: the off-diagonal of `axes_misalignment_pct`.
    Misalignment,
    /// White-noise density (angle / velocity random walk).
    NoiseDensity,
    /// Bias instability (flicker).
    BiasInstability,
    /// Rate random walk.
    RandomWalk,
    /// Bias per °C.
    TemperatureBias,
    /// Scale factor per °C.
    TemperatureScaleFactor,
    /// Gyroscope g-sensitivity.
    AccelerationBias,
}

impl Term {
    /// Every term, in file order.
    pub const ALL: [Self; 11] = [
        Self::MeasurementRange,
        Self::Resolution,
        Self::ConstantBias,
        Self::ScaleFactor,
        Self::Misalignment,
        Self::NoiseDensity,
        Self::BiasInstability,
        Self::RandomWalk,
        Self::TemperatureBias,
        Self::TemperatureScaleFactor,
        Self::AccelerationBias,
    ];

    /// The key in `[datasheet.<sensor>]`.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::MeasurementRange => "measurement_range",
            Self::Resolution => "resolution",
            Self::ConstantBias => "constant_bias",
            Self::ScaleFactor => "scale_factor",
            Self::Misalignment => "misalignment",
            Self::NoiseDensity => "noise_density",
            Self::BiasInstability => "bias_instability",
            Self::RandomWalk => "random_walk",
            Self::TemperatureBias => "temperature_bias",
            Self::TemperatureScaleFactor => "temperature_scale_factor",
            Self::AccelerationBias => "acceleration_bias",
        }
    }

    /// A short name for people (`"turn-on bias"`).
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::MeasurementRange => "range",
            Self::Resolution => "resolution",
            Self::ConstantBias => "turn-on bias",
            Self::ScaleFactor => "scale factor",
            Self::Misalignment => "misalignment",
            Self::NoiseDensity => "white noise",
            Self::BiasInstability => "bias instability",
            Self::RandomWalk => "random walk",
            Self::TemperatureBias => "temperature bias",
            Self::TemperatureScaleFactor => "temperature scale factor",
            Self::AccelerationBias => "g-sensitivity",
        }
    }

    /// The terms a sensor's model has.
    #[must_use]
    pub fn of(sensor: Sensor) -> Vec<Self> {
        Self::ALL
            .into_iter()
            .filter(|t| *t != Self::AccelerationBias || sensor == Sensor::Gyroscope)
            .collect()
    }

    /// A spread across parts and runs (its model value is a 1σ), as opposed to a part's own
    /// noise coefficient or a specification.
    fn is_spread(self) -> bool {
        matches!(
            self,
            Self::ConstantBias
                | Self::ScaleFactor
                | Self::Misalignment
                | Self::TemperatureBias
                | Self::TemperatureScaleFactor
                | Self::AccelerationBias
        )
    }

    /// Whether `statistic` can state this term, or why not.
    fn accepts(self, statistic: Statistic) -> std::result::Result<(), &'static str> {
        use Statistic as S;
        let ok = match self {
            Self::MeasurementRange | Self::Resolution => statistic == S::Spec,
            Self::BiasInstability => statistic == S::AllanMinimum,
            Self::NoiseDensity | Self::RandomWalk => {
                matches!(statistic, S::Typical | S::Max | S::OneSigma)
            }
            _ => matches!(statistic, S::OneSigma | S::Rms | S::Typical),
        };
        if ok {
            Ok(())
        } else if self.is_spread() && matches!(statistic, S::Max | S::Range) {
            Err("a bound, not a 1σ statistic: the model takes the 1σ of the spread")
        } else {
            Err("not a statistic this term is stated by")
        }
    }
}

/// One figure as the data sheet states it.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// The number(s) quoted: one, or x, y, z.
    pub quoted: Vec<f64>,
    /// Their unit as the data sheet writes it (`"°/√h"`, `"mg"`, `"ppm"`, `"LSB/g"`).
    pub unit: String,
    /// The statistic.
    pub statistic: Statistic,
    /// The data sheet's line.
    pub line: String,
    /// For a change quoted over a temperature span, the span in °C.
    pub span_c: Option<f64>,
}

/// A term as the data sheet gives it, or not.
#[derive(Clone, Debug, PartialEq)]
pub enum Entry {
    /// The figure.
    Given(Figure),
    /// The data sheet (or the source transcribed) does not give this term.
    NotGiven,
}

/// A part's data-sheet figures, per sensor and term.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Datasheet {
    /// `(sensor, term) → entry`.
    pub entries: BTreeMap<(usize, Term), Entry>,
}

const NOT_GIVEN: &str = "not given";

impl Datasheet {
    /// Reads a `datasheet` table (`{ accelerometer = { … }, gyroscope = { … } }`).
    ///
    /// # Errors
    /// Unknown sensors, terms, statistics or keys; figures without a number, unit or line.
    pub fn parse(value: &ParamValue, origin: &str) -> Result<Self> {
        let ParamValue::Table(sensors) = value else {
            return Err(invalid(origin, "expected a table of sensors"));
        };
        let mut out = Self::default();
        for (name, table) in sensors {
            let field = format!("{origin}.{name}");
            let i = Sensor::ALL
                .iter()
                .position(|s| s.key() == name)
                .ok_or_else(|| {
                    invalid(
                        &field,
                        "unknown sensor (expected accelerometer, gyroscope, magnetometer)",
                    )
                })?;
            let ParamValue::Table(terms) = table else {
                return Err(invalid(&field, "expected a table of terms"));
            };
            for (key, v) in terms {
                let field = format!("{field}.{key}");
                let term = Term::of(Sensor::ALL[i])
                    .into_iter()
                    .find(|t| t.key() == key)
                    .ok_or_else(|| {
                        let known: Vec<&str> =
                            Term::of(Sensor::ALL[i]).iter().map(|t| t.key()).collect();
                        invalid(
                            &field,
                            format!("unknown term (known: {})", known.join(", ")),
                        )
                    })?;
                let entry = match v {
                    ParamValue::Text(s) if s == NOT_GIVEN => Entry::NotGiven,
                    ParamValue::Table(t) => Entry::Given(parse_figure(t, &field)?),
                    _ => {
                        return Err(invalid(
                            &field,
                            format!(
                                "expected \"{NOT_GIVEN}\" or {{ quoted, unit, statistic, line }}"
                            ),
                        ));
                    }
                };
                out.entries.insert((i, term), entry);
            }
        }
        Ok(out)
    }

    /// The entry of `sensor`'s `term`.
    #[must_use]
    pub fn entry(&self, sensor: Sensor, term: Term) -> Option<&Entry> {
        self.entries.get(&(sensor_index(sensor), term))
    }

    /// The terms marked not given, as `sensor.term`.
    #[must_use]
    pub fn not_given(&self) -> Vec<String> {
        self.entries
            .iter()
            .filter(|(_, e)| matches!(e, Entry::NotGiven))
            .map(|((i, t), _)| format!("{}.{}", Sensor::ALL[*i].key(), t.key()))
            .collect()
    }

    /// The error terms that decide how a part navigates — turn-on bias, scale factor,
    /// misalignment, white noise, bias instability, random walk — that the data sheet leaves out,
    /// per sensor: `"accelerometer: turn-on bias, random walk; gyroscope: random walk"`, or empty.
    #[must_use]
    pub fn missing_error_terms(&self) -> String {
        const TERMS: [Term; 6] = [
            Term::ConstantBias,
            Term::ScaleFactor,
            Term::Misalignment,
            Term::NoiseDensity,
            Term::BiasInstability,
            Term::RandomWalk,
        ];
        let mut parts = Vec::new();
        for sensor in [Sensor::Accelerometer, Sensor::Gyroscope] {
            let missing: Vec<&str> = TERMS
                .iter()
                .filter(|t| matches!(self.entry(sensor, **t), Some(Entry::NotGiven)))
                .map(|t| t.label())
                .collect();
            if !missing.is_empty() {
                parts.push(format!("{}: {}", sensor.key(), missing.join(", ")));
            }
        }
        parts.join("; ")
    }

    /// Whether `sensor`'s `term` is given by the data sheet.
    #[must_use]
    pub fn gives(&self, sensor: Sensor, term: Term) -> bool {
        matches!(self.entry(sensor, term), Some(Entry::Given(_)))
    }

    /// Every way `params` (the sensors in `present`) departs from these figures: a term with no
    /// entry, a figure of the wrong statistic, a figure whose model value differs from the
    /// parameter, a term not given but set. Empty when the parameters are the data sheet's.
    #[must_use]
    pub fn check(&self, params: &ImuParams, present: [bool; 3]) -> Vec<String> {
        let mut problems = Vec::new();
        for (i, sensor) in Sensor::ALL.into_iter().enumerate() {
            if !present[i] {
                if self.entries.keys().any(|(s, _)| *s == i) {
                    problems.push(format!(
                        "{}: figures for a sensor the file does not describe",
                        sensor.key()
                    ));
                }
                continue;
            }
            let p = params.get(sensor);
            for term in Term::of(sensor) {
                let at = format!("{}.{}", sensor.key(), term.key());
                let set = model_value(p, term);
                match self.entry(sensor, term) {
                    None => problems.push(format!("{at}: no entry (a figure, or \"{NOT_GIVEN}\")")),
                    Some(Entry::NotGiven) => {
                        if set.iter().any(|&v| v != ideal_value(term)) {
                            problems
                                .push(format!("{at}: marked not given, but set to {}", show(&set)));
                        }
                    }
                    Some(Entry::Given(f)) => match f.model_value(term) {
                        Err(e) => problems.push(format!("{at}: {e}")),
                        Ok(want) => {
                            let want = if want.len() == 1 {
                                vec![want[0]; set.len()]
                            } else {
                                want
                            };
                            if want.len() != set.len()
                                || want.iter().zip(&set).any(|(w, s)| !close(*w, *s))
                            {
                                problems.push(format!(
                                    "{at}: the data sheet's {} {} {} is {} in the model, the \
                                     parameters set {}",
                                    f.statistic.name(),
                                    show(&f.quoted),
                                    f.unit,
                                    show(&want),
                                    show(&set)
                                ));
                            }
                        }
                    },
                }
            }
        }
        problems
    }
}

fn sensor_index(sensor: Sensor) -> usize {
    Sensor::ALL
        .iter()
        .position(|s| *s == sensor)
        .unwrap_or_default()
}

fn parse_figure(t: &BTreeMap<String, ParamValue>, field: &str) -> Result<Figure> {
    const KEYS: [&str; 5] = ["quoted", "unit", "statistic", "line", "span_c"];
    if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(invalid(
            format!("{field}.{k}"),
            format!("unknown key (known: {})", KEYS.join(", ")),
        ));
    }
    let number = |v: &ParamValue, at: &str| match v {
        ParamValue::Number(x) if x.is_finite() => Ok(*x),
        #[allow(clippy::cast_precision_loss)]
        ParamValue::Integer(n) => Ok(*n as f64),
        _ => Err(invalid(at, "expected a finite number")),
    };
    let text = |k: &str| {
        t.get(k)
            .and_then(ParamValue::as_str)
            .map(str::to_string)
            .ok_or_else(|| invalid(format!("{field}.{k}"), "expected a string"))
    };
    let at = format!("{field}.quoted");
    let quoted = match t.get("quoted") {
        Some(ParamValue::List(xs)) if xs.len() == 3 => xs
            .iter()
            .map(|x| number(x, &at))
            .collect::<Result<Vec<_>>>()?,
        Some(v) => vec![number(v, &at)?],
        None => return Err(invalid(at, "missing")),
    };
    let span_c = t
        .get("span_c")
        .map(|v| number(v, &format!("{field}.span_c")))
        .transpose()?;
    if span_c.is_some_and(|s| s <= 0.0) {
        return Err(invalid(format!("{field}.span_c"), "expected > 0 °C"));
    }
    Ok(Figure {
        quoted,
        unit: text("unit")?,
        statistic: Statistic::parse(&text("statistic")?, &format!("{field}.statistic"))?,
        line: text("line")?,
        span_c,
    })
}

impl Figure {
    /// The value the model takes for `term` from this figure, by the rule of its statistic: one
    /// number (the same on every axis or element) or one per axis.
    ///
    /// # Errors
    /// A statistic that cannot state the term (a bound for a spread), an unknown unit.
    pub fn model_value(&self, term: Term) -> std::result::Result<Vec<f64>, String> {
        term.accepts(self.statistic)
            .map_err(|why| format!("{} figure: {why}", self.statistic.name()))?;
        let unit = self.unit.trim().to_lowercase().replace(' ', "");
        let one = |q: f64| -> std::result::Result<f64, String> {
            let v = match term {
                Term::ScaleFactor | Term::Misalignment => percent(q, &unit)?,
                Term::Resolution => match unit.strip_prefix("lsb/") {
                    Some(per) => si(1.0 / q, per.trim_matches(|c| c == '(' || c == ')'))?,
                    None => si(q, &unit)?,
                },
                Term::TemperatureScaleFactor if self.span_c.is_some() => percent(q, &unit)?,
                _ => si(q, &unit)?,
            };
            let v = match (term, self.span_c) {
                (Term::BiasInstability, _) => datasheet_bias_instability(v),
                (Term::TemperatureBias | Term::TemperatureScaleFactor, Some(span)) => v / span,
                (_, Some(_)) => return Err("span_c is for temperature figures".into()),
                _ => v,
            };
            Ok(v)
        };
        self.quoted.iter().map(|&q| one(q)).collect()
    }

    /// Half a unit in the last digit quoted (`0.15` → 0.005, `2` → 0.5): the figure stands for
    /// any value within this of it.
    #[must_use]
    pub fn rounding(&self) -> f64 {
        self.quoted
            .iter()
            .map(|q| {
                let s = format!("{q}");
                let decimals = s.split_once('.').map_or(0, |(_, d)| d.len());
                0.5 * 10f64.powi(-i32::try_from(decimals).unwrap_or(0))
            })
            .fold(0.0, f64::max)
    }
}

fn si(q: f64, unit: &str) -> std::result::Result<f64, String> {
    convert(q, unit).map(|c| c.value).map_err(|e| e.to_string())
}

/// A scale-factor or misalignment figure in percent.
fn percent(q: f64, unit: &str) -> std::result::Result<f64, String> {
    Ok(match unit {
        "%" | "pct" => q,
        "ppm" => q * 1e-4,
        "mrad" => q * 0.1,
        "deg" | "°" => q.to_radians() * 100.0,
        _ => return Err(format!("unit \"{unit}\": expected %, ppm, mrad or °")),
    })
}

/// The parameter `term` sets, per axis (misalignment: the six off-diagonal elements).
fn model_value(p: &SensorParams, term: Term) -> Vec<f64> {
    let m = &p.axes_misalignment_pct;
    match term {
        Term::MeasurementRange => vec![p.measurement_range],
        Term::Resolution => vec![p.resolution],
        Term::ConstantBias => p.constant_bias.map(f64::abs).to_vec(),
        Term::ScaleFactor => (0..3).map(|k| (m[k][k] - 100.0).abs()).collect(),
        Term::Misalignment => (0..3)
            .flat_map(|r| (0..3).filter(move |&c| c != r).map(move |c| m[r][c].abs()))
            .collect(),
        Term::NoiseDensity => p.noise_density.to_vec(),
        Term::BiasInstability => p.bias_instability.to_vec(),
        Term::RandomWalk => p.random_walk.to_vec(),
        Term::TemperatureBias => p.temperature_bias.map(f64::abs).to_vec(),
        Term::TemperatureScaleFactor => p.temperature_scale_factor_pct.map(f64::abs).to_vec(),
        Term::AccelerationBias => p.acceleration_bias.map(f64::abs).to_vec(),
    }
}

fn ideal_value(term: Term) -> f64 {
    if term == Term::MeasurementRange {
        f64::INFINITY
    } else {
        0.0
    }
}

fn close(a: f64, b: f64) -> bool {
    // Preset files write six significant figures.
    a == b || (a - b).abs() <= 5e-6 * a.abs().max(b.abs())
}

fn show(xs: &[f64]) -> String {
    let s: Vec<String> = xs.iter().map(|x| format!("{x:.6e}")).collect();
    if let Some(first) = s.first().filter(|f| s.iter().all(|x| x == *f)) {
        first.clone()
    } else {
        format!("[{}]", s.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sheet(toml: &str) -> Datasheet {
        let v: ParamValue = toml::from_str(toml).unwrap();
        Datasheet::parse(&v, "datasheet").unwrap()
    }

    #[test]
    fn a_range_is_refused_for_a_bias_and_an_allan_minimum_becomes_the_flicker_coefficient() {
        let mut p = ImuParams::default();
        p.gyroscope.constant_bias = [1.212e-3; 3];
        let d = sheet(
            r#"[gyroscope]
            constant_bias = { quoted = 250, unit = "°/h", statistic = "range", line = "Bias range ±250 °/h" }"#,
        );
        let problems = d.check(&p, [false, true, false]);
        assert!(
            problems
                .iter()
                .any(|e| e.contains("constant_bias: range figure: a bound, not a 1σ")),
            "{problems:?}"
        );
        // Every other gyroscope term is missing.
        assert_eq!(problems.len(), Term::of(Sensor::Gyroscope).len());

        let minimum = 0.5_f64.to_radians() / 3600.0;
        let mut p = ImuParams::default();
        p.gyroscope.bias_instability = [minimum / 0.664_282_470_267_960_1; 3];
        let d = sheet(
            r#"[gyroscope]
            bias_instability = { quoted = 0.5, unit = "°/h", statistic = "allan-minimum", line = "x" }"#,
        );
        let problems = d.check(&p, [false, true, false]);
        assert!(
            !problems
                .iter()
                .any(|e| e.starts_with("gyroscope.bias_instability")),
            "{problems:?}"
        );
    }

    #[test]
    fn not_given_terms_must_be_ideal_and_spans_divide() {
        let mut p = ImuParams::default();
        p.accelerometer.random_walk = [1e-6; 3];
        p.accelerometer.temperature_bias = [35e-3 * 9.80665 / 70.0; 3];
        let d = sheet(
            r#"[accelerometer]
            random_walk = "not given"
            temperature_bias = { quoted = 35, unit = "mg", statistic = "typical", span_c = 70, line = "±35 mg over 0–70 °C" }"#,
        );
        let problems = d.check(&p, [true, false, false]);
        assert!(problems.iter().any(|e| {
            e.starts_with("accelerometer.random_walk: marked not given, but set to 1.000000e-6")
        }));
        assert!(
            !problems
                .iter()
                .any(|e| e.starts_with("accelerometer.temperature_bias")),
            "{problems:?}"
        );
        assert_eq!(d.not_given(), vec!["accelerometer.random_walk".to_string()]);
    }

    #[test]
    fn bad_tables_name_their_key() {
        let v: ParamValue =
            toml::from_str("[gyroscope]\nnoise_density = { quoted = 1, unit = \"x\", statistic = \"often\", line = \"\" }")
                .unwrap();
        let e = Datasheet::parse(&v, "datasheet").unwrap_err().to_string();
        assert!(
            e.contains("datasheet.gyroscope.noise_density.statistic"),
            "{e}"
        );
        let v: ParamValue = toml::from_str("[gyroscope]\nwobble = \"not given\"").unwrap();
        let e = Datasheet::parse(&v, "datasheet").unwrap_err().to_string();
        assert!(
            e.contains("datasheet.gyroscope.wobble: unknown term"),
            "{e}"
        );
    }
}
