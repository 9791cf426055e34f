//! Scenarios and truth: `simulate` (TOML/JSON text or a dict), truth from formulas, samples,
//! body rates and waypoints, ideal readings of a truth table, the built-in scenarios, and the
//! array helpers of the compatibility module.
use std::collections::BTreeMap;
use std::path::Path;

use imu_core::EulerZyx;
use imu_core::kinematics::sampled::SampledOptions;
use imu_core::kinematics::tangent::DEFAULT_MIN_SPEED_M_S;
use imukit::ScenarioSpec;
use imukit::arrays::{self, IdealRequest};
use imukit::choice::Choice;
use imukit::io::columns::TRUTH_COLUMNS;
use imukit::io::conventions::{AccelSignName, NavFrameName};
use imukit::io::table::ImuKind;
use imukit::motion::waypoints::Waypoints;
use imukit::motion::{BodyRatesData, SampledAttitudeData};
use imukit::pipeline::RunThreads;
use imukit::scenario::{ExpressionSpec, Formula, builtin};
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{
    DescribedOut, TableOut, check_len, choice, described_out, description_dict, fixed, fixed_opt,
    non_negative, rows, rows_out, table_in, table_out, value_tree, vector,
};
use crate::errors::{refused, shape_error};

/// Truth (unless left out), IMU and (when the scenario has them) GNSS, barometer and odometer
/// tables of one run, and the warnings the user should see (the scenario's, the run's).
type SimulationOut<'py> = (
    Option<DescribedOut<'py>>,
    DescribedOut<'py>,
    Option<DescribedOut<'py>>,
    Option<DescribedOut<'py>>,
    Option<DescribedOut<'py>>,
    Vec<String>,
);

/// A scenario spec from TOML or JSON text.
fn text_spec(text: &str, format: &str, origin: &str) -> PyResult<ScenarioSpec> {
    match format {
        "toml" => ScenarioSpec::from_toml(text, origin),
        "json" => ScenarioSpec::from_json(text, origin),
        other => {
            return Err(PyValueError::new_err(format!(
                "format must be \"toml\" or \"json\", got {other:?}"
            )));
        }
    }
    .map_err(refused)
}

/// A scenario spec from a dict (keys as in a file, values typed: `inf` and integers kept).
fn dict_spec(scenario: &Bound<'_, PyAny>, origin: &str) -> PyResult<ScenarioSpec> {
    ScenarioSpec::from_tree(&value_tree(scenario, "scenario")?, origin).map_err(refused)
}

/// Runs a resolved scenario spec on at most `threads` threads with the GIL released, the truth
/// (when `truth`) and IMU rows written straight into NumPy arrays (NumPy's allocator: huge pages
/// where the kernel offers them), the IMU rows into `imu_out` when given (a Monte Carlo run's
/// slot of the gathered array, of the run's shape).
#[allow(clippy::too_many_arguments)]
fn run_spec<'py>(
    py: Python<'py>,
    spec: ScenarioSpec,
    base_dir: &str,
    run: Option<i64>,
    threads: Option<i64>,
    truth: bool,
    imu_out: Option<Bound<'py, PyArray2<f64>>>,
) -> PyResult<SimulationOut<'py>> {
    let run = run.map(|r| non_negative("run", r)).transpose()?;
    let threads = RunThreads::at_most(threads, "threads").map_err(refused)?;
    let base = base_dir.to_string();
    let (scenario, shape, described) = py
        .detach(move || {
            let sc = spec.resolve(Path::new(&base))?;
            let shape = sc.gathered_shape()?;
            let described = sc.description(None);
            Ok::<_, imukit::Error>((sc, shape, described))
        })
        .map_err(refused)?;
    // Each table is described as the scenario's, of its own kind.
    let of_kind = |columns: &[String]| imukit::io::description::Description {
        kind: imukit::io::schema::TableKind::detect(columns),
        ..described.clone()
    };
    let truth =
        truth.then(|| PyArray2::<f64>::zeros(py, [shape.rows, shape.truth_columns.len()], false));
    let imu_shape = [shape.rows, shape.imu_columns.len()];
    let imu = match imu_out {
        Some(out) if out.shape() == imu_shape => out,
        Some(out) => {
            return Err(shape_error(format!(
                "imu_out has shape {:?}, the run makes {imu_shape:?}",
                out.shape()
            )));
        }
        None => PyArray2::<f64>::zeros(py, imu_shape, false),
    };
    let mut warnings = scenario.warnings.clone();
    let sample_rate_hz = scenario.sample_rate_hz;
    let aids = {
        let mut truth_rw = truth.as_ref().map(|t| t.readwrite());
        let mut imu_rw = imu.readwrite();
        let truth_values = truth_rw
            .as_mut()
            .map(|t| t.as_slice_mut().map_err(|e| shape_error(e.to_string())))
            .transpose()?;
        let imu_values = imu_rw
            .as_slice_mut()
            .map_err(|e| shape_error(e.to_string()))?;
        py.detach(move || scenario.simulate_streamed_into(run, threads, truth_values, imu_values))
            .map_err(refused)?
    };
    warnings.extend(aids.report.warnings(sample_rate_hz));
    let names = |c: Vec<&str>| c.into_iter().map(str::to_string).collect::<Vec<String>>();
    let optional = |t: Option<imukit::Table>| {
        t.map(|t| {
            let d = of_kind(&t.columns);
            described_out(py, t, &d)
        })
        .transpose()
    };
    let with_description = |columns: Vec<String>, values| {
        let d = description_dict(py, &of_kind(&columns))?;
        Ok::<_, PyErr>((columns, values, d))
    };
    Ok((
        truth
            .map(|t| with_description(names(shape.truth_columns), t))
            .transpose()?,
        with_description(names(shape.imu_columns), imu)?,
        optional(aids.gnss)?,
        optional(aids.baro)?,
        optional(aids.odometer)?,
        warnings,
    ))
}

