//! A calibration's residuals (`imukit calibrate --plot`): per rest, gravity's magnitude less
//! the accelerometer's mean reading; per rotation, the angle by which the integrated rate
//! misses the next rest's gravity; per magnetometer reading, its distance from the fitted
//! sphere — calibrated, with the RMS of each, calibrated and raw, in the panel's title (the raw
//! residual is orders of magnitude larger: on one axis it would flatten the calibrated one).
use std::path::Path;

use imukit::calibrate::Residuals;

use crate::PlotError;
use crate::draw::{FigureSize, err};
use crate::panels::{Panel, Series, draw_panel};

/// A panel of one calibrated residual against time, titled with its RMS and the raw one's;
/// `None` when it has no points.
fn panel(
    title: &str,
    unit: &str,
    t: &[f64],
    raw: &[f64],
    calibrated: &[f64],
    scale: f64,
) -> Option<Panel> {
    let rms =
        |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt() * scale;
    (!t.is_empty()).then(|| Panel {
        title: format!(
            "{title}: RMS {:.3e} {unit} (raw {:.3e})",
            rms(calibrated),
            rms(raw)
        ),
        x_label: "t (s)".into(),
        y_label: unit.into(),
        series: vec![Series {
            label: "calibrated".into(),
            points: t
                .iter()
                .zip(calibrated)
                .map(|(x, y)| (*x, y * scale))
                .collect(),
            color: 0,
            style: 0,
        }],
    })
}

/// Draws the residuals `r` of the calibration of `source` into `path` (SVG or PNG).
///
/// # Errors
/// Nothing to draw, or the figure's own failure.
pub fn calibration_figure(
    path: &Path,
    r: &Residuals,
    source: &str,
    size: FigureSize,
) -> Result<(), PlotError> {
    let panels: Vec<Panel> = [
        panel(
            "Accelerometer at the rests, |a| − g",
            "m/s²",
            &r.rest_t_s,
            &r.accel_raw_m_s2,
            &r.accel_m_s2,
            1.0,
        ),
        panel(
            "Gyroscope over the turns, gravity missed by",
            "°",
            &r.rotation_t_s,
            &r.gyro_raw_rad,
            &r.gyro_rad,
            180.0 / std::f64::consts::PI,
        ),
        panel(
            "Magnetometer, distance from the sphere",
            "%",
            &r.mag_t_s,
            &r.mag_raw,
            &r.mag,
            100.0,
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    if panels.is_empty() {
        return Err(PlotError::Draw {
            path: path.display().to_string(),
            message: "nothing to plot: the calibration has no residuals".into(),
        });
    }
    let rows = u32::try_from(panels.len()).unwrap_or(1);
    let title = format!("Calibration residuals — {source}");
    size.write(path, 900, 40 + 300 * rows, |root| {
        let root = root.titled(&title, ("sans-serif", 18)).map_err(err)?;
        for (p, area) in panels
            .iter()
            .zip(root.split_evenly((panels.len(), 1)).iter())
        {
            draw_panel(area, p)?;
        }
        Ok(())
    })
}
