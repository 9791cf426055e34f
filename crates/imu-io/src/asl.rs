//! The ASL layout of EuRoC and TUM-VI sequences (`mav0/imu0/data.csv`,
//! `mav0/state_groundtruth_estimate0/data.csv`, `mav0/mocap0/data.csv`), read by its header:
//! a first line `#timestamp [ns],w_RS_S_x [rad s^-1],…` that names each column with its unit in
//! brackets. Every reader of CSV tables reads such a file as the imukit table it is:
//!
//! | ASL column | imukit column |
//! |---|---|
//! | `#timestamp [ns]` | `t_s` |
//! | `w_RS_S_x [rad s^-1]` … | `gyro_x_rad_s` … |
//! | `a_RS_S_x [m s^-2]` … | `accel_x_m_s2` … |
//! | `p_RS_R_x [m]` … | `pos_x_m` … |
//! | `v_RS_R_x [m s^-1]` … | `vel_x_m_s` … |
//! | `q_RS_w []` … | `q_w` … (`q_RS`: sensor to reference, imukit's `q_nb`) |
//!
//! Other columns (the ground truth's bias estimates `b_w_RS_S_x`, …) keep their name without the
//! unit. A known column in another unit than the layout's is refused by name. [`AslWriter`]
//! writes the layout (`imukit simulate --layout euroc`).
//!
//! **Time.** Stamps are integer nanoseconds since the Unix epoch. They are kept exactly: `t_s`
//! counts seconds from the UTC midnight before the file's first stamp (the *time origin*,
//! [`time_origin_ns`]), where an `f64` resolves 15 picoseconds, so every stamp of a day-long
//! recording comes back to the nanosecond, and the IMU and ground-truth files of one sequence
//! share an origin. (Seconds since the epoch in an `f64` would resolve only 0.24 µs.)
use crate::error::Result;

/// Nanoseconds in a day.
pub const DAY_NS: i64 = 86_400_000_000_000;

/// The first line of an ASL file starts with this (after optional spaces).
pub const HEADER_START: &str = "#timestamp";

/// `(ASL name, unit in brackets, imukit name)` of the columns the layout defines.
const COLUMNS: &[(&str, &str, &str)] = &[
    ("#timestamp", "ns", "t_s"),
    ("w_RS_S_x", "rad s^-1", "gyro_x_rad_s"),
    ("w_RS_S_y", "rad s^-1", "gyro_y_rad_s"),
    ("w_RS_S_z", "rad s^-1", "gyro_z_rad_s"),
    ("a_RS_S_x", "m s^-2", "accel_x_m_s2"),
    ("a_RS_S_y", "m s^-2", "accel_y_m_s2"),
    ("a_RS_S_z", "m s^-2", "accel_z_m_s2"),
    ("p_RS_R_x", "m", "pos_x_m"),
    ("p_RS_R_y", "m", "pos_y_m"),
    ("p_RS_R_z", "m", "pos_z_m"),
    ("v_RS_R_x", "m s^-1", "vel_x_m_s"),
    ("v_RS_R_y", "m s^-1", "vel_y_m_s"),
    ("v_RS_R_z", "m s^-1", "vel_z_m_s"),
    ("q_RS_w", "", "q_w"),
    ("q_RS_x", "", "q_x"),
    ("q_RS_y", "", "q_y"),
    ("q_RS_z", "", "q_z"),
];

/// Writes tables in the ASL layout: an IMU file (`#timestamp [ns]`, then `w_RS_S_*` and
/// `a_RS_S_*`, the order EuRoC's readers index) or a ground truth (`p_RS_R_*`, `q_RS_*`,
/// `v_RS_R_*`), stamps as integer nanoseconds (`t_s` rounded to the nanosecond); other
/// columns are left out.
#[derive(Clone, Debug, PartialEq)]
pub struct AslWriter {
    /// The table's column of each file column; the first is `t_s`.
    order: Vec<usize>,
}

/// The imukit columns of an ASL IMU file and of a ground truth, in the file's order.
const IMU_ORDER: [&str; 6] = [
    "gyro_x_rad_s",
    "gyro_y_rad_s",
    "gyro_z_rad_s",
    "accel_x_m_s2",
    "accel_y_m_s2",
    "accel_z_m_s2",
];
const TRUTH_ORDER: [&str; 10] = [
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
];

