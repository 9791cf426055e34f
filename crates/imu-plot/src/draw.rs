//! Drawing shared by every figure: colours, legends, thinning long series, and writing a figure
//! as SVG or as PNG (the SVG rasterised by resvg with the embedded DejaVu Sans, so PNGs look the
//! same on every machine), atomically.
use std::path::Path;

use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;

use crate::PlotError;

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

/// A series' legend key: a short line in its colour.
pub fn key(color: RGBColor) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + LEGEND_KEY_PX, y)], color.stroke_width(2))
}

/// Length of a legend key, pixels.
pub const LEGEND_KEY_PX: i32 = 18;

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

/// Draws a `width × height` figure with `draw` and writes it to `path` as SVG or PNG (by
/// extension).
pub fn write_figure(
    path: &Path,
    width: u32,
    height: u32,
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
        FigureFormat::Png => rasterise(&svg, width, height)
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
pub fn rasterise(svg: &str, width: u32, height: u32) -> Result<resvg::tiny_skia::Pixmap, String> {
    let options = resvg::usvg::Options {
        fontdb: fonts(),
        ..resvg::usvg::Options::default()
    };
    let tree = resvg::usvg::Tree::from_str(svg, &options).map_err(err)?;
    let mut pixmap = resvg::tiny_skia::Pixmap::new(width, height).ok_or("empty figure size")?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}
