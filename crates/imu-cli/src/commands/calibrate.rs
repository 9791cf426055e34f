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
) -> Result<(), CliError> {
    check_outputs(&[("input", source.path())], &[("--out", out)])?;
    crate::report::warn_implausible(source);
    let result = calibrate_log(source, gravity_m_s2, window)?;
    let text = result.to_toml();
    write_atomically(out, |w| std::io::Write::write_all(w, text.as_bytes()))?;
    for line in summary(&result) {
        match line.strip_prefix("warning: ") {
            Some(w) => crate::report::warn(w),
            None => crate::out_line!("{line}"),
        }
    }
    crate::note!("imukit: calibration written to {}", out.display());
    Ok(())
}
