//! The kinds of table imukit writes and reads, and which kind a table is.
//!
//! Each kind's column set is defined once, in [`crate::columns`]; [`TableKind::columns`]
//! names it, and [`TableKind::detect`] recognises a table by them, for every reader: the command
//! line, the binding and the figures.
use crate::choice::{Choice, display_as_name};
use crate::columns::{
    ACCEL_COLUMNS, BARO_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, ERROR_COLUMNS, FUSE_COLUMNS,
    GNSS_COLUMNS, GNSS_EARTH_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, NAV_COLUMNS, ODOMETER_COLUMNS,
    ORIENT_COLUMNS, ORIENTATION_ERROR_COLUMNS, PLANAR_COLUMNS, PLANAR_NAV_COLUMNS, TRUTH_COLUMNS,
};

/// A kind of table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TableKind {
    /// IMU readings: rates (`accel_*_m_s2`, `gyro_*_rad_s`, `mag_*_ut`) or increments
    /// (`dv_*_m_s`, `dtheta_*_rad`), with `t_s`.
    #[default]
    Readings,
    /// Planar readings (`t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s`).
    PlanarReadings,
    /// Truth kinematics ([`TRUTH_COLUMNS`]).
    Truth,
    /// A strapdown estimate ([`NAV_COLUMNS`]).
    Navigation,
    /// A fused estimate with its one-sigmas and bias estimates ([`FUSE_COLUMNS`]).
    Fused,
    /// A planar dead-reckoning estimate ([`PLANAR_NAV_COLUMNS`]).
    PlanarNavigation,
    /// An orientation estimate ([`ORIENT_COLUMNS`]).
    Orientation,
    /// Errors of a navigation estimate against truth ([`ERROR_COLUMNS`]).
    Errors,
    /// Errors of an orientation estimate against truth ([`ORIENTATION_ERROR_COLUMNS`]).
    OrientationErrors,
    /// Allan deviations (`tau_s, adev_<column>…`).
    Allan,
    /// GNSS fixes in the tangent plane ([`GNSS_COLUMNS`]).
    Gnss,
    /// Geodetic GNSS fixes ([`GNSS_EARTH_COLUMNS`]).
    GnssGeodetic,
    /// Barometer readings ([`BARO_COLUMNS`]).
    Baro,
    /// Odometer readings ([`ODOMETER_COLUMNS`]).
    Odometer,
    /// An outage study's curves (`t_s`, then per preset `<preset>_rms_error_m`,
    /// `<preset>_sigma_m` and with smoothing `<preset>_smoothed_rms_error_m`; `run::study`).
    Study,
}

impl Choice for TableKind {
    const WHAT: &'static str = "table kind";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("readings", Self::Readings),
        ("planar-readings", Self::PlanarReadings),
        ("truth", Self::Truth),
        ("navigation", Self::Navigation),
        ("fused", Self::Fused),
        ("planar-navigation", Self::PlanarNavigation),
        ("orientation", Self::Orientation),
        ("errors", Self::Errors),
        ("orientation-errors", Self::OrientationErrors),
        ("allan", Self::Allan),
        ("gnss", Self::Gnss),
        ("gnss-geodetic", Self::GnssGeodetic),
        ("baro", Self::Baro),
        ("odometer", Self::Odometer),
        ("study", Self::Study),
    ];
}

display_as_name!(TableKind);

/// The time column every table but the Allan table starts with.
const TIME: [&str; 1] = ["t_s"];

