//! `imukit presets [NAME]`: list the sensor presets or print one (or a parameter file, with
//! `--params`) as a parameter file or as Kalibr's `imu.yaml`.
use std::path::Path;

use imukit::io::kalibr::KalibrImu;
use imukit::io::params::Profile;
use imukit::io::part_file::{ParamFile, read_param_file, to_toml};
use imukit::io::presets;

use super::CliError;
use crate::cli::PresetFormat;

pub fn run(
    name: Option<&str>,
    format: PresetFormat,
    rate_hz: f64,
    topic: &str,
) -> Result<(), CliError> {
    match name {
        None => {
            for n in presets::names() {
                let file = presets::load(n)?;
                let grade = file.info.get("grade").map(String::as_str).unwrap_or("");
                let source = file.info.get("source").map(String::as_str).unwrap_or("");
                crate::out_line!("{n:<14} {grade:<11} {source}");
                let missing = file
                    .datasheet
                    .map(|d| d.missing_error_terms())
                    .unwrap_or_default();
                if !missing.is_empty() {
                    crate::out_line!("{:<26} not given: {missing}", "");
                }
                if let Some(c) = &file.chain {
                    let settings: Vec<&str> = c.settings.keys().map(String::as_str).collect();
                    crate::out_line!(
                        "{:<26} chain: {} {} ([imu.chain] setting = …)",
                        "",
                        c.register,
                        settings.join(", ")
                    );
                }
            }
        }
        Some(n) => match format {
            PresetFormat::Toml => crate::out!("{}", presets::text(n)?),
            PresetFormat::Kalibr => kalibr(&presets::load(n)?, rate_hz, topic)?,
        },
    }
    Ok(())
}

/// `imukit presets --params FILE`: a parameter file as imukit's TOML or Kalibr's file.
pub fn file(
    path: &Path,
    part: Option<&str>,
    format: PresetFormat,
    rate_hz: f64,
    topic: &str,
) -> Result<(), CliError> {
    let params = read_param_file(path, part, Profile::Default)?;
    for warning in &params.warnings {
        crate::err_line!("imukit: warning: {warning}");
    }
    match format {
        PresetFormat::Toml => crate::out!("{}", to_toml(&params)),
        PresetFormat::Kalibr => kalibr(&params, rate_hz, topic)?,
    }
    Ok(())
}

fn kalibr(params: &ParamFile, rate_hz: f64, topic: &str) -> Result<(), CliError> {
    let imu = KalibrImu::from_params(params, rate_hz, topic)?;
    crate::out!("{}", imu.to_yaml());
    Ok(())
}
