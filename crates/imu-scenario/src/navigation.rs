//! 3D strapdown for the CLI and Python, and errors of an estimate against truth.
//!
//! IMU input: rates (`accel_*_m_s2`, `gyro_*_rad_s`, turned into increments by the trapezoid) or
//! increments (`dv_*_m_s`, `dtheta_*_rad`). The accelerometer columns must hold specific force
//! (imukit's default sign); data in MATLAB's sign is flipped with `accel_sign = matlab`.
//! Navigation output has the truth columns the integrator estimates: `t_s, pos_*, vel_*, q_*,
//! yaw_rad, pitch_rad, roll_rad`.
use imu_core::strapdown::rk4::strapdown_rates_rk4;
use std::io::Write;
use std::path::Path;

use imu_core::strapdown::step::{
    NavState, RateStrapdown, Strapdown, StrapdownError, StrapdownOptions, strapdown_increments,
    strapdown_rates,
};
use imu_core::{AccelSign, Enu, EulerZyx, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::scenario::NavFrameName;
use crate::table::{
    ACCEL_COLUMNS, AtomicFile, CsvRows, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS, Table, write_rows,
};

/// Navigation output columns.
pub const NAV_COLUMNS: [&str; 14] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
];

/// Columns [`compare`] reads from truth and estimate: the navigation columns up to the
/// quaternion.
pub const STATE_COLUMNS: &[&str] = NAV_COLUMNS.split_at(11).0;

/// Error columns of [`compare`].
pub const ERROR_COLUMNS: [&str; 9] = [
    "t_s",
    "pos_err_x_m",
    "pos_err_y_m",
    "pos_err_z_m",
    "pos_err_m",
    "vel_err_x_m_s",
    "vel_err_y_m_s",
    "vel_err_z_m_s",
    "att_err_rad",
];

/// The initial state of a 3D integration, frame-free (default: at rest at the origin, level).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialState {
    /// Position, navigation frame, m.
    pub position_m: [f64; 3],
    /// Velocity, navigation frame, m/s.
    pub velocity_m_s: [f64; 3],
    /// Attitude quaternion `q_nb` `[w, x, y, z]`.
    pub quaternion: [f64; 4],
}

impl Default for InitialState {
    fn default() -> Self {
        Self {
            position_m: [0.0; 3],
            velocity_m_s: [0.0; 3],
            quaternion: [1.0, 0.0, 0.0, 0.0],
        }
    }
}

impl InitialState {
    /// From position, velocity and z-y-x Euler angles.
    #[must_use]
    pub fn from_euler(position_m: [f64; 3], velocity_m_s: [f64; 3], euler: EulerZyx) -> Self {
        Self {
            position_m,
            velocity_m_s,
            quaternion: Rotation::<imu_core::Body, Enu>::from_euler(euler).to_wxyz(),
        }
    }

    /// The first row of a truth (or navigation) table.
    ///
    /// # Errors
    /// Missing columns or an empty table.
    pub fn from_table(t: &Table) -> Result<Self> {
        let first = |c: &str| {
            t.column(c)
                .and_then(|v| v.first().copied())
                .ok_or_else(|| invalid("initial state", format!("the truth file has no {c} value")))
        };
        Ok(Self {
            position_m: [first("pos_x_m")?, first("pos_y_m")?, first("pos_z_m")?],
            velocity_m_s: [
                first("vel_x_m_s")?,
                first("vel_y_m_s")?,
                first("vel_z_m_s")?,
            ],
            quaternion: [first("q_w")?, first("q_x")?, first("q_y")?, first("q_z")?],
        })
    }

    /// The first row of a truth CSV file (read alone: memory does not grow with the file).
    ///
    /// # Errors
    /// Missing columns, a bad first row (file, row, column), an empty file.
    pub fn from_csv(path: &Path) -> Result<Self> {
        const COLS: [&str; 10] = [
            "pos_x_m",
            "pos_y_m",
            "pos_z_m",
            "vel_x_m_s",
            "vel_y_m_s",
            "vel_z_m_s",
            "q_w",
            "q_x",
            "q_y",
            "q_z",
        ];
        let mut rows = CsvRows::open(path, &COLS, "the initial state comes from a truth CSV")?;
        let mut r = [0.0; 10];
        if rows.next_row(&mut r)?.is_none() {
            return Err(crate::Error::CsvFormat {
                file: path.into(),
                message: "no data rows after the header".into(),
            });
        }
        Ok(Self {
            position_m: [r[0], r[1], r[2]],
            velocity_m_s: [r[3], r[4], r[5]],
            quaternion: [r[6], r[7], r[8], r[9]],
        })
    }
}

