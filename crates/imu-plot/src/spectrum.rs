//! A readings' spectrum (`imukit spectrum --plot`): each column's power spectral density on a
//! log scale against frequency up to the readings' Nyquist frequency, and for a simulated log
//! (`--scenario`) where its vibration lands — each sine's alias marked — with, below, the
//! part's chain: its gain over the internal band, the vibration's frequencies and the multiples
//! of the output rate (every band between two of them folds onto the readings' band).
use std::path::Path;

use imukit::Table;
use imukit::spectrum::Overlay;
use plotters::prelude::*;

use crate::PlotError;
use crate::allan::log_range;
use crate::draw::{COLORS, FigureSize, draw_legend, err, key, tick};

/// Draws the density table `psd` (`frequency_hz`, `psd_<column>`) of `source` into `path`,
/// with `overlay` when given.
///
/// # Errors
/// A table without `frequency_hz` or densities, nothing positive to draw, the figure's own
/// failure.
pub fn spectrum_figure(
    path: &Path,
    psd: &Table,
    source: &str,
    overlay: Option<&Overlay>,
    size: FigureSize,
) -> Result<(), PlotError> {
    let fail = |message: &str| PlotError::Draw {
        path: path.display().to_string(),
        message: message.into(),
    };
    let f = psd
        .column("frequency_hz")
        .ok_or_else(|| fail("the table has no frequency_hz column"))?;
    let curves: Vec<(String, Vec<f64>)> = psd
        .columns
        .iter()
        .filter_map(|c| {
            c.strip_prefix("psd_")
                .map(|n| (n.to_string(), psd.column(c).unwrap_or_default()))
        })
        .collect();
    let positive = curves
        .iter()
        .flat_map(|(_, p)| p.iter().copied())
        .filter(|v| *v > 0.0);
    let (lo, hi) = positive.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    if curves.is_empty() || !lo.is_finite() || f.len() < 2 {
        return Err(fail("nothing to plot: no positive density"));
    }
    // Twelve decades below the highest: an ideal sensor's empty bins (rounding, 1e-30) would
    // squeeze the rest into a corner.
    let lo = lo.max(hi * 1e-12);
    let response = overlay.filter(|o| !o.response.is_empty());
    let rows = 1 + usize::from(response.is_some());
    let top = f[f.len() - 1];
    let title = format!("Power spectral density — {source}");
    let height = 60 + 420 * u32::try_from(rows).unwrap_or(1);
    size.write(path, 900, height, |root| {
        let root = root.titled(&title, ("sans-serif", 20)).map_err(err)?;
        let areas = root.split_evenly((rows, 1));
        let mut chart = ChartBuilder::on(&areas[0])
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..top, log_range(lo * 0.5, hi * 2.0).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("f (Hz)")
            .y_desc("PSD (unit²/Hz)")
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(err)?;
        for (k, (name, p)) in curves.iter().enumerate() {
            let color = COLORS[k % COLORS.len()];
            let points: Vec<(f64, f64)> = f
                .iter()
                .copied()
                .zip(p.iter().copied())
                .filter(|(_, v)| *v > 0.0)
                .collect();
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(1)))
                .map_err(err)?
                .label(name.clone())
                .legend(key(color, 0));
        }
        if let Some(o) = overlay {
            for (input, alias) in &o.aliases {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(*alias, lo * 0.5), (*alias, hi * 2.0)],
                        6,
                        4,
                        BLACK.mix(0.6).stroke_width(1),
                    ))
                    .map_err(err)?
                    .label(format!("{} Hz → alias {} Hz", tick(*input), tick(*alias)))
                    .legend(key(BLACK, 1));
            }
        }
        draw_legend(&mut chart)?;
        if let (Some(o), Some(area)) = (response, areas.get(1)) {
            let band = o.response[o.response.len() - 1].0;
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(0.0..band, 0.0..1.1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("f (Hz), the part's internal band")
                .y_desc("chain gain |H|")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(LineSeries::new(
                    o.response.clone(),
                    COLORS[0].stroke_width(2),
                ))
                .map_err(err)?
                .label("the chain's gain")
                .legend(key(COLORS[0], 0));
            let mut fold = o.rate_hz;
            while fold < band {
                chart
                    .draw_series(LineSeries::new(
                        vec![(fold, 0.0), (fold, 1.1)],
                        BLACK.mix(0.15),
                    ))
                    .map_err(err)?;
                fold += o.rate_hz;
            }
            for (input, _) in &o.aliases {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(*input, 0.0), (*input, 1.1)],
                        6,
                        4,
                        BLACK.mix(0.6).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
            draw_legend(&mut chart)?;
        }
        Ok(())
    })
}
