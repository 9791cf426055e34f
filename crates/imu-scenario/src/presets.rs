//! Presets of real parts: datasheet values converted to SI, with their source, as imukit
//! parameter files (`presets/*.toml` in this crate). `imukit presets` lists them and
//! `imukit presets NAME` prints one.
use serde_json::Value;

use crate::error::{Error, Result, invalid};
use crate::params::{ParamFile, Profile, parse_param_document};

/// `(name, TOML text)` of every preset.
pub const PRESETS: [(&str, &str); 1] = [("ideal", include_str!("../presets/ideal.toml"))];

/// Names of the presets.
#[must_use]
pub fn names() -> Vec<&'static str> {
    PRESETS.iter().map(|(n, _)| *n).collect()
}

/// The TOML text of preset `name` (case-insensitive).
///
/// # Errors
/// Unknown preset, with the known names.
pub fn text(name: &str) -> Result<&'static str> {
    PRESETS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            invalid(
                "imu.preset",
                format!("unknown preset \"{name}\" (known: {})", names().join(", ")),
            )
        })
}

/// The parameters of preset `name`.
///
/// # Errors
/// Unknown preset.
pub fn load(name: &str) -> Result<ParamFile> {
    let doc: Value = toml::from_str(text(name)?).map_err(|e| Error::Scenario {
        origin: format!("preset {name}"),
        message: e.to_string(),
    })?;
    parse_param_document(&doc, &format!("preset {name}"), Profile::Default)
}
