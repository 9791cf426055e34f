//! A sensor's parameter table read into the model's parameters: numbers, triples, the
//! misalignment matrix, filter coefficients, each checked and named by its key.

use imu_core::sensor::NoiseType;

use super::{ParamValue, Sensor, SensorTable};
use crate::error::{Error, Result, invalid};
use crate::sensor::{BiasInstabilityModel, FilterCoefficients, SensorParams};

fn as_number(v: &ParamValue, field: &str) -> Result<f64> {
    match v {
        ParamValue::Number(x) if x.is_nan() => Err(invalid(field, "not a finite number (NaN)")),
        ParamValue::Number(x) => Ok(*x),
        #[allow(clippy::cast_precision_loss)]
        ParamValue::Integer(i) => Ok(*i as f64),
        ParamValue::Text(s)
            if matches!(s.to_ascii_lowercase().as_str(), "inf" | "infinity" | "+inf") =>
        {
            Ok(f64::INFINITY)
        }
        other => Err(invalid(field, format!("expected a number, got {other}"))),
    }
}

fn finite_number(v: &ParamValue, field: &str) -> Result<f64> {
    let x = as_number(v, field)?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(field, "must be finite"))
    }
}

/// A number (same on every axis) or a 3-vector.
fn triple(v: &ParamValue, field: &str) -> Result<[f64; 3]> {
    match v {
        ParamValue::List(a) if a.len() == 3 => Ok([
            finite_number(&a[0], &format!("{field}[0]"))?,
            finite_number(&a[1], &format!("{field}[1]"))?,
            finite_number(&a[2], &format!("{field}[2]"))?,
        ]),
        ParamValue::List(a) => Err(invalid(
            field,
            format!("expected a number or 3 numbers, got {} values", a.len()),
        )),
        other => Ok([finite_number(other, field)?; 3]),
    }
}

/// MATLAB's AxesMisalignment forms: scalar, 3-vector or 3×3, percent.
fn misalignment(v: &ParamValue, field: &str) -> Result<[[f64; 3]; 3]> {
    match v {
        // MATLAB also takes a 3×1 column for the 3-vector form.
        ParamValue::List(rows)
            if rows.len() == 3
                && rows
                    .iter()
                    .all(|r| matches!(r, ParamValue::List(c) if c.len() == 1)) =>
        {
            let column: Vec<ParamValue> = rows
                .iter()
                .filter_map(|r| match r {
                    ParamValue::List(c) => c.first().cloned(),
                    _ => None,
                })
                .collect();
            Ok(SensorParams::misalignment_from_vector(triple(
                &ParamValue::List(column),
                field,
            )?))
        }
        ParamValue::List(rows) if rows.len() == 3 && rows.iter().all(ParamValue::is_list) => {
            let mut m = [[0.0; 3]; 3];
            for (i, row) in rows.iter().enumerate() {
                m[i] = triple(row, &format!("{field}[{i}]"))?;
            }
            Ok(m)
        }
        ParamValue::List(_) => Ok(SensorParams::misalignment_from_vector(triple(v, field)?)),
        other => Ok(SensorParams::misalignment_from_scalar(finite_number(
            other, field,
        )?)),
    }
}

fn list(v: &ParamValue, field: &str) -> Result<Vec<f64>> {
    match v {
        ParamValue::List(a) => a
            .iter()
            .enumerate()
            .map(|(k, x)| finite_number(x, &format!("{field}[{k}]")))
            .collect(),
        other => Ok(vec![finite_number(other, field)?]),
    }
}

fn noise_type(v: &ParamValue, field: &str) -> Result<NoiseType> {
    match v.as_str().map(str::to_ascii_lowercase).as_deref() {
        Some("single-sided") => Ok(NoiseType::SingleSided),
        Some("double-sided") => Ok(NoiseType::DoubleSided),
        _ => Err(invalid(
            field,
            format!("expected \"single-sided\" or \"double-sided\", got {v}"),
        )),
    }
}

