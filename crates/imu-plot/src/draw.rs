//! Drawing shared by every figure: colours, legends, thinning long series, and writing a figure
//! as SVG or as PNG (the SVG rasterised by resvg with the embedded DejaVu Sans, so PNGs look the
//! same on every machine), atomically.
use std::path::Path;

use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::{FigureOption, PlotError};

/// The series colours (matplotlib's tab10 order).
pub const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// The stride that leaves at most `max` of `len` points.
#[must_use]
pub fn stride_for(len: usize, max: usize) -> usize {
    len.div_ceil(max.max(1)).max(1)
}

/// Every `stride`-th item and the last.
#[must_use]
pub fn every<T: Copy>(v: &[T], stride: usize) -> Vec<T> {
    let mut out: Vec<T> = v.iter().copied().step_by(stride.max(1)).collect();
    if v.len() > 1 && !(v.len() - 1).is_multiple_of(stride.max(1)) {
        out.extend(v.last().copied());
    }
    out
}

/// The dash pattern of line style `style` (0 solid, 1 dashed, 2 dotted, 3 long dashes, then
/// again): `(drawn, gap)` in pixels, `None` for a solid line. Series and legend keys share it, so
/// a key looks like its line.
#[must_use]
pub fn dashes(style: usize) -> Option<(u32, u32)> {
    match style % 4 {
        0 => None,
        1 => Some((6, 4)),
        2 => Some((2, 3)),
        _ => Some((12, 4)),
    }
}

/// Draws `points` as one line in `color` with the dash pattern of `style` ([`dashes`]) and
/// labels it `label` with a key of the same pattern (no legend entry for an empty label).
///
/// # Errors
/// The chart's drawing error, as text.
pub fn draw_line<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    points: Vec<CT::From>,
    color: RGBColor,
    style: usize,
    label: &str,
) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
    CT::From: Clone + 'static,
{
    let stroke = color.stroke_width(2);
    let drawn = match dashes(style) {
        None => chart.draw_series(LineSeries::new(points, stroke)),
        Some((on, off)) => chart.draw_series(DashedLineSeries::new(points, on, off, stroke)),
    }
    .map_err(err)?;
    if !label.is_empty() {
        drawn.label(label).legend(key(color, style));
    }
    Ok(())
}

/// A series' legend key: a short line in its colour and with its dash pattern (`style`, as
/// [`dashes`]).
pub fn key(
    color: RGBColor,
    style: usize,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, u32> {
    // A solid key is one dash as long as the key.
    let (on, off) = dashes(style).unwrap_or((LEGEND_KEY_PX.unsigned_abs(), 0));
    move |(x, y)| {
        DashedPathElement::new(
            vec![(x, y), (x + LEGEND_KEY_PX, y)],
            on,
            off,
            color.stroke_width(2),
        )
    }
}

/// Length of a legend key, pixels.
pub const LEGEND_KEY_PX: i32 = 24;

/// Draws the legend of `chart`'s labelled series in its upper right corner.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 11))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)
}

/// An axis tick's label: at most four significant digits, no trailing zeros, no `-0`; plain
/// from 0.001 to below 10⁵, else `2.5e-4`, `1e6` (not `1.0e-2` nor `-0.0`).
#[must_use]
pub fn tick(v: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    // Round to four significant digits first, so that 0.30000000000000004 reads 0.3 and a tick
    // a hair below zero reads 0.
    let rounded: f64 = format!("{v:.3e}").parse().unwrap_or(v);
    if rounded == 0.0 {
        return "0".into();
    }
    let magnitude = rounded.abs();
    if (1e-3..1e5).contains(&magnitude) {
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "a decimal exponent between -3 and 4"
        )]
        let decimals = (3 - magnitude.log10().floor() as i32).max(0) as usize;
        let text = format!("{rounded:.decimals$}");
        return if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        };
    }
    let text = format!("{rounded:.3e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    format!("{mantissa}e{exponent}")
}

/// [`tick`] on a linear axis spanning `span`: a tick within a billionth of the span of zero
/// (a sum of steps that missed zero by rounding) reads `0`.
#[must_use]
pub fn tick_on(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span.abs() {
        "0".into()
    } else {
        tick(v)
    }
}