/// Resolves and runs a scenario given as TOML or JSON text; returns the (truth or None unless
/// `truth`, imu, gnss, baro, odometer or None) tables.
#[pyfunction]
#[pyo3(signature = (text, *, format = "toml", origin = "scenario", base_dir = ".", run = None, threads = None,
                    truth = true, imu_out = None))]
#[allow(clippy::too_many_arguments)]
fn simulate_text<'py>(
    py: Python<'py>,
    text: &str,
    format: &str,
    origin: &str,
    base_dir: &str,
    run: Option<i64>,
    threads: Option<i64>,
    truth: bool,
    imu_out: Option<Bound<'py, PyArray2<f64>>>,
) -> PyResult<SimulationOut<'py>> {
    let spec = text_spec(text, format, origin)?;
    run_spec(py, spec, base_dir, run, threads, truth, imu_out)
}

/// Resolves and runs a scenario given as a dict (keys as in a file, values typed: `inf` and
/// integers kept); returns the tables as [`simulate_text`].
#[pyfunction]
#[pyo3(signature = (scenario, *, origin = "scenario dict", base_dir = ".", run = None, threads = None,
                    truth = true, imu_out = None))]
#[allow(clippy::too_many_arguments)]
fn simulate_dict<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    origin: &str,
    base_dir: &str,
    run: Option<i64>,
    threads: Option<i64>,
    truth: bool,
    imu_out: Option<Bound<'py, PyArray2<f64>>>,
) -> PyResult<SimulationOut<'py>> {
    let spec = dict_spec(scenario, origin)?;
    run_spec(py, spec, base_dir, run, threads, truth, imu_out)
}

/// Writes one run's readings (`columns`, `values`) at `path` as the command line's `simulate
/// --runs` writes them: described by the scenario (TOML or JSON text, or a dict with
/// `format = "dict"`, resolved against `base_dir`), whose text goes into the description.
#[pyfunction]
#[pyo3(signature = (path, columns, values, scenario, *, format, origin, base_dir))]
#[allow(clippy::too_many_arguments)]
fn write_run(
    py: Python<'_>,
    path: &str,
    columns: Vec<String>,
    values: numpy::PyReadonlyArray2<'_, f64>,
    scenario: &Bound<'_, PyAny>,
    format: &str,
    origin: &str,
    base_dir: &str,
) -> PyResult<()> {
    let (spec, text) = if format == "dict" {
        (dict_spec(scenario, origin)?, None)
    } else {
        let text: String = scenario.extract()?;
        (text_spec(&text, format, origin)?, Some(text))
    };
    let table = crate::convert::table_in("values", columns, &values)?;
    let base = std::path::PathBuf::from(base_dir);
    py.detach(move || {
        let described = spec.resolve(&base)?.description(text);
        table.write_described(std::path::Path::new(path), &described)
    })
    .map_err(refused)
}

