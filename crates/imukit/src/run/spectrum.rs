//! `imukit spectrum`: the power spectral density of readings by Welch's method — segments of
//! `segment_s`, half overlapping, each less its mean and under a periodic Hann window, their
//! periodograms averaged; one-sided, so `∫₀^{fs/2} S df` is the variance (Parseval) — and,
//! for a simulated log, where its scenario's vibration lands: each sine's alias in the
//! readings, and the chain's response that let it through ([`Overlay`]).
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use crate::Scenario;
use crate::error::{Result, invalid};
use crate::io::Input;
use crate::io::read::{read_header, read_table_columns};
use crate::io::rows::TimeWindow;
use crate::io::table::Table;
use crate::scenario::vibration::VibrationKind;

/// Length of a segment unless given, s.
pub const DEFAULT_SEGMENT_S: f64 = 4.0;

/// The one-sided power spectral density of `x` sampled at `rate_hz`, over segments of
/// `segment` samples: `(frequencies, density)`, `segment/2 + 1` of each, density in the unit of
/// `x` squared per Hz.
///
/// # Errors
/// A segment under 8 samples or longer than `x`, a rate that is not finite and positive, a
/// value that is not finite.
pub fn welch(x: &[f64], rate_hz: f64, segment: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(invalid("rate_hz", format!("{rate_hz} is not a rate")));
    }
    if segment < 8 || segment > x.len() {
        return Err(invalid(
            "segment_s",
            format!(
                "a segment of {segment} samples: it needs at least 8, and no more than the {} \
                 samples read",
                x.len()
            ),
        ));
    }
    if let Some(k) = x.iter().position(|v| !v.is_finite()) {
        return Err(invalid("readings", format!("sample {k} is not finite")));
    }
    let fft = FftPlanner::<f64>::new().plan_fft_forward(segment);
    let window: Vec<f64> = (0..segment)
        .map(|n| {
            let s = (std::f64::consts::PI * n as f64 / segment as f64).sin();
            s * s
        })
        .collect();
    let power: f64 = window.iter().map(|w| w * w).sum();
    let bins = segment / 2 + 1;
    let mut density = vec![0.0; bins];
    let mut buffer = vec![Complex::new(0.0, 0.0); segment];
    let step = (segment / 2).max(1);
    let mut segments = 0usize;
    let mut start = 0;
    while start + segment <= x.len() {
        let part = &x[start..start + segment];
        let mean = part.iter().sum::<f64>() / segment as f64;
        for ((b, v), w) in buffer.iter_mut().zip(part).zip(&window) {
            *b = Complex::new((v - mean) * w, 0.0);
        }
        fft.process(&mut buffer);
        for (k, d) in density.iter_mut().enumerate() {
            // One-sided: every bin but DC and (for an even segment) Nyquist counts twice.
            let twice = k != 0 && !(segment.is_multiple_of(2) && k == segment / 2);
            let scale = if twice { 2.0 } else { 1.0 };
            *d += scale * buffer[k].norm_sqr() / (rate_hz * power);
        }
        segments += 1;
        start += step;
    }
    let n = segments as f64;
    Ok((
        (0..bins)
            .map(|k| k as f64 * rate_hz / segment as f64)
            .collect(),
        density.into_iter().map(|d| d / n).collect(),
    ))
}

/// The density of each of `columns` of `table` (with `t_s`), over segments of `segment_s`:
/// `frequency_hz`, then `psd_<column>`. The rate is the table's mean (`(n − 1)/(t_last −
/// t_first)`); the samples are taken as evenly spaced.
///
/// # Errors
/// A missing column, times that do not give a rate, and as [`welch`]; each naming `source`.
pub fn spectrum_table(
    table: &Table,
    columns: &[String],
    segment_s: f64,
    source: &str,
) -> Result<Table> {
    let t = table
        .column("t_s")
        .ok_or_else(|| invalid(source, "has no t_s column"))?;
    let span = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
    let rate = (t.len().saturating_sub(1)) as f64 / span;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(invalid(source, "its times do not give a sample rate"));
    }
    if !(segment_s.is_finite() && segment_s > 0.0) {
        return Err(crate::error::refused(
            crate::error::RequestOption::SegmentS,
            format!("{segment_s} is not a length of time (s, > 0)"),
        ));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let segment = ((segment_s * rate).round() as usize).min(t.len());
    let mut names = vec!["frequency_hz".to_string()];
    let mut curves = Vec::new();
    for c in columns {
        let x = table
            .column(c)
            .ok_or_else(|| invalid(source, format!("has no column {c}")))?;
        let (f, p) = welch(&x, rate, segment).map_err(|e| match e {
            crate::Error::Invalid { field, message } => invalid(
                format!("{source}, column {c}"),
                format!("{field}: {message}"),
            ),
            other => other,
        })?;
        if curves.is_empty() {
            curves.push(f);
        }
        names.push(format!("psd_{c}"));
        curves.push(p);
    }
    let names_ref: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut out = Table::new(&names_ref);
    for k in 0..curves.first().map_or(0, Vec::len) {
        let row: Vec<f64> = curves.iter().map(|c| c[k]).collect();
        out.push_row(&row);
    }
    Ok(out)
}

