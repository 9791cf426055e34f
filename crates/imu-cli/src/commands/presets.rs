//! `imukit presets [NAME]`: list the sensor presets or print one as a parameter file.
use imukit::io::presets;

use super::CliError;

pub fn run(name: Option<&str>) -> Result<(), CliError> {
    match name {
        None => {
            for n in presets::names() {
                let info = presets::load(n)?.info;
                let grade = info.get("grade").map(String::as_str).unwrap_or("");
                let source = info.get("source").map(String::as_str).unwrap_or("");
                println!("{n:<14} {grade:<11} {source}");
            }
        }
        Some(n) => print!("{}", presets::text(n)?),
    }
    Ok(())
}
