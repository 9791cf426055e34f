//! The array-level API behind the Python functions: plain slices in, [`Table`]s out, with errors
//! that name the argument and index.
use imu_core::ideal::at_lever_arm;
use imu_core::kinematics::sampled::SampledOptions;
use imu_core::kinematics::tangent::tangent_series;
use imu_core::{Body, Enu, EulerZyx, IdealReading, NavFrame, Ned, Rotation, Truth, Vec3};

use crate::error::{Error, Result, invalid};
use crate::io::columns::TRUTH_COLUMNS;
use crate::io::conventions::{AccelSignName, NavFrameName};
use crate::io::table::{ImuKind, Table};
use crate::motion::analytic::AnalyticOptions;
use crate::motion::{SampledAttitudeData, SampledPath, Trajectory};
use crate::run::simulate::motion_chunks;
use crate::scenario::resolve::finite_vec;
use crate::scenario::{ExpressionSpec, ImuSetup};

fn in_frame<T>(nav: NavFrameName, enu: impl FnOnce() -> T, ned: impl FnOnce() -> T) -> T {
    match nav {
        NavFrameName::ENU => enu(),
        NavFrameName::NED => ned(),
    }
}

/// The truth as a table, refused if a value is not finite.
fn finite_truth<N: NavFrame>(truth: &[Truth<N>]) -> Result<Table> {
    let table = Table::from_truth(truth);
    table.check_finite("truth")?;
    Ok(table)
}

/// Exact truth at `t_s` from formulas, written row by row into `out` (`n` rows of
/// [`TRUTH_COLUMNS`], row-major), a chunk at a time as `imukit simulate` streams it: no truth
/// vector or table of the whole series is built on the way.
///
/// # Errors
/// Unparsable formulas, non-increasing times, gimbal lock, non-finite results; an `out` of the
/// wrong length.
pub fn truth_from_expressions_into(
    t_s: Vec<f64>,
    spec: &ExpressionSpec,
    nav: NavFrameName,
    out: &mut [f64],
) -> Result<()> {
    const WIDTH: usize = TRUTH_COLUMNS.len();
    if out.len() != t_s.len() * WIDTH {
        return Err(invalid(
            "output",
            format!("has {} values, expected {} × {WIDTH}", out.len(), t_s.len()),
        ));
    }
    let min_speed_m_s =
        crate::scenario::resolve::check_min_speed("min_speed_m_s", spec.min_speed_m_s)?;
    let motion = spec.motion()?;
    let options = AnalyticOptions { min_speed_m_s };
    let what = "trajectory (expression)";
    imu_core::kinematics::check_times(&t_s).map_err(|e| crate::motion::with_time(&t_s, e, what))?;
    let times = crate::scenario::SampleTimes::Listed(t_s);
    let mut rows = out.chunks_exact_mut(WIDTH);
    let chunk = crate::run::simulate::STREAM_CHUNK;
    match nav {
        NavFrameName::ENU => {
            motion_chunks::<_, Enu>(&motion, options, &times, chunk, what, &mut |c| {
                fill_rows(c, &mut rows)
            })
        }
        NavFrameName::NED => {
            motion_chunks::<_, Ned>(&motion, options, &times, chunk, what, &mut |c| {
                fill_rows(c, &mut rows)
            })
        }
    }?;
    crate::io::table::check_finite(&TRUTH_COLUMNS, out, "truth")
}

/// Truth from sampled arrays by finite differences, written row by row into `out` (`n` rows of
/// [`TRUTH_COLUMNS`], row-major), chunk by chunk: no truth vector
/// or table of the whole series is built on the way.
///
/// # Errors
/// As [`SampledPath::truth`], with array indices; an `out` of the wrong length.
pub fn truth_from_arrays_into(
    t_s: Vec<f64>,
    position_m: Vec<[f64; 3]>,
    attitude: SampledAttitudeData,
    options: SampledOptions,
    nav: NavFrameName,
    out: &mut [f64],
) -> Result<()> {
    const WIDTH: usize = crate::io::columns::TRUTH_COLUMNS.len();
    if out.len() != t_s.len() * WIDTH {
        return Err(invalid(
            "output",
            format!("has {} values, expected {} × {WIDTH}", out.len(), t_s.len()),
        ));
    }
    let path = SampledPath {
        origin: "samples".into(),
        t_s,
        position_m,
        attitude,
        options,
        first_row: 0,
        geodetic: false,
    };
    let mut rows = out.chunks_exact_mut(WIDTH);
    const CHUNK: usize = 4096;
    match nav {
        NavFrameName::ENU => path.truth_chunks::<Enu>(CHUNK, &mut |c| fill_rows(c, &mut rows)),
        NavFrameName::NED => path.truth_chunks::<Ned>(CHUNK, &mut |c| fill_rows(c, &mut rows)),
    }?;
    crate::io::table::check_finite(&TRUTH_COLUMNS, out, "truth")
}

