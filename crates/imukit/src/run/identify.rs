//! Noise identification of a static log: the Allan curves with their confidence bands, the
//! fitted terms in SI and in data-sheet units, and what follows from them — an imukit parameter
//! file, a Kalibr `imu.yaml`, the fusion filter's noise. Shared by `imukit identify` and Python's
//! `imukit.identify`.
use std::collections::BTreeMap;

use imu_core::allan::{NoiseFit, NoiseTerm, ScaleEstimate, ScaleTerm, TermEstimate};
use imu_core::fusion::process_noise::triad_psd;
use imu_core::sensor::{BiasInstabilityModel, NoiseType};

use crate::error::{Result, invalid};
use crate::io::kalibr::KalibrImu;
use crate::io::params::{ImuParams, Sensor};
use crate::io::part_file::ParamFile;
use crate::io::table::Table;
use crate::io::units::factor_to;
use crate::run::allan::{AllanResult, ColumnNoise};
use crate::sensor::SensorParams;

/// What a column measures, from its name's unit suffix.
fn sensor_of(column: &str) -> Option<Sensor> {
    if column.ends_with("_rad_s") {
        Some(Sensor::Gyroscope)
    } else if column.ends_with("_m_s2") {
        Some(Sensor::Accelerometer)
    } else {
        None
    }
}

/// The axis (0, 1, 2) of a column named `…_x_…`, `…_y_…`, `…_z_…`.
fn axis_of(column: &str) -> Option<usize> {
    ["_x_", "_y_", "_z_"]
        .iter()
        .position(|a| column.contains(a))
}

/// A term's SI unit for a sensor.
#[must_use]
pub fn si_unit(sensor: Option<Sensor>, term: NoiseTerm) -> &'static str {
    let gyro = sensor != Some(Sensor::Accelerometer);
    match (term, gyro) {
        (NoiseTerm::Quantization, true) => "rad",
        (NoiseTerm::Quantization, false) => "m/s",
        (NoiseTerm::White, true) => "rad/s/√Hz",
        (NoiseTerm::White, false) => "m/s²/√Hz",
        (NoiseTerm::BiasInstability, true) => "rad/s",
        (NoiseTerm::BiasInstability, false) => "m/s²",
        (NoiseTerm::RandomWalk, true) => "rad/s·√Hz",
        (NoiseTerm::RandomWalk, false) => "m/s²·√Hz",
        (NoiseTerm::RateRamp, true) => "rad/s²",
        (NoiseTerm::RateRamp, false) => "m/s³",
    }
}

/// The data-sheet unit a term is quoted in (°/√h, °/h, °/h/√h; m/s/√h, µg, m/s/h/√h), if it
/// has one, with the factor from it to SI (from the units room).
#[must_use]
pub fn datasheet_unit(sensor: Option<Sensor>, term: NoiseTerm) -> Option<(&'static str, f64)> {
    let unit = match (sensor, term) {
        (Some(Sensor::Gyroscope), NoiseTerm::White) => "°/√h",
        (Some(Sensor::Gyroscope), NoiseTerm::BiasInstability) => "°/h",
        (Some(Sensor::Gyroscope), NoiseTerm::RandomWalk) => "°/h/√h",
        (Some(Sensor::Accelerometer), NoiseTerm::White) => "m/s/√h",
        (Some(Sensor::Accelerometer), NoiseTerm::BiasInstability) => "µg",
        (Some(Sensor::Accelerometer), NoiseTerm::RandomWalk) => "m/s/h/√h",
        _ => return None,
    };
    let factor = factor_to(unit, si_unit(sensor, term)).ok()?;
    Some((unit, factor))
}