impl AslWriter {
    /// The writer of a table with `columns`, and its header line (without the line end).
    ///
    /// # Errors
    /// A table that is neither IMU rates nor a ground truth, named by `file`.
    pub fn for_columns(columns: &[String], file: &str) -> Result<(Self, String)> {
        let find = |name: &str| columns.iter().position(|c| c == name);
        let pick = |names: &[&str]| -> Option<Vec<usize>> {
            std::iter::once("t_s")
                .chain(names.iter().copied())
                .map(find)
                .collect()
        };
        let order = pick(&IMU_ORDER)
            .or_else(|| pick(&TRUTH_ORDER))
            .ok_or_else(|| crate::Error::CsvFormat {
                file: file.into(),
                message: "the ASL layout holds IMU rates (t_s, gyro_*, accel_*) or a ground \
                          truth (t_s, pos_*, q_*, vel_*)"
                    .into(),
            })?;
        let header: Vec<String> = order
            .iter()
            .map(|&k| {
                let (asl, unit, _) = COLUMNS
                    .iter()
                    .find(|(.., imukit)| *imukit == columns[k])
                    .expect("every written column is one of the layout's");
                format!("{asl} [{unit}]")
            })
            .collect();
        Ok((Self { order }, header.join(",")))
    }

    /// Writes row-major `data` (rows of `width` values, finite) in the layout.
    ///
    /// # Errors
    /// The writer's.
    pub fn write_rows(
        &self,
        w: &mut impl std::io::Write,
        data: &[f64],
        width: usize,
    ) -> std::io::Result<()> {
        let mut line = String::new();
        for row in data.chunks_exact(width.max(1)) {
            use std::fmt::Write as _;
            line.clear();
            // Finite times of any run fit: i64 nanoseconds reach 292 years.
            let ns = stamp_ns(row[self.order[0]]).unwrap_or_default();
            let _ = write!(line, "{ns}");
            for &k in &self.order[1..] {
                let _ = write!(line, ",{}", row[k]);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    }
}

/// Whether the first line of a CSV file is an ASL header.
#[must_use]
pub fn is_header(first_line: &str) -> bool {
    first_line.trim_start().starts_with(HEADER_START)
}

/// The imukit names of the columns of an ASL header line.
///
/// # Errors
/// A known column in another unit than the layout's, or a name that appears twice (named with
/// the header's field number).
pub fn column_names(header_line: &str, file: &str) -> Result<Vec<String>> {
    let refuse = |message: String| crate::Error::CsvFormat {
        file: file.into(),
        message,
    };
    let mut names: Vec<String> = Vec::new();
    for (k, field) in header_line
        .trim_end_matches(['\r', '\n'])
        .split(',')
        .enumerate()
    {
        let field = field.trim();
        let (name, unit) = match field.split_once('[') {
            Some((name, rest)) => (name.trim(), Some(rest.trim_end_matches(']').trim())),
            None => (field, None),
        };
        let imukit = match COLUMNS.iter().find(|(asl, ..)| *asl == name) {
            Some((asl, expected, imukit)) => {
                if let Some(unit) = unit.filter(|u| u != expected) {
                    return Err(refuse(format!(
                        "column {asl} (field {}) is in [{unit}]; the ASL layout has it in \
                         [{expected}]",
                        k + 1
                    )));
                }
                (*imukit).to_string()
            }
            None => name.trim_start_matches('#').to_string(),
        };
        if let Some(i) = names.iter().position(|n| *n == imukit) {
            return Err(refuse(format!(
                "column {imukit} appears twice in the ASL header (fields {} and {})",
                i + 1,
                k + 1
            )));
        }
        names.push(imukit);
    }
    Ok(names)
}

/// The names of an ASL header line's columns as the file gives them, without units (for
/// messages: `w_RS_S_x`, `#timestamp`).
#[must_use]
pub fn file_names(header_line: &str) -> Vec<String> {
    header_line
        .trim_end_matches(['\r', '\n'])
        .split(',')
        .map(|f| f.split('[').next().unwrap_or_default().trim().to_string())
        .collect()
}

/// The time origin of a file whose first stamp is `first_ns`: the UTC midnight before it, ns.
#[must_use]
pub fn time_origin_ns(first_ns: i64) -> i64 {
    first_ns.div_euclid(DAY_NS) * DAY_NS
}

/// The time origin shared by the files of the EuRoC/TUM-VI sequence that holds `path`
/// (`…/mav0/<sensor>/data.csv`): the UTC midnight before the earliest first stamp of the
/// sequence's ASL files, so that the IMU and the ground truth of a recording that crosses
/// midnight count from one origin. `None` for a file outside such a folder, or when no sibling
/// gives a stamp (the file's own first stamp then sets it).
#[must_use]
pub fn sequence_origin_ns(path: &std::path::Path) -> Option<i64> {
    let sequence = path.parent()?.parent()?;
    if sequence.file_name()? != "mav0" {
        return None;
    }
    let mut first: Option<i64> = None;
    // A sequence has a handful of sensors; a folder of thousands is not one.
    for entry in std::fs::read_dir(sequence).ok()?.take(64) {
        let file = entry.ok()?.path().join("data.csv");
        if let Some(ns) = first_stamp_ns(&file) {
            first = Some(first.map_or(ns, |f| f.min(ns)));
        }
    }
    first.map(time_origin_ns)
}

/// The first stamp of the ASL file at `path`, ns: its first data row's first field (`None`
/// when it is no ASL file or has no row). At most two lines of 64 KiB are read.
fn first_stamp_ns(path: &std::path::Path) -> Option<i64> {
    use std::io::{BufRead, Read};
    let file = std::fs::File::open(path).ok()?;
    let mut reader = std::io::BufReader::new(file.take(128 * 1024));
    let mut header = String::new();
    reader.read_line(&mut header).ok()?;
    if !is_header(&header) {
        return None;
    }
    let mut row = String::new();
    reader.read_line(&mut row).ok()?;
    row.split(',').next()?.trim().parse().ok()
}

/// `t_s` as an integer-nanosecond stamp (rounded to the nanosecond); `None` when it is not
/// finite or beyond ±292 years.
#[must_use]
#[allow(clippy::cast_possible_truncation)]
pub fn stamp_ns(t_s: f64) -> Option<i64> {
    let ns = (t_s * 1e9).round();
    // i64::MAX as f64 rounds up to 2⁶³: the range is checked below it.
    (ns.is_finite() && ns.abs() < 9.2e18).then_some(ns as i64)
}

/// A stamp in integer nanoseconds as seconds after `origin_ns`.
#[must_use]
#[allow(clippy::cast_precision_loss)]
pub fn seconds_after(stamp_ns: i64, origin_ns: i64) -> f64 {
    // Exact in i128; the difference, below 2⁵³ ns (104 days), converts exactly.
    let ns = i128::from(stamp_ns) - i128::from(origin_ns);
    ns as f64 * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    const EUROC_IMU: &str = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],\
        w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]";