/// Writes truth samples into the next rows.
fn fill_rows<N: NavFrame>(
    chunk: &[Truth<N>],
    rows: &mut std::slice::ChunksExactMut<'_, f64>,
) -> Result<()> {
    for (s, row) in chunk.iter().zip(rows.by_ref()) {
        row.copy_from_slice(&crate::io::table::truth_row(s));
    }
    Ok(())
}

/// Truth samples from a table with the truth columns (attitude from the quaternion columns).
///
/// # Errors
/// Missing columns, non-finite values or zero quaternions (with the row index).
pub fn truth_from_table<N: NavFrame>(table: &Table) -> Result<Vec<Truth<N>>> {
    let idx: Vec<usize> = TRUTH_COLUMNS
        .iter()
        .map(|c| {
            table
                .columns
                .iter()
                .position(|h| h == c)
                .ok_or_else(|| invalid("truth", format!("missing column {c}")))
        })
        .collect::<Result<_>>()?;
    let width = table.columns.len();
    (0..table.rows())
        .map(|i| {
            let row = &table.data[i * width..(i + 1) * width];
            let v = |k: usize| row[idx[k]];
            if let Some(k) = (0..TRUTH_COLUMNS.len()).find(|&k| !v(k).is_finite()) {
                return Err(invalid(
                    "truth",
                    format!("row {i}, column {}: not a finite number", TRUTH_COLUMNS[k]),
                ));
            }
            let v3 = |k: usize| [v(k), v(k + 1), v(k + 2)];
            let attitude = Rotation::from_wxyz([v(10), v(11), v(12), v(13)])
                .ok_or_else(|| invalid("truth", format!("row {i}: quaternion has zero norm")))?;
            Ok(Truth {
                t_s: v(0),
                position_m: Vec3::from_array(v3(1)),
                velocity_m_s: Vec3::from_array(v3(4)),
                acceleration_m_s2: Vec3::from_array(v3(7)),
                attitude,
                euler: EulerZyx::from_array(v3(14)),
                omega_b_rad_s: Vec3::from_array(v3(17)),
                alpha_b_rad_s2: Vec3::from_array(v3(20)),
            })
        })
        .collect()
}

/// Ideal IMU readings from a truth table.
///
/// # Errors
/// As [`truth_from_table`]; a non-finite gravity.
pub fn ideal_from_truth(
    table: &Table,
    imu: &ImuSetup,
    gravity_m_s2: f64,
    nav: NavFrameName,
) -> Result<Table> {
    crate::scenario::resolve::check_gravity("gravity_m_s2", gravity_m_s2)?;
    fn run<N: NavFrame>(table: &Table, imu: &ImuSetup, g: f64) -> Result<Table> {
        let truth = truth_from_table::<N>(table)?;
        let mount = imu.mount::<N>(g);
        let mut readings = vec![IdealReading::default(); truth.len()];
        mount.read_into(&truth, &mut readings);
        let t: Vec<f64> = truth.iter().map(|s| s.t_s).collect();
        let readings: Vec<_> = readings
            .iter()
            .map(crate::scenario::sensors::ideal_as_reading)
            .collect();
        let table = Table::from_readings(&t, &readings, imu.kind);
        table.check_finite("IMU readings")?;
        Ok(table)
    }
    in_frame(
        nav,
        || run::<Enu>(table, imu, gravity_m_s2),
        || run::<Ned>(table, imu, gravity_m_s2),
    )
}

