//! Panels: time series, trajectories in the plane (equal scales) and in 3D, start ● and end ✕.
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::PlotError;
use crate::draw::{COLORS, draw_legend, draw_line, err, every, stride_for, tick_on, write_figure};

/// One line of a time-series panel.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour index.
    pub color: usize,
    /// Line style: 0 solid (the first file), 1 dashed, 2 dotted, 3 long dashes (later files).
    pub style: usize,
}

/// A time-series panel.
pub struct Panel {
    /// Title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
}

/// At most this many points of a line are drawn (every k-th point and the last): more cannot be
/// seen at these sizes and make the files large.
const MAX_POINTS: usize = 1500;

/// Every k-th item and the last, so at most `MAX_POINTS` remain.
fn thin<T: Copy>(v: Vec<T>) -> Vec<T> {
    every(&v, stride_for(v.len(), MAX_POINTS))
}

/// The finite points, each coordinate within ±[`AXIS_LIMIT`] (where [`range`] puts the axes,
/// so every point maps inside the drawing).
fn finite(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let clamp = |v: f64| v.clamp(-AXIS_LIMIT, AXIS_LIMIT);
    points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|&(x, y)| (clamp(x), clamp(y)))
        .collect()
}

/// Values beyond ±this are drawn at the edge: the axis's span stays a finite number.
const AXIS_LIMIT: f64 = 1e300;

/// An axis range holding `values` with a margin. The margin is at least a billionth of the
/// values' magnitude, so the tick marks' spacing is always more than the numbers' own
/// resolution (a range of a few ulps at 1e283 would leave the tick search stepping by
/// nothing).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let (lo, hi) = (
        lo.clamp(-AXIS_LIMIT, AXIS_LIMIT),
        hi.clamp(-AXIS_LIMIT, AXIS_LIMIT),
    );
    let pad = if hi > lo {
        (0.05 * (hi - lo)).max(1e-9 * lo.abs().max(hi.abs()))
    } else {
        0.5 * lo.abs().max(1e-9)
    };
    (lo - pad, hi + pad)
}

/// The offset drawn values of an axis from `lo` to `hi` are shown less: 0 unless they are a
/// hundred spans or more from zero (four significant digits would then label two ticks alike),
/// else the values rounded down to the power of ten at or above the span.
#[must_use]
pub fn axis_offset(lo: f64, hi: f64) -> f64 {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) || lo.abs().max(hi.abs()) < 100.0 * span {
        return 0.0;
    }
    let step = 10f64.powf(span.log10().ceil());
    (lo / step).floor() * step
}

/// An axis label for values drawn less `offset`: `t (s)` becomes `t − 68500 (s)`.
fn offset_label(label: &str, offset: f64) -> String {
    if offset == 0.0 {
        return label.to_string();
    }
    match label.rsplit_once(" (") {
        Some((name, unit)) => format!("{name} − {offset} ({unit}"),
        None => format!("{label} − {offset}"),
    }
}

/// Draws a time-series panel into `area`.
pub fn draw_panel(area: &DrawingArea<SVGBackend<'_>, Shift>, panel: &Panel) -> Result<(), String> {
    let all: Vec<(f64, f64)> = panel
        .series
        .iter()
        .flat_map(|s| finite(&s.points))
        .collect();
    let (x0, x1) = range(all.iter().map(|p| p.0));
    let (y0, y1) = range(all.iter().map(|p| p.1));
    // Values far from zero for their span (a log stamped from midnight or the epoch) are drawn
    // less a round offset, which the axis label names: else the ticks read 68580, 68580, ….
    let (dx, dy) = (axis_offset(x0, x1), axis_offset(y0, y1));
    let (x0, x1, y0, y1) = (x0 - dx, x1 - dx, y0 - dy, y1 - dy);
    let (x_label, y_label) = (
        offset_label(&panel.x_label, dx),
        offset_label(&panel.y_label, dy),
    );
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label.as_str())
        .y_desc(y_label.as_str())
        .label_style(("sans-serif", 11))
        .x_label_formatter(&|v| tick_on(*v, x1 - x0))
        .y_label_formatter(&|v| tick_on(*v, y1 - y0))
        .draw()
        .map_err(err)?;
    for s in &panel.series {
        let color = COLORS[s.color % COLORS.len()];
        let shifted: Vec<(f64, f64)> = s.points.iter().map(|&(x, y)| (x - dx, y - dy)).collect();
        draw_line(&mut chart, thin(finite(&shifted)), color, s.style, &s.label)?;
    }
    draw_legend(&mut chart)
}