/// The 3D integration scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NavScheme {
    /// DESIGN §6: exact rotation-vector step, two-sample coning and sculling, trapezoidal
    /// position; rates or increments; second order.
    #[default]
    ConingSculling,
    /// RK4 with `substeps` per interval and quintic interpolation of the rate samples; rates only;
    /// fourth order (see `imu_core::strapdown::rk4`).
    Rk4 {
        /// RK4 steps per sample interval.
        substeps: usize,
    },
}

/// What to integrate and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavSetup {
    /// Navigation frame.
    pub nav_frame: NavFrameName,
    /// Algorithm options (gravity, coning, sculling).
    pub options: StrapdownOptions,
    /// Sign of the accelerometer columns.
    pub accel_sign: AccelSign,
    /// Integration scheme.
    pub scheme: NavScheme,
}

impl Default for NavSetup {
    fn default() -> Self {
        Self {
            nav_frame: NavFrameName::ENU,
            options: StrapdownOptions::default(),
            accel_sign: AccelSign::SpecificForce,
            scheme: NavScheme::ConingSculling,
        }
    }
}

/// Intervals longer than this many median intervals count as gaps in the data.
pub const MAX_GAP_FACTOR: f64 = 2.5;

/// Refuses a gap in sample times: an interval longer than [`MAX_GAP_FACTOR`] median intervals
/// (missing samples would be bridged silently by the integration). `first_row` is the file row of
/// sample 0 (2 below a CSV header), for the message.
///
/// # Errors
/// [`crate::Error::Invalid`] naming the rows and the intervals.
pub fn check_gaps(t_s: &[f64], what: &str, first_row: usize) -> Result<()> {
    if t_s.len() < 3 {
        return Ok(());
    }
    let median = median_interval(t_s);
    let found = t_s
        .windows(2)
        .map(|w| w[1] - w[0])
        .enumerate()
        .find(|(_, d)| *d > MAX_GAP_FACTOR * median);
    match found {
        Some((i, d)) => Err(gap_error(what, i + first_row, d, median)),
        None => Ok(()),
    }
}

/// The median interval of increasing times (at least 2).
fn median_interval(t_s: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    dt[dt.len() / 2]
}

fn gap_error(what: &str, row: usize, d: f64, median: f64) -> crate::Error {
    invalid(
        what,
        format!(
            "gap in the sample times between rows {row} and {} ({d} s, the median interval is {median} s)",
            row + 1
        ),
    )
}

fn triples(t: &Table, names: &[&str; 3]) -> Option<Vec<[f64; 3]>> {
    let c: Vec<Vec<f64>> = names.iter().map(|n| t.column(n)).collect::<Option<_>>()?;
    Some((0..t.rows()).map(|i| [c[0][i], c[1][i], c[2][i]]).collect())
}

/// Integrates an IMU table (rates or increments) from `initial`.
///
/// # Errors
/// Missing columns (both layouts named), invalid initial quaternion, non-finite values or
/// non-increasing times (sample index named).
pub fn integrate(imu: &Table, initial: &InitialState, setup: &NavSetup) -> Result<Table> {
    match setup.nav_frame {
        NavFrameName::ENU => integrate_in::<Enu>(imu, initial, setup),
        NavFrameName::NED => integrate_in::<Ned>(imu, initial, setup),
    }
}

