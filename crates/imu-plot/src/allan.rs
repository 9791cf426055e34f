//! The Allan-deviation figure: log-log curves with the fitted −½, 0 and +½ lines dashed.
use std::path::Path;

use imukit::run::allan::AllanResult;
use plotters::prelude::*;

use crate::PlotError;
use crate::draw::{COLORS, draw_legend, err, key, write_figure};

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

/// Draws `result` (one curve per column) into `path` (SVG or PNG).
pub fn allan_figure(path: &Path, result: &AllanResult) -> Result<(), PlotError> {
    let table = &result.table;
    let tau = table.column("tau_s").unwrap_or_default();
    let curves: Vec<(String, Vec<f64>)> = table
        .columns
        .iter()
        .skip(1)
        .map(|c| {
            (
                c.trim_start_matches("adev_").to_string(),
                table.column(c).unwrap_or_default(),
            )
        })
        .collect();
    let positive = curves
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| *v > 0.0);
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    if tau.is_empty() || !lo.is_finite() {
        return Err(PlotError::Draw {
            path: path.display().to_string(),
            message: "nothing to plot: the Allan deviation is empty or zero".into(),
        });
    }
    write_figure(path, 900, 600, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption("Allan deviation", ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(
                log_range(tau[0] * 0.8, tau[tau.len() - 1] * 1.25).log_scale(),
                log_range(lo * 0.5, hi * 2.0).log_scale(),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("τ (s)")
            .y_desc("σ(τ) (unit of the column)")
            .y_label_formatter(&|v| format!("{v:.1e}"))
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(err)?;
        for (k, ((name, adev), (_, id))) in curves.iter().zip(&result.noise).enumerate() {
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
                .legend(key(color));
            chart
                .draw_series(points.iter().map(|p| Circle::new(*p, 3, color.filled())))
                .map_err(err)?;
            for line in [id.white_line, id.bias_line, id.random_walk_line]
                .into_iter()
                .flatten()
            {
                let ends = [tau[0], tau[tau.len() - 1]].map(|t| (t, line.at(t)));
                chart
                    .draw_series(DashedLineSeries::new(
                        ends,
                        6,
                        4,
                        color.mix(0.6).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
        }
        draw_legend(&mut chart)
    })
}