/// Parses one sensor table (imukit's or MATLAB's keys) onto `base`; `prefix` names the table in
/// messages (e.g. `imu.gyroscope`); `default_noise` is the noise type when the table has none
/// (`None` keeps `base`'s).
///
/// # Errors
/// Unknown keys (the known ones listed), bad values, invalid parameters — each named.
pub fn parse_sensor(
    map: &SensorTable,
    sensor: Sensor,
    prefix: &str,
    default_noise: Option<NoiseType>,
    base: SensorParams,
) -> Result<SensorParams> {
    parse_sensor_keys(map, sensor, prefix, default_noise, base, None)
}

/// [`parse_sensor`], skipping unknown keys into `skipped` when it is given (MATLAB's
/// `loadparams` ignores properties it does not know) instead of refusing them.
pub(crate) fn parse_sensor_keys(
    map: &SensorTable,
    sensor: Sensor,
    prefix: &str,
    default_noise: Option<NoiseType>,
    base: SensorParams,
    mut skipped: Option<&mut Vec<String>>,
) -> Result<SensorParams> {
    let u = sensor.unit();
    let key = |name: &str| format!("{name}_{u}");
    let mut p = base;
    let mut noise_set = false;
    let mut model = BiasModelKeys::default();
    let known = [
        key("measurement_range"),
        key("resolution"),
        key("constant_bias"),
        "axes_misalignment_pct".into(),
        format!("noise_density_{u}_per_rt_hz"),
        key("bias_instability"),
        "bias_instability_numerator".into(),
        "bias_instability_denominator".into(),
        "bias_instability_flicker_tau_s".into(),
        "bias_instability_correlation_time_s".into(),
        format!("random_walk_{u}_rt_hz"),
        "noise_type".into(),
        format!("temperature_bias_{u}_per_c"),
        "temperature_scale_factor_pct_per_c".into(),
        "acceleration_bias_rad_s_per_m_s2".into(),
        "quantization_carry".into(),
        format!("scale_factor_nonlinearity_per_{u}"),
        "scale_factor_asymmetry_pct".into(),
        "acceleration_squared_bias_rad_s_per_m2_s4".into(),
    ];
    for (k, v) in map {
        let field = format!("{prefix}.{k}");
        let own = known.iter().position(|n| n == k);
        match (own, k.as_str()) {
            (Some(0), _) | (_, "MeasurementRange") => p.measurement_range = as_number(v, &field)?,
            (Some(1), _) | (_, "Resolution") => p.resolution = finite_number(v, &field)?,
            (Some(2), _) | (_, "ConstantBias") => p.constant_bias = triple(v, &field)?,
            (Some(3), _) | (_, "AxesMisalignment") => {
                p.axes_misalignment_pct = misalignment(v, &field)?
            }
            (Some(4), _) | (_, "NoiseDensity") => p.noise_density = triple(v, &field)?,
            (Some(5), _) | (_, "BiasInstability") => p.bias_instability = triple(v, &field)?,
            (Some(6), _) => model.numerator = Some(list(v, &field)?),
            (Some(7), _) => model.denominator = Some(list(v, &field)?),
            (_, "BiasInstabilityCoefficients") => model.matlab_coefficients(v, &field)?,
            (Some(8), _) => {
                let l = list(v, &field)?;
                if l.len() != 2 {
                    return Err(invalid(field, "expected [tau_min_s, tau_max_s]"));
                }
                model.flicker = Some([l[0], l[1]]);
            }
            (Some(9), _) => model.correlation = Some(finite_number(v, &field)?),
            (Some(10), _) | (_, "RandomWalk") => p.random_walk = triple(v, &field)?,
            (Some(11), _) | (_, "NoiseType") => {
                p.noise_type = noise_type(v, &field)?;
                noise_set = true;
            }
            (Some(12), _) | (_, "TemperatureBias") => p.temperature_bias = triple(v, &field)?,
            (Some(13), _) | (_, "TemperatureScaleFactor") => {
                p.temperature_scale_factor_pct = triple(v, &field)?
            }
            (Some(15), _) => {
                let ParamValue::Bool(carry) = v else {
                    return Err(invalid(field, format!("expected true or false, got {v}")));
                };
                p.quantization_carry = *carry;
            }
            (Some(14), _) | (_, "AccelerationBias") if sensor == Sensor::Gyroscope => {
                p.acceleration_bias = triple(v, &field)?;
            }
            (Some(16), _) | (_, "ScaleFactorNonlinearity") => {
                p.scale_factor_nonlinearity = triple(v, &field)?;
            }
            (Some(17), _) | (_, "ScaleFactorAsymmetry") => {
                p.scale_factor_asymmetry_pct = triple(v, &field)?;
            }
            (Some(18), _) | (_, "AccelerationSquaredBias") if sensor == Sensor::Gyroscope => {
                p.acceleration_squared_bias = triple(v, &field)?;
            }
            _ => {
                if let Some(list) = skipped.as_deref_mut() {
                    list.push(format!(
                        "{field}: unknown property, skipped (as MATLAB does)"
                    ));
                    continue;
                }
                return Err(invalid(
                    field,
                    format!(
                        "unknown parameter (known for the {}: {})",
                        sensor.key(),
                        known.join(", ")
                    ),
                ));
            }
        }
    }
    if let (false, Some(n)) = (noise_set, default_noise) {
        p.noise_type = n;
    }
    if let Some(m) = model.chosen(prefix)? {
        p.bias_instability_model = m;
    }
    p.validate().map_err(|source| Error::Param {
        context: prefix.into(),
        source,
    })?;
    Ok(p)
}