fn integrate_in<N: NavFrame>(
    imu: &Table,
    initial: &InitialState,
    setup: &NavSetup,
) -> Result<Table> {
    let t = imu
        .column("t_s")
        .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
    if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1] || t[i].is_nan()) {
        return Err(invalid(
            "IMU data",
            format!(
                "time at row {} does not increase after row {}",
                i + 2,
                i + 1
            ),
        ));
    }
    check_gaps(&t, "IMU data", 2)?;
    let attitude = Rotation::from_wxyz(initial.quaternion).ok_or_else(|| {
        invalid(
            "initial state",
            "the quaternion has zero norm or is not finite",
        )
    })?;
    let s0 = NavState::<N> {
        t_s: t.first().copied().unwrap_or(0.0),
        attitude,
        velocity_m_s: Vec3::from_array(initial.velocity_m_s),
        position_m: Vec3::from_array(initial.position_m),
    };
    let flip = |v: Vec<[f64; 3]>| match setup.accel_sign {
        AccelSign::SpecificForce => v,
        AccelSign::Matlab => v.into_iter().map(|a| a.map(|x| -x)).collect(),
    };
    let mut out = vec![NavState::<N>::default(); t.len()];
    let result = if let (Some(f), Some(w)) =
        (triples(imu, &ACCEL_COLUMNS), triples(imu, &GYRO_COLUMNS))
    {
        match setup.scheme {
            NavScheme::ConingSculling => {
                strapdown_rates(&t, &w, &flip(f), s0, setup.options, &mut out)
            }
            NavScheme::Rk4 { substeps } => strapdown_rates_rk4(
                &t,
                &w,
                &flip(f),
                s0,
                setup.options.gravity_m_s2,
                substeps,
                &mut out,
            ),
        }
    } else if let (Some(dv), Some(dth)) = (triples(imu, &DV_COLUMNS), triples(imu, &DTHETA_COLUMNS))
    {
        if setup.scheme != NavScheme::ConingSculling {
            return Err(invalid(
                "IMU data",
                "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
            ));
        }
        strapdown_increments(&t, &dth, &flip(dv), s0, setup.options, &mut out)
    } else {
        return Err(invalid(
            "IMU data",
            "needs accel_x/y/z_m_s2 and gyro_x/y/z_rad_s (rates) or dv_x/y/z_m_s and dtheta_x/y/z_rad (increments)",
        ));
    };
    result.map_err(|e| invalid("IMU data", e.to_string()))?;
    let mut table = Table::new(&NAV_COLUMNS);
    let mut last_yaw: Option<f64> = None;
    for s in &out {
        table.push_row(&nav_row(s, &mut last_yaw));
    }
    Ok(table)
}

/// One navigation output row in [`NAV_COLUMNS`] order; yaw is unwrapped against `last_yaw`.
fn nav_row<N: NavFrame>(s: &NavState<N>, last_yaw: &mut Option<f64>) -> [f64; 14] {
    let [qw, qx, qy, qz] = s.attitude.to_wxyz();
    let mut e = s.attitude.to_euler();
    if let Some(y) = *last_yaw {
        let tau = std::f64::consts::TAU;
        e.yaw_rad += tau * ((y - e.yaw_rad) / tau).round();
    }
    *last_yaw = Some(e.yaw_rad);
    let [px, py, pz] = s.position_m.to_array();
    let [vx, vy, vz] = s.velocity_m_s.to_array();
    [
        s.t_s,
        px,
        py,
        pz,
        vx,
        vy,
        vz,
        qw,
        qx,
        qy,
        qz,
        e.yaw_rad,
        e.pitch_rad,
        e.roll_rad,
    ]
}

/// Errors of an estimate against truth, both tables with `t_s`, positions, velocities and
/// quaternions, on the estimate's times (truth linearly interpolated in position and velocity,
/// its attitude by quaternion slerp).
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Per sample ([`ERROR_COLUMNS`]).
    pub table: Table,
    /// RMS of the position error norm, m.
    pub position_rms_m: f64,
    /// Final position error norm, m.
    pub position_final_m: f64,
    /// RMS of the velocity error norm, m/s.
    pub velocity_rms_m_s: f64,
    /// Final velocity error norm, m/s.
    pub velocity_final_m_s: f64,
    /// RMS of the attitude error angle, rad.
    pub attitude_rms_rad: f64,
    /// Final attitude error angle, rad.
    pub attitude_final_rad: f64,
}

