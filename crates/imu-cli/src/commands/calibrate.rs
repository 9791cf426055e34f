//! `imukit calibrate LOG --out CAL.toml`.
use std::path::Path;

use imukit::calibrate::{calibrate_log, summary};
use imukit::io::Input;
use imukit::io::output::{check_outputs, write_atomically};
use imukit::io::rows::TimeWindow;

use super::CliError;

pub fn run(
    source: &Input,
    gravity_m_s2: f64,
    window: TimeWindow,
    out: &Path,
    plot: Option<(&Path, imu_plot::FigureSize)>,
) -> Result<(), CliError> {
    let mut outputs = vec![("--out", out)];
    if let Some((p, _)) = plot {
        imu_plot::check_figure_path(p)?;
        outputs.push(("--plot", p));
    }
    check_outputs(&[("input", source.path())], &outputs)?;
    crate::report::warn_implausible(source);
    let result = calibrate_log(source, gravity_m_s2, window)?;
    let text = result.to_toml();
    write_atomically(out, |w| std::io::Write::write_all(w, text.as_bytes()))?;
    if let Some((p, size)) = plot {
        let name = super::allan::file_name(source.path());
        imu_plot::calibration_figure(p, &result.residuals, &name, size)?;
    }
    for line in summary(&result) {
        match line.strip_prefix("warning: ") {
            Some(w) => crate::report::warn(w),
            None => crate::out_line!("{line}"),
        }
    }
    crate::note!("imukit: calibration written to {}", out.display());
    if let Some((p, _)) = plot {
        crate::note!("imukit: figure written to {}", p.display());
    }
    Ok(())
}
