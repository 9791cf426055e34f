//! Readings that look like a unit slip: accelerations in g or mg read as m/s², rates in °/s
//! read as rad/s, time stamps in milliseconds or microseconds read as seconds. Nothing here
//! refuses: a drop tower reads no gravity and a centrifuge reads more, so a reading that only
//! looks wrong is warned about, naming the likely slip and the option or map key that fixes it.
//!
//! The rules, from what every IMU log holds:
//! - **Gravity.** An accelerometer on Earth reads about 9.8 m/s² on average over any record
//!   longer than its manoeuvres: a median magnitude within 30 % of 1 (g) or of 1000 (mg) names
//!   that unit. Other magnitudes (a fast manoeuvre, a fall) name none and pass.
//! - **Rates.** No MEMS gyroscope measures beyond 2000 °/s (34.9 rad/s); a median rate beyond it
//!   says °/s.
//! - **Intervals.** An IMU logs at 1 Hz or faster: a median interval of 1 s or more says
//!   milliseconds (or microseconds, beyond 1000 s).
use crate::columns::{ACCEL_COLUMNS, GYRO_COLUMNS};
use crate::table::Table;

/// The widest range of a MEMS gyroscope, rad/s (2000 °/s).
const MAX_MEMS_RATE_RAD_S: f64 = 2000.0 * core::f64::consts::PI / 180.0;

/// The rows looked at, the first of a table or file: enough for a median, little to read.
pub const HEAD_ROWS: usize = 20_000;

/// The median of `v` (NaN when empty), `v` reordered.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Norms of three columns, row by row (`None` when one is missing).
fn norms(t: &Table, names: &[&str; 3]) -> Option<Vec<f64>> {
    let rows = t.triples(names)?;
    Some(
        rows.iter()
            .map(|[x, y, z]| (x * x + y * y + z * z).sqrt())
            .filter(|n| n.is_finite())
            .collect(),
    )
}

/// What looks like a unit slip in the IMU readings `t` read from `source` (a file, a table's
/// name), on its first [`HEAD_ROWS`] rows, each a sentence naming the column, the figure and
/// the likely unit; `fix` is the option or key that declares units (`--map`, the map's `unit`).
#[must_use]
pub fn readings(t: &Table, source: &str, fix: &str) -> Vec<String> {
    let head;
    let t = if t.rows() > HEAD_ROWS {
        head = Table {
            columns: t.columns.clone(),
            data: t.data[..HEAD_ROWS * t.columns.len()].to_vec(),
        };
        &head
    } else {
        t
    };
    let mut out = Vec::new();
    if let Some(mut a) = norms(t, &ACCEL_COLUMNS)
        && a.len() >= 2
    {
        let m = median(&mut a);
        // Only a magnitude that names a unit: a fast manoeuvre or a fall reads far from 9.81
        // without any slip.
        let likely = if (m - 1.0).abs() < 0.3 {
            Some("g")
        } else if (m / 1000.0 - 1.0).abs() < 0.3 {
            Some("mg")
        } else {
            None
        };
        if let Some(unit) = likely {
            out.push(format!(
                "{source}: the accelerometers read {m:.4} m/s² (median magnitude) where gravity \
                 alone reads 9.81 — accelerations in {unit} read as m/s²? ({fix})"
            ));
        }
    }
    if let Some(mut w) = norms(t, &GYRO_COLUMNS)
        && w.len() >= 2
    {
        let m = median(&mut w);
        if m > MAX_MEMS_RATE_RAD_S {
            out.push(format!(
                "{source}: the gyroscopes read {m:.4} rad/s (median magnitude), beyond any MEMS \
                 gyroscope's 34.9 rad/s (2000 °/s) — rates in °/s read as rad/s? ({fix})"
            ));
        }
    }
    if let Some(time) = t.column("t_s") {
        let mut dt: Vec<f64> = time
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| d.is_finite() && *d > 0.0)
            .collect();
        if dt.len() >= 2 {
            let m = median(&mut dt);
            if m >= 1.0 {
                let unit = if m >= 1000.0 {
                    "microseconds"
                } else {
                    "milliseconds"
                };
                out.push(format!(
                    "{source}: the samples are {m} s apart (median), an IMU below 1 Hz — time \
                     stamps in {unit} read as seconds? ({fix})"
                ));
            }
        }
    }
    out
}

