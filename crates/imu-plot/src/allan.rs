//! The Allan-deviation figure: log-log curves with their 95 % bands and the fitted noise terms'
//! sum dashed.
use std::path::Path;

use imukit::allan::{AllanResult, ColumnNoise};
use plotters::prelude::*;

use crate::PlotError;
use crate::draw::{COLORS, FigureSize, draw_legend, err, key, tick};

/// Most decades a log axis spans: plotters counts an axis's decades through `hi / lo`, which
/// must stay finite (beyond about 308 decades it is infinite and the tick loop never ends).
pub const MAX_LOG_AXIS_DECADES: i32 = 300;

/// A log axis from `lo` to `hi` kept within the positive normal numbers and within
/// [`MAX_LOG_AXIS_DECADES`] below `hi` (values further down are cut off at the axis).
pub(crate) fn log_range(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let hi = hi.clamp(f64::MIN_POSITIVE, f64::MAX);
    let lo = lo
        .clamp(f64::MIN_POSITIVE, f64::MAX)
        .max(hi / 10f64.powi(MAX_LOG_AXIS_DECADES));
    if hi > lo { lo..hi } else { lo..lo * 10.0 }
}

/// The unit of an Allan column (`adev_gyro_x_rad_s` → `rad/s`), for the axis it is drawn on.
fn unit_of(column: &str) -> &'static str {
    // An overlay's label names its file after the column: `adev_gyro_x_rad_s (imu)`.
    let column = column.split(" (").next().unwrap_or(column);
    if column.ends_with("_rad_s") {
        "rad/s"
    } else if column.ends_with("_m_s2") {
        "m/s²"
    } else if column.ends_with("_ut") {
        "µT"
    } else if column.ends_with("_rad") {
        "rad"
    } else if column.ends_with("_m_s") {
        "m/s"
    } else {
        "unit of the column"
    }
}

/// Draws `result` (one curve per column) into `path` (SVG or PNG) at `size`: one panel per
/// unit (the gyroscopes' rad/s apart from the accelerometers' m/s²), each curve's 95 % band and
/// fitted terms drawn where `result` has them,
/// titled with `source` (the data's file).
///
/// # Errors
/// Nothing positive to draw, or the figure's own failure.
pub fn allan_figure(
    path: &Path,
    result: &AllanResult,
    source: &str,
    size: FigureSize,
) -> Result<(), PlotError> {
    let table = &result.table;
    let tau = table.column("tau_s").unwrap_or_default();
    let curves: Vec<(String, &'static str, Vec<f64>)> = table
        .columns
        .iter()
        .skip(1)
        .map(|c| {
            (
                c.trim_start_matches("adev_").to_string(),
                unit_of(c),
                table.column(c).unwrap_or_default(),
            )
        })
        .collect();
    let positive = curves
        .iter()
        .flat_map(|(_, _, v)| v.iter().copied())
        .filter(|v| *v > 0.0);
    let (lo, _) = positive.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    if tau.is_empty() || !lo.is_finite() {
        return Err(PlotError::Draw {
            path: path.display().to_string(),
            message: "nothing to plot: the Allan deviation is empty or zero".into(),
        });
    }
    let mut units: Vec<&'static str> = Vec::new();
    for (_, unit, _) in &curves {
        if !units.contains(unit) {
            units.push(unit);
        }
    }
    let rows = u32::try_from(units.len()).unwrap_or(1).max(1);
    let title = format!("Allan deviation — {source}");
    size.write(path, 900, 120 + 480 * rows, |root| {
        let root = root.titled(&title, ("sans-serif", 22)).map_err(err)?;
        let areas = root.split_evenly((units.len().max(1), 1));
        for (unit, area) in units.iter().zip(&areas) {
            let members: Vec<usize> = (0..curves.len())
                .filter(|&k| curves[k].1 == *unit)
                .collect();
            let values = members
                .iter()
                .flat_map(|&k| curves[k].2.iter().copied())
                .filter(|v| *v > 0.0);
            let (lo, hi) = values.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
            if !lo.is_finite() {
                continue;
            }
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(
                    log_range(tau[0] * 0.8, tau[tau.len() - 1] * 1.25).log_scale(),
                    log_range(lo * 0.5, hi * 2.0).log_scale(),
                )
                .map_err(err)?;
            let y_desc = format!("σ(τ) ({unit})");
            chart
                .configure_mesh()
                .x_desc("τ (s)")
                .y_desc(y_desc.as_str())
                .y_label_formatter(&|v| tick(*v))
                .x_label_formatter(&|v| tick(*v))
                .draw()
                .map_err(err)?;
            for &k in &members {
                let (name, _, adev) = &curves[k];
                let color = COLORS[k % COLORS.len()];
                let points: Vec<(f64, f64)> = tau
                    .iter()
                    .copied()
                    .zip(adev.iter().copied())
                    .filter(|(_, a)| *a > 0.0)
                    .collect();
                chart
                    .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                    .map_err(err)?
                    .label(name.clone())
                    .legend(key(color, 0));
                chart
                    .draw_series(points.iter().map(|p| Circle::new(*p, 3, color.filled())))
                    .map_err(err)?;
                if let Some(noise) = result.noise.get(k) {
                    draw_band_and_fit(&mut chart, &tau, noise, color)?;
                }
            }
            draw_legend(&mut chart)?;
        }
        Ok(())
    })
}

/// Draws a deviation's 95 % band, thin, and its fitted terms' sum, dashed, in `color`.
fn draw_band_and_fit<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>,
    tau: &[f64],
    noise: &ColumnNoise,
    color: RGBColor,
) -> Result<(), String> {
    for edge in [&noise.lower, &noise.upper] {
        let points: Vec<(f64, f64)> = tau
            .iter()
            .copied()
            .zip(edge.iter().copied())
            .filter(|(_, a)| *a > 0.0)
            .collect();
        chart
            .draw_series(LineSeries::new(points, color.mix(0.35).stroke_width(1)))
            .map_err(err)?;
    }
    let (t0, t1) = (tau[0], tau[tau.len() - 1]);
    let fitted: Vec<(f64, f64)> = (0..=64)
        .map(|i| {
            let t = t0 * (t1 / t0).powf(f64::from(i) / 64.0);
            (t, noise.fit.variance_at(t).sqrt())
        })
        .filter(|(_, a)| *a > 0.0)
        .collect();
    chart
        .draw_series(DashedLineSeries::new(
            fitted,
            6,
            4,
            color.mix(0.8).stroke_width(1),
        ))
        .map_err(err)?;
    Ok(())
}