/// The keys that choose a bias instability process other than the default filter, as read.
#[derive(Default)]
struct BiasModelKeys {
    numerator: Option<Vec<f64>>,
    denominator: Option<Vec<f64>>,
    flicker: Option<[f64; 2]>,
    correlation: Option<f64>,
}

impl BiasModelKeys {
    /// MATLAB's `BiasInstabilityCoefficients`, a table of `Numerator` and `Denominator`.
    fn matlab_coefficients(&mut self, v: &ParamValue, field: &str) -> Result<()> {
        let ParamValue::Table(t) = v else {
            return Err(invalid(field, "needs Numerator and Denominator"));
        };
        if let Some(other) = t
            .keys()
            .find(|k| !matches!(k.as_str(), "Numerator" | "Denominator"))
        {
            return Err(invalid(
                format!("{field}.{other}"),
                "unknown key (BiasInstabilityCoefficients has Numerator and Denominator)",
            ));
        }
        let get = |name: &str| {
            t.get(name)
                .map(|x| list(x, &format!("{field}.{name}")))
                .transpose()
        };
        self.numerator = get("Numerator")?;
        self.denominator = get("Denominator")?;
        if self.numerator.is_none() || self.denominator.is_none() {
            return Err(invalid(field, "needs Numerator and Denominator"));
        }
        Ok(())
    }

    /// The process the keys choose (`None`: none given); more than one is refused.
    fn chosen(self, prefix: &str) -> Result<Option<BiasInstabilityModel>> {
        let filter = self.numerator.is_some() || self.denominator.is_some();
        let given = [filter, self.flicker.is_some(), self.correlation.is_some()];
        if given.iter().filter(|c| **c).count() > 1 {
            return Err(invalid(
                format!("{prefix}.bias_instability"),
                "give one of the filter coefficients, bias_instability_flicker_tau_s or bias_instability_correlation_time_s",
            ));
        }
        if filter {
            let num = self.numerator.unwrap_or_else(|| vec![1.0]);
            let den = self.denominator.unwrap_or_else(|| vec![1.0, -0.5]);
            let c = FilterCoefficients::new(&num, &den).map_err(|source| Error::Param {
                context: prefix.into(),
                source,
            })?;
            return Ok(Some(BiasInstabilityModel::Filter(c)));
        }
        if let Some([tau_min_s, tau_max_s]) = self.flicker {
            return Ok(Some(BiasInstabilityModel::Flicker {
                tau_min_s,
                tau_max_s,
            }));
        }
        Ok(self
            .correlation
            .map(|correlation_time_s| BiasInstabilityModel::GaussMarkov { correlation_time_s }))
    }
}