/// One term of one column, as reported.
#[derive(Clone, Debug, PartialEq)]
pub struct TermRow {
    /// The column.
    pub column: String,
    /// The estimate.
    pub estimate: TermEstimate,
    /// Its SI unit.
    pub unit: &'static str,
    /// Its data-sheet unit and the factor from that unit to SI.
    pub datasheet: Option<(&'static str, f64)>,
}

impl TermRow {
    /// The line printed for it.
    #[must_use]
    pub fn line(&self) -> String {
        let e = &self.estimate;
        let t = e.term;
        let name = match t {
            NoiseTerm::Quantization => "quantisation",
            NoiseTerm::White => "white noise",
            NoiseTerm::BiasInstability => "bias instability",
            NoiseTerm::RandomWalk => "rate random walk",
            NoiseTerm::RateRamp => "rate ramp",
        };
        let ds = |x: f64| {
            self.datasheet
                .map(|(u, f)| format!(" ({:.4} {u})", x / f))
                .unwrap_or_default()
        };
        if e.resolved {
            format!(
                "  {} {name:<17} {:.4e} {}{}  95 %: {:.4e} … {:.4e}",
                t.symbol(),
                e.value,
                self.unit,
                ds(e.value),
                e.lower,
                e.upper
            )
        } else {
            let needs = match e.needs_record_s {
                Some(s) => format!("needs ≥ {:.1} h of data", s / 3600.0),
                None => "no record of a practical length resolves it".to_owned(),
            };
            format!(
                "  {} {name:<17} not resolved: < {:.4e} {}{} (95 %); a term that large {needs}",
                t.symbol(),
                e.upper,
                self.unit,
                ds(e.upper),
            )
        }
    }
}

/// Every term of every column of `result`, in column then term order.
#[must_use]
pub fn term_rows(result: &AllanResult) -> Vec<TermRow> {
    result
        .noise
        .iter()
        .flat_map(|c| {
            let sensor = sensor_of(&c.column);
            c.fit.terms.iter().map(move |e| TermRow {
                column: c.column.clone(),
                estimate: *e,
                unit: si_unit(sensor, e.term),
                datasheet: datasheet_unit(sensor, e.term),
            })
        })
        .collect()
}

/// A term with a time scale (Markov noise, a sinusoid) that a column's curve supports, as
/// reported.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleRow {
    /// The column.
    pub column: String,
    /// The estimate.
    pub estimate: ScaleEstimate,
    /// The amplitude's SI unit (the rate's: rad/s or m/s²).
    pub unit: &'static str,
    /// The time scale's unit.
    pub scale_unit: &'static str,
    /// The fall in χ² a term had to buy to be kept ([`NoiseFit::criterion`]).
    pub criterion: f64,
}

impl ScaleRow {
    /// The line printed for it.
    #[must_use]
    pub fn line(&self) -> String {
        let e = &self.estimate;
        let (name, amplitude, scale) = match e.term {
            ScaleTerm::Markov => ("Markov noise", "σ", "correlation time"),
            ScaleTerm::Sinusoid => ("sinusoid", "amplitude", "frequency"),
        };
        format!(
            "  {} {name:<17} {amplitude} {:.4e} {}  95 %: {:.4e} … {:.4e}; {scale} {:.4} {} \
             (95 %: {:.4} … {:.4} {}); χ² fell by {:.1} (kept above {:.1})",
            e.term.symbol(),
            e.value,
            self.unit,
            e.lower,
            e.upper,
            e.scale,
            self.scale_unit,
            e.scale_lower,
            e.scale_upper,
            self.scale_unit,
            e.chi2_drop,
            self.criterion
        )
    }
}

/// Every term with a time scale kept in a column of `result`, in column order.
#[must_use]
pub fn scale_rows(result: &AllanResult) -> Vec<ScaleRow> {
    result
        .noise
        .iter()
        .flat_map(|c| {
            let unit = si_unit(sensor_of(&c.column), NoiseTerm::BiasInstability);
            c.fit.scaled.iter().flatten().map(move |e| ScaleRow {
                column: c.column.clone(),
                estimate: *e,
                unit,
                scale_unit: match e.term {
                    ScaleTerm::Markov => "s",
                    ScaleTerm::Sinusoid => "Hz",
                },
                criterion: c.fit.criterion,
            })
        })
        .collect()
}

/// The curve with its bands and the fitted model: `tau_s`, then per column `adev_<c>`,
/// `lower95_<c>`, `upper95_<c>`, `edf_<c>`, `fit_<c>` (the fitted terms' deviation).
#[must_use]
pub fn curve_table(result: &AllanResult) -> Table {
    let tau = result.table.column("tau_s").unwrap_or_default();
    let mut columns = vec!["tau_s".to_owned()];
    for c in &result.noise {
        for prefix in ["adev", "lower95", "upper95", "edf", "fit"] {
            columns.push(format!("{prefix}_{}", c.column));
        }
    }
    let mut data = Vec::with_capacity(tau.len() * columns.len());
    for (i, t) in tau.iter().enumerate() {
        data.push(*t);
        for c in &result.noise {
            let adev = result
                .table
                .column(&format!("adev_{}", c.column))
                .map_or(f64::NAN, |v| v[i]);
            data.extend([
                adev,
                c.lower[i],
                c.upper[i],
                c.fit.edf[i],
                c.fit.variance_at(*t).sqrt(),
            ]);
        }
    }
    Table { columns, data }
}

