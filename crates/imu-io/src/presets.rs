//! Presets of real parts: datasheet values converted to SI, with their source, as imukit
//! parameter files (`presets/*.toml` in this crate, each number commented with the datasheet
//! figure it came from). `imukit presets` lists them and `imukit presets NAME` prints one.
//!
//! Conversions follow [`crate::units`]: single-sided densities, standard gravity, and
//! "bias instability" quoted as an Allan minimum turned into the flicker model's
//! `B = minimum/0.664` over an assumed τ range of 1–1000 s. Where a datasheet value was not
//! transcribed, the field keeps its ideal value and the preset's `notes` say so.

use crate::error::{Error, Result, invalid};
use crate::params::Profile;
use crate::part_file::{ParamFile, parse_param_document};

/// `(name, TOML text)` of every preset.
pub const PRESETS: [(&str, &str); 9] = [
    ("ideal", include_str!("../presets/ideal.toml")),
    ("mpu-6050", include_str!("../presets/mpu-6050.toml")),
    ("icm-20948", include_str!("../presets/icm-20948.toml")),
    ("icm-42688-p", include_str!("../presets/icm-42688-p.toml")),
    ("adis16465-1", include_str!("../presets/adis16465-1.toml")),
    ("mti-1", include_str!("../presets/mti-1.toml")),
    ("stim300", include_str!("../presets/stim300.toml")),
    ("hg1700", include_str!("../presets/hg1700.toml")),
    ("hg9900", include_str!("../presets/hg9900.toml")),
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
    let doc: crate::params::ParamValue =
        toml::from_str(text(name)?).map_err(|e| Error::Scenario {
            origin: format!("preset {name}"),
            message: e.to_string(),
        })?;
    parse_param_document(&doc, &format!("preset {name}"), Profile::Default)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::datasheet::Entry;

    /// Preset `name`'s parameters are its data sheet's statistics: every term of each sensor it
    /// describes has a figure with its line (converted by the rule of its statistic to the value
    /// the preset sets) or is marked not given and left ideal.
    fn figures_are_the_data_sheets(name: &str) {
        let file = load(name).unwrap();
        let sheet = file.datasheet.as_ref().expect("a [datasheet] table");
        let problems = sheet.check(&file.params, file.present);
        assert!(problems.is_empty(), "{name}: {problems:#?}");
        for entry in sheet.entries.values() {
            if let Entry::Given(f) = entry {
                assert!(
                    !f.line.trim().is_empty(),
                    "{name}: a figure without its line"
                );
            }
        }
    }

    #[test]
    fn mpu_6050_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("mpu-6050");
    }

    #[test]
    fn icm_20948_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("icm-20948");
    }

    #[test]
    fn icm_42688_p_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("icm-42688-p");
    }

    #[test]
    fn adis16465_1_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("adis16465-1");
    }

    #[test]
    fn mti_1_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("mti-1");
    }

    #[test]
    fn stim300_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("stim300");
    }

    #[test]
    fn hg1700_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("hg1700");
    }

    #[test]
    fn hg9900_figures_are_its_data_sheets() {
        figures_are_the_data_sheets("hg9900");
    }

    #[test]
    fn every_part_has_figures_and_the_ideal_part_none() {
        for n in names() {
            let file = load(n).unwrap();
            assert_eq!(file.datasheet.is_some(), n != "ideal", "{n}");
        }
    }

    /// A part file written back ([`crate::part_file::to_toml`]) keeps its chain settings, and a
    /// setting that names a setting is refused by its key.
    #[test]
    fn chain_settings_survive_a_round_trip_and_nest_no_further() {
        let part = load("mpu-6050").unwrap();
        let written = crate::part_file::to_toml(&part);
        let doc: crate::params::ParamValue = toml::from_str(&written).unwrap();
        let back = parse_param_document(&doc, "written", Profile::Default).unwrap();
        assert_eq!(back.chain, part.chain);
        assert_eq!(back.chain.unwrap().settings.len(), 7);
        let nested = text("mpu-6050")
            .unwrap()
            .replace("delay_s = 0.0186 }", "delay_s = 0.0186 }\nsetting = 5");
        let doc: crate::params::ParamValue = toml::from_str(&nested).unwrap();
        let e = parse_param_document(&doc, "nested", Profile::Default)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("nested: chain.settings.6.setting"), "{e}");
        let typo = text("mpu-6050")
            .unwrap()
            .replace("register = ", "regster = ");
        let doc: crate::params::ParamValue = toml::from_str(&typo).unwrap();
        let e = parse_param_document(&doc, "typo", Profile::Default)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("typo: chain") && e.contains("regster"), "{e}");
    }

    /// The check is not vacuous: the STIM300's bias range, put back as its turn-on bias, is
    /// refused as a bound.
    #[test]
    fn a_range_in_place_of_a_one_sigma_bias_is_caught() {
        let text = text("stim300").unwrap().replace(
            "constant_bias = { quoted = 0.5, unit = \"°/h\", statistic = \"1-sigma\"",
            "constant_bias = { quoted = 250, unit = \"°/h\", statistic = \"range\"",
        );
        let doc: crate::params::ParamValue = toml::from_str(&text).unwrap();
        // Refused when the file is read, naming the data sheet and the bound.
        let e = parse_param_document(&doc, "test", Profile::Default)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("test: datasheet") && e.contains("a bound, not a 1σ statistic"),
            "{e}"
        );
        assert_eq!(e.matches("a bound").count(), 1, "{e}");
    }
}
