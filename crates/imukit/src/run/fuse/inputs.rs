//! What a fusion reads, checked: the IMU's times and rates, the fixes' stamps, positions,
//! velocities and own accuracies, and the fixes in the filter's terms.
use imu_core::Vec3;

use crate::error::Data;
use crate::error::{Result, invalid};
use crate::io::columns::{
    ACCEL_COLUMNS, FIX_ACCURACY_COLUMNS, FIX_SIGMA_COLUMNS, GNSS_COLUMNS, GNSS_EARTH_COLUMNS,
    GYRO_COLUMNS,
};
use crate::io::table::Table;
use crate::run::nav_earth::NavEarth;

/// GNSS stamps: finite, increasing, inside the IMU's span `[t0, t1]` (the row named), and not
/// more frequent on average than the IMU's `samples` (fixes are applied at IMU samples).
fn check_fix_times(g_t: &[f64], (t0, t1): (f64, f64), samples: usize) -> Result<()> {
    for (k, &tk) in g_t.iter().enumerate() {
        if !tk.is_finite() || (k > 0 && tk <= g_t[k - 1]) {
            return Err(invalid(
                Data::Gnss,
                format!("row {}: times must be finite and increase", k + 2),
            ));
        }
        if tk < t0 || tk > t1 {
            return Err(invalid(
                Data::Gnss,
                format!(
                    "row {}: time {tk} s is outside the IMU's span [{t0}, {t1}] s",
                    k + 2
                ),
            ));
        }
    }
    if let (Some(&first), Some(&last)) = (g_t.first(), g_t.last())
        && g_t.len() > 1
        && samples > 1
    {
        let (fix_dt, imu_dt) = (
            (last - first) / (g_t.len() - 1) as f64,
            (t1 - t0) / (samples - 1) as f64,
        );
        if fix_dt < imu_dt {
            return Err(invalid(
                Data::Gnss,
                format!(
                    "fixes come every {fix_dt} s, more often than the IMU's samples (every \
                     {imu_dt} s): the filter applies fixes at IMU samples, so the IMU must be the \
                     faster sensor"
                ),
            ));
        }
    }
    Ok(())
}

/// What a fusion reads: IMU times and rates (the frame's body convention, as in the table),
/// GNSS stamps, positions (three columns) and velocities, checked.
pub(super) struct FusionInputs {
    pub(super) t: Vec<f64>,
    pub(super) f: Vec<[f64; 3]>,
    pub(super) w: Vec<[f64; 3]>,
    /// The IMU's samples that repeated the one before exactly, dropped from `t`, `f`, `w`.
    pub(super) repeats: crate::io::rows::Repeats,
    pub(super) g_t: Vec<f64>,
    pub(super) g_p: Vec<[f64; 3]>,
    /// The fixes' velocities (zeros where they have none).
    pub(super) g_v: Vec<[f64; 3]>,
    /// What the fixes give of their velocity.
    pub(super) velocities: FixVelocity,
    /// Each fix's own one-sigma per axis of the frame ([`FIX_ACCURACY_COLUMNS`] horizontal and
    /// vertical, or [`FIX_SIGMA_COLUMNS`] per axis), if the table gives them.
    pub(super) accuracy: Option<Vec<[f64; 3]>>,
}

/// What a table of fixes gives of the velocity, by its columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum FixVelocity {
    /// No velocity column: positions only (a `NavSatFix`, an NMEA `GGA`).
    None,
    /// The two horizontal columns only (NMEA's speed and course over ground): the vertical one
    /// is not known.
    Horizontal,
    /// All three.
    Full,
}

/// The one-sigma given to a vertical velocity the fixes do not know, m/s: no information.
pub(super) const UNKNOWN_VELOCITY_SIGMA_M_S: f64 = 1e4;