/// One trajectory: a name and its points (x, y, z).
pub struct Trace {
    /// Legend text.
    pub name: String,
    /// Points, m.
    pub points: Vec<(f64, f64, f64)>,
}

impl Trace {
    /// The `pos_x_m`, `pos_y_m` (and `pos_z_m` if present) columns of a table; NED positions
    /// become east, north, up.
    ///
    /// # Errors
    /// [`PlotError::Invalid`] naming the table when `pos_x_m` or `pos_y_m` is missing.
    pub fn from_table(name: &str, t: &imukit::Table, ned: bool) -> Result<Self, PlotError> {
        let column = |c: &str| {
            t.column(c).ok_or_else(|| PlotError::Invalid {
                field: name.to_string(),
                message: format!(
                    "no {c} column: a trajectory needs pos_x_m and pos_y_m (pos_z_m optional)"
                ),
            })
        };
        let (x, y) = (column("pos_x_m")?, column("pos_y_m")?);
        let z = t.column("pos_z_m").unwrap_or_else(|| vec![0.0; x.len()]);
        let points = (0..x.len())
            .map(|i| {
                let [e, n, u] = crate::scene::point_enu([x[i], y[i], z[i]], ned);
                (e, n, u)
            })
            .collect();
        Ok(Self {
            name: name.to_string(),
            points,
        })
    }
}

/// Draws trajectories seen from above (X east/north…, equal scales), start ● and end ✕.
pub fn draw_plan_view(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    traces: &[Trace],
) -> Result<(), String> {
    let pts = |t: &Trace| -> Vec<(f64, f64)> {
        thin(finite(
            &t.points.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(),
        ))
    };
    let all: Vec<(f64, f64)> = traces.iter().flat_map(pts).collect();
    let (x0, x1) = range(all.iter().map(|p| p.0));
    let (y0, y1) = range(all.iter().map(|p| p.1));
    let (w, h) = area.dim_in_pixel();
    let aspect = f64::from(w.max(1)) / f64::from(h.max(1));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let half_y = (0.5 * (y1 - y0)).max(0.5 * (x1 - x0) / aspect).max(1e-9);
    let half_x = half_y * aspect;
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(56)
        .build_cartesian_2d(cx - half_x..cx + half_x, cy - half_y..cy + half_y)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style(("sans-serif", 11))
        .x_label_formatter(&|v| tick_on(*v, 2.0 * half_x))
        .y_label_formatter(&|v| tick_on(*v, 2.0 * half_y))
        .draw()
        .map_err(err)?;
    for (k, t) in traces.iter().enumerate() {
        // The second trace (an estimate over the truth) dashed, the third dotted, as in the panels.
        let color = COLORS[k % COLORS.len()];
        let p = pts(t);
        draw_line(&mut chart, p.clone(), color, k, &t.name)?;
        if let (Some(first), Some(last)) = (p.first(), p.last()) {
            chart
                .draw_series([Circle::new(*first, 6, color.filled())])
                .map_err(err)?;
            chart
                .draw_series([Cross::new(*last, 7, color.stroke_width(3))])
                .map_err(err)?;
        }
    }
    draw_legend(&mut chart)?;
    area.draw(&Text::new("● start   ✕ end", (8, 6), ("sans-serif", 12)))
        .map_err(err)
}

/// Draws trajectories in 3D (isometric view), start ● and end ✕.
pub fn draw_3d(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    traces: &[Trace],
) -> Result<(), String> {
    let all: Vec<(f64, f64, f64)> = traces
        .iter()
        .flat_map(|t| t.points.iter().copied())
        .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
        .collect();
    let (x0, x1) = range(all.iter().map(|p| p.0));
    let (y0, y1) = range(all.iter().map(|p| p.1));
    let (z0, z1) = range(all.iter().map(|p| p.2));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(8)
        .build_cartesian_3d(x0..x1, z0..z1, y0..y1)
        .map_err(err)?;
    chart.with_projection(|mut p| {
        p.pitch = 0.5;
        p.yaw = 0.6;
        p.scale = 0.8;
        p.into_matrix()
    });
    let (sx, sy, sz) = (x1 - x0, y1 - y0, z1 - z0);
    chart
        .configure_axes()
        .label_style(("sans-serif", 10))
        .x_formatter(&|v| tick_on(*v, sx))
        .y_formatter(&|v| tick_on(*v, sz))
        .z_formatter(&|v| tick_on(*v, sy))
        .draw()
        .map_err(err)?;
    for (k, t) in traces.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let p: Vec<(f64, f64, f64)> = thin(
            t.points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
                .map(|p| (p.0, p.2, p.1))
                .collect(),
        );
        draw_line(&mut chart, p.clone(), color, k, &t.name)?;
        if let (Some(first), Some(last)) = (p.first(), p.last()) {
            chart
                .draw_series([Circle::new(*first, 6, color.filled())])
                .map_err(err)?;
            chart
                .draw_series([Cross::new(*last, 7, color.stroke_width(3))])
                .map_err(err)?;
        }
    }
    draw_legend(&mut chart)?;
    area.draw(&Text::new(
        "● start   ✕ end   (z up the page)",
        (8, 6),
        ("sans-serif", 12),
    ))
    .map_err(err)
}