/// Compares an estimate with truth (see [`Comparison`]).
///
/// # Errors
/// Missing columns; estimate times outside the truth's time span.
pub fn compare(truth: &Table, estimate: &Table) -> Result<Comparison> {
    let col = |t: &Table, what: &str, c: &str| {
        t.column(c)
            .ok_or_else(|| invalid(what, format!("missing column {c}")))
    };
    let names = &STATE_COLUMNS[1..];
    let tt = col(truth, "truth", "t_s")?;
    let te = col(estimate, "estimate", "t_s")?;
    let tv: Vec<Vec<f64>> = names
        .iter()
        .map(|c| col(truth, "truth", c))
        .collect::<Result<_>>()?;
    let ev: Vec<Vec<f64>> = names
        .iter()
        .map(|c| col(estimate, "estimate", c))
        .collect::<Result<_>>()?;
    if tt.is_empty() || te.is_empty() {
        return Err(invalid("compare", "empty table"));
    }
    let (t0, t1) = (tt[0], tt[tt.len() - 1]);
    let mut table = Table::new(&ERROR_COLUMNS);
    let (mut sp, mut sv, mut sa) = (0.0, 0.0, 0.0);
    let (mut fp, mut fv, mut fa) = (0.0, 0.0, 0.0);
    for (i, &t) in te.iter().enumerate() {
        if t < t0 - 1e-9 || t > t1 + 1e-9 {
            return Err(invalid(
                "compare",
                format!(
                    "estimate time {t} s (row {}) is outside the truth's {t0}…{t1} s",
                    i + 2
                ),
            ));
        }
        // Bracketing truth samples ka ≤ t ≤ kb (a single-row truth brackets with itself).
        let (ka, kb) = if tt.len() == 1 {
            (0, 0)
        } else {
            let k = tt.partition_point(|&x| x <= t).clamp(1, tt.len() - 1);
            (k - 1, k)
        };
        let w = if kb == ka || tt[kb] == tt[ka] {
            0.0
        } else {
            ((t - tt[ka]) / (tt[kb] - tt[ka])).clamp(0.0, 1.0)
        };
        let lerp = |c: usize| tv[c][ka] + w * (tv[c][kb] - tv[c][ka]);
        let dp: [f64; 3] = std::array::from_fn(|j| ev[j][i] - lerp(j));
        let dv: [f64; 3] = std::array::from_fn(|j| ev[3 + j][i] - lerp(3 + j));
        let q = |v: &Vec<Vec<f64>>, r: usize| {
            Rotation::<imu_core::Body, Enu>::from_wxyz([v[6][r], v[7][r], v[8][r], v[9][r]])
        };
        let (qa, qb, qe) = match (q(&tv, ka), q(&tv, kb), q(&ev, i)) {
            (Some(a), Some(b), Some(e)) => (a, b, e),
            _ => {
                return Err(invalid(
                    "compare",
                    format!("zero quaternion near estimate row {}", i + 2),
                ));
            }
        };
        let qt = qa.quaternion().slerp(qb.quaternion(), w);
        let att = qe.quaternion().angle_to(&qt);
        let (np, nv) = (
            dp.iter().map(|x| x * x).sum::<f64>().sqrt(),
            dv.iter().map(|x| x * x).sum::<f64>().sqrt(),
        );
        table.push_row(&[t, dp[0], dp[1], dp[2], np, dv[0], dv[1], dv[2], att]);
        (sp, sv, sa) = (sp + np * np, sv + nv * nv, sa + att * att);
        (fp, fv, fa) = (np, nv, att);
    }
    let n = te.len() as f64;
    Ok(Comparison {
        table,
        position_rms_m: (sp / n).sqrt(),
        position_final_m: fp,
        velocity_rms_m_s: (sv / n).sqrt(),
        velocity_final_m_s: fv,
        attitude_rms_rad: (sa / n).sqrt(),
        attitude_final_rad: fa,
    })
}

/// Rows a streamed integration reads ahead to set the reference interval of the gap check (the
/// median of their intervals; files this short are checked exactly as [`integrate`] checks).
pub const GAP_WINDOW: usize = 1001;

/// What a streamed integration wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavSummary {
    /// Rows written.
    pub rows: usize,
    /// The last position, m.
    pub end_position_m: [f64; 3],
}

/// Integrates the IMU CSV file `input` into the navigation CSV `out` ([`NAV_COLUMNS`]), the
/// same numbers as [`integrate`]. The coning/sculling scheme streams (memory does not grow with
/// the file; gaps are judged against the median interval of the first [`GAP_WINDOW`] rows); the
/// RK4 scheme, which interpolates over neighbouring samples, reads the file whole. `out`
/// appears only when complete.
///
/// # Errors
/// As [`integrate`], CSV errors naming file, row and column, and I/O errors.
pub fn integrate_csv(
    input: &Path,
    initial: &InitialState,
    setup: &NavSetup,
    out: &Path,
) -> Result<NavSummary> {
    if setup.scheme != NavScheme::ConingSculling {
        let nav = integrate(&crate::table::read_table(input)?, initial, setup)?;
        nav.write_csv(out)?;
        let last = |c: &str| nav.column(c).and_then(|v| v.last().copied()).unwrap_or(0.0);
        return Ok(NavSummary {
            rows: nav.rows(),
            end_position_m: [last("pos_x_m"), last("pos_y_m"), last("pos_z_m")],
        });
    }
    match setup.nav_frame {
        NavFrameName::ENU => integrate_csv_in::<Enu>(input, initial, setup, out),
        NavFrameName::NED => integrate_csv_in::<Ned>(input, initial, setup, out),
    }
}

/// The per-sample integrator of a streamed file.
enum Stepper<N> {
    Rates(RateStrapdown<N>),
    Increments { nav: Strapdown<N>, started: bool },
}