impl FusionInputs {
    /// Reads `imu` (rates) and `gnss` (`columns`: `t_s`, three position and three velocity
    /// columns, the velocity's optional, or its vertical one alone; `hint` follows the list of
    /// missing ones)
    /// and checks the stamps ([`check_fix_times`]).
    ///
    /// # Errors
    /// Missing columns, named; the stamps' refusals.
    pub(super) fn read(
        imu: &Table,
        gnss: &Table,
        columns: &[&str; 7],
        hint: &str,
        accuracy: [f64; 2],
    ) -> Result<Self> {
        let t = imu
            .column("t_s")
            .ok_or_else(|| invalid(Data::Imu, "missing column t_s"))?;
        let (Some(f), Some(w)) = (imu.triples(&ACCEL_COLUMNS), imu.triples(&GYRO_COLUMNS)) else {
            return Err(invalid(
                Data::Imu,
                "fusion needs rates: accel_x/y/z_m_s2 and gyro_x/y/z_rad_s",
            ));
        };
        // A logger's copies of its last sample are dropped (counted in `repeats`).
        let (repeated, repeats) = crate::io::rows::repeated_samples(&t, &[&f, &w]);
        let (t, f, w) = if repeats.count > 0 {
            use crate::io::rows::without;
            (
                without(t, &repeated),
                without(f, &repeated),
                without(w, &repeated),
            )
        } else {
            (t, f, w)
        };
        if t.len() < 2 {
            return Err(invalid(
                Data::Imu,
                format!("{} rows: fusion needs at least two samples", t.len()),
            ));
        }
        let has = |c: &&str| gnss.columns.iter().any(|h| h == c);
        if gnss.columns.is_empty() {
            // No fixes at all (a table without columns): the IMU and the other aids alone.
            return Ok(Self {
                t,
                f,
                w,
                repeats,
                g_t: Vec::new(),
                g_p: Vec::new(),
                g_v: Vec::new(),
                velocities: FixVelocity::None,
                accuracy: None,
            });
        }
        // Positions only when none of the velocity's columns is there; the horizontal velocity
        // alone when the vertical one is missing.
        let velocities = match (columns[4..6].iter().any(has), has(&columns[6])) {
            (false, false) => FixVelocity::None,
            (true, false) => FixVelocity::Horizontal,
            _ => FixVelocity::Full,
        };
        let needed = match velocities {
            FixVelocity::None => &columns[..4],
            FixVelocity::Horizontal => &columns[..6],
            FixVelocity::Full => &columns[..],
        };
        let missing: Vec<&str> = needed.iter().copied().filter(|c| !has(c)).collect();
        if !missing.is_empty() {
            // Fixes of the other Earth's kind: say which option reads them.
            let (plane, geodetic) = (GNSS_COLUMNS[1], GNSS_EARTH_COLUMNS[1]);
            let other = if has(&geodetic) && missing.contains(&plane) {
                " — these fixes are geodetic (lat_rad, lon_rad, height_m): they are read on the \
                 WGS-84 Earth (--earth wgs84; Python earth=\"wgs84\")"
            } else if has(&plane) && missing.contains(&geodetic) {
                " — these fixes are plane coordinates (pos_x_m, …): they are read on the flat \
                 Earth (--earth flat; Python earth=\"flat\")"
            } else {
                ""
            };
            return Err(invalid(
                Data::Gnss,
                format!("missing column(s) {}{hint}{other}", missing.join(", ")),
            ));
        }
        let g_t = gnss.column("t_s").unwrap_or_default();
        let g_p = gnss
            .triples(&[columns[1], columns[2], columns[3]])
            .unwrap_or_default();
        let g_v = match velocities {
            FixVelocity::Full => gnss.triples(&[columns[4], columns[5], columns[6]]),
            FixVelocity::Horizontal => gnss
                .column(columns[4])
                .zip(gnss.column(columns[5]))
                .map(|(a, b)| a.into_iter().zip(b).map(|(x, y)| [x, y, 0.0]).collect()),
            FixVelocity::None => None,
        }
        .unwrap_or_else(|| vec![[0.0; 3]; g_t.len()]);
        check_fix_times(&g_t, (t[0], t[t.len() - 1]), t.len())?;
        let accuracy = fix_accuracy(gnss, accuracy)?;
        Ok(Self {
            t,
            f,
            w,
            repeats,
            g_t,
            g_p,
            g_v,
            velocities,
            accuracy,
        })
    }

