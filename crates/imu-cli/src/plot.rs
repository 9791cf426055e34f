//! Figures written by the CLI (plotters, SVG backend).
use std::path::Path;

use imu_scenario::analysis::AllanResult;
use plotters::prelude::*;

use crate::commands::CliError;

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Allan deviation on log-log axes, one curve per column, with the fitted −½, 0 and +½ lines
/// dashed; written to `path` (SVG) through a temporary file.
pub fn allan_svg(path: &Path, result: &AllanResult) -> Result<(), CliError> {
    let io = |e: String| CliError::Plot {
        path: path.display().to_string(),
        message: e,
    };
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
        return Err(io(
            "nothing to plot: the Allan deviation is empty or zero".into()
        ));
    }
    let tmp = path.with_extension("svg.imukit-partial");
    {
        let root = SVGBackend::new(&tmp, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| io(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption("Allan deviation", ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(
                (tau[0] * 0.8..tau[tau.len() - 1] * 1.25).log_scale(),
                (lo * 0.5..hi * 2.0).log_scale(),
            )
            .map_err(|e| io(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("τ (s)")
            .y_desc("σ(τ) (unit of the column)")
            .y_label_formatter(&|v| format!("{v:.1e}"))
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| io(e.to_string()))?;
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
                .map_err(|e| io(e.to_string()))?
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|p| Circle::new(*p, 3, color.filled())))
                .map_err(|e| io(e.to_string()))?;
            for line in [id.white_line, id.bias_line, id.random_walk_line]
                .into_iter()
                .flatten()
            {
                let ends = [tau[0], tau[tau.len() - 1]].map(|t| (t, line.at(t)));
                let dashed = DashedLineSeries::new(ends, 6, 4, color.mix(0.6).stroke_width(1));
                chart.draw_series(dashed).map_err(|e| io(e.to_string()))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| io(e.to_string()))?;
        root.present().map_err(|e| io(e.to_string()))?;
    }
    std::fs::rename(&tmp, path).map_err(|e| io(e.to_string()))
}

/// One trajectory to draw: a name and its X, Y points.
pub struct Trace {
    /// Legend text.
    pub name: String,
    /// Points (X, Y), m.
    pub points: Vec<(f64, f64)>,
}

impl Trace {
    /// The `pos_x_m`, `pos_y_m` columns of a table.
    #[must_use]
    pub fn from_table(name: &str, t: &imu_scenario::Table) -> Self {
        let (x, y) = (
            t.column("pos_x_m").unwrap_or_default(),
            t.column("pos_y_m").unwrap_or_default(),
        );
        Self {
            name: name.to_string(),
            points: x.into_iter().zip(y).collect(),
        }
    }
}

/// Trajectories in the plane with equal axis scales, start (circle) and end (cross) marked.
pub fn trajectories_svg(path: &Path, title: &str, traces: &[Trace]) -> Result<(), CliError> {
    let io = |e: String| CliError::Plot {
        path: path.display().to_string(),
        message: e,
    };
    let all = traces
        .iter()
        .flat_map(|t| t.points.iter().copied())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !x0.is_finite() {
        return Err(io("no finite points to plot".into()));
    }
    // Equal scales: pad the shorter side.
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let half = 0.55 * (x1 - x0).max((y1 - y0) * 1.5).max(1e-6);
    let (xr, yr) = (cx - half..cx + half, cy - half / 1.5..cy + half / 1.5);
    let tmp = path.with_extension("svg.imukit-partial");
    {
        let root = SVGBackend::new(&tmp, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| io(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(xr, yr)
            .map_err(|e| io(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("X (m)")
            .y_desc("Y (m)")
            .draw()
            .map_err(|e| io(e.to_string()))?;
        for (k, t) in traces.iter().enumerate() {
            let color = COLORS[k % COLORS.len()];
            let pts: Vec<(f64, f64)> = t
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(|e| io(e.to_string()))?
                .label(t.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            if let (Some(first), Some(last)) = (pts.first(), pts.last()) {
                chart
                    .draw_series([Circle::new(*first, 6, color.filled())])
                    .map_err(|e| io(e.to_string()))?;
                chart
                    .draw_series([Cross::new(*last, 7, color.stroke_width(3))])
                    .map_err(|e| io(e.to_string()))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| io(e.to_string()))?;
        root.draw(&Text::new("● start   ✕ end", (20, 580), ("sans-serif", 14)))
            .map_err(|e| io(e.to_string()))?;
        root.present().map_err(|e| io(e.to_string()))?;
    }
    std::fs::rename(&tmp, path).map_err(|e| io(e.to_string()))
}
