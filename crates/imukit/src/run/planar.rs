//! Planar IMU files and planar dead reckoning for the CLI and Python (the planar cart exercise).
//!
//! Planar IMU data: CSV with `t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s` (extra columns
//! ignored, so a full imukit IMU CSV works), or the exercise's whitespace-separated `.dat` files
//! with the columns t, a_x, a_y, ω_z in that order (lines starting with `#` or `%` skipped).
use std::path::Path;

use imu_core::strapdown::planar::{PlanarSample, PlanarScheme, PlanarState, dead_reckon};

use crate::error::{Error, RequestOption, Result, invalid};
use crate::io::Input;
use crate::io::columns::{PLANAR_COLUMNS, PLANAR_NAV_COLUMNS};
use crate::io::output::write_atomically;
use crate::io::read::read_columns;
use crate::io::table::{Table, write_rows};
use crate::scenario::resolve::finite_vec;

fn is_dat(path: &Path, first_line: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("dat"))
        || first_line
            .split_whitespace()
            .next()
            .is_some_and(|w| w.parse::<f64>().is_ok())
            && !first_line.contains(',')
}

/// Reads planar IMU samples from a CSV or `.dat` file.
///
/// # Errors
/// Unreadable files, missing columns, a `.dat` line with the wrong number of columns or a value
/// that is not a finite number (file and line named).
pub fn read_planar(input: impl Into<Input>) -> Result<Vec<PlanarSample>> {
    let input = input.into();
    let path = input.path();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    if !is_dat(path, first) {
        let cols = read_columns(&input, &PLANAR_COLUMNS, "")?;
        let (t, ax, ay, wz) = (
            cols.get("t_s"),
            cols.get("accel_x_m_s2"),
            cols.get("accel_y_m_s2"),
            cols.get("gyro_z_rad_s"),
        );
        return Ok((0..t.len())
            .map(|i| PlanarSample {
                t_s: t[i],
                accel_x_m_s2: ax[i],
                accel_y_m_s2: ay[i],
                gyro_z_rad_s: wz[i],
            })
            .collect());
    }
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') || l.starts_with('%') {
            continue;
        }
        let at = |msg: String| Error::CsvFormat {
            file: path.into(),
            message: format!("line {}: {msg}", n + 1),
        };
        let words: Vec<&str> = l.split_whitespace().collect();
        if words.len() != 4 {
            return Err(at(format!(
                "expected 4 columns (t, a_x, a_y, ω_z), found {}",
                words.len()
            )));
        }
        let mut v = [0.0; 4];
        for (k, w) in words.iter().enumerate() {
            let x: f64 = w
                .parse()
                .map_err(|_| at(format!("column {}: not a number: \"{w}\"", k + 1)))?;
            if !x.is_finite() {
                return Err(at(format!(
                    "column {}: not a finite number: \"{w}\"",
                    k + 1
                )));
            }
            v[k] = x;
        }
        out.push(PlanarSample {
            t_s: v[0],
            accel_x_m_s2: v[1],
            accel_y_m_s2: v[2],
            gyro_z_rad_s: v[3],
        });
    }
    if out.is_empty() {
        return Err(Error::CsvFormat {
            file: path.into(),
            message: "no data lines".into(),
        });
    }
    Ok(out)
}

/// Planar samples from an IMU table (its `t_s`, `accel_x/y`, `gyro_z` columns).
///
/// # Errors
/// Missing columns.
pub fn samples_from_table(t: &Table) -> Result<Vec<PlanarSample>> {
    let col = |c: &str| {
        t.column(c)
            .ok_or_else(|| invalid("imu", format!("missing column {c}")))
    };
    let (ts, ax, ay, wz) = (
        col("t_s")?,
        col("accel_x_m_s2")?,
        col("accel_y_m_s2")?,
        col("gyro_z_rad_s")?,
    );
    Ok((0..ts.len())
        .map(|i| PlanarSample {
            t_s: ts[i],
            accel_x_m_s2: ax[i],
            accel_y_m_s2: ay[i],
            gyro_z_rad_s: wz[i],
        })
        .collect())
}