/// The density of a log's `columns` (none: every gyroscope and accelerometer column) over
/// `window` ([`spectrum_table`]).
///
/// # Errors
/// As [`spectrum_table`], and a file that cannot be read.
pub fn spectrum_of_log(
    source: &Input,
    columns: &[String],
    window: TimeWindow,
    segment_s: f64,
) -> Result<Table> {
    let file = source.path().display().to_string();
    let chosen: Vec<String> = if columns.is_empty() {
        let header = read_header(source)?;
        crate::io::columns::GYRO_COLUMNS
            .iter()
            .chain(&crate::io::columns::ACCEL_COLUMNS)
            .filter(|c| header.iter().any(|h| h == *c))
            .map(|c| (*c).to_string())
            .collect()
    } else {
        columns.to_vec()
    };
    if chosen.is_empty() {
        return Err(invalid(
            file.as_str(),
            "no gyro_* or accel_* columns: name columns with --column",
        ));
    }
    let mut names = vec!["t_s"];
    names.extend(chosen.iter().map(String::as_str));
    let table = read_table_columns(source, &names, "")?;
    let t0 = TimeWindow::first_time(&table, &file)?;
    let table = window.apply(table, t0, &file, 8)?;
    spectrum_table(&table, &chosen, segment_s, &file)
}

/// Where a scenario's vibration lands in one column's spectrum: each sine of that sensor and
/// axis with the frequency it appears at in the readings, and the chain's gain over the
/// internal band (none without a chain).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overlay {
    /// `(frequency, alias)` of each sine, Hz.
    pub aliases: Vec<(f64, f64)>,
    /// `(frequency, gain)` of the sensor's chain from 0 to half the internal rate.
    pub response: Vec<(f64, f64)>,
    /// The readings' rate, Hz.
    pub rate_hz: f64,
}

/// The [`Overlay`] of `scenario`'s vibration for the readings' column `column`
/// (`gyro_z_rad_s`, `accel_x_m_s2`, …); `None` for a column of no sensor's or a scenario
/// without vibration or chain.
///
/// # Errors
/// The chain's refusal.
pub fn overlay(scenario: &Scenario, column: &str) -> Result<Option<Overlay>> {
    let (sensor, kind) = match column.split('_').next() {
        Some("accel") => (0, Some(VibrationKind::Acceleration)),
        Some("gyro") => (1, Some(VibrationKind::AngularRate)),
        Some("mag") => (2, None),
        _ => return Ok(None),
    };
    let axis = column.split('_').nth(1).unwrap_or("");
    let imu = &scenario.imu;
    let rate = scenario.sample_rate_hz;
    if imu.chain.is_none() && imu.vibration.is_none() {
        return Ok(None);
    }
    let chain = match &imu.chain {
        Some(c) => Some(c.chains(rate)?[sensor].clone()),
        None => None,
    };
    let alias = |f: f64| {
        chain
            .as_ref()
            .map_or_else(|| (f - rate * (f / rate).round()).abs(), |c| c.alias_hz(f))
    };
    let aliases = imu
        .vibration
        .iter()
        .flat_map(|v| &v.sines)
        .filter(|s| Some(s.kind) == kind && axis_name(s.axis) == axis)
        .map(|s| (s.frequency_hz, alias(s.frequency_hz)))
        .collect();
    let response = chain.as_ref().map_or_else(Vec::new, |c| {
        let top = c.internal_rate_hz() / 2.0;
        (0..=400)
            .map(|k| {
                let f = top * f64::from(k) / 400.0;
                (f, c.response(f).gain)
            })
            .collect()
    });
    Ok(Some(Overlay {
        aliases,
        response,
        rate_hz: rate,
    }))
}

/// The axis as the readings' columns name it.
fn axis_name(a: crate::scenario::vibration::Axis) -> &'static str {
    use crate::scenario::vibration::Axis;
    match a {
        Axis::X => "x",
        Axis::Y => "y",
        Axis::Z => "z",
    }
}