/// True when the traces leave the plane noticeably (z range above 1 % of the horizontal range).
#[must_use]
pub fn is_3d(traces: &[Trace]) -> bool {
    let all: Vec<[f64; 3]> = traces
        .iter()
        .flat_map(|t| t.points.iter().map(|p| [p.0, p.1, p.2]))
        .collect();
    crate::spec::leaves_plane(&all)
}

/// A figure of trajectories in the plane, start and end marked (the exercise's figure).
pub fn trajectories_figure(path: &Path, title: &str, traces: &[Trace]) -> Result<(), PlotError> {
    write_figure(path, 900, 640, |root| draw_plan_view(root, title, traces))
}

#[cfg(test)]
mod tests {

    #[test]
    fn an_axis_far_from_zero_is_drawn_less_a_round_offset() {
        // Midnight-stamped seconds: over 6.6 s less a multiple of 10, over 16.6 s of 100.
        assert_eq!(axis_offset(68_579.2, 68_585.8), 68_570.0);
        assert_eq!(axis_offset(68_579.2, 68_595.8), 68_500.0);
        // Epoch seconds over 100 s, and a span of an hour.
        assert_eq!(axis_offset(1.7e9 + 12.0, 1.7e9 + 90.0), 1.7e9);
        assert_eq!(axis_offset(1.7e9 + 12.0, 1.7e9 + 3600.0), 1.7e9);
        // Near zero, or far from it for its span but under a hundred spans: no offset.
        assert_eq!(axis_offset(0.0, 60.0), 0.0);
        assert_eq!(axis_offset(-5.0, 5.0), 0.0);
        assert_eq!(axis_offset(900.0, 1000.0), 0.0);
        assert_eq!(axis_offset(3.0, 3.0), 0.0);
        assert_eq!(offset_label("t (s)", 68_570.0), "t − 68570 (s)");
        assert_eq!(offset_label("x", 100.0), "x − 100");
        assert_eq!(offset_label("t (s)", 0.0), "t (s)");
    }

    use super::*;

    #[test]
    fn axis_ranges_of_extreme_values_are_finite_and_wider_than_their_resolution() {
        let (lo, hi) = range([-1.4e308, 8e283, 3.0].into_iter());
        assert!(
            lo.is_finite() && hi.is_finite() && lo < -1e300 && hi > 8e283,
            "{lo} {hi}"
        );
        // Two values an ulp apart at 1e283: the margin is a billionth of their size.
        let x = 1e283_f64;
        let (lo, hi) = range([x, f64::from_bits(x.to_bits() + 1)].into_iter());
        assert!((hi - lo) / x > 1.9e-9, "{lo} {hi}");
        // A constant keeps half its size either side, as before.
        assert_eq!(range([9.8, 9.8].into_iter()), (4.9, 14.700000000000001));
    }

    #[test]
    fn a_panel_of_extreme_values_is_drawn() {
        let mut svg = String::new();
        let panel = Panel {
            title: "t".into(),
            x_label: "t (s)".into(),
            y_label: "y".into(),
            series: vec![Series {
                label: "a".into(),
                points: vec![
                    (0.0, -1.45e308),
                    (8e283, 1e283),
                    (-1.7e259, 2e300),
                    (1.0, 1e283),
                ],
                color: 0,
                style: 0,
            }],
        };
        {
            let area = SVGBackend::with_string(&mut svg, (400, 300)).into_drawing_area();
            draw_panel(&area, &panel).unwrap();
        }
        assert!(svg.contains("<svg"));
    }
}