/// The rows and IMU columns one run of a scenario makes (TOML or JSON text, or a dict with
/// `format = "dict"`), and the truth columns that differ by run, refused as a run would be,
/// without running it: what a caller allocates for many runs' readings.
#[pyfunction]
#[pyo3(signature = (scenario, *, format, origin, base_dir))]
fn simulation_shape(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    format: &str,
    origin: &str,
    base_dir: &str,
) -> PyResult<(usize, Vec<String>, Vec<String>)> {
    let spec = if format == "dict" {
        dict_spec(scenario, origin)?
    } else {
        text_spec(&scenario.extract::<String>()?, format, origin)?
    };
    let base = base_dir.to_string();
    let (shape, by_run) = py
        .detach(move || {
            let scenario = spec.resolve(Path::new(&base))?;
            Ok::<_, imukit::Error>((
                scenario.gathered_shape()?,
                scenario.truth_columns_of_each_run(),
            ))
        })
        .map_err(refused)?;
    let columns = shape.imu_columns.into_iter().map(str::to_string).collect();
    let by_run = by_run.iter().map(|c| (*c).to_string()).collect();
    Ok((shape.rows, columns, by_run))
}

/// Exact truth from formula strings at the times `t_s`.
#[pyfunction]
#[pyo3(signature = (t_s, position_m, *, attitude = None, yaw_rad = None, pitch_rad = None, roll_rad = None,
                    constants = None, nav_frame = NavFrameName::default_name(), min_speed_m_s = None))]
#[allow(clippy::too_many_arguments)]
fn truth_from_expressions<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    position_m: [String; 3],
    attitude: Option<String>,
    yaw_rad: Option<String>,
    pitch_rad: Option<String>,
    roll_rad: Option<String>,
    constants: Option<BTreeMap<String, f64>>,
    nav_frame: &str,
    min_speed_m_s: Option<f64>,
) -> PyResult<TableOut<'py>> {
    let t = vector(&t_s);
    let spec = ExpressionSpec {
        constants: constants.unwrap_or_default(),
        position_m: Some(position_m.map(Formula::Text)),
        latitude_rad: None,
        longitude_rad: None,
        height_m: None,
        attitude: attitude
            .map(|a| choice::<imukit::scenario::spec::AttitudeMode>("attitude", &a))
            .transpose()?,
        yaw_rad: yaw_rad.map(Formula::Text),
        pitch_rad: pitch_rad.map(Formula::Text),
        roll_rad: roll_rad.map(Formula::Text),
        min_speed_m_s,
    };
    let nav = choice::<NavFrameName>("nav_frame", nav_frame)?;
    let out = PyArray2::<f64>::zeros(py, [t.len(), TRUTH_COLUMNS.len()], false);
    {
        let mut guard = out.readwrite();
        let values = guard
            .as_slice_mut()
            .map_err(|e| shape_error(e.to_string()))?;
        py.detach(move || arrays::truth_from_expressions_into(t, &spec, nav, values))
            .map_err(refused)?;
    }
    let columns = TRUTH_COLUMNS.iter().map(|c| (*c).to_string()).collect();
    Ok((columns, out))
}

/// The attitude arguments of `truth_from_samples` as the library's attitude.
fn sampled_attitude(
    n: usize,
    euler_rad: Option<PyReadonlyArray2<'_, f64>>,
    quaternion: Option<PyReadonlyArray2<'_, f64>>,
    attitude: Option<&str>,
) -> PyResult<SampledAttitudeData> {
    Ok(match (euler_rad, quaternion, attitude) {
        (Some(e), None, None) => {
            let e = rows::<3>("euler_rad", &e)?;
            check_len("euler_rad", e.len(), n)?;
            SampledAttitudeData::Euler(e.into_iter().map(EulerZyx::from_array).collect())
        }
        (None, Some(q), None) => {
            let q = rows::<4>("quaternion", &q)?;
            check_len("quaternion", q.len(), n)?;
            SampledAttitudeData::Quaternion(q)
        }
        (None, None, Some("tangent")) => SampledAttitudeData::Tangent,
        (None, None, Some("level") | None) => {
            SampledAttitudeData::Euler(vec![EulerZyx::default(); n])
        }
        (None, None, Some(other)) => {
            return Err(PyValueError::new_err(format!(
                "attitude must be \"tangent\" or \"level\", got {other:?}"
            )));
        }
        _ => {
            return Err(PyValueError::new_err(
                "give at most one of euler_rad, quaternion and attitude",
            ));
        }
    })
}

/// Truth from sampled positions and attitude by finite differences.
#[pyfunction]
#[pyo3(signature = (t_s, position_m, *, euler_rad = None, quaternion = None, attitude = None, order = 6,
                    nav_frame = NavFrameName::default_name(), min_speed_m_s = None))]