/// The identified part as an imukit parameter file: per axis, the white noise, the bias
/// instability (flicker over the curve's τ range) and the random walk; a term not resolved is
/// written at its 95 % bound (what the log cannot rule out) and named in `notes`. Axes without a column take the largest identified
/// axis of their sensor (also noted).
///
/// # Errors
/// No gyroscope (`*_rad_s`) or accelerometer (`*_m_s2`) column among those identified.
pub fn param_file(result: &AllanResult, source: &str) -> Result<ParamFile> {
    let mut params = ImuParams::default();
    let mut present = [false; 3];
    let mut notes = Vec::new();
    let tau = result.table.column("tau_s").unwrap_or_default();
    let (tau_lo, tau_hi) = (
        tau.first().copied().unwrap_or(1.0),
        tau.last().copied().unwrap_or(1000.0),
    );
    for sensor in [Sensor::Accelerometer, Sensor::Gyroscope] {
        let columns: Vec<_> = result
            .noise
            .iter()
            .filter(|c| sensor_of(&c.column) == Some(sensor))
            .collect();
        if columns.is_empty() {
            continue;
        }
        present[Sensor::ALL.iter().position(|s| *s == sensor).unwrap_or(0)] = true;
        let p = params.get_mut(sensor);
        p.noise_type = NoiseType::SingleSided;
        let markov = gauss_markov_bias(&columns);
        p.bias_instability_model = match markov {
            Some(correlation_time_s) => {
                notes.push(format!(
                    "{}: bias instability is the Markov noise every axis shows (no flicker \
                     resolved), a Gauss–Markov bias of correlation time {correlation_time_s:.4} s \
                     (the axes' median)",
                    sensor.key()
                ));
                BiasInstabilityModel::GaussMarkov { correlation_time_s }
            }
            None => BiasInstabilityModel::Flicker {
                tau_min_s: tau_lo,
                tau_max_s: tau_hi.max(tau_lo * 2.0),
            },
        };
        let mut seen = [false; 3];
        for c in &columns {
            let Some(axis) = axis_of(&c.column) else {
                continue;
            };
            seen[axis] = true;
            column_into(p, c, axis, sensor, markov, &mut notes);
            notes.extend(unmodelled_terms(c, sensor, markov));
        }
        fill_missing_axes(p, seen, sensor, &mut notes);
    }
    if !present.iter().any(|p| *p) {
        return Err(invalid(
            "identify",
            "a parameter file needs gyroscope (*_rad_s) or accelerometer (*_m_s2) columns",
        ));
    }
    let mut info = BTreeMap::new();
    info.insert("name".to_owned(), format!("{source} (identified)"));
    info.insert(
        "source".to_owned(),
        format!(
            "imukit identify: Allan fit of {} samples at {:.6} Hz ({:.3} h), 95 % intervals",
            result.samples,
            result.sample_rate_hz,
            result.samples as f64 / result.sample_rate_hz / 3600.0
        ),
    );
    if !notes.is_empty() {
        info.insert("notes".to_owned(), notes.join("; "));
    }
    Ok(ParamFile {
        params,
        present,
        info,
        warnings: Vec::new(),
        datasheet: None,
        chain: None,
    })
}

/// One column's terms written into its sensor's axis `axis` of `p`; a term not resolved is
/// written at its bound (a filter tuned from the file then allows for as much of it as the log
/// cannot rule out), and so noted.
fn column_into(
    p: &mut SensorParams,
    c: &ColumnNoise,
    axis: usize,
    sensor: Sensor,
    markov: Option<f64>,
    notes: &mut Vec<String>,
) {
    let value = |t: NoiseTerm| {
        let e = c.fit.term(t);
        if e.resolved { e.value } else { e.upper }
    };
    p.noise_density[axis] = value(NoiseTerm::White);
    p.bias_instability[axis] = match (markov, c.fit.scaled(ScaleTerm::Markov)) {
        (Some(_), Some(e)) => e.value,
        _ => value(NoiseTerm::BiasInstability),
    };
    p.random_walk[axis] = value(NoiseTerm::RandomWalk);
    // A gyroscope at rest reads its turn-on bias (and the Earth rate's share, at most
    // 7.3e-5 rad/s); an accelerometer's mean also holds gravity's, in an attitude the
    // log does not give, so only the gyroscope's is written.
    if sensor == Sensor::Gyroscope {
        p.constant_bias[axis] = c.mean;
        notes.push(format!(
            "{}: constant_bias is the mean at rest, {:.4e} ± {:.1e} rad/s (Earth rate \
             included)",
            c.column, c.mean, c.mean_sigma
        ));
    }
    for e in c.fit.terms.iter().filter(|e| !e.resolved) {
        if matches!(e.term, NoiseTerm::White | NoiseTerm::RandomWalk)
            || (e.term == NoiseTerm::BiasInstability && markov.is_none())
        {
            notes.push(format!(
                "{}: {} not resolved, written as its 95 % bound {:.4e} {}",
                c.column,
                e.term.name(),
                e.upper,
                si_unit(Some(sensor), e.term)
            ));
        }
    }
}

