//! The fused table's rows: the navigation columns, the one-sigmas, the bias estimates, the
//! position on the Earth, the sensor errors when estimated, the resets so far.
use imu_core::fusion::{
    BASE_STATES, EskfState, FULL_STATES, SensorErrorEstimate, has_sensor_errors,
};

use crate::io::columns::NAV_COLUMNS;
use crate::io::table::Table;
use crate::run::nav_earth::{self, NavEarth};

/// The columns a fused estimate gains when the filter estimates the IMU's scale-factor,
/// misalignment and g-sensitivity errors ([`FuseSetup::estimate_sensor_errors`](super::FuseSetup::estimate_sensor_errors)): for the
/// accelerometer then the gyroscope, row by row, a diagonal entry of `M` as
/// `<triad>_scale_factor_<axis>` and an off-diagonal one as `<triad>_misalignment_<row><column>`
/// (fractions: the reading is `(I + M) x + b`), then the gyroscopes' g-sensitivity
/// `gyro_g_sensitivity_<axis>_rad_s_per_m_s2`, then the same names with `_sigma` for their
/// one-sigma (before the unit).
#[must_use]
pub fn sensor_error_columns() -> Vec<String> {
    let axes = ["x", "y", "z"];
    // (name, unit suffix)
    let mut names: Vec<(String, &str)> = ["accel", "gyro"]
        .iter()
        .flat_map(|triad| {
            (0..9).map(move |k| {
                let (r, c) = (k / 3, k % 3);
                if r == c {
                    (format!("{triad}_scale_factor_{}", axes[r]), "")
                } else {
                    (format!("{triad}_misalignment_{}{}", axes[r], axes[c]), "")
                }
            })
        })
        .collect();
    names.extend(axes.map(|a| (format!("gyro_g_sensitivity_{a}"), "_rad_s_per_m_s2")));
    let values = names.iter().map(|(n, u)| format!("{n}{u}"));
    let sigmas = names.iter().map(|(n, u)| format!("{n}_sigma{u}"));
    values.chain(sigmas).collect()
}

/// The column names of a fused estimate: `base` and, with the sensor matrices,
/// [`sensor_error_columns`].
pub(super) fn fused_columns(base: &[&str], sensor_errors: bool) -> Vec<String> {
    let mut columns: Vec<String> = base.iter().map(|c| (*c).to_string()).collect();
    if sensor_errors {
        columns.extend(sensor_error_columns());
    }
    columns
}

/// Appends the sensor errors' estimates and one-sigmas (`sigmas`: the 21 states in order) to
/// `row`.
fn push_sensor_errors(row: &mut Vec<f64>, estimate: &SensorErrorEstimate, sigmas: &[f64]) {
    for m in [&estimate.accel, &estimate.gyro] {
        for r in m {
            row.extend_from_slice(r);
        }
    }
    row.extend_from_slice(&estimate.gyro_g_sensitivity);
    row.extend_from_slice(sigmas);
}

/// The fused estimate's last column: the resets to the fixes so far (a step at each).
pub const RESETS_COLUMN: &str = "gnss_resets";

/// Appends one row of the fused table: the state `s` (with the sensor errors and one-sigmas
/// `sig`), in the frame of `origin`, the yaw unwrapped against the last, the resets so far.
pub(super) fn push_fused_row<E: NavEarth, const S: usize>(
    table: &mut Table,
    row: &mut Vec<f64>,
    (s, errors, sig): (&EskfState<E>, &SensorErrorEstimate, &[f64; S]),
    (origin, last_yaw): (&E::Origin, &mut Option<f64>),
    resets: usize,
) {
    let (nav_width, base) = (nav_earth::nav_width::<E>(), NAV_COLUMNS.len());
    let nav = nav_earth::nav_row(&s.nav, origin, last_yaw);
    row.clear();
    row.extend_from_slice(&nav[..base]);
    row.extend_from_slice(&sig[..9]);
    row.extend_from_slice(&s.accel_bias_m_s2);
    row.extend_from_slice(&s.gyro_bias_rad_s);
    row.extend_from_slice(&sig[9..15]);
    row.extend_from_slice(&nav[base..nav_width]);
    if has_sensor_errors(S) {
        push_sensor_errors(row, errors, &sig[BASE_STATES..FULL_STATES]);
    }
    #[allow(clippy::cast_precision_loss)]
    row.push(resets as f64);
    table.push_row(row);
}
