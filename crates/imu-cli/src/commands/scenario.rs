//! `imukit scenario [NAME]`: list built-ins or print one as TOML.
use imukit::scenario::builtin;

use super::CliError;

pub fn run(name: Option<&str>) -> Result<(), CliError> {
    match name {
        None => {
            for n in builtin::NAMES {
                crate::out_line!("{n}");
            }
        }
        Some(n) => crate::out!("{}", builtin::toml(n)?),
    }
    Ok(())
}
