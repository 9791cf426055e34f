//! NMEA 0183 logs (`.nmea`) read as GNSS fixes: `GGA` for the position, `RMC` or `VTG` for the
//! ground velocity, each sentence's checksum checked (the `nmea` crate parses them).
//!
//! One fix per epoch (a `GGA` and the `RMC` of the same time, a `VTG` after them): `t_s`,
//! `lat_rad`, `lon_rad`, `height_m` — the ellipsoidal height, `GGA`'s altitude above the geoid
//! plus its geoid separation — and, when every fix has a speed and a course, `vel_n_m_s` and
//! `vel_e_m_s` (NMEA gives no vertical speed: the filter takes such fixes' velocity as
//! horizontal only; without velocities the fixes are positions only and it updates on those),
//! and `hdop` when every `GGA` gives it ([`with_uere`] turns it into each fix's horizontal
//! accuracy), and `horizontal_accuracy_m` and `vertical_accuracy_m` when every fix has a `GST`
//! (its latitude and longitude deviations' root mean square, its altitude deviation).
//! Epochs without a fix (`GGA` quality 0) are left out; an `RMC` marked void gives no velocity.
//!
//! `t_s` is the UTC time of day counted from the midnight before the first fix (the rule of
//! [`crate::asl`]), a day added each time the clock passes midnight. Other sentences
//! (`GSV`, `GSA`, a vendor's) are skipped; text before a sentence's `$` on its line (a logger's
//! own stamp) is ignored. A bad checksum, or a `GGA`, `RMC`, `VTG` or `GST` that does not parse,
//! is refused naming the file and its line.
//!
//! Reading a log needs the `nmea` feature (on by default); a build without it refuses one by
//! name. [`with_uere`] works on any table of fixes with an `hdop` column.
#[cfg(feature = "nmea")]
mod read;

#[cfg(feature = "nmea")]
pub use read::read_table;

use crate::error::Result;
use crate::table::Table;

/// Refuses the log: this build reads no NMEA (its `nmea` feature is off).
///
/// # Errors
/// Always.
#[cfg(not(feature = "nmea"))]
pub fn read_table(path: &std::path::Path) -> Result<Table> {
    Err(crate::error::invalid(
        path.display().to_string(),
        "an NMEA log: this build of imu-io reads no NMEA (its `nmea` feature is off)",
    ))
}

/// The column of `GGA`'s horizontal dilution of precision.
pub const HDOP_COLUMN: &str = "hdop";

/// `fixes` with a `horizontal_accuracy_m` column of their `hdop` times the user-equivalent
/// range error `uere_m` (one-sigma, m): the horizontal accuracy a receiver's geometry gives.
///
/// # Errors
/// A `uere_m` that is not positive and finite; fixes without `hdop`.
pub fn with_uere(fixes: &Table, uere_m: f64) -> Result<Table> {
    if !(uere_m.is_finite() && uere_m > 0.0) {
        return Err(crate::error::refused(
            crate::error::RequestOption::GnssUere,
            format!("must be a positive number of metres, got {uere_m}"),
        ));
    }
    let Some(hdop) = fixes.column(HDOP_COLUMN) else {
        return Err(crate::error::refused(
            crate::error::RequestOption::GnssUere,
            "the fixes have no hdop column (an NMEA log's GGA gives it) to scale",
        ));
    };
    let name = crate::columns::FIX_ACCURACY_COLUMNS[0];
    let mut columns: Vec<&str> = fixes
        .columns
        .iter()
        .map(String::as_str)
        .filter(|c| *c != name)
        .collect();
    columns.push(name);
    let mut out = Table::new(&columns);
    let index: Vec<usize> = columns[..columns.len() - 1]
        .iter()
        .filter_map(|c| fixes.columns.iter().position(|h| h == c))
        .collect();
    let width = fixes.columns.len().max(1);
    let mut row = Vec::with_capacity(columns.len());
    for (r, h) in fixes.data.chunks_exact(width).zip(hdop) {
        row.clear();
        row.extend(index.iter().map(|&k| r[k]));
        row.push(h * uere_m);
        out.push_row(&row);
    }
    Ok(out)
}