impl<N: NavFrame> Stepper<N> {
    /// `force` is the accelerometer column (rates) or Δv, `turn` the gyroscope column or Δθ.
    fn step(
        &mut self,
        t_s: f64,
        force: [f64; 3],
        turn: [f64; 3],
    ) -> core::result::Result<NavState<N>, StrapdownError> {
        match self {
            Self::Rates(r) => r.step(t_s, turn, force),
            Self::Increments { nav, started } if !*started => {
                *started = true;
                Ok(*nav.state())
            }
            Self::Increments { nav, .. } => nav.step(t_s, turn, force),
        }
    }
}

fn integrate_csv_in<N: NavFrame>(
    input: &Path,
    initial: &InitialState,
    setup: &NavSetup,
    out: &Path,
) -> Result<NavSummary> {
    let header = crate::table::read_header(input)?;
    let has_all = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
    let rates = has_all(&ACCEL_COLUMNS) && has_all(&GYRO_COLUMNS);
    let (force, turn) = if rates {
        (ACCEL_COLUMNS, GYRO_COLUMNS)
    } else if has_all(&DV_COLUMNS) && has_all(&DTHETA_COLUMNS) {
        (DV_COLUMNS, DTHETA_COLUMNS)
    } else {
        return Err(invalid(
            "IMU data",
            "needs accel_x/y/z_m_s2 and gyro_x/y/z_rad_s (rates) or dv_x/y/z_m_s and dtheta_x/y/z_rad (increments)",
        ));
    };
    let mut columns = vec!["t_s"];
    columns.extend(force);
    columns.extend(turn);
    let mut rows = CsvRows::open(input, &columns, "")?;
    let mut row = [0.0; 7];
    let mut ahead: Vec<[f64; 7]> = Vec::with_capacity(GAP_WINDOW + 1);
    while ahead.len() <= GAP_WINDOW && rows.next_row(&mut row)?.is_some() {
        ahead.push(row);
    }
    if ahead.is_empty() {
        return Err(crate::Error::CsvFormat {
            file: input.into(),
            message: "no data rows after the header".into(),
        });
    }
    let times: Vec<f64> = ahead.iter().map(|r| r[0]).collect();
    let median = if times.len() > 2 {
        Some(median_interval(&times))
    } else {
        None
    };
    let attitude = Rotation::from_wxyz(initial.quaternion).ok_or_else(|| {
        invalid(
            "initial state",
            "the quaternion has zero norm or is not finite",
        )
    })?;
    let s0 = NavState::<N> {
        t_s: times[0],
        attitude,
        velocity_m_s: Vec3::from_array(initial.velocity_m_s),
        position_m: Vec3::from_array(initial.position_m),
    };
    let mut stepper = if rates {
        Stepper::Rates(RateStrapdown::new(s0, setup.options))
    } else {
        Stepper::Increments {
            nav: Strapdown::new(s0, setup.options),
            started: false,
        }
    };
    let sign = match setup.accel_sign {
        AccelSign::SpecificForce => 1.0,
        AccelSign::Matlab => -1.0,
    };
    let mut file = AtomicFile::create(out)?;
    file.writer()
        .write_all(NAV_COLUMNS.join(",").as_bytes())
        .and_then(|()| file.writer().write_all(b"\n"))
        .map_err(|e| file.error(e))?;
    let (mut last_yaw, mut previous_t, mut end) = (None, None::<f64>, s0);
    let mut i = 0usize;
    let mut process = |r: &[f64; 7], file: &mut AtomicFile| -> Result<()> {
        let t = r[0];
        if let Some(p) = previous_t {
            if t <= p {
                return Err(invalid(
                    "IMU data",
                    format!(
                        "time at row {} does not increase after row {}",
                        i + 2,
                        i + 1
                    ),
                ));
            }
            if let Some(m) = median.filter(|m| t - p > MAX_GAP_FACTOR * m) {
                return Err(gap_error("IMU data", i + 1, t - p, m));
            }
        }
        previous_t = Some(t);
        let f = [sign * r[1], sign * r[2], sign * r[3]];
        let state = stepper
            .step(t, f, [r[4], r[5], r[6]])
            .map_err(|e| invalid("IMU data", e.to_string()))?;
        write_rows(
            file.writer(),
            &nav_row(&state, &mut last_yaw),
            NAV_COLUMNS.len(),
            b",",
        )
        .map_err(|e| file.error(e))?;
        end = state;
        i += 1;
        Ok(())
    };
    for r in &ahead {
        process(r, &mut file)?;
    }
    while rows.next_row(&mut row)?.is_some() {
        process(&row, &mut file)?;
    }
    file.commit()?;
    Ok(NavSummary {
        rows: i,
        end_position_m: end.position_m.to_array(),
    })
}