/// Writes planar samples as an exercise `.dat` file (t, a_x, a_y, ω_z; shortest round-trip
/// numbers), atomically.
///
/// # Errors
/// [`Error::Io`].
pub fn write_dat(path: &Path, samples: &[PlanarSample]) -> Result<()> {
    let data: Vec<f64> = samples
        .iter()
        .flat_map(|s| [s.t_s, s.accel_x_m_s2, s.accel_y_m_s2, s.gyro_z_rad_s])
        .collect();
    write_atomically(path, |w| write_rows(w, &data, 4, b" "))
}

/// Planar samples as a table of [`PLANAR_COLUMNS`].
#[must_use]
pub fn samples_table(samples: &[PlanarSample]) -> Table {
    let mut t = Table::new(&PLANAR_COLUMNS);
    for s in samples {
        t.push_row(&[s.t_s, s.accel_x_m_s2, s.accel_y_m_s2, s.gyro_z_rad_s]);
    }
    t
}

/// The exercise's start position X₀, m (the default of `imukit integrate --planar` and Python's
/// `planar_dead_reckon`).
pub const EXERCISE_POSITION0_M: [f64; 2] = [100.0, 100.0];

/// A planar dead reckoning as a front end states it; checked once, in [`PlanarRequest::run`].
/// Errors name the fields as written here (`position0_m`, `heading0_rad`, `velocity0_m_s`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarRequest {
    /// The scheme.
    pub scheme: PlanarScheme,
    /// Start position, navigation X, Y, m.
    pub position0_m: [f64; 2],
    /// Start heading from nav X counter-clockwise, rad.
    pub heading0_rad: f64,
    /// Start velocity in the navigation frame, m/s.
    pub velocity0_m_s: [f64; 2],
}

impl Default for PlanarRequest {
    fn default() -> Self {
        Self {
            scheme: PlanarScheme::default(),
            position0_m: EXERCISE_POSITION0_M,
            heading0_rad: 0.0,
            velocity0_m_s: [0.0; 2],
        }
    }
}

impl PlanarRequest {
    /// The state at the first sample's time `t0_s`: the body-frame velocity is the navigation
    /// velocity turned by −heading (`v_b = R(α)ᵀ v_n`).
    ///
    /// # Errors
    /// Non-finite start values, named.
    pub fn initial_state(&self, t0_s: f64) -> Result<PlanarState> {
        finite_vec("position0_m", self.position0_m)
            .map_err(|e| e.of_option(RequestOption::Position0))?;
        finite_vec("heading0_rad", [self.heading0_rad])
            .map_err(|e| e.of_option(RequestOption::Heading0))?;
        finite_vec("velocity0_m_s", self.velocity0_m_s)
            .map_err(|e| e.of_option(RequestOption::Velocity0))?;
        let (s, c) = self.heading0_rad.sin_cos();
        let v = self.velocity0_m_s;
        Ok(PlanarState {
            t_s: t0_s,
            position_m: self.position0_m,
            heading_rad: self.heading0_rad,
            velocity_nav_m_s: v,
            velocity_body_m_s: [c * v[0] + s * v[1], -s * v[0] + c * v[1]],
        })
    }

    /// Dead reckoning of `samples` from this request's start with its scheme.
    ///
    /// # Errors
    /// As [`PlanarRequest::scheme`], [`PlanarRequest::initial_state`] and [`integrate`].
    pub fn run(&self, samples: &[PlanarSample]) -> Result<Table> {
        let scheme = self.scheme;
        let initial = self.initial_state(samples.first().map_or(0.0, |x| x.t_s))?;
        integrate(samples, scheme, initial)
    }
}

/// Dead reckoning of planar samples into a navigation table ([`PLANAR_NAV_COLUMNS`]).
///
/// # Errors
/// Non-finite values or non-increasing times, with the sample index.
pub fn integrate(
    samples: &[PlanarSample],
    scheme: PlanarScheme,
    initial: PlanarState,
) -> Result<Table> {
    let mut states = vec![PlanarState::default(); samples.len()];
    dead_reckon(samples, scheme, initial, &mut states).map_err(|source| Error::Planar {
        context: "planar IMU".into(),
        source,
    })?;
    let mut t = Table::new(&PLANAR_NAV_COLUMNS);
    for s in &states {
        t.push_row(&[
            s.t_s,
            s.position_m[0],
            s.position_m[1],
            s.heading_rad,
            s.velocity_nav_m_s[0],
            s.velocity_nav_m_s[1],
            s.velocity_body_m_s[0],
            s.velocity_body_m_s[1],
        ]);
    }
    t.check_finite("planar navigation")?;
    Ok(t)
}
