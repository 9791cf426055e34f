//! NMEA 0183 sentences read as one fix per epoch (the `nmea` crate).
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use chrono::Timelike;
use nmea::ParseResult;

use super::HDOP_COLUMN;
use crate::columns::GNSS_EARTH_COLUMNS;
use crate::error::{Error, Result};
use crate::table::Table;

/// The longest line read, bytes (NMEA's limit is 82 characters; loggers add their own stamp).
const MAX_LINE_BYTES: u64 = 4096;

/// Metres per second in a knot.
const KNOT_M_S: f64 = 1852.0 / 3600.0;

/// Seconds in a day.
const DAY_NS: i64 = 86_400_000_000_000;

/// One epoch's fix as it is gathered.
#[derive(Clone, Copy, Debug, Default)]
struct Epoch {
    /// UTC time of day, ns (kept whole: a fix at 0.6 s is read as the double nearest 0.6).
    time_of_day_ns: i64,
    /// The line of the sentence that began it.
    line: usize,
    position: Option<[f64; 3]>,
    /// `GGA`'s horizontal dilution of precision.
    hdop: Option<f64>,
    /// Speed over ground (m/s) and true course (rad).
    ground: Option<(f64, f64)>,
    /// `GST`'s standard deviations of latitude, longitude and altitude, m.
    sigma: Option<[f64; 3]>,
}

/// The columns of a table of fixes with horizontal velocities: the geodetic fix table's
/// ([`GNSS_EARTH_COLUMNS`]) without `vel_d_m_s`.
const COLUMNS: &[&str] = GNSS_EARTH_COLUMNS.split_at(6).0;

/// Reads the NMEA log at `path` as a table of fixes (see the module documentation).
///
/// # Errors
/// An unreadable file, a line longer than 4096 bytes, a bad checksum or a sentence of the three
/// read that does not parse (file and line), a log without a fix.
pub fn read_table(path: &Path) -> Result<Table> {
    let epochs = read_epochs(path)?;
    let fixes: Vec<Epoch> = epochs
        .into_iter()
        .filter(|e| e.position.is_some())
        .collect();
    if fixes.is_empty() {
        return Err(Error::CsvFormat {
            file: path.into(),
            message: "no GGA sentence with a fix".into(),
        });
    }
    Ok(table_of(&fixes))
}

/// The epochs of the log at `path`, in the order of their sentences.
fn read_epochs(path: &Path) -> Result<Vec<Epoch>> {
    let (file, _) = crate::open_with_length(path)?;
    let bad = |line: usize, message: String| Error::CsvFormat {
        file: path.into(),
        message: format!("line {line}: {message}"),
    };
    let mut reader = BufReader::new(file);
    let mut epochs: Vec<Epoch> = Vec::new();
    let mut bytes = Vec::new();
    let mut line = 0;
    loop {
        bytes.clear();
        let read = (&mut reader)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut bytes)
            .map_err(|source| Error::Io {
                path: path.into(),
                source,
            })?;
        if read == 0 {
            break;
        }
        line += 1;
        if bytes.len() as u64 > MAX_LINE_BYTES {
            return Err(bad(line, format!("longer than {MAX_LINE_BYTES} bytes")));
        }
        let text = String::from_utf8_lossy(&bytes);
        let Some(start) = text.find('$') else {
            continue;
        };
        let sentence = text[start..].trim_end();
        match nmea::parse_str(sentence) {
            Ok(ParseResult::GGA(g)) => add_gga(&mut epochs, &g, line, bad)?,
            Ok(ParseResult::RMC(r)) => {
                let (Some(time), Some(speed), Some(course)) =
                    (r.fix_time, r.speed_over_ground, r.true_course)
                else {
                    continue;
                };
                if r.status_of_fix == nmea::sentences::rmc::RmcStatusOfFix::Invalid {
                    continue;
                }
                let g = ground(speed, course).map_err(|m| bad(line, format!("RMC: {m}")))?;
                epoch_at(&mut epochs, nanos_of(time), line).ground = Some(g);
            }
            Ok(ParseResult::GST(g)) => {
                // Deviations the receiver left empty, or that are not positive, give nothing.
                let (Some(time), Some(n), Some(e), Some(u)) =
                    (g.time, g.lat_sd, g.long_sd, g.alt_sd)
                else {
                    continue;
                };
                let sigma = [n, e, u].map(f64::from);
                if sigma.iter().all(|s| s.is_finite() && *s > 0.0) {
                    epoch_at(&mut epochs, nanos_of(time), line).sigma = Some(sigma);
                }
            }
            Ok(ParseResult::VTG(v)) => {
                // No time of its own: the epoch of the sentences before it.
                if let (Some(last), Some(speed), Some(course)) =
                    (epochs.last_mut(), v.speed_over_ground, v.true_course)
                    && last.ground.is_none()
                {
                    last.ground =
                        Some(ground(speed, course).map_err(|m| bad(line, format!("VTG: {m}")))?);
                }
            }
            Ok(_) | Err(nmea::Error::Unsupported(_) | nmea::Error::Unknown(_)) => {}
            Err(nmea::Error::ChecksumMismatch { calculated, found }) => {
                return Err(bad(
                    line,
                    format!("checksum {found:02X} where the sentence's is {calculated:02X}"),
                ));
            }
            Err(e) => {
                let kind = sentence.get(3..6).unwrap_or("");
                if ["GGA", "RMC", "VTG", "GST"].contains(&kind) {
                    return Err(bad(line, format!("{kind}: {e}")));
                }
            }
        }
    }
    Ok(epochs)
}