    /// The IMU's span `[t₀, t₁]`, s.
    pub(super) fn span(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }
}

/// A fix table's own accuracy per axis: [`FIX_SIGMA_COLUMNS`] (all three), or
/// [`FIX_ACCURACY_COLUMNS`] (horizontal for x and y, vertical for z; where one of the two is
/// missing, `setup`'s for it), each value a positive finite number; `None` without any.
///
/// # Errors
/// A value that is not positive and finite (its row); per-axis columns beside the horizontal
/// and vertical ones, or only some of the three.
fn fix_accuracy(gnss: &Table, setup: [f64; 2]) -> Result<Option<Vec<[f64; 3]>>> {
    let rows = gnss.rows();
    let per_axis = FIX_SIGMA_COLUMNS.map(|c| gnss.column(c));
    let split = FIX_ACCURACY_COLUMNS.map(|c| gnss.column(c));
    let sigmas: Vec<[f64; 3]> = match (
        per_axis.iter().filter(|c| c.is_some()).count(),
        split.iter().any(Option::is_some),
    ) {
        (0, false) => return Ok(None),
        (0, true) => {
            let [h, v] = [0, 1].map(|k| split[k].clone().unwrap_or_else(|| vec![setup[k]; rows]));
            h.into_iter().zip(v).map(|(a, b)| [a, a, b]).collect()
        }
        (3, false) => {
            let [x, y, z] = per_axis.map(Option::unwrap_or_default);
            (0..rows).map(|k| [x[k], y[k], z[k]]).collect()
        }
        (3, true) => {
            return Err(invalid(
                Data::Gnss,
                format!(
                    "give the fixes' accuracy as {} or as {}, not both",
                    FIX_SIGMA_COLUMNS.join(", "),
                    FIX_ACCURACY_COLUMNS.join(", ")
                ),
            ));
        }
        (_, _) => {
            let missing: Vec<&str> = FIX_SIGMA_COLUMNS
                .iter()
                .zip(&per_axis)
                .filter(|(_, c)| c.is_none())
                .map(|(n, _)| *n)
                .collect();
            return Err(invalid(
                Data::Gnss,
                format!(
                    "per-axis accuracy needs all three of {}: missing {}",
                    FIX_SIGMA_COLUMNS.join(", "),
                    missing.join(", ")
                ),
            ));
        }
    };
    if let Some((k, s)) = sigmas
        .iter()
        .enumerate()
        .find(|(_, s)| !s.iter().all(|v| v.is_finite() && *v > 0.0))
    {
        return Err(invalid(
            Data::Gnss,
            format!(
                "row {}: the fix's accuracy must be positive and finite, got {} m",
                k + 2,
                s.map(|v| v.to_string()).join(" m, ")
            ),
        ));
    }
    Ok(Some(sigmas))
}

/// The fixes in the filter's terms: positions on its Earth, velocities in its frame.
pub(super) struct Fixes<E: NavEarth> {
    /// Each fix's position.
    pub(super) position: Vec<E::Position>,
    /// Each fix's velocity (zero where the table has none).
    pub(super) velocity: Vec<Vec3<E::Frame>>,
}

impl<E: NavEarth> Fixes<E> {
    /// The fixes of `inputs`.
    ///
    /// # Errors
    /// A position outside the Earth's domain (its row).
    pub(super) fn of(inputs: &FusionInputs) -> Result<Self> {
        let position = inputs
            .g_p
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                E::fix_position(p).ok_or_else(|| {
                    invalid(
                        Data::Gnss,
                        format!(
                            "row {}: the latitude must be within ±89.9° and the longitude and \
                             height finite",
                            k + 2
                        ),
                    )
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let velocity = inputs.g_v.iter().map(|&v| E::fix_velocity(v)).collect();
        Ok(Self { position, velocity })
    }
}