#[allow(clippy::too_many_arguments)]
fn truth_from_samples<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    position_m: PyReadonlyArray2<'py, f64>,
    euler_rad: Option<PyReadonlyArray2<'py, f64>>,
    quaternion: Option<PyReadonlyArray2<'py, f64>>,
    attitude: Option<&str>,
    order: i64,
    nav_frame: &str,
    min_speed_m_s: Option<f64>,
) -> PyResult<TableOut<'py>> {
    let order = usize::try_from(non_negative("order", order)?).unwrap_or(usize::MAX);
    let t = vector(&t_s);
    let pos = rows::<3>("position_m", &position_m)?;
    check_len("position_m", pos.len(), t.len())?;
    let att = sampled_attitude(t.len(), euler_rad, quaternion, attitude)?;
    let options = SampledOptions {
        order,
        min_speed_m_s: min_speed_m_s.unwrap_or(DEFAULT_MIN_SPEED_M_S),
    };
    let nav = choice::<NavFrameName>("nav_frame", nav_frame)?;
    let out = PyArray2::<f64>::zeros(py, [t.len(), TRUTH_COLUMNS.len()], false);
    {
        let mut guard = out.readwrite();
        let values = guard
            .as_slice_mut()
            .map_err(|e| shape_error(e.to_string()))?;
        py.detach(move || arrays::truth_from_arrays_into(t, pos, att, options, nav, values))
            .map_err(refused)?;
    }
    let columns = TRUTH_COLUMNS.iter().map(|c| (*c).to_string()).collect();
    Ok((columns, out))
}

/// Ideal IMU readings from a truth table (its column names and values).
#[pyfunction]
#[pyo3(signature = (columns, values, *, lever_arm_m = vec![0.0, 0.0, 0.0], accel_sign = AccelSignName::default_name(),
                    gravity_m_s2 = imu_core::DEFAULT_GRAVITY_M_S2, magnetic_field_ut = None,
                    nav_frame = NavFrameName::default_name(), kind = ImuKind::default_name()))]
#[allow(clippy::too_many_arguments)]
fn ideal_imu<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    lever_arm_m: Vec<f64>,
    accel_sign: &str,
    gravity_m_s2: f64,
    magnetic_field_ut: Option<Vec<f64>>,
    nav_frame: &str,
    kind: &str,
) -> PyResult<TableOut<'py>> {
    let truth = table_in("truth", columns, &values)?;
    let request = IdealRequest {
        kind: choice("kind", kind)?,
        lever_arm_m: fixed::<3>("lever_arm_m", &lever_arm_m)?,
        accel_sign: choice("accel_sign", accel_sign)?,
        gravity_m_s2,
        magnetic_field_ut: fixed_opt::<3>("magnetic_field_ut", magnetic_field_ut)?,
        nav_frame: choice("nav_frame", nav_frame)?,
    };
    let out = py.detach(|| request.run(&truth)).map_err(refused)?;
    table_out(py, out)
}

/// Tangent z-y-x Euler angles `[yaw, pitch, roll]` of a velocity series.
#[pyfunction]
#[pyo3(signature = (velocity_m_s, *, min_speed_m_s = DEFAULT_MIN_SPEED_M_S))]
fn tangent_euler<'py>(
    py: Python<'py>,
    velocity_m_s: PyReadonlyArray2<'py, f64>,
    min_speed_m_s: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let v = rows::<3>("velocity_m_s", &velocity_m_s)?;
    let e = py
        .detach(move || arrays::tangent_euler(&v, min_speed_m_s))
        .map_err(refused)?;
    rows_out(py, e.into_iter().map(EulerZyx::to_array).collect())
}

/// `C_nbᵀ v_n`: navigation-frame vectors resolved in the body frame, per sample.
#[pyfunction]
fn nav_to_body<'py>(
    py: Python<'py>,
    euler_rad: PyReadonlyArray2<'py, f64>,
    v_n: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e: Vec<EulerZyx> = rows::<3>("euler_rad", &euler_rad)?
        .into_iter()
        .map(EulerZyx::from_array)
        .collect();
    let v = rows::<3>("v_n", &v_n)?;
    check_len("v_n", v.len(), e.len())?;
    rows_out(py, py.detach(move || arrays::nav_to_body(&e, &v)))
}

/// `a + ω × (ω × r) + α × r` per sample (body frame).
#[pyfunction]
fn at_lever_arm<'py>(
    py: Python<'py>,
    a: PyReadonlyArray2<'py, f64>,
    omega: PyReadonlyArray2<'py, f64>,
    alpha: PyReadonlyArray2<'py, f64>,
    r: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = fixed::<3>("r", &r)?;
    let (a, w, al) = (
        rows::<3>("a", &a)?,
        rows::<3>("omega", &omega)?,
        rows::<3>("alpha", &alpha)?,
    );
    check_len("omega", w.len(), a.len())?;
    check_len("alpha", al.len(), a.len())?;
    rows_out(
        py,
        py.detach(move || arrays::at_lever_arm_series(&a, &w, &al, r)),
    )
}