/// Adds a `GGA` sentence's fix to its epoch (nothing when it has no valid fix).
fn add_gga(
    epochs: &mut Vec<Epoch>,
    g: &nmea::sentences::GgaData,
    line: usize,
    bad: impl Fn(usize, String) -> Error,
) -> Result<()> {
    let (Some(time), Some(lat), Some(lon)) = (g.fix_time, g.latitude, g.longitude) else {
        return Ok(());
    };
    if g.fix_type.is_none_or(|f| !f.is_valid()) {
        return Ok(());
    }
    let altitude = f64::from(g.altitude.unwrap_or(0.0));
    let separation = f64::from(g.geoid_separation.unwrap_or(0.0));
    if !(lat.abs() <= 90.0 && lon.abs() <= 180.0) {
        return Err(bad(
            line,
            format!("GGA: latitude {lat}, longitude {lon} is not a place on the Earth"),
        ));
    }
    let height = altitude + separation;
    if height.is_nan() || height.abs() >= MAX_HEIGHT_M {
        return Err(bad(
            line,
            format!(
                "GGA: altitude {altitude} m and geoid separation {separation} m is \
                 not a height within {MAX_HEIGHT_M} m of the Earth"
            ),
        ));
    }
    let position = [lat.to_radians(), lon.to_radians(), height];
    let at = nanos_of(time);
    if let Some(last) = epochs.last()
        && last.time_of_day_ns == at
        && last.position.is_some_and(|p| p != position)
    {
        return Err(bad(
            line,
            format!(
                "GGA: a second fix, elsewhere, at the time of line {} ({} s of the \
                 day): one fix per time",
                last.line,
                at as f64 / 1e9
            ),
        ));
    }
    let epoch = epoch_at(epochs, at, line);
    epoch.position = Some(position);
    epoch.hdop = g.hdop.map(f64::from).filter(|h| h.is_finite() && *h > 0.0);
    Ok(())
}

/// The table of the epochs with a fix: velocities, HDOP and accuracies when every fix has them.
fn table_of(fixes: &[Epoch]) -> Table {
    let velocities = fixes.iter().all(|e| e.ground.is_some());
    let hdop = fixes.iter().all(|e| e.hdop.is_some());
    let gst = fixes.iter().all(|e| e.sigma.is_some());
    let width = if velocities { 6 } else { 4 };
    let mut columns = COLUMNS[..width].to_vec();
    if hdop {
        columns.push(HDOP_COLUMN);
    }
    if gst {
        columns.extend(crate::columns::FIX_ACCURACY_COLUMNS);
    }
    let mut table = Table::new(&columns);
    let (mut day, mut previous) = (0, fixes[0].time_of_day_ns);
    for e in fixes {
        // Past midnight: the clock starts again.
        if e.time_of_day_ns < previous - DAY_NS / 2 {
            day += DAY_NS;
        }
        previous = e.time_of_day_ns;
        let [lat, lon, h] = e.position.unwrap_or_default();
        // One rounding, from whole nanoseconds: 0.6 s is the double nearest 0.6.
        #[allow(clippy::cast_precision_loss)]
        let t_s = (day + e.time_of_day_ns) as f64 / 1e9;
        let mut row = vec![t_s, lat, lon, h];
        if let Some((speed, course)) = e.ground.filter(|_| velocities) {
            row.extend([speed * course.cos(), speed * course.sin()]);
        }
        if let Some(h) = e.hdop.filter(|_| hdop) {
            row.push(h);
        }
        // The fix's accuracy per horizontal axis (the mean of north's and east's variances)
        // and vertically.
        if let Some([n, east, up]) = e.sigma.filter(|_| gst) {
            row.extend([(0.5 * (n * n + east * east)).sqrt(), up]);
        }
        table.push_row(&row);
    }
    table
}

