//! The conventions a file or a request names: the navigation frame, the accelerometer's sign,
//! the Earth model and its gravity. Files state them in their description
//! ([`crate::description`]), scenarios and jobs take them by these names.
use imu_core::AccelSign;
use serde::{Deserialize, Serialize};

use crate::choice::{Choice, display_as_name};

/// The navigation frame, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum NavFrameName {
    /// East-North-Up (default).
    #[default]
    #[serde(alias = "enu")]
    ENU,
    /// North-East-Down.
    #[serde(alias = "ned")]
    NED,
}

impl Choice for NavFrameName {
    const WHAT: &'static str = "navigation frame";
    const NAMES: &'static [(&'static str, Self)] = &[("ENU", Self::ENU), ("NED", Self::NED)];
}

/// Accelerometer sign convention, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelSignName {
    /// Specific force (default).
    #[default]
    SpecificForce,
    /// MATLAB imuSensor's gravity-minus-acceleration.
    Matlab,
}

impl Choice for AccelSignName {
    const WHAT: &'static str = "accelerometer sign";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("specific-force", Self::SpecificForce),
        ("matlab", Self::Matlab),
    ];
}

impl From<AccelSignName> for AccelSign {
    fn from(s: AccelSignName) -> Self {
        match s {
            AccelSignName::SpecificForce => Self::SpecificForce,
            AccelSignName::Matlab => Self::Matlab,
        }
    }
}

/// The Earth model of a scenario.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EarthName {
    /// Flat, non-rotating, constant gravity (the default).
    #[default]
    Flat,
    /// The rotating WGS-84 ellipsoid with normal gravity.
    Wgs84,
}

impl Choice for EarthName {
    const WHAT: &'static str = "Earth model";
    const NAMES: &'static [(&'static str, Self)] = &[("flat", Self::Flat), ("wgs84", Self::Wgs84)];
}

/// Gravity on the WGS-84 Earth by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EarthGravityName {
    /// WGS-84 normal gravity at the position (the default).
    #[default]
    Normal,
    /// A constant magnitude (the request's `gravity_m_s2`) along the local vertical.
    Constant,
}

impl Choice for EarthGravityName {
    const WHAT: &'static str = "gravity model";
    const NAMES: &'static [(&'static str, Self)] =
        &[("normal", Self::Normal), ("constant", Self::Constant)];
}

display_as_name!(NavFrameName, AccelSignName, EarthName, EarthGravityName);

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<T: Choice>() {
        for (name, choice) in T::NAMES {
            assert_eq!(T::parse("f", name).unwrap(), *choice);
            assert_eq!(T::parse("f", &name.to_ascii_uppercase()).unwrap(), *choice);
            assert_eq!(choice.name(), *name);
        }
        assert!(T::NAMES.iter().any(|(_, c)| *c == T::default()));
    }

    #[test]
    fn names_round_trip_and_refusals_list_them() {
        round_trip::<NavFrameName>();
        round_trip::<AccelSignName>();
        round_trip::<EarthName>();
        let e = NavFrameName::parse("nav_frame", "ECEF").unwrap_err();
        assert_eq!(e.location().field.as_deref(), Some("nav_frame"));
        assert_eq!(
            e.to_string(),
            "nav_frame: unknown navigation frame \"ECEF\" (ENU, NED)"
        );
    }
}