/// Truth from body-frame acceleration and angular velocity (MATLAB kinematicTrajectory).
#[pyfunction]
#[pyo3(signature = (t_s, accel_body_m_s2, omega_body_rad_s, *, position0_m = vec![0.0; 3],
                    velocity0_m_s = vec![0.0; 3], euler0_rad = vec![0.0; 3], nav_frame = NavFrameName::default_name()))]
#[allow(clippy::too_many_arguments)]
fn truth_from_body_rates<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    accel_body_m_s2: PyReadonlyArray2<'py, f64>,
    omega_body_rad_s: PyReadonlyArray2<'py, f64>,
    position0_m: Vec<f64>,
    velocity0_m_s: Vec<f64>,
    euler0_rad: Vec<f64>,
    nav_frame: &str,
) -> PyResult<TableOut<'py>> {
    let position0_m = fixed::<3>("position0_m", &position0_m)?;
    let velocity0_m_s = fixed::<3>("velocity0_m_s", &velocity0_m_s)?;
    let euler0_rad = fixed::<3>("euler0_rad", &euler0_rad)?;
    let t = vector(&t_s);
    let a = rows::<3>("accel_body_m_s2", &accel_body_m_s2)?;
    let w = rows::<3>("omega_body_rad_s", &omega_body_rad_s)?;
    check_len("accel_body_m_s2", a.len(), t.len())?;
    check_len("omega_body_rad_s", w.len(), t.len())?;
    let data = BodyRatesData {
        accel_body_m_s2: a,
        omega_body_rad_s: w,
        alpha_body_rad_s2: None,
        position0_m,
        velocity0_m_s,
        euler0_rad,
    };
    let nav = choice::<NavFrameName>("nav_frame", nav_frame)?;
    let table = py
        .detach(move || arrays::truth_from_body_rates(&t, data, nav))
        .map_err(refused)?;
    table_out(py, table)
}

/// Exact truth at `t_s` of a waypoint trajectory (cubic spline through the waypoints).
#[pyfunction]
#[pyo3(signature = (t_s, time_s, position_m, *, velocity_m_s = None, euler_rad = None, nav_frame = NavFrameName::default_name()))]
fn truth_from_waypoints<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    time_s: PyReadonlyArray1<'py, f64>,
    position_m: PyReadonlyArray2<'py, f64>,
    velocity_m_s: Option<PyReadonlyArray2<'py, f64>>,
    euler_rad: Option<PyReadonlyArray2<'py, f64>>,
    nav_frame: &str,
) -> PyResult<TableOut<'py>> {
    let t = vector(&t_s);
    let knots = vector(&time_s);
    let p = rows::<3>("position_m", &position_m)?;
    let v = velocity_m_s
        .as_ref()
        .map(|v| rows::<3>("velocity_m_s", v))
        .transpose()?;
    let e = euler_rad
        .as_ref()
        .map(|e| rows::<3>("euler_rad", e))
        .transpose()?;
    let w = Waypoints::new(&knots, &p, v.as_deref(), e.as_deref()).map_err(refused)?;
    let nav = choice::<NavFrameName>("nav_frame", nav_frame)?;
    let table = py
        .detach(move || arrays::truth_from_waypoints(&t, w, nav))
        .map_err(refused)?;
    table_out(py, table)
}

/// Names of the built-in scenarios.
#[pyfunction]
fn builtin_names() -> Vec<&'static str> {
    builtin::NAMES.to_vec()
}

/// A built-in scenario as TOML text.
#[pyfunction]
fn builtin_toml(name: &str) -> PyResult<String> {
    builtin::toml(name).map_err(refused)
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DEFAULT_GRAVITY_M_S2", imu_core::DEFAULT_GRAVITY_M_S2)?;
    m.add_function(wrap_pyfunction!(simulate_text, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_dict, m)?)?;
    m.add_function(wrap_pyfunction!(simulation_shape, m)?)?;
    m.add_function(wrap_pyfunction!(write_run, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_expressions, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_samples, m)?)?;
    m.add_function(wrap_pyfunction!(ideal_imu, m)?)?;
    m.add_function(wrap_pyfunction!(tangent_euler, m)?)?;
    m.add_function(wrap_pyfunction!(nav_to_body, m)?)?;
    m.add_function(wrap_pyfunction!(at_lever_arm, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_body_rates, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_waypoints, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_names, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_toml, m)?)?;
    Ok(())
}