impl TableKind {
    /// The columns a table of this kind has at least (its writer may add more: the geodetic
    /// columns on the WGS-84 Earth, the sensor-error states, a sigma column). Readings and
    /// Allan tables name theirs by sensor and by column: `t_s` and `tau_s` alone here.
    #[must_use]
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            Self::Readings => &TIME,
            Self::PlanarReadings => &PLANAR_COLUMNS,
            Self::Truth => &TRUTH_COLUMNS,
            Self::Navigation => &NAV_COLUMNS,
            Self::Fused => &FUSE_COLUMNS,
            Self::PlanarNavigation => &PLANAR_NAV_COLUMNS,
            Self::Orientation => &ORIENT_COLUMNS,
            Self::Errors => &ERROR_COLUMNS,
            Self::OrientationErrors => &ORIENTATION_ERROR_COLUMNS,
            Self::Allan => &["tau_s"],
            Self::Gnss => &GNSS_COLUMNS,
            Self::GnssGeodetic => &GNSS_EARTH_COLUMNS,
            Self::Baro => &BARO_COLUMNS,
            Self::Odometer => &ODOMETER_COLUMNS,
            Self::Study => &TIME,
        }
    }

    /// The columns that tell this kind apart (a subset of [`Self::columns`]): what
    /// [`Self::detect`] looks for.
    #[must_use]
    fn signature(self) -> &'static [&'static str] {
        match self {
            Self::Truth => &["acc_x_m_s2", "omega_x_rad_s"],
            Self::Fused => &["pos_x_sigma_m", "q_w"],
            Self::PlanarNavigation => &["body_vel_x_m_s"],
            Self::Navigation => &["pos_x_m", "q_w"],
            Self::Errors => &["pos_err_m"],
            Self::OrientationErrors => &["att_err_rad", "yaw_err_rad"],
            Self::Orientation => &["q_w"],
            Self::Gnss => &["pos_x_m", "vel_x_m_s"],
            Self::GnssGeodetic => &["lat_rad", "vel_n_m_s"],
            Self::Baro => &["baro_height_m"],
            Self::Odometer => &["speed_m_s"],
            Self::Readings | Self::PlanarReadings | Self::Allan | Self::Study => &[],
        }
    }

    /// The kind of a table with these columns, recognised by the columns that tell the kinds
    /// apart, the most specific first (truth before an estimate, a fused estimate before a
    /// navigation estimate, planar readings when a cart's three sensors are all a 3D IMU's
    /// table has); `None` when it is none of imukit's kinds. [`Self::missing`] then says
    /// whether the table has all of the kind's columns.
    #[must_use]
    pub fn detect<S: AsRef<str>>(columns: &[S]) -> Option<Self> {
        let has = |c: &str| columns.iter().any(|h| h.as_ref() == c);
        if has("tau_s") && columns.iter().any(|c| c.as_ref().starts_with("adev_")) {
            return Some(Self::Allan);
        }
        // A study: time, and for each preset its error and the filter's one-sigma, nothing else.
        let preset_of = |c: &str| {
            c.strip_suffix("_smoothed_rms_error_m")
                .or_else(|| c.strip_suffix("_rms_error_m"))
                .or_else(|| c.strip_suffix("_sigma_m"))
                .map(str::to_owned)
        };
        let rest = columns.iter().filter(|c| c.as_ref() != "t_s");
        if has("t_s")
            && columns.len() >= 3
            && rest.clone().all(|c| preset_of(c.as_ref()).is_some())
            && rest.clone().all(|c| {
                let p = preset_of(c.as_ref()).unwrap_or_default();
                has(&format!("{p}_rms_error_m")) && has(&format!("{p}_sigma_m"))
            })
        {
            return Some(Self::Study);
        }
        let by_signature = [
            Self::Truth,
            Self::Fused,
            Self::PlanarNavigation,
            Self::Navigation,
            Self::Errors,
            Self::OrientationErrors,
            Self::Orientation,
            Self::Gnss,
            Self::GnssGeodetic,
        ];
        if let Some(kind) = by_signature
            .into_iter()
            .find(|k| k.signature().iter().all(|c| has(c)))
        {
            return Some(kind);
        }
        let sensors = [
            ACCEL_COLUMNS,
            GYRO_COLUMNS,
            MAG_COLUMNS,
            DV_COLUMNS,
            DTHETA_COLUMNS,
        ];
        let any_sensor = sensors.iter().flatten().any(|c| has(c));
        if has("t_s") && any_sensor {
            // A cart's three sensors, and none of a 3D IMU's other axes.
            let planar = PLANAR_COLUMNS.iter().all(|c| has(c))
                && !has(ACCEL_COLUMNS[2])
                && !has(GYRO_COLUMNS[0]);
            return Some(if planar {
                Self::PlanarReadings
            } else {
                Self::Readings
            });
        }
        [Self::Baro, Self::Odometer]
            .into_iter()
            .find(|k| has("t_s") && k.signature().iter().all(|c| has(c)))
    }

    /// The columns of [`Self::columns`] that `columns` lacks.
    #[must_use]
    pub fn missing<S: AsRef<str>>(self, columns: &[S]) -> Vec<&'static str> {
        self.columns()
            .iter()
            .copied()
            .filter(|c| !columns.iter().any(|h| h.as_ref() == *c))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An outage study's table is told apart by its per-preset pairs, smoothed or not.
    #[test]
    fn a_study_is_recognised_by_its_preset_pairs() {
        let study = [
            "t_s",
            "a_rms_error_m",
            "a_sigma_m",
            "b-2_rms_error_m",
            "b-2_sigma_m",
        ];
        assert_eq!(TableKind::detect(&study), Some(TableKind::Study));
        let smoothed = [
            "t_s",
            "a_rms_error_m",
            "a_sigma_m",
            "a_smoothed_rms_error_m",
        ];
        assert_eq!(TableKind::detect(&smoothed), Some(TableKind::Study));
        assert_eq!(TableKind::detect(&["t_s", "a_rms_error_m"]), None);
        assert_eq!(
            TableKind::detect(&["t_s", "a_rms_error_m", "b_sigma_m"]),
            None
        );
        let fused: Vec<&str> = FUSE_COLUMNS.to_vec();
        assert_eq!(TableKind::detect(&fused), Some(TableKind::Fused));
    }

    #[test]
    fn every_kind_is_recognised_by_its_own_columns() {
        for (name, kind) in TableKind::NAMES {
            let mut columns: Vec<&str> = kind.columns().to_vec();
            match kind {
                TableKind::Readings => columns.extend(GYRO_COLUMNS),
                TableKind::Allan => columns.push("adev_gyro_x_rad_s"),
                TableKind::Study => columns.extend(["stim300_rms_error_m", "stim300_sigma_m"]),
                _ => {}
            }
            assert_eq!(TableKind::detect(&columns), Some(*kind), "{name}");
        }
        assert_eq!(TableKind::detect(&["t_s", "a", "b"]), None);
        // A truth table that lacks a column is still truth, and says what it lacks.
        let partial: Vec<&str> = TRUTH_COLUMNS
            .iter()
            .copied()
            .filter(|c| *c != "pos_y_m")
            .collect();
        assert_eq!(TableKind::detect(&partial), Some(TableKind::Truth));
        assert_eq!(TableKind::Truth.missing(&partial), ["pos_y_m"]);
        assert!(TableKind::Truth.missing(&TRUTH_COLUMNS).is_empty());
        assert_eq!(
            TableKind::detect(&["t_s", "dv_x_m_s", "dtheta_x_rad"]),
            Some(TableKind::Readings)
        );
    }
}
