//! `imukit presets [NAME]`: list the sensor presets or print one as a parameter file or as
//! Kalibr's `imu.yaml`.
use imukit::io::kalibr::KalibrImu;
use imukit::io::presets;

use super::CliError;
use crate::cli::PresetFormat;
use crate::error::by_flag;

pub fn run(
    name: Option<&str>,
    format: PresetFormat,
    rate_hz: f64,
    topic: &str,
) -> Result<(), CliError> {
    match name {
        None => {
            for n in presets::names() {
                let info = presets::load(n)?.info;
                let grade = info.get("grade").map(String::as_str).unwrap_or("");
                let source = info.get("source").map(String::as_str).unwrap_or("");
                println!("{n:<14} {grade:<11} {source}");
            }
        }
        Some(n) => match format {
            PresetFormat::Toml => print!("{}", presets::text(n)?),
            PresetFormat::Kalibr => {
                let imu = KalibrImu::from_params(&presets::load(n)?, rate_hz, topic).map_err(
                    |e| match e {
                        imukit::Error::Invalid { ref field, .. } if field == "rate_hz" => {
                            by_flag(e)
                        }
                        other => other,
                    },
                )?;
                print!("{}", imu.to_yaml());
            }
        },
    }
    Ok(())
}