/// [`readings`] of the IMU file `input` (through its column map, if it has one), of which
/// only the first [`HEAD_ROWS`] rows are read; nothing when it has no IMU columns or cannot be read (the job that reads it says
/// why).
#[must_use]
pub fn file_readings(input: impl Into<crate::Input>, fix: &str) -> Vec<String> {
    let input = input.into();
    let Ok(header) = crate::read::read_header(&input) else {
        return Vec::new();
    };
    let names: Vec<&str> = std::iter::once("t_s")
        .chain(ACCEL_COLUMNS)
        .chain(GYRO_COLUMNS)
        .filter(|c| header.iter().any(|h| h == c))
        .collect();
    let Ok(mut rows) = crate::read::CsvRows::open(&input, &names, "") else {
        return Vec::new();
    };
    let mut head = Table::new(&names);
    let mut row = vec![0.0; names.len()];
    while head.rows() < HEAD_ROWS {
        match rows.next_row(&mut row) {
            Ok(Some(_)) => head.push_row(&row),
            _ => break,
        }
    }
    readings(&head, &input.path().display().to_string(), fix)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn imu(dt: f64, accel: [f64; 3], gyro: [f64; 3]) -> Table {
        let mut t = Table::new(&[
            "t_s",
            "accel_x_m_s2",
            "accel_y_m_s2",
            "accel_z_m_s2",
            "gyro_x_rad_s",
            "gyro_y_rad_s",
            "gyro_z_rad_s",
        ]);
        for k in 0..100 {
            let wobble = 1.0 + 0.01 * f64::from(k % 5);
            let row: Vec<f64> = std::iter::once(f64::from(k) * dt)
                .chain(accel.iter().map(|a| a * wobble))
                .chain(gyro.iter().map(|w| w * wobble))
                .collect();
            t.push_row(&row);
        }
        t
    }

    #[test]
    fn plausible_readings_say_nothing_and_each_slip_is_named() {
        let fine = imu(0.01, [0.3, -0.2, 9.7], [0.1, 0.0, 0.5]);
        assert!(readings(&fine, "f", "--map").is_empty());
        let in_g = imu(0.01, [0.03, 0.0, 0.99], [0.1, 0.0, 0.5]);
        let w = readings(&in_g, "f.csv", "--map");
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("f.csv") && w[0].contains("in g read as m/s²") && w[0].contains("--map")
        );
        let in_mg = imu(0.01, [0.0, 0.0, 1000.0], [0.0; 3]);
        assert!(readings(&in_mg, "f", "m")[0].contains("in mg read as m/s²"));
        let in_deg = imu(0.01, [0.0, 0.0, 9.81], [0.0, 0.0, 90.0]);
        assert!(readings(&in_deg, "f", "m")[0].contains("in °/s read as rad/s"));
        let in_ms = imu(10.0, [0.0, 0.0, 9.81], [0.0; 3]);
        assert!(readings(&in_ms, "f", "m")[0].contains("milliseconds read as seconds"));
        let in_us = imu(10_000.0, [0.0, 0.0, 9.81], [0.0; 3]);
        assert!(readings(&in_us, "f", "m")[0].contains("microseconds read as seconds"));
        // A fall or a fast manoeuvre is far from gravity but names no unit.
        for a in [[0.0, 0.0, 0.02], [30.0, 0.0, 20.0]] {
            assert!(readings(&imu(0.01, a, [0.0; 3]), "f", "m").is_empty());
        }
    }
}