/// A drawing error as text.
pub fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The kinds of figure file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureFormat {
    /// `.svg`.
    Svg,
    /// `.png`.
    Png,
}

/// The format a figure path asks for, by extension; checked before any work.
///
/// # Errors
/// [`PlotError::Draw`] for another extension.
pub fn check_figure_path(path: &Path) -> Result<FigureFormat, PlotError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => Ok(FigureFormat::Svg),
        Some("png") => Ok(FigureFormat::Png),
        _ => Err(PlotError::Draw {
            path: path.display().to_string(),
            message: "the figure file must end in .svg or .png".into(),
        }),
    }
}

/// A figure's size and resolution, as `--size` and `--dpi` give them. A figure is laid out at
/// [`FigureSize::LAYOUT_DPI`] pixels per inch (its fonts and lines keep their size relative to
/// the page); a PNG is rasterised at `dpi`, an SVG is resolution-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FigureSize {
    /// Width and height, inches; `None`: the figure's own size for its panels.
    pub size_in: Option<(f64, f64)>,
    /// Pixels per inch of a PNG.
    pub dpi: f64,
}

impl Default for FigureSize {
    fn default() -> Self {
        Self {
            size_in: None,
            dpi: Self::LAYOUT_DPI,
        }
    }
}

impl FigureSize {
    /// Pixels per inch of the layout (and of a PNG by default).
    pub const LAYOUT_DPI: f64 = 100.0;
    /// The smallest and largest side, inches.
    pub const SIDE_IN: (f64, f64) = (1.0, 100.0);
    /// The lowest and highest resolution, pixels per inch.
    pub const DPI: (f64, f64) = (10.0, 1200.0);
    /// The most pixels a PNG may have on a side.
    pub const MAX_SIDE_PX: f64 = 20_000.0;

    /// A size and resolution, checked: sides within [`Self::SIDE_IN`] inches, `dpi` within
    /// [`Self::DPI`], a PNG at most [`Self::MAX_SIDE_PX`] pixels on a side.
    ///
    /// # Errors
    /// [`PlotError::Invalid`] on `size` or `dpi`.
    pub fn new(size_in: Option<(f64, f64)>, dpi: Option<f64>) -> Result<Self, PlotError> {
        let invalid = |option, message: String| PlotError::Option { option, message };
        let (lo, hi) = Self::SIDE_IN;
        if let Some((w, h)) = size_in
            && !(w.is_finite() && h.is_finite() && (lo..=hi).contains(&w) && (lo..=hi).contains(&h))
        {
            return Err(invalid(
                FigureOption::Size,
                format!("{w} × {h} inches: each side must be from {lo} to {hi} inches"),
            ));
        }
        let dpi = dpi.unwrap_or(Self::LAYOUT_DPI);
        let (dlo, dhi) = Self::DPI;
        if !(dpi.is_finite() && (dlo..=dhi).contains(&dpi)) {
            return Err(invalid(
                FigureOption::Dpi,
                format!("{dpi}: the resolution must be from {dlo} to {dhi} pixels per inch"),
            ));
        }
        if let Some((w, h)) = size_in
            && w.max(h) * dpi > Self::MAX_SIDE_PX
        {
            return Err(invalid(
                FigureOption::Dpi,
                format!(
                    "{dpi} pixels per inch make a side of {:.0} pixels (at most {})",
                    w.max(h) * dpi,
                    Self::MAX_SIDE_PX
                ),
            ));
        }
        Ok(Self { size_in, dpi })
    }

    /// Draws a figure laid out at `width × height` pixels unless a size was given, and writes it
    /// to `path` as SVG or PNG (by extension), a PNG at this resolution.
    ///
    /// # Errors
    /// As [`write_figure`].
    pub fn write(
        &self,
        path: &Path,
        width: u32,
        height: u32,
        draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
    ) -> Result<(), PlotError> {
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "sides checked to lie within 1 to 100 inches"
        )]
        let (width, height) = self.size_in.map_or((width, height), |(w, h)| {
            (
                (w * Self::LAYOUT_DPI).round() as u32,
                (h * Self::LAYOUT_DPI).round() as u32,
            )
        });
        render_figure(path, width, height, self.dpi / Self::LAYOUT_DPI, draw)
    }
}

