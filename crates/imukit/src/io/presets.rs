//! Presets of real parts: datasheet values converted to SI, with their source, as imukit
//! parameter files (`presets/*.toml` in this crate, each number commented with the datasheet
//! figure it came from). `imukit presets` lists them and `imukit presets NAME` prints one.
//!
//! Conversions follow [`crate::io::units`]: single-sided densities, standard gravity, and
//! "bias instability" quoted as an Allan minimum turned into the flicker model's
//! `B = minimum/0.664` over an assumed τ range of 1–1000 s. Where a datasheet value was not
//! transcribed, the field keeps its ideal value and the preset's `notes` say so.

use crate::error::{Error, Result, invalid};
use crate::io::params::{ParamFile, Profile, parse_param_document};

/// `(name, TOML text)` of every preset.
pub const PRESETS: [(&str, &str); 9] = [
    ("ideal", include_str!("../../presets/ideal.toml")),
    ("mpu-6050", include_str!("../../presets/mpu-6050.toml")),
    ("icm-20948", include_str!("../../presets/icm-20948.toml")),
    (
        "icm-42688-p",
        include_str!("../../presets/icm-42688-p.toml"),
    ),
    (
        "adis16465-1",
        include_str!("../../presets/adis16465-1.toml"),
    ),
    ("mti-1", include_str!("../../presets/mti-1.toml")),
    ("stim300", include_str!("../../presets/stim300.toml")),
    ("hg1700", include_str!("../../presets/hg1700.toml")),
    ("hg9900", include_str!("../../presets/hg9900.toml")),
];

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
    let doc: crate::io::params::ParamValue =
        toml::from_str(text(name)?).map_err(|e| Error::Scenario {
            origin: format!("preset {name}"),
            message: e.to_string(),
        })?;
    parse_param_document(&doc, &format!("preset {name}"), Profile::Default)
}