/// Notes of the terms a column shows that the sensor model written has no place for: a
/// sinusoid, Markov noise not written as the bias, resolved quantization and rate ramp.
fn unmodelled_terms(c: &ColumnNoise, sensor: Sensor, markov: Option<f64>) -> Vec<String> {
    let mut notes = Vec::new();
    for e in c.fit.scaled.iter().flatten() {
        if e.term == ScaleTerm::Sinusoid || markov.is_none() {
            notes.push(format!(
                "{}: {} ({:.4e} at {:.4} {}) found but not part of the sensor model \
                 written",
                c.column,
                e.term.name(),
                e.value,
                e.scale,
                if e.term == ScaleTerm::Markov {
                    "s"
                } else {
                    "Hz"
                }
            ));
        }
    }
    for t in [NoiseTerm::Quantization, NoiseTerm::RateRamp] {
        let e = c.fit.term(t);
        if e.resolved {
            notes.push(format!(
                "{}: {} {:.4e} {} resolved but not part of the sensor model",
                c.column,
                t.name(),
                e.value,
                si_unit(Some(sensor), t)
            ));
        }
    }
    notes
}

/// The axes of `p` without a column (`seen` false) take the largest identified axis's terms.
fn fill_missing_axes(
    p: &mut SensorParams,
    seen: [bool; 3],
    sensor: Sensor,
    notes: &mut Vec<String>,
) {
    if seen.iter().all(|s| *s) {
        return;
    }
    let largest = |v: [f64; 3]| v.iter().fold(0.0_f64, |a, b| a.max(*b));
    let (n, b, k) = (
        largest(p.noise_density),
        largest(p.bias_instability),
        largest(p.random_walk),
    );
    for axis in (0..3).filter(|a| !seen[*a]) {
        p.noise_density[axis] = n;
        p.bias_instability[axis] = b;
        p.random_walk[axis] = k;
        notes.push(format!(
            "{} axis {} had no column: the largest identified axis is used",
            sensor.key(),
            ["x", "y", "z"][axis]
        ));
    }
}

/// The correlation time of a Gauss–Markov bias for a sensor whose every column has Markov
/// noise and none resolves flicker (the median of the columns' correlation times), or `None`:
/// the sensor model has one bias instability process per sensor.
fn gauss_markov_bias(columns: &[&crate::run::allan::ColumnNoise]) -> Option<f64> {
    if columns
        .iter()
        .any(|c| c.fit.term(NoiseTerm::BiasInstability).resolved)
    {
        return None;
    }
    let mut times: Vec<f64> = columns
        .iter()
        .map(|c| c.fit.scaled(ScaleTerm::Markov).map(|e| e.scale))
        .collect::<Option<_>>()?;
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).copied()
}

/// The identified part as Kalibr's `imu.yaml` at the log's rate on `topic`, each density
/// multiplied by `inflation` (Kalibr's authors advise inflating figures from a static log, for
/// the effects a static log does not show; the factor is written in the file).
///
/// # Errors
/// An inflation that is not finite and ≥ 1; no accelerometer or no gyroscope column.
pub fn kalibr(
    result: &AllanResult,
    file: &ParamFile,
    inflation: f64,
    topic: &str,
) -> Result<String> {
    if !(inflation.is_finite() && inflation >= 1.0) {
        return Err(invalid(
            "kalibr inflation",
            format!("must be a finite factor ≥ 1, got {inflation}"),
        ));
    }
    let mut imu = KalibrImu::from_params(file, result.sample_rate_hz, topic)?;
    for k in [&mut imu.accelerometer, &mut imu.gyroscope] {
        if inflation != 1.0 {
            k.noise_density *= inflation;
            k.random_walk *= inflation;
            k.notes.push(format!(
                "noise density and random walk multiplied by {inflation} (inflation for Kalibr)"
            ));
        } else {
            k.notes
                .push("figures as identified, not inflated (--kalibr-inflation to inflate)".into());
        }
    }
    Ok(imu.to_yaml())
}