/// Ideal readings of a truth table as a front end states them (names for the kind, the sign and
/// the frame); checked once, in [`IdealRequest::run`]. Errors name the fields as written here.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealRequest {
    /// Which sensors.
    pub kind: ImuKind,
    /// Lever arm from the reference point to the IMU, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// The accelerometer sign.
    pub accel_sign: AccelSignName,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// Magnetic field, navigation frame, µT (`None`: MATLAB's default).
    pub magnetic_field_ut: Option<[f64; 3]>,
    /// The navigation frame.
    pub nav_frame: NavFrameName,
}

impl IdealRequest {
    /// Ideal IMU readings of `truth`.
    ///
    /// # Errors
    /// Non-finite vectors (named), and as [`ideal_from_truth`].
    pub fn run(&self, truth: &Table) -> Result<Table> {
        let lever_arm_m = finite_vec("lever_arm_m", self.lever_arm_m)?;
        let magnetic_field_ut = self
            .magnetic_field_ut
            .map(|m| finite_vec("magnetic_field_ut", m))
            .transpose()?;
        let imu = ImuSetup::ideal(
            self.kind,
            lever_arm_m,
            self.accel_sign.into(),
            magnetic_field_ut,
        );
        ideal_from_truth(truth, &imu, self.gravity_m_s2, self.nav_frame)
    }
}

/// Tangent Euler angles of a velocity series (hold at standstill, unwrapped yaw).
///
/// # Errors
/// Vertical velocity or non-finite values, with the index.
pub fn tangent_euler(velocity_m_s: &[[f64; 3]], min_speed_m_s: f64) -> Result<Vec<EulerZyx>> {
    let mut out = vec![EulerZyx::default(); velocity_m_s.len()];
    tangent_series(velocity_m_s, min_speed_m_s, &mut out).map_err(|source| Error::Kinematics {
        context: "velocity".into(),
        source,
    })?;
    Ok(out)
}

/// `C_nbᵀ v_n` for each sample: navigation-frame vectors resolved in the body frame.
#[must_use]
pub fn nav_to_body(euler: &[EulerZyx], v_n: &[[f64; 3]]) -> Vec<[f64; 3]> {
    euler
        .iter()
        .zip(v_n)
        .map(|(e, v)| {
            Rotation::<Body, Enu>::from_euler(*e)
                .inverse()
                .apply(Vec3::from_array(*v))
                .to_array()
        })
        .collect()
}

/// `a + ω × (ω × r) + α × r` for each sample (body frame).
#[must_use]
pub fn at_lever_arm_series(
    a: &[[f64; 3]],
    omega: &[[f64; 3]],
    alpha: &[[f64; 3]],
    r: [f64; 3],
) -> Vec<[f64; 3]> {
    let r = Vec3::<Body>::from_array(r);
    a.iter()
        .zip(omega)
        .zip(alpha)
        .map(|((a, w), al)| {
            at_lever_arm(
                Vec3::from_array(*a),
                Vec3::from_array(*w),
                Vec3::from_array(*al),
                r,
            )
            .to_array()
        })
        .collect()
}

/// Truth from body-frame acceleration and angular velocity arrays (MATLAB kinematicTrajectory).
///
/// # Errors
/// As [`imu_core::kinematics::body_rates::truth_from_body_rates`], with array indices.
pub fn truth_from_body_rates(
    t_s: &[f64],
    data: crate::motion::BodyRatesData,
    nav: NavFrameName,
) -> Result<Table> {
    let traj = Trajectory::BodyRates(data);
    in_frame(
        nav,
        || finite_truth(&traj.truth::<Enu>(t_s)?),
        || finite_truth(&traj.truth::<Ned>(t_s)?),
    )
}

/// Exact truth at `t_s` of a waypoint trajectory.
///
/// # Errors
/// As [`crate::motion::waypoints::Waypoints::new`]; the core's refusal.
pub fn truth_from_waypoints(
    t_s: &[f64],
    waypoints: crate::motion::waypoints::Waypoints,
    nav: NavFrameName,
) -> Result<Table> {
    let traj = Trajectory::Waypoints(waypoints);
    in_frame(
        nav,
        || finite_truth(&traj.truth::<Enu>(t_s)?),
        || finite_truth(&traj.truth::<Ned>(t_s)?),
    )
}