/// Draws a `width × height` figure with `draw` and writes it to `path` as SVG or PNG (by
/// extension).
///
/// # Errors
/// A drawing error or an I/O error naming the file.
pub fn write_figure(
    path: &Path,
    width: u32,
    height: u32,
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), PlotError> {
    render_figure(path, width, height, 1.0, draw)
}

fn render_figure(
    path: &Path,
    width: u32,
    height: u32,
    scale: f64,
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), PlotError> {
    let fail = |message: String| PlotError::Draw {
        path: path.display().to_string(),
        message,
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(err(e)))?;
        draw(&root).map_err(fail)?;
        root.present().map_err(|e| fail(err(e)))?;
    }
    let bytes = match check_figure_path(path)? {
        FigureFormat::Svg => svg.into_bytes(),
        FigureFormat::Png => rasterise_scaled(&svg, width, height, scale)
            .map_err(fail)?
            .encode_png()
            .map_err(|e| fail(err(e)))?,
    };
    imukit::io::output::write_atomically(path, |w| std::io::Write::write_all(w, &bytes))?;
    Ok(())
}

/// The fonts of every PNG: DejaVu Sans as the sans-serif family, loaded once.
fn fonts() -> std::sync::Arc<resvg::usvg::fontdb::Database> {
    static FONTS: std::sync::OnceLock<std::sync::Arc<resvg::usvg::fontdb::Database>> =
        std::sync::OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = resvg::usvg::fontdb::Database::new();
            db.load_font_data(dejavu::sans::regular().to_vec());
            db.set_sans_serif_family("DejaVu Sans");
            std::sync::Arc::new(db)
        })
        .clone()
}

/// Rasterises SVG text into a pixmap.
///
/// # Errors
/// SVG that does not parse, or an empty size.
pub fn rasterise(svg: &str, width: u32, height: u32) -> Result<resvg::tiny_skia::Pixmap, String> {
    rasterise_scaled(svg, width, height, 1.0)
}

/// [`rasterise`] at `scale` pixels per layout pixel.
fn rasterise_scaled(
    svg: &str,
    width: u32,
    height: u32,
    scale: f64,
) -> Result<resvg::tiny_skia::Pixmap, String> {
    let options = resvg::usvg::Options {
        fontdb: fonts(),
        ..resvg::usvg::Options::default()
    };
    let tree = resvg::usvg::Tree::from_str(svg, &options).map_err(err)?;
    #[allow(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "sizes and scales checked by FigureSize::new"
    )]
    let (w, h) = (
        (f64::from(width) * scale).round() as u32,
        (f64::from(height) * scale).round() as u32,
    );
    let mut pixmap = resvg::tiny_skia::Pixmap::new(w, h).ok_or("empty figure size")?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    #[allow(clippy::cast_possible_truncation, reason = "a scale of 0.1 to 12")]
    let s = scale as f32;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(s, s),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short_and_never_minus_zero() {
        for (v, text) in [
            (0.0, "0"),
            (-0.0, "0"),
            (-1e-17, "-1e-17"),
            (0.01, "0.01"),
            (0.30000000000000004, "0.3"),
            (-2.5, "-2.5"),
            (100.0, "100"),
            (12345.0, "12340"),
            (2.5e-4, "2.5e-4"),
            (1e6, "1e6"),
            (99999.0, "1e5"),
        ] {
            assert_eq!(tick(v), text, "{v}");
        }
        assert_eq!(tick_on(-5.551e-17, 0.6), "0");
        assert_eq!(tick_on(0.1, 0.6), "0.1");
    }

    #[test]
    fn a_legend_key_is_dashed_as_its_line() {
        assert_eq!(dashes(0), None);
        assert_eq!(dashes(1), Some((6, 4)));
        assert_eq!(dashes(2), Some((2, 3)));
        assert_eq!(dashes(5), dashes(1));
    }
}
