//! Datasheet units → imukit's SI parameters.
//!
//! Conventions: `g` is standard gravity 9.80665 m/s²; noise densities and random walks are
//! **single-sided** (the datasheet / IEEE-952 convention, imukit's default `noise_type`):
//! an angle random walk of A °/√h is a rate noise density of A·(π/180)/60 rad/s/√Hz. Datasheets
//! quote "bias instability" as the minimum of the Allan deviation; IEEE 952's B, which imukit's
//! `bias_instability` with the flicker model takes, is that minimum / 0.664
//! ([`datasheet_bias_instability`]).
use crate::error::{Result, invalid};

/// Standard gravity, m/s².
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// What a datasheet quantity converts to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Converted {
    /// The value in SI.
    pub value: f64,
    /// The SI unit.
    pub unit: &'static str,
    /// The imukit parameters it fits.
    pub fits: &'static str,
}

const DEG: f64 = std::f64::consts::PI / 180.0;

/// `(accepted spellings, factor to SI, SI unit, fitting parameters)`.
const UNITS: &[(&[&str], f64, &str, &str)] = &[
    (
        &[
            "deg/s/rt-hz",
            "°/s/√hz",
            "dps/√hz",
            "dps/rt-hz",
            "deg/s/sqrt(hz)",
        ],
        DEG,
        "rad/s/√Hz",
        "gyroscope noise_density",
    ),
    (
        &["mdps/√hz", "mdps/rt-hz"],
        DEG * 1e-3,
        "rad/s/√Hz",
        "gyroscope noise_density",
    ),
    (
        &["deg/rt-h", "°/√h", "deg/sqrt(h)", "deg/rt-hr", "°/√hr"],
        DEG / 60.0,
        "rad/s/√Hz",
        "gyroscope noise_density (angle random walk)",
    ),
    (
        &["deg/h", "°/h", "deg/hr", "°/hr"],
        DEG / 3600.0,
        "rad/s",
        "gyroscope constant_bias, bias_instability",
    ),
    (
        &["deg/s", "°/s", "dps"],
        DEG,
        "rad/s",
        "gyroscope measurement_range, constant_bias, resolution",
    ),
    (
        &["deg/h/rt-h", "°/h/√h", "deg/h/sqrt(h)"],
        DEG / 3600.0 / 60.0,
        "rad/s·√Hz",
        "gyroscope random_walk",
    ),
    (
        &["deg/s/g", "°/s/g", "dps/g"],
        DEG / STANDARD_GRAVITY,
        "(rad/s)/(m/s²)",
        "gyroscope acceleration_bias",
    ),
    (
        &["deg/h/g", "°/h/g"],
        DEG / 3600.0 / STANDARD_GRAVITY,
        "(rad/s)/(m/s²)",
        "gyroscope acceleration_bias",
    ),
    (
        &["ug/rt-hz", "µg/√hz", "ug/√hz", "ug/sqrt(hz)"],
        STANDARD_GRAVITY * 1e-6,
        "m/s²/√Hz",
        "accelerometer noise_density",
    ),
    (
        &["m/s/rt-h", "m/s/√h", "m/s/sqrt(h)", "m/s/rt-hr"],
        1.0 / 60.0,
        "m/s²/√Hz",
        "accelerometer noise_density (velocity random walk)",
    ),
    (
        &["fps/rt-h", "ft/s/√h", "fps/√hr"],
        0.3048 / 60.0,
        "m/s²/√Hz",
        "accelerometer noise_density (velocity random walk)",
    ),
    (
        &["m/s/h/√h", "m/s/h/rt-h", "m/s/h/sqrt(h)"],
        1.0 / 3600.0 / 60.0,
        "m/s²·√Hz",
        "accelerometer random_walk",
    ),
    (
        &["g"],
        STANDARD_GRAVITY,
        "m/s²",
        "accelerometer measurement_range, constant_bias",
    ),
    (
        &["mg"],
        STANDARD_GRAVITY * 1e-3,
        "m/s²",
        "accelerometer constant_bias, bias_instability",
    ),
    (
        &["ug", "µg"],
        STANDARD_GRAVITY * 1e-6,
        "m/s²",
        "accelerometer constant_bias, bias_instability",
    ),
    (
        &["mg/°c", "mg/degc", "mg/c"],
        STANDARD_GRAVITY * 1e-3,
        "m/s²/°C",
        "accelerometer temperature_bias",
    ),
    (
        &["°/s/°c", "dps/°c", "deg/s/degc"],
        DEG,
        "rad/s/°C",
        "gyroscope temperature_bias",
    ),
    (
        &["ut", "µt"],
        1.0,
        "µT",
        "magnetometer measurement_range, constant_bias, resolution",
    ),
    (
        &["gauss", "g_s"],
        100.0,
        "µT",
        "magnetometer measurement_range, constant_bias",
    ),
    (
        &["m/s^2", "m/s2", "m/s²", "m s^-2"],
        1.0,
        "m/s²",
        "accelerometer readings",
    ),
    (&["rad/s", "rad s^-1"], 1.0, "rad/s", "gyroscope readings"),
    (
        &["mdps", "mdeg/s"],
        DEG * 1e-3,
        "rad/s",
        "gyroscope readings",
    ),
    (&["mrad/s"], 1e-3, "rad/s", "gyroscope readings"),
    (&["nt"], 1e-3, "µT", "magnetometer readings"),
    (
        &["mg", "mgauss", "milligauss"],
        0.1,
        "µT",
        "magnetometer readings (milligauss)",
    ),
    (&["g"], 100.0, "µT", "magnetometer readings (gauss)"),
    (
        &["ppm"],
        1e-4,
        "% (add to the diagonal of axes_misalignment_pct)",
        "axes_misalignment_pct scale-factor error",
    ),
    (
        &["mrad"],
        0.1,
        "% (off-diagonal of axes_misalignment_pct)",
        "axes_misalignment_pct cross-axis",
    ),
    (
        &["%/°c", "%/degc"],
        1.0,
        "%/°C",
        "temperature_scale_factor_pct",
    ),
];