/// Refuses rows holding a value that is not finite, naming `name[i]`.
fn finite_rows<const K: usize>(name: &str, rows: &[[f64; K]]) -> Result<()> {
    match rows.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
        None => Ok(()),
        Some(i) => Err(invalid(format!("{name}[{i}]"), "is not finite")),
    }
}

/// Refuses matrices holding a value that is not finite, naming `dcm[i]`.
fn finite_matrices(dcm: &[[[f64; 3]; 3]]) -> Result<()> {
    match dcm
        .iter()
        .position(|m| !m.iter().flatten().all(|v| v.is_finite()))
    {
        None => Ok(()),
        Some(i) => Err(invalid(format!("dcm[{i}]"), "is not finite")),
    }
}

/// z-y-x Euler angles `[yaw, pitch, roll]` → quaternions `q_nb` `[w, x, y, z]`, row by row.
///
/// # Errors
/// A row that is not finite.
pub fn euler_to_quaternion(euler_rad: &[[f64; 3]]) -> Result<Vec<[f64; 4]>> {
    finite_rows("euler_rad", euler_rad)?;
    Ok(euler_rad
        .iter()
        .map(|e| Rotation::<Body, Enu>::from_euler(EulerZyx::from_array(*e)).to_wxyz())
        .collect())
}

/// Quaternions `[w, x, y, z]` → rotations, row by row.
///
/// # Errors
/// A quaternion of zero norm or not finite, named `quaternion[i]`.
fn rotations(quaternion: &[[f64; 4]]) -> Result<Vec<Rotation<Body, Enu>>> {
    quaternion
        .iter()
        .enumerate()
        .map(|(i, q)| {
            Rotation::from_wxyz(*q).ok_or_else(|| crate::Error::BadQuaternion {
                field: format!("quaternion[{i}]"),
            })
        })
        .collect()
}

/// Quaternions `q_nb` → z-y-x Euler angles, row by row.
///
/// # Errors
/// As [`quaternion_to_dcm`].
pub fn quaternion_to_euler(quaternion: &[[f64; 4]]) -> Result<Vec<[f64; 3]>> {
    Ok(rotations(quaternion)?
        .iter()
        .map(|r| r.to_euler().to_array())
        .collect())
}

/// Quaternions `q_nb` → direction cosine matrices `C_nb`, row by row.
///
/// # Errors
/// A quaternion of zero norm or not finite, named `quaternion[i]`.
pub fn quaternion_to_dcm(quaternion: &[[f64; 4]]) -> Result<Vec<[[f64; 3]; 3]>> {
    Ok(rotations(quaternion)?
        .iter()
        .map(Rotation::to_dcm)
        .collect())
}

/// z-y-x Euler angles → direction cosine matrices `C_nb`, row by row.
///
/// # Errors
/// A row that is not finite.
pub fn euler_to_dcm(euler_rad: &[[f64; 3]]) -> Result<Vec<[[f64; 3]; 3]>> {
    finite_rows("euler_rad", euler_rad)?;
    Ok(euler_rad
        .iter()
        .map(|e| EulerZyx::from_array(*e).to_dcm())
        .collect())
}

/// Direction cosine matrices `C_nb` → z-y-x Euler angles, row by row.
///
/// # Errors
/// A matrix that is not finite.
pub fn dcm_to_euler(dcm: &[[[f64; 3]; 3]]) -> Result<Vec<[f64; 3]>> {
    finite_matrices(dcm)?;
    Ok(dcm
        .iter()
        .map(|c| EulerZyx::from_dcm(c).to_array())
        .collect())
}

/// Direction cosine matrices `C_nb` → quaternions `q_nb`, row by row.
///
/// # Errors
/// A matrix that is not finite.
pub fn dcm_to_quaternion(dcm: &[[[f64; 3]; 3]]) -> Result<Vec<[f64; 4]>> {
    finite_matrices(dcm)?;
    Ok(dcm
        .iter()
        .map(|c| Rotation::<Body, Enu>::from_dcm(c).to_wxyz())
        .collect())
}