/// The epoch at time of day `t` (the last one when it is the same time, else a new one).
fn epoch_at(epochs: &mut Vec<Epoch>, t_ns: i64, line: usize) -> &mut Epoch {
    if epochs.last().is_none_or(|e| e.time_of_day_ns != t_ns) {
        epochs.push(Epoch {
            time_of_day_ns: t_ns,
            line,
            ..Epoch::default()
        });
    }
    let last = epochs.len() - 1;
    &mut epochs[last]
}

/// A UTC time of day in seconds.
fn nanos_of(t: chrono::NaiveTime) -> i64 {
    // A leap second's nanoseconds run past 10⁹: they stay within the day.
    i64::from(t.num_seconds_from_midnight()) * 1_000_000_000 + i64::from(t.nanosecond())
}

/// The farthest from the ellipsoid a fix's height may be, m (a receiver on a rocket is within).
const MAX_HEIGHT_M: f64 = 1.0e7;

/// Speed (knots) and true course (degrees) as m/s and radians; a speed or course that is no
/// number (`nan`, `inf`, a speed below zero or of `1e308` knots) is refused.
fn ground(speed_knots: f32, course_deg: f32) -> core::result::Result<(f64, f64), String> {
    let (speed, course) = (f64::from(speed_knots), f64::from(course_deg));
    if !(speed.is_finite() && speed >= 0.0 && course.is_finite()) {
        return Err(format!(
            "speed {speed_knots} knots, course {course_deg}° is not a motion over the ground"
        ));
    }
    Ok((speed * KNOT_M_S, course.to_radians()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::with_uere;

    /// `body` with its checksum (the XOR of the characters between `$` and `*`).
    fn sentence(body: &str) -> String {
        let sum = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{sum:02X}")
    }

    fn write(dir: &tempfile::TempDir, lines: &[String]) -> std::path::PathBuf {
        let path = dir.path().join("log.nmea");
        std::fs::write(&path, lines.join("\r\n") + "\r\n").expect("written");
        path
    }

    #[test]
    fn fixes_come_with_their_height_velocity_and_time_across_midnight() {
        let dir = tempfile::tempdir().expect("dir");
        let lines = [
            sentence("GPGSV,3,1,11,10,63,137,17,07,61,098,15,05,59,290,20,08,54,157,30"),
            sentence("GPGGA,235959.50,4807.038,N,01131.000,E,1,08,0.9,545.4,M,47.0,M,,"),
            sentence("GPRMC,235959.50,A,4807.038,N,01131.000,E,10.0,90.0,230394,003.1,W"),
            "12345.6 ".to_string()
                + &sentence("GPGGA,000000.50,4807.040,S,01131.002,W,2,08,0.9,546.0,M,47.0,M,,"),
            sentence("GPVTG,180.0,T,,M,2.0,N,3.7,K"),
            sentence("GPGGA,000001.50,4807.041,N,01131.003,E,0,00,,,M,,M,,"),
        ];
        let t = read_table(&write(&dir, &lines)).expect("read");
        assert_eq!(t.columns, [COLUMNS, &[HDOP_COLUMN]].concat());
        assert_eq!(t.rows(), 2, "the epoch without a fix is left out");
        let (a, b) = (&t.data[..7], &t.data[7..]);
        assert_eq!((a[6], b[6]), (f64::from(0.9_f32), f64::from(0.9_f32)));
        let scaled = with_uere(&t, 4.0).expect("scaled");
        assert_eq!(
            scaled.column("horizontal_accuracy_m"),
            Some(vec![f64::from(0.9_f32) * 4.0; 2])
        );
        assert!(with_uere(&t, 0.0).is_err());
        assert_eq!(a[0], 86_399.5);
        assert_eq!(b[0], 86_400.5, "a day added past midnight");
        assert!((a[1] - (48.0 + 7.038 / 60.0_f64).to_radians()).abs() < 1e-15);
        assert!((a[2] - (11.0 + 31.0 / 60.0_f64).to_radians()).abs() < 1e-15);
        assert!(
            (b[1] + (48.0 + 7.040 / 60.0_f64).to_radians()).abs() < 1e-15,
            "south"
        );
        assert!(b[2] < 0.0, "west");
        assert!(
            (a[3] - 592.4).abs() < 1e-4,
            "altitude plus geoid separation"
        );
        // 10 knots due east, then 2 knots due south from the VTG.
        assert!(a[4].abs() < 1e-12 && (a[5] - 10.0 * KNOT_M_S).abs() < 1e-5);
        assert!((b[4] + 2.0 * KNOT_M_S).abs() < 1e-5 && b[5].abs() < 1e-5);
    }

    #[test]
    fn a_receivers_gst_gives_each_fix_its_accuracy() {
        let dir = tempfile::tempdir().expect("dir");
        let gga = |time: &str| {
            sentence(&format!(
                "GPGGA,{time},4807.038,N,01131.000,E,1,08,0.9,545.4,M,47.0,M,,"
            ))
        };
        let gst = |time: &str, n: &str, e: &str, u: &str| {
            sentence(&format!("GPGST,{time},15.5,15.3,7.2,21.8,{n},{e},{u}"))
        };
        let lines = [
            gga("120000.00"),
            gst("120000.00", "0.9", "1.2", "2.5"),
            gga("120001.00"),
            gst("120001.00", "3.0", "4.0", "5.0"),
        ];
        let t = read_table(&write(&dir, &lines)).expect("read");
        let h = t.column("horizontal_accuracy_m").expect("horizontal");
        let v = t.column("vertical_accuracy_m").expect("vertical");
        let f = |x: f32| f64::from(x);
        assert_eq!(
            h,
            [
                (0.5 * (f(0.9) * f(0.9) + f(1.2) * f(1.2))).sqrt(),
                (0.5 * (f(3.0) * f(3.0) + f(4.0) * f(4.0))).sqrt()
            ]
        );
        assert_eq!(v, [f(2.5), f(5.0)]);
        // One fix without (an empty deviation): no accuracy columns at all.
        let lines = [
            lines[0].clone(),
            lines[1].clone(),
            gga("120001.00"),
            gst("120001.00", "", "4.0", "5.0"),
        ];
        let t = read_table(&write(&dir, &lines)).expect("read");
        assert_eq!(t.column("horizontal_accuracy_m"), None);
    }

    #[test]
    fn a_fix_time_is_the_double_nearest_its_stamp_and_numbers_that_are_not_refused() {
        let dir = tempfile::tempdir().expect("dir");
        let gga_at = |time: &str, lat: &str, alt: &str| {
            sentence(&format!(
                "GPGGA,{time},{lat},N,01131.000,E,1,08,0.9,{alt},M,47.0,M,,"
            ))
        };
        let gga = |time: &str, lat: &str| gga_at(time, lat, "545.4");
        let t = read_table(&write(
            &dir,
            &[gga("000000.60", "4807.038"), gga("000001.70", "4807.038")],
        ))
        .expect("read");
        assert_eq!(t.column("t_s"), Some(vec![0.6, 1.7]));
        for (lines, needle) in [
            (
                vec![gga_at("000000.60", "4807.038", "nan")],
                "line 1: GGA: altitude NaN m",
            ),
            (
                vec![gga_at("000000.60", "4807.038", "inf")],
                "line 1: GGA: altitude inf m",
            ),
            (
                vec![gga("000000.60", "9107.038")],
                "not a place on the Earth",
            ),
            (
                vec![
                    gga("000000.60", "4807.038"),
                    sentence("GPRMC,000000.60,A,4807.038,N,01131.000,E,1e308,90.0,230394,003.1,W"),
                ],
                "line 2: RMC: speed inf knots",
            ),
            (
                vec![gga("000000.60", "4807.038"), gga("000000.60", "4808.038")],
                "line 2: GGA: a second fix, elsewhere, at the time of line 1",
            ),
        ] {
            let e = read_table(&write(&dir, &lines)).unwrap_err().to_string();
            assert!(
                e.contains("log.nmea") && e.contains(needle),
                "{needle}: {e}"
            );
        }
    }

    #[test]
    fn fixes_without_speed_are_positions_only_and_bad_sentences_are_refused_by_line() {
        let dir = tempfile::tempdir().expect("dir");
        let gga = sentence("GPGGA,120000.00,4807.038,N,01131.000,E,1,08,0.9,545.4,M,47.0,M,,");
        let t = read_table(&write(&dir, std::slice::from_ref(&gga))).expect("read");
        assert_eq!(t.columns, [&COLUMNS[..4], &[HDOP_COLUMN]].concat());
        let mut broken = gga.clone();
        broken.replace_range(gga.len() - 2.., "00");
        let e = read_table(&write(&dir, &[gga.clone(), broken]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("log.nmea") && e.contains("line 2: checksum 00"),
            "{e}"
        );
        let e = read_table(&write(&dir, &[sentence("GPGGA,12x000,4807.038,N")]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1: GGA"), "{e}");
        let e = read_table(&write(&dir, &[sentence("GPGSV,1,1,00")]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("no GGA sentence with a fix"), "{e}");
        let long = write(&dir, &["$".repeat(5000)]);
        assert!(
            read_table(&long)
                .unwrap_err()
                .to_string()
                .contains("longer than 4096 bytes")
        );
    }
}