    #[test]
    fn euroc_headers_name_imukit_columns() {
        assert!(is_header(EUROC_IMU));
        assert_eq!(
            column_names(EUROC_IMU, "imu0/data.csv").unwrap(),
            [
                "t_s",
                "gyro_x_rad_s",
                "gyro_y_rad_s",
                "gyro_z_rad_s",
                "accel_x_m_s2",
                "accel_y_m_s2",
                "accel_z_m_s2"
            ]
        );
        let truth = "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], \
            q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], \
            b_w_RS_S_x [rad s^-1]\r\n";
        let names = column_names(truth, "gt.csv").unwrap();
        assert_eq!(names[0], "t_s");
        assert_eq!(&names[4..8], ["q_w", "q_x", "q_y", "q_z"]);
        assert_eq!(names[11], "b_w_RS_S_x");
        let e = column_names("#timestamp [ns],w_RS_S_x [deg s^-1]", "d.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("d.csv") && e.contains("w_RS_S_x (field 2) is in [deg s^-1]"),
            "{e}"
        );
        let e = column_names("#timestamp [ns],a_RS_S_x,a_RS_S_x", "d.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("accel_x_m_s2 appears twice"), "{e}");
    }

    #[test]
    fn stamps_come_back_to_the_nanosecond() {
        // EuRoC MH_01's first IMU stamp, and stamps through the rest of its day.
        let first = 1_403_636_579_758_555_392_i64;
        let origin = time_origin_ns(first);
        assert_eq!(origin % DAY_NS, 0);
        assert!(first - origin < DAY_NS);
        for k in 0..2000_i64 {
            let stamp = first + k * 43_200_017_123 + (k % 7) * 999;
            let t = seconds_after(stamp, origin);
            assert_eq!((t * 1e9).round() as i64 + origin, stamp, "{k}");
        }
        assert_eq!(time_origin_ns(-1), -DAY_NS);
    }
}