/// Converts `value` in a datasheet `unit` (case-insensitive; `√`, `rt-` and `sqrt()` spellings).
///
/// # Errors
/// Unknown units, with the accepted ones listed.
pub fn convert(value: f64, unit: &str) -> Result<Converted> {
    let key = unit.trim().to_lowercase().replace(' ', "");
    UNITS
        .iter()
        .find(|(names, ..)| names.iter().any(|n| *n == key))
        .map(|(_, factor, si, fits)| Converted {
            value: value * factor,
            unit: si,
            fits,
        })
        .ok_or_else(|| {
            let known: Vec<&str> = UNITS.iter().map(|(n, ..)| n[0]).collect();
            invalid(
                "unit",
                format!("unknown unit \"{unit}\" (known: {})", known.join(", ")),
            )
        })
}

/// The factor that takes readings in `unit` to the SI unit `si` (`"m/s²"`, `"rad/s"`, `"µT"`):
/// the unit is looked up among those of that quantity, so `mG` for a magnetometer is
/// milligauss and `mg` for an accelerometer milli-g (case-insensitive).
///
/// # Errors
/// An unknown unit, or one of another quantity, with the units of `si` listed.
pub fn factor_to(unit: &str, si: &str) -> std::result::Result<f64, String> {
    let key = unit.trim().to_lowercase().replace(' ', "");
    let key = key.as_str();
    let of_si = || {
        UNITS
            .iter()
            .filter(|(_, _, u, _)| *u == si)
            .flat_map(|(names, ..)| names.iter().copied())
            .collect::<Vec<_>>()
            .join(", ")
    };
    UNITS
        .iter()
        .find(|(names, _, u, _)| *u == si && names.contains(&key))
        .map(|(_, factor, ..)| *factor)
        .ok_or_else(|| format!("\"{unit}\" is not a unit of {si} (known: {})", of_si()))
}

/// IEEE 952's bias-instability coefficient B from a datasheet's bias instability quoted as the
/// Allan-deviation minimum: `B = minimum / 0.664`, so a flicker model with this B reproduces the
/// datasheet's floor.
#[must_use]
pub fn datasheet_bias_instability(allan_minimum: f64) -> f64 {
    allan_minimum / imu_core::allan::BIAS_INSTABILITY_FACTOR
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn common_datasheet_units_convert_to_si() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(
            convert(0.15, "°/√h").unwrap().value,
            0.15 * DEG / 60.0
        ));
        assert!(close(
            convert(0.005, "deg/s/rt-Hz").unwrap().value,
            8.726_646_259_971_648e-5
        ));
        assert!(close(convert(400.0, "µg/√Hz").unwrap().value, 3.922_66e-3));
        assert!(close(
            convert(2.0, "deg/h").unwrap().value,
            9.696_273_622_190_722e-6
        ));
        assert!(close(convert(0.06, "m/s/rt-h").unwrap().value, 1e-3));
        assert!(close(convert(50.0, "mg").unwrap().value, 0.490_332_5));
        assert!(close(convert(300.0, "ppm").unwrap().value, 0.03));
        assert_eq!(convert(1.0, "deg/s").unwrap().unit, "rad/s");
        let e = convert(1.0, "furlong/fortnight").unwrap_err().to_string();
        assert!(
            e.contains("unknown unit") && e.contains("°/√h") || e.contains("deg/rt-h"),
            "{e}"
        );
        assert!(close(
            datasheet_bias_instability((2.0 * 2f64.ln() / std::f64::consts::PI).sqrt()),
            1.0
        ));
    }
}