/// The fusion filter's noise for the identified part (what `fuse --imu FILE` uses): per present
/// sensor, `(sensor, white √q, bias drift √q)`.
#[must_use]
pub fn filter_noise(file: &ParamFile, rate_hz: f64) -> Vec<(Sensor, f64, f64)> {
    [Sensor::Accelerometer, Sensor::Gyroscope]
        .into_iter()
        .filter(|s| file.present[Sensor::ALL.iter().position(|x| x == s).unwrap_or(0)])
        .map(|s| {
            let (white, drift) = triad_psd(file.params.get(s), rate_hz);
            (s, white, drift)
        })
        .collect()
}

/// The report printed for a column's fit.
#[must_use]
pub fn column_header(column: &str, fit: &NoiseFit, samples: usize, rate_hz: f64) -> String {
    format!(
        "{column} ({samples} samples at {rate_hz:.6} Hz, {:.3} h; reduced χ² {:.2})",
        samples as f64 / rate_hz / 3600.0,
        fit.reduced_chi2
    )
}

/// A reduced χ² above which `identify` says the noise model does not describe a curve
/// (the intervals are widened by its square root whenever it exceeds 1; see
/// `imu_core::allan::fit`).
pub const POOR_FIT_CHI2: f64 = 3.0;

/// Where a column's fitted curve misses its Allan curve: the τ ranges, s, of consecutive points
/// whose variance lies more than three of its standard deviations (`σ²·√(2/ν)`, ν the point's
/// degrees of freedom) off the fit.
#[must_use]
pub fn misfit_ranges(
    result: &AllanResult,
    column: &crate::run::allan::ColumnNoise,
) -> Vec<(f64, f64)> {
    let tau = result.table.column("tau_s").unwrap_or_default();
    let adev = result
        .table
        .column(&format!("adev_{}", column.column))
        .unwrap_or_default();
    let fit = &column.fit;
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut previous_off = false;
    for i in 0..fit.points.min(tau.len()).min(adev.len()) {
        let var = adev[i] * adev[i];
        let sigma = var * (2.0 / fit.edf[i]).sqrt();
        let off = (var - fit.variance_at(tau[i])).abs() > 3.0 * sigma;
        if off {
            match out.last_mut() {
                Some(last) if previous_off => last.1 = tau[i],
                _ => out.push((tau[i], tau[i])),
            }
        }
        previous_off = off;
    }
    out
}

/// What `identify` warns about a column: a log that moves (where), a fit that does not
/// describe the curve (its reduced χ², how the intervals were widened, the τ it misses).
#[must_use]
pub fn column_warnings(
    result: &AllanResult,
    column: &crate::run::allan::ColumnNoise,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if column.constant {
        warnings.push(format!(
            "{}: reads a constant ({:.6e}) but for rounding: there is no noise to identify (an \
             ideal sensor, or a stuck channel?)",
            column.column, column.mean
        ));
        return warnings;
    }
    if !column.moving.is_empty() {
        const SHOWN: usize = 5;
        let mut at: Vec<String> = column
            .moving
            .iter()
            .take(SHOWN)
            .map(|(a, b)| format!("{a:.0}–{b:.0} s"))
            .collect();
        if column.moving.len() > SHOWN {
            at.push(format!("… ({} more)", column.moving.len() - SHOWN));
        }
        warnings.push(format!(
            "{}: not at rest at t = {} from the start: identify needs a static log (its curve \
             and terms mix the motion with the noise; cut the log with --start-s/--end-s)",
            column.column,
            at.join(", ")
        ));
    }
    let chi2 = column.fit.reduced_chi2;
    if chi2 > POOR_FIT_CHI2 {
        let misses: Vec<String> = misfit_ranges(result, column)
            .iter()
            .map(|(a, b)| {
                if a == b {
                    format!("τ = {a} s")
                } else {
                    format!("τ = {a}–{b} s")
                }
            })
            .collect();
        warnings.push(format!(
            "{}: the noise model does not describe this curve (reduced χ² {chi2:.1}): the \
             intervals are widened by √{chi2:.1} = {:.1}{}",
            column.column,
            chi2.sqrt(),
            if misses.is_empty() {
                String::new()
            } else {
                format!("; it misses {}", misses.join(", "))
            }
        ));
    }
    warnings
}

/// The bias at rest printed for a column: its mean with the mean's one-sigma.
#[must_use]
pub fn rest_line(column: &crate::run::allan::ColumnNoise) -> String {
    let unit = si_unit(sensor_of(&column.column), NoiseTerm::BiasInstability);
    format!(
        "  mean at rest     {:>12.4e} ± {:.1e} {unit}{}",
        column.mean,
        column.mean_sigma,
        if sensor_of(&column.column) == Some(Sensor::Accelerometer) {
            " (with gravity's share)"
        } else {
            ""
        }
    )
}
