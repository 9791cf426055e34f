//! The outage-study figure: per IMU preset, the Monte Carlo RMS horizontal position error
//! through the outage (solid), the filter's own one-sigma (dashed) and, for a study run with
//! smoothing, the smoothed estimate's RMS error (dotted), log scale.
use std::path::Path;

use imukit::Table;
use plotters::prelude::*;

use crate::PlotError;
use crate::allan::log_range;
use crate::draw::{COLORS, draw_legend, err, key, tick, write_figure};

/// The suffix of a preset's smoothed-error column.
const SMOOTHED: &str = "_smoothed_rms_error_m";

/// Draws a study table (`t_s`, then per preset `<preset>_rms_error_m` and `<preset>_sigma_m`,
/// and `<preset>_smoothed_rms_error_m` with smoothing, as `imukit::study` writes it) into
/// `path` (SVG or PNG).
///
/// # Errors
/// A table without `t_s` or without a preset's pair of columns, nothing positive to draw, or
/// the figure's own failure.
pub fn study_figure(path: &Path, table: &Table) -> Result<(), PlotError> {
    let fail = |message: String| PlotError::Draw {
        path: path.display().to_string(),
        message,
    };
    let t = table
        .column("t_s")
        .ok_or_else(|| fail("the study table has no t_s column".into()))?;
    let presets: Vec<&str> = table
        .columns
        .iter()
        .filter(|c| !c.ends_with(SMOOTHED))
        .filter_map(|c| c.strip_suffix("_rms_error_m"))
        .collect();
    let mut curves = Vec::with_capacity(presets.len());
    for p in &presets {
        let error = table.column(&format!("{p}_rms_error_m"));
        let sigma = table.column(&format!("{p}_sigma_m"));
        let (Some(error), Some(sigma)) = (error, sigma) else {
            return Err(fail(format!("the study table lacks {p}_sigma_m")));
        };
        let smoothed = table.column(&format!("{p}{SMOOTHED}"));
        curves.push((*p, error, sigma, smoothed));
    }
    let positive = curves
        .iter()
        .flat_map(|(_, e, s, m)| e.iter().chain(s).chain(m.iter().flat_map(|m| m.iter())))
        .copied()
        .filter(|v| *v > 0.0 && v.is_finite());
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    let t_end = t.last().copied().unwrap_or(0.0);
    if curves.is_empty() || !lo.is_finite() || !(t_end > 0.0 && t_end.is_finite()) {
        return Err(fail(
            "nothing to plot: no preset columns, no time, or no positive error".into(),
        ));
    }
    write_figure(path, 900, 600, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Horizontal position error through the GNSS outage",
                ("sans-serif", 22),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..t_end, log_range(lo * 0.7, hi * 1.5).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time since the outage began (s)")
            .y_desc(if curves.iter().any(|c| c.3.is_some()) {
                "m (solid: RMS over runs; dashed: filter's 1σ; dotted: smoothed)"
            } else {
                "m (solid: RMS over runs; dashed: filter's 1σ)"
            })
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(err)?;
        for (k, (name, error, sigma, smoothed)) in curves.iter().enumerate() {
            let color = COLORS[k % COLORS.len()];
            let line = |v: &[f64]| -> Vec<(f64, f64)> {
                t.iter()
                    .copied()
                    .zip(v.iter().copied())
                    .filter(|(_, y)| *y > 0.0 && y.is_finite())
                    .collect()
            };
            chart
                .draw_series(LineSeries::new(line(error), color.stroke_width(2)))
                .map_err(err)?
                .label((*name).to_string())
                .legend(key(color, 0));
            chart
                .draw_series(DashedLineSeries::new(
                    line(sigma),
                    6,
                    4,
                    color.mix(0.8).stroke_width(2),
                ))
                .map_err(err)?;
            if let Some(smoothed) = smoothed {
                chart
                    .draw_series(DashedLineSeries::new(
                        line(smoothed),
                        2,
                        4,
                        color.stroke_width(2),
                    ))
                    .map_err(err)?;
            }
        }
        draw_legend(&mut chart)
    })
}
