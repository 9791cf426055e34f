//! Python bindings of imukit (`imukit._core`): convert NumPy input, release the GIL, call the
//! shared std layer (`imu-scenario`), convert back. No numerics here.
use std::collections::BTreeMap;
use std::path::Path;

use imu_core::Ned;
use imu_core::kinematics::sampled::SampledOptions;
use imu_core::kinematics::tangent::DEFAULT_MIN_SPEED_M_S;
use imu_core::sensor::{ImuModel, ImuState, SeededNormals, Temperatures};
use imu_core::strapdown::planar::{PlanarSample, PlanarScheme, PlanarState};
use imu_core::strapdown::step::StrapdownOptions;
use imu_core::{Body, Enu, EulerZyx, NavFrame, Rotation, Vec3};
use imu_plot::spec::{self as figures, TableKind};
use imukit::io::params::{Profile, read_param_file, to_toml};
use imukit::io::presets;
use imukit::io::table::ImuKind;
use imukit::motion::{BodyRatesData, SampledAttitudeData};
use imukit::run::{allan as analysis, arrays, navigate as navigation, planar};
use imukit::scenario::sensors::{SensorKeys, SensorSetup};
use imukit::scenario::{
    AccelSignName, ExpressionSpec, Formula, ImuSetup, NavFrameName, parse_name,
};
use imukit::{ScenarioSpec, Table};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::create_exception;

mod orientation;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    _core,
    ImuError,
    PyValueError,
    "imukit refused the input; the message says what and where."
);

fn refused(e: impl ToString) -> PyErr {
    ImuError::new_err(e.to_string())
}

type TableOut<'py> = (Vec<String>, Bound<'py, PyArray2<f64>>);

fn table_out(py: Python<'_>, t: Table) -> PyResult<TableOut<'_>> {
    let shape = (t.rows(), t.columns.len());
    let arr =
        Array2::from_shape_vec(shape, t.data).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((t.columns, arr.into_pyarray(py)))
}

fn rows<const K: usize>(name: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; K]>> {
    let v = a.as_array();
    if v.ncols() != K {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (N, {K}), got {:?}",
            v.shape()
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

fn check_len(name: &str, got: usize, expected: usize) -> PyResult<()> {
    if got == expected {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{name} has {got} rows, expected {expected} (one per time)"
        )))
    }
}

/// A row-major (rows, cols) array from flat data.
fn array2(
    py: Python<'_>,
    rows: usize,
    cols: usize,
    data: Vec<f64>,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    Array2::from_shape_vec((rows, cols), data)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

fn out3(py: Python<'_>, v: Vec<[f64; 3]>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = v.len();
    array2(py, n, 3, v.into_iter().flatten().collect())
}

fn nav(name: &str) -> PyResult<NavFrameName> {
    frame("nav_frame", name)
}

/// The navigation frame `name` given for the argument `field`.
fn frame(field: &str, name: &str) -> PyResult<NavFrameName> {
    parse_name(field, &name.to_ascii_uppercase()).map_err(refused)
}

/// Resolves and runs a scenario given as TOML or JSON text; returns (truth, imu) tables.
#[pyfunction]
#[pyo3(signature = (text, *, format = "toml", origin = "scenario", base_dir = ".", run = None))]
fn simulate_text<'py>(
    py: Python<'py>,
    text: &str,
    format: &str,
    origin: &str,
    base_dir: &str,
    run: Option<u64>,
) -> PyResult<(TableOut<'py>, TableOut<'py>)> {
    let spec = match format {
        "toml" => ScenarioSpec::from_toml(text, origin),
        "json" => ScenarioSpec::from_json(text, origin),
        other => {
            return Err(PyValueError::new_err(format!(
                "format must be \"toml\" or \"json\", got {other:?}"
            )));
        }
    }
    .map_err(refused)?;
    let base = base_dir.to_string();
    let sim = py
        .detach(move || {
            let sc = spec.resolve(Path::new(&base))?;
            match run {
                Some(r) => sc.simulate_run(r),
                None => sc.simulate(),
            }
        })
        .map_err(refused)?;
    Ok((table_out(py, sim.truth)?, table_out(py, sim.imu)?))
}

/// Exact truth from formula strings at the times `t_s`.
#[pyfunction]
#[pyo3(signature = (t_s, position_m, *, attitude = None, yaw_rad = None, pitch_rad = None, roll_rad = None,
                    constants = None, nav_frame = "ENU", min_speed_m_s = None))]
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
    let t = t_s.as_array().to_vec();
    let spec = ExpressionSpec {
        constants: constants.unwrap_or_default(),
        position_m: position_m.map(Formula::Text),
        attitude,
        yaw_rad: yaw_rad.map(Formula::Text),
        pitch_rad: pitch_rad.map(Formula::Text),
        roll_rad: roll_rad.map(Formula::Text),
        min_speed_m_s,
    };
    let nav = nav(nav_frame)?;
    let table = py
        .detach(move || arrays::truth_from_expressions(&t, &spec, nav))
        .map_err(refused)?;
    table_out(py, table)
}

/// Truth from sampled positions and attitude by finite differences.
#[pyfunction]
#[pyo3(signature = (t_s, position_m, *, euler_rad = None, quaternion = None, attitude = None, order = 6,
                    nav_frame = "ENU", min_speed_m_s = None))]
#[allow(clippy::too_many_arguments)]
fn truth_from_samples<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    position_m: PyReadonlyArray2<'py, f64>,
    euler_rad: Option<PyReadonlyArray2<'py, f64>>,
    quaternion: Option<PyReadonlyArray2<'py, f64>>,
    attitude: Option<&str>,
    order: usize,
    nav_frame: &str,
    min_speed_m_s: Option<f64>,
) -> PyResult<TableOut<'py>> {
    let t = t_s.as_array().to_vec();
    let pos = rows::<3>("position_m", &position_m)?;
    check_len("position_m", pos.len(), t.len())?;
    let att = match (euler_rad, quaternion, attitude) {
        (Some(e), None, None) => {
            let e = rows::<3>("euler_rad", &e)?;
            check_len("euler_rad", e.len(), t.len())?;
            SampledAttitudeData::Euler(e.into_iter().map(EulerZyx::from_array).collect())
        }
        (None, Some(q), None) => {
            let q = rows::<4>("quaternion", &q)?;
            check_len("quaternion", q.len(), t.len())?;
            SampledAttitudeData::Quaternion(q)
        }
        (None, None, Some("tangent")) => SampledAttitudeData::Tangent,
        (None, None, Some("level") | None) => {
            SampledAttitudeData::Euler(vec![EulerZyx::default(); t.len()])
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
    };
    let options = SampledOptions {
        order,
        min_speed_m_s: min_speed_m_s.unwrap_or(DEFAULT_MIN_SPEED_M_S),
    };
    let nav = nav(nav_frame)?;
    let n = t.len();
    let out = PyArray2::<f64>::zeros(py, [n, imukit::io::table::TRUTH_COLUMNS.len()], false);
    {
        let mut guard = out.readwrite();
        let values = guard
            .as_slice_mut()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        py.detach(move || arrays::truth_from_arrays_into(t, pos, att, options, nav, values))
            .map_err(refused)?;
    }
    Ok((
        imukit::io::table::TRUTH_COLUMNS
            .iter()
            .map(|c| (*c).to_string())
            .collect(),
        out,
    ))
}

/// Ideal IMU readings from a truth table (its column names and values).
#[pyfunction]
#[pyo3(signature = (columns, values, *, lever_arm_m = [0.0, 0.0, 0.0], accel_sign = "specific-force",
                    gravity_m_s2 = 9.81, magnetic_field_ut = None, nav_frame = "ENU", kind = "accel-gyro-mag"))]
#[allow(clippy::too_many_arguments)]
fn ideal_imu<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    lever_arm_m: [f64; 3],
    accel_sign: &str,
    gravity_m_s2: f64,
    magnetic_field_ut: Option<[f64; 3]>,
    nav_frame: &str,
    kind: &str,
) -> PyResult<TableOut<'py>> {
    let v = values.as_array();
    if v.ncols() != columns.len() {
        return Err(PyValueError::new_err(format!(
            "truth has {} columns but {} column names",
            v.ncols(),
            columns.len()
        )));
    }
    let table = Table {
        columns,
        data: v.iter().copied().collect(),
    };
    if let Some(k) = lever_arm_m
        .iter()
        .chain(magnetic_field_ut.iter().flatten())
        .position(|c| !c.is_finite())
    {
        let field = if k < 3 {
            "lever_arm_m"
        } else {
            "magnetic_field_ut"
        };
        return Err(ImuError::new_err(format!("{field}: must be finite")));
    }
    let imu = ImuSetup::ideal(
        parse_name::<ImuKind>("kind", kind).map_err(refused)?,
        lever_arm_m,
        parse_name::<AccelSignName>("accel_sign", accel_sign)
            .map_err(refused)?
            .into(),
        magnetic_field_ut,
    );
    let nav = nav(nav_frame)?;
    let out = py
        .detach(move || arrays::ideal_from_truth(&table, &imu, gravity_m_s2, nav))
        .map_err(refused)?;
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
    out3(py, e.into_iter().map(EulerZyx::to_array).collect())
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
    out3(py, py.detach(move || arrays::nav_to_body(&e, &v)))
}

/// `a + ω × (ω × r) + α × r` per sample (body frame).
#[pyfunction]
fn at_lever_arm<'py>(
    py: Python<'py>,
    a: PyReadonlyArray2<'py, f64>,
    omega: PyReadonlyArray2<'py, f64>,
    alpha: PyReadonlyArray2<'py, f64>,
    r: [f64; 3],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, w, al) = (
        rows::<3>("a", &a)?,
        rows::<3>("omega", &omega)?,
        rows::<3>("alpha", &alpha)?,
    );
    check_len("omega", w.len(), a.len())?;
    check_len("alpha", al.len(), a.len())?;
    out3(
        py,
        py.detach(move || arrays::at_lever_arm_series(&a, &w, &al, r)),
    )
}

/// z-y-x Euler angles `[yaw, pitch, roll]` (N, 3) → quaternions `[w, x, y, z]` (N, 4).
#[pyfunction]
fn euler_to_quaternion<'py>(
    py: Python<'py>,
    euler_rad: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = rows::<3>("euler_rad", &euler_rad)?;
    let q: Vec<f64> = e
        .iter()
        .flat_map(|a| Rotation::<Body, Enu>::from_euler(EulerZyx::from_array(*a)).to_wxyz())
        .collect();
    array2(py, e.len(), 4, q)
}

/// Quaternions `[w, x, y, z]` (N, 4) → z-y-x Euler angles `[yaw, pitch, roll]` (N, 3).
#[pyfunction]
fn quaternion_to_euler<'py>(
    py: Python<'py>,
    quaternion: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = rotations(&quaternion)?
        .iter()
        .map(|r| r.to_euler().to_array())
        .collect();
    out3(py, e)
}

/// Rows of `[w, x, y, z]` as rotations; refuses zero or non-finite quaternions by index.
fn rotations(quaternion: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Rotation<Body, Enu>>> {
    rows::<4>("quaternion", quaternion)?
        .iter()
        .enumerate()
        .map(|(i, q)| {
            Rotation::from_wxyz(*q).ok_or_else(|| {
                ImuError::new_err(format!("quaternion[{i}] has zero norm or is not finite"))
            })
        })
        .collect()
}

fn dcm_out(py: Python<'_>, m: Vec<[[f64; 3]; 3]>) -> PyResult<Bound<'_, PyArray3<f64>>> {
    let n = m.len();
    Array3::from_shape_vec((n, 3, 3), m.into_iter().flatten().flatten().collect())
        .map(|a| a.into_pyarray(py))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

fn dcm_in(name: &str, a: &PyReadonlyArray3<'_, f64>) -> PyResult<Vec<[[f64; 3]; 3]>> {
    let v = a.as_array();
    if v.shape()[1..] != [3, 3] {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (N, 3, 3), got {:?}",
            v.shape()
        )));
    }
    Ok(v.outer_iter()
        .map(|m| std::array::from_fn(|i| std::array::from_fn(|k| m[[i, k]])))
        .collect())
}

/// z-y-x Euler angles (N, 3) → direction cosine matrices `C_nb` (N, 3, 3).
#[pyfunction]
fn euler_to_dcm<'py>(
    py: Python<'py>,
    euler_rad: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let e = rows::<3>("euler_rad", &euler_rad)?;
    dcm_out(
        py,
        e.into_iter()
            .map(|a| EulerZyx::from_array(a).to_dcm())
            .collect(),
    )
}

/// Direction cosine matrices (N, 3, 3) → z-y-x Euler angles (N, 3).
#[pyfunction]
fn dcm_to_euler<'py>(
    py: Python<'py>,
    dcm: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = dcm_in("dcm", &dcm)?;
    out3(
        py,
        m.iter().map(|c| EulerZyx::from_dcm(c).to_array()).collect(),
    )
}

/// Quaternions (N, 4) → direction cosine matrices (N, 3, 3).
#[pyfunction]
fn quaternion_to_dcm<'py>(
    py: Python<'py>,
    quaternion: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let m = rotations(&quaternion)?
        .iter()
        .map(Rotation::to_dcm)
        .collect();
    dcm_out(py, m)
}

/// Direction cosine matrices (N, 3, 3) → quaternions (N, 4).
#[pyfunction]
fn dcm_to_quaternion<'py>(
    py: Python<'py>,
    dcm: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = dcm_in("dcm", &dcm)?;
    let q: Vec<f64> = m
        .iter()
        .flat_map(|c| Rotation::<Body, Enu>::from_dcm(c).to_wxyz())
        .collect();
    array2(py, m.len(), 4, q)
}

/// A contiguous (N, K) float array as one flat slice, row after row.
fn flat_rows<'a, const K: usize>(
    name: &str,
    a: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<&'a [f64]> {
    let shape = a.as_array().shape().to_vec();
    if shape[1] != K {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (N, {K}), got {shape:?}"
        )));
    }
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name} must be C-contiguous")))
}

/// The orientation of each sample as the caller gave it.
enum Orientation<'a> {
    /// `[w, x, y, z]` rows, flat.
    Quaternions(&'a [f64]),
    /// MATLAB rotation matrices (nav → body, `C_nbᵀ`) already read.
    Matrices(&'a [[[f64; 3]; 3]]),
}

impl Orientation<'_> {
    fn len(&self) -> usize {
        match self {
            Self::Quaternions(q) => q.len() / 4,
            Self::Matrices(m) => m.len(),
        }
    }

    /// Sample `i`'s rotation; `None` for a quaternion of zero norm or not finite.
    fn at<N: NavFrame>(&self, i: usize) -> Option<Rotation<Body, N>> {
        match self {
            Self::Quaternions(q) => {
                let c = &q[4 * i..4 * i + 4];
                Rotation::from_wxyz([c[0], c[1], c[2], c[3]])
            }
            Self::Matrices(m) => Some(Rotation::from_dcm(&m[i])),
        }
    }
}

/// MATLAB's batch call: nav-frame inputs row by row into `out` (accel, gyro, mag per row), with
/// no intermediate buffers and no separate validation pass. A bad quaternion stops the call
/// with its index, `state` and `noise` as they were before the call.
#[allow(clippy::too_many_arguments)]
fn measure_rows<N: NavFrame>(
    model: &ImuModel<N>,
    a: &[f64],
    w: &[f64],
    orientation: &Orientation<'_>,
    temps: &Temperatures,
    state: &mut ImuState,
    noise: &mut SeededNormals,
    out: &mut [f64],
) -> Result<(), usize> {
    let (start_state, start_noise) = (*state, noise.clone());
    for (i, o) in out.chunks_exact_mut(9).enumerate() {
        let Some(attitude) = orientation.at::<N>(i) else {
            (*state, *noise) = (start_state, start_noise);
            return Err(i);
        };
        let v = |x: &[f64]| Vec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        let r = model.measure_nav(v(a), v(w), &attitude, temps, state, noise);
        o[..3].copy_from_slice(&r.accel_m_s2);
        o[3..6].copy_from_slice(&r.gyro_rad_s);
        o[6..].copy_from_slice(&r.mag_ut);
    }
    Ok(())
}

/// The navigation-frame generic model behind `ImuSensor`.
enum Model {
    Enu(ImuModel<Enu>),
    Ned(ImuModel<Ned>),
}

/// MATLAB-shaped IMU simulator (see the Python class `imukit.ImuSensor`).
#[pyclass(module = "imukit._core", name = "ImuSensor")]
struct PyImuSensor {
    model: Model,
    kind: ImuKind,
    state: ImuState,
    noise: SeededNormals,
    seed: u64,
    temperature: Temperatures,
}

fn json(name: &str, text: Option<String>) -> PyResult<Option<serde_json::Value>> {
    text.map(|t| {
        serde_json::from_str(&t).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
    })
    .transpose()
}

#[pymethods]
impl PyImuSensor {
    #[new]
    #[pyo3(signature = (imu_type = "accel-gyro", *, reference_frame = "NED", sample_rate = 100.0, temperature = 25.0,
                        magnetic_field = None, accelerometer = None, gyroscope = None, magnetometer = None,
                        preset = None, seed = 0, profile = "matlab", accel_sign = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        imu_type: &str,
        reference_frame: &str,
        sample_rate: f64,
        temperature: f64,
        magnetic_field: Option<[f64; 3]>,
        accelerometer: Option<String>,
        gyroscope: Option<String>,
        magnetometer: Option<String>,
        preset: Option<String>,
        seed: u64,
        profile: &str,
        accel_sign: Option<&str>,
    ) -> PyResult<Self> {
        let kind = parse_name::<ImuKind>("imu_type", imu_type).map_err(refused)?;
        let profile = parse_name::<Profile>("profile", profile).map_err(refused)?;
        let tables = [
            json("accelerometer", accelerometer)?,
            json("gyroscope", gyroscope)?,
            json("magnetometer", magnetometer)?,
        ];
        let keys = SensorKeys {
            profile: Some(profile),
            seed: Some(seed),
            preset: preset.as_deref(),
            tables: [tables[0].as_ref(), tables[1].as_ref(), tables[2].as_ref()],
            ..SensorKeys::default()
        };
        let sensors = SensorSetup::resolve(&keys, Path::new(".")).map_err(refused)?;
        if !temperature.is_finite() {
            return Err(ImuError::new_err("temperature: must be finite"));
        }
        let sign = match accel_sign {
            Some(s) => parse_name::<AccelSignName>("accel_sign", s)
                .map_err(refused)?
                .into(),
            None => profile.accel_sign(),
        };
        let setup = ImuSetup {
            sensors,
            ..ImuSetup::ideal(kind, [0.0; 3], sign, magnetic_field)
        };
        let model = match frame("reference_frame", reference_frame)? {
            NavFrameName::ENU => {
                Model::Enu(setup.model::<Enu>(9.81, sample_rate).map_err(refused)?)
            }
            NavFrameName::NED => {
                Model::Ned(setup.model::<Ned>(9.81, sample_rate).map_err(refused)?)
            }
        };
        Ok(Self {
            model,
            kind,
            state: ImuState::default(),
            noise: SeededNormals::new(seed),
            seed,
            temperature: Temperatures::uniform(temperature),
        })
    }

    /// Readings for nav-frame acceleration (N, 3), angular velocity (N, 3) and attitude
    /// quaternions `q_nb` (N, 4) or `C_nb` matrices (N, 3, 3); returns (N, 9) rows of
    /// accel, gyro, mag (absent sensors zero). State and noise stream carry over between calls.
    /// `out`, a C-contiguous writeable (N, 9) float64 array, receives the rows instead of a new
    /// array (a buffer reused across chunks is not page-faulted again).
    #[pyo3(signature = (acceleration, angular_velocity, *, quaternion = None, dcm = None, out = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        acceleration: PyReadonlyArray2<'py, f64>,
        angular_velocity: PyReadonlyArray2<'py, f64>,
        quaternion: Option<PyReadonlyArray2<'py, f64>>,
        dcm: Option<PyReadonlyArray3<'py, f64>>,
        out: Option<Bound<'py, PyArray2<f64>>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = flat_rows::<3>("acceleration", &acceleration)?;
        let w = flat_rows::<3>("angular_velocity", &angular_velocity)?;
        check_len("angular_velocity", w.len() / 3, a.len() / 3)?;
        let n = a.len() / 3;
        // The orientation stays in the caller's array; each sample's rotation is made in the loop.
        let dcm_rows;
        let orientation = match (&quaternion, &dcm) {
            (Some(q), None) => Orientation::Quaternions(flat_rows::<4>("quaternion", q)?),
            (None, Some(m)) => {
                dcm_rows = dcm_in("orientation", m)?;
                Orientation::Matrices(&dcm_rows)
            }
            _ => {
                return Err(PyValueError::new_err(
                    "give the orientation as quaternions or as matrices",
                ));
            }
        };
        check_len("orientation", orientation.len(), n)?;
        let out = match out {
            Some(o) if o.shape() == [n, 9] => o,
            Some(o) => {
                return Err(PyValueError::new_err(format!(
                    "out must have shape ({n}, 9), got ({}, {})",
                    o.shape()[0],
                    o.shape()[1]
                )));
            }
            None => PyArray2::<f64>::zeros(py, [n, 9], false),
        };
        {
            let mut guard = out
                .try_readwrite()
                .map_err(|e| PyValueError::new_err(format!("out: {e}")))?;
            let o = guard
                .as_slice_mut()
                .map_err(|e| PyValueError::new_err(format!("out must be C-contiguous: {e}")))?;
            let (model, state, noise, temps) = (
                &self.model,
                &mut self.state,
                &mut self.noise,
                self.temperature,
            );
            py.detach(|| match model {
                Model::Enu(m) => measure_rows(m, a, w, &orientation, &temps, state, noise, o),
                Model::Ned(m) => measure_rows(m, a, w, &orientation, &temps, state, noise, o),
            })
            .map_err(|i| {
                ImuError::new_err(format!("quaternion[{i}] has zero norm or is not finite"))
            })?;
        }
        Ok(out)
    }

    /// Back to the initial state and the start of the seeded noise stream.
    fn reset(&mut self) {
        self.state = ImuState::default();
        self.noise = SeededNormals::new(self.seed);
    }

    /// `"accel-gyro"`, `"accel-mag"` or `"accel-gyro-mag"`.
    #[getter]
    fn imu_type(&self) -> &'static str {
        match self.kind {
            ImuKind::AccelGyro => "accel-gyro",
            ImuKind::AccelMag => "accel-mag",
            ImuKind::AccelGyroMag => "accel-gyro-mag",
        }
    }

    /// Temperature of all sensors, °C.
    #[getter]
    fn get_temperature(&self) -> f64 {
        self.temperature.accel_c
    }

    #[setter]
    fn set_temperature(&mut self, t: f64) -> PyResult<()> {
        if !t.is_finite() {
            return Err(ImuError::new_err("temperature: must be finite"));
        }
        self.temperature = Temperatures::uniform(t);
        Ok(())
    }
}

/// `(tau_s, adev)`.
type AllanOut<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// Overlapping Allan deviation of each column of `x` (N,) or (N, k) at octave τ:
/// returns `(tau_s, adev)` with `adev` of shape (T,) or (T, k).
#[pyfunction]
fn allan_deviation<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    sample_rate_hz: f64,
) -> PyResult<AllanOut<'py>> {
    let v = x.as_array();
    let series: Vec<(String, Vec<f64>)> = (0..v.ncols())
        .map(|k| (format!("column {k}"), v.column(k).to_vec()))
        .collect();
    let result = py
        .detach(move || analysis::allan(&series, sample_rate_hz))
        .map_err(refused)?;
    let t = result.table;
    let tau = t.column("tau_s").unwrap_or_default();
    let cols = t.columns.len() - 1;
    let adev: Vec<f64> = t
        .data
        .chunks(t.columns.len())
        .flat_map(|r| r[1..].to_vec())
        .collect();
    let adev = Array2::from_shape_vec((tau.len(), cols), adev)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((PyArray1::from_vec(py, tau), adev.into_pyarray(py)))
}

/// N, K, B and the fitted lines of an Allan curve, as a dict.
#[pyfunction]
fn identify_noise<'py>(
    py: Python<'py>,
    tau_s: PyReadonlyArray1<'py, f64>,
    adev: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let (tau, a) = (tau_s.as_array().to_vec(), adev.as_array().to_vec());
    check_len("adev", a.len(), tau.len())?;
    let id = imu_core::allan::identify_noise(&tau, &a);
    let d = pyo3::types::PyDict::new(py);
    d.set_item("noise_density", id.noise_density)?;
    d.set_item("bias_instability", id.bias_instability)?;
    d.set_item("random_walk", id.random_walk)?;
    for (name, line) in [
        ("white_line", id.white_line),
        ("random_walk_line", id.random_walk_line),
        ("bias_line", id.bias_line),
    ] {
        d.set_item(name, line.map(|l| (l.slope, l.intercept)))?;
    }
    Ok(d)
}

/// A datasheet figure in imukit's SI units: `(value, unit, fitting parameters)`.
#[pyfunction]
fn convert(value: f64, unit: &str) -> PyResult<(f64, &'static str, &'static str)> {
    let c = imukit::io::units::convert(value, unit).map_err(refused)?;
    Ok((c.value, c.unit, c.fits))
}

/// Names of the sensor presets.
#[pyfunction]
fn preset_names() -> Vec<&'static str> {
    presets::names()
}

/// A preset as an imukit parameter file (TOML text).
#[pyfunction]
fn preset_toml(name: &str) -> PyResult<&'static str> {
    presets::text(name).map_err(refused)
}

/// A parameter file (imukit TOML/JSON or MATLAB loadparams JSON) as imukit TOML text.
#[pyfunction]
#[pyo3(signature = (path, *, part = None))]
fn load_params_toml(path: &str, part: Option<&str>) -> PyResult<String> {
    read_param_file(Path::new(path), part, Profile::Default)
        .map(|f| to_toml(&f))
        .map_err(refused)
}

/// Planar dead reckoning of (t, a_x, a_y, ω_z) into a navigation table.
#[pyfunction]
#[pyo3(signature = (t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s, *, scheme = "trapezoid",
                    position0_m = [100.0, 100.0], heading0_rad = 0.0, velocity0_m_s = [0.0, 0.0]))]
#[allow(clippy::too_many_arguments)]
fn planar_dead_reckon<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    accel_x_m_s2: PyReadonlyArray1<'py, f64>,
    accel_y_m_s2: PyReadonlyArray1<'py, f64>,
    gyro_z_rad_s: PyReadonlyArray1<'py, f64>,
    scheme: &str,
    position0_m: [f64; 2],
    heading0_rad: f64,
    velocity0_m_s: [f64; 2],
) -> PyResult<TableOut<'py>> {
    let t = t_s.as_array();
    let (ax, ay, wz) = (
        accel_x_m_s2.as_array(),
        accel_y_m_s2.as_array(),
        gyro_z_rad_s.as_array(),
    );
    for (name, len) in [
        ("accel_x_m_s2", ax.len()),
        ("accel_y_m_s2", ay.len()),
        ("gyro_z_rad_s", wz.len()),
    ] {
        check_len(name, len, t.len())?;
    }
    let samples: Vec<PlanarSample> = (0..t.len())
        .map(|i| PlanarSample {
            t_s: t[i],
            accel_x_m_s2: ax[i],
            accel_y_m_s2: ay[i],
            gyro_z_rad_s: wz[i],
        })
        .collect();
    let scheme = match scheme {
        "trapezoid" => PlanarScheme::Trapezoid,
        "exercise" => PlanarScheme::Exercise,
        other => {
            return Err(ImuError::new_err(format!(
                "scheme: unknown scheme \"{other}\" (trapezoid, exercise)"
            )));
        }
    };
    let (s, c) = heading0_rad.sin_cos();
    let initial = PlanarState {
        t_s: samples.first().map_or(0.0, |x| x.t_s),
        position_m: position0_m,
        heading_rad: heading0_rad,
        velocity_nav_m_s: velocity0_m_s,
        velocity_body_m_s: [
            c * velocity0_m_s[0] + s * velocity0_m_s[1],
            -s * velocity0_m_s[0] + c * velocity0_m_s[1],
        ],
    };
    let table = py
        .detach(move || planar::integrate(&samples, scheme, initial))
        .map_err(refused)?;
    table_out(py, table)
}

/// Planar IMU samples from a CSV or `.dat` file, as a table with `t_s, accel_x_m_s2,
/// accel_y_m_s2, gyro_z_rad_s`.
#[pyfunction]
fn read_planar<'py>(py: Python<'py>, path: &str) -> PyResult<TableOut<'py>> {
    let samples = planar::read_planar(Path::new(path)).map_err(refused)?;
    let mut t = Table::new(&planar::PLANAR_COLUMNS);
    for s in &samples {
        t.push_row(&[s.t_s, s.accel_x_m_s2, s.accel_y_m_s2, s.gyro_z_rad_s]);
    }
    table_out(py, t)
}

/// 3D strapdown of an IMU table (rates or increments) from an initial state.
#[pyfunction]
#[pyo3(signature = (columns, values, *, position0_m, velocity0_m_s, quaternion0, nav_frame = "ENU",
                    gravity_m_s2 = 9.81, coning = true, sculling = true, accel_sign = "specific-force",
                    scheme = "coning", substeps = 4))]
#[allow(clippy::too_many_arguments)]
fn strapdown<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    position0_m: [f64; 3],
    velocity0_m_s: [f64; 3],
    quaternion0: [f64; 4],
    nav_frame: &str,
    gravity_m_s2: f64,
    coning: bool,
    sculling: bool,
    accel_sign: &str,
    scheme: &str,
    substeps: usize,
) -> PyResult<TableOut<'py>> {
    let scheme = match scheme {
        "coning" => navigation::NavScheme::ConingSculling,
        "rk4" if substeps >= 1 => navigation::NavScheme::Rk4 { substeps },
        "rk4" => return Err(ImuError::new_err("substeps: must be ≥ 1")),
        other => {
            return Err(ImuError::new_err(format!(
                "scheme: unknown scheme \"{other}\" (coning, rk4)"
            )));
        }
    };
    let v = values.as_array();
    if v.ncols() != columns.len() {
        return Err(PyValueError::new_err(format!(
            "imu has {} columns but {} column names",
            v.ncols(),
            columns.len()
        )));
    }
    let table = Table {
        columns,
        data: v.iter().copied().collect(),
    };
    let initial = navigation::InitialState {
        position_m: position0_m,
        velocity_m_s: velocity0_m_s,
        quaternion: quaternion0,
    };
    if !(gravity_m_s2.is_finite() && gravity_m_s2 >= 0.0) {
        return Err(ImuError::new_err(format!(
            "gravity_m_s2: must be a finite number ≥ 0, got {gravity_m_s2}"
        )));
    }
    let setup = navigation::NavSetup {
        scheme,
        nav_frame: nav(nav_frame)?,
        options: StrapdownOptions {
            gravity_m_s2,
            coning,
            sculling,
        },
        accel_sign: parse_name::<AccelSignName>("accel_sign", accel_sign)
            .map_err(refused)?
            .into(),
    };
    let out = py
        .detach(move || navigation::integrate(&table, &initial, &setup))
        .map_err(refused)?;
    table_out(py, out)
}

/// Errors of an estimate against truth: (error table, summary dict).
#[pyfunction]
fn compare<'py>(
    py: Python<'py>,
    truth_columns: Vec<String>,
    truth: PyReadonlyArray2<'py, f64>,
    estimate_columns: Vec<String>,
    estimate: PyReadonlyArray2<'py, f64>,
) -> PyResult<(TableOut<'py>, Bound<'py, pyo3::types::PyDict>)> {
    let t = Table {
        columns: truth_columns,
        data: truth.as_array().iter().copied().collect(),
    };
    let e = Table {
        columns: estimate_columns,
        data: estimate.as_array().iter().copied().collect(),
    };
    let c = py
        .detach(move || imukit::run::compare::compare(&t, &e))
        .map_err(refused)?;
    let d = pyo3::types::PyDict::new(py);
    let s = &c.summary;
    let put = |name: &str, unit: &str, stats: &imu_core::orientation::DistanceStats| {
        d.set_item(format!("{name}_rms_{unit}"), stats.rms())?;
        d.set_item(format!("{name}_max_{unit}"), stats.max())?;
        d.set_item(format!("{name}_final_{unit}"), stats.last())
    };
    if let Some(p) = &s.position {
        put("position", "m", p)?;
    }
    if let Some(v) = &s.velocity {
        put("velocity", "m_s", v)?;
    }
    put("attitude", "rad", &s.attitude)?;
    Ok((table_out(py, c.table)?, d))
}

/// Truth from body-frame acceleration and angular velocity (MATLAB kinematicTrajectory).
#[pyfunction]
#[pyo3(signature = (t_s, accel_body_m_s2, omega_body_rad_s, *, position0_m = [0.0; 3],
                    velocity0_m_s = [0.0; 3], euler0_rad = [0.0; 3], nav_frame = "ENU"))]
#[allow(clippy::too_many_arguments)]
fn truth_from_body_rates<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    accel_body_m_s2: PyReadonlyArray2<'py, f64>,
    omega_body_rad_s: PyReadonlyArray2<'py, f64>,
    position0_m: [f64; 3],
    velocity0_m_s: [f64; 3],
    euler0_rad: [f64; 3],
    nav_frame: &str,
) -> PyResult<TableOut<'py>> {
    let t = t_s.as_array().to_vec();
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
    let nav = nav(nav_frame)?;
    let table = py
        .detach(move || arrays::truth_from_body_rates(&t, data, nav))
        .map_err(refused)?;
    table_out(py, table)
}

/// Exact truth at `t_s` of a waypoint trajectory (cubic spline through the waypoints).
#[pyfunction]
#[pyo3(signature = (t_s, time_s, position_m, *, velocity_m_s = None, euler_rad = None, nav_frame = "ENU"))]
fn truth_from_waypoints<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    time_s: PyReadonlyArray1<'py, f64>,
    position_m: PyReadonlyArray2<'py, f64>,
    velocity_m_s: Option<PyReadonlyArray2<'py, f64>>,
    euler_rad: Option<PyReadonlyArray2<'py, f64>>,
    nav_frame: &str,
) -> PyResult<TableOut<'py>> {
    let t = t_s.as_array().to_vec();
    let knots = time_s.as_array().to_vec();
    let p = rows::<3>("position_m", &position_m)?;
    let v = velocity_m_s
        .as_ref()
        .map(|v| rows::<3>("velocity_m_s", v))
        .transpose()?;
    let e = euler_rad
        .as_ref()
        .map(|e| rows::<3>("euler_rad", e))
        .transpose()?;
    let w = imukit::motion::waypoints::Waypoints::new(&knots, &p, v.as_deref(), e.as_deref())
        .map_err(refused)?;
    let nav = nav(nav_frame)?;
    let table = py
        .detach(move || arrays::truth_from_waypoints(&t, w, nav))
        .map_err(refused)?;
    table_out(py, table)
}

/// Names of the built-in scenarios.
#[pyfunction]
fn builtin_names() -> Vec<&'static str> {
    imukit::scenario::builtin::NAMES.to_vec()
}

/// A built-in scenario as TOML text.
#[pyfunction]
fn builtin_toml(name: &str) -> PyResult<String> {
    imukit::scenario::builtin::toml(name).map_err(refused)
}

/// Every column of an imukit CSV file.
#[pyfunction]
fn read_csv<'py>(py: Python<'py>, path: &str) -> PyResult<TableOut<'py>> {
    let t = imukit::io::table::read_table(Path::new(path)).map_err(refused)?;
    table_out(py, t)
}

/// Writes a table as an imukit CSV (shortest round-trip numbers, atomically).
#[pyfunction]
fn write_csv(
    py: Python<'_>,
    path: &str,
    columns: Vec<String>,
    values: PyReadonlyArray2<'_, f64>,
) -> PyResult<()> {
    let v = values.as_array();
    if v.ncols() != columns.len() {
        return Err(PyValueError::new_err(format!(
            "values have {} columns, the header {}",
            v.ncols(),
            columns.len()
        )));
    }
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    let mut t = Table::new(&names);
    for row in v.rows() {
        t.push_row(&row.to_vec());
    }
    py.detach(move || t.write_csv(Path::new(path)))
        .map_err(refused)
}

/// The file of Monte Carlo run `run` of `runs` for the output `out` (`imu.csv` → `imu_run0007.csv`).
#[pyfunction]
fn run_path(out: &str, run: u64, runs: u64) -> String {
    imukit::io::table::run_path(Path::new(out), run, runs)
        .display()
        .to_string()
}

/// The kind key of a table with these columns (`truth`, `imu`, `navigation`, `allan`,
/// `errors`), or `None`.
#[pyfunction]
fn table_kind(columns: Vec<String>) -> Option<&'static str> {
    TableKind::detect(&columns).map(TableKind::key)
}

/// A panel for Python: `(title, y_label, scale, [(column, label)])`.
type PanelOut = (String, String, f64, Vec<(String, String)>);

/// The default panels of a kind.
#[pyfunction]
fn figure_panels(kind: &str) -> PyResult<Vec<PanelOut>> {
    let kind = TableKind::from_key(kind).map_err(refused)?;
    Ok(kind
        .panels()
        .into_iter()
        .map(|p| {
            (
                p.title.to_string(),
                p.y_label.to_string(),
                p.scale,
                p.columns,
            )
        })
        .collect())
}

/// The samples each animation frame shows and the speed (seconds of motion per second).
#[pyfunction]
#[pyo3(signature = (t_s, fps, speed=None))]
fn frame_plan(
    t_s: PyReadonlyArray1<'_, f64>,
    fps: f64,
    speed: Option<f64>,
) -> PyResult<(Vec<usize>, f64)> {
    let t = t_s
        .as_slice()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let plan = figures::frame_plan(t, fps, speed, "t_s").map_err(refused)?;
    Ok((plan.indices, plan.speed))
}

/// The default body box (length, width, height) for a path of this extent, m.
#[pyfunction]
fn default_body_m(extent_m: f64) -> [f64; 3] {
    figures::default_body_m(extent_m)
}

/// Whether a path (N, 3) is drawn in 3D.
#[pyfunction]
fn leaves_plane(points: PyReadonlyArray2<'_, f64>) -> PyResult<bool> {
    Ok(figures::leaves_plane(&rows::<3>("points", &points)?))
}

/// The compiled core of the `imukit` package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ImuError", m.py().get_type::<ImuError>())?;
    m.add_function(wrap_pyfunction!(simulate_text, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_expressions, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_samples, m)?)?;
    m.add_function(wrap_pyfunction!(ideal_imu, m)?)?;
    m.add_function(wrap_pyfunction!(tangent_euler, m)?)?;
    m.add_function(wrap_pyfunction!(nav_to_body, m)?)?;
    m.add_function(wrap_pyfunction!(at_lever_arm, m)?)?;
    m.add_function(wrap_pyfunction!(euler_to_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_to_euler, m)?)?;
    m.add_function(wrap_pyfunction!(euler_to_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_to_euler, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_to_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_to_quaternion, m)?)?;
    m.add_class::<PyImuSensor>()?;
    m.add_function(wrap_pyfunction!(allan_deviation, m)?)?;
    m.add_function(wrap_pyfunction!(identify_noise, m)?)?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(load_params_toml, m)?)?;
    m.add_function(wrap_pyfunction!(planar_dead_reckon, m)?)?;
    m.add_function(wrap_pyfunction!(read_planar, m)?)?;
    m.add_function(wrap_pyfunction!(strapdown, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_body_rates, m)?)?;
    m.add_function(wrap_pyfunction!(truth_from_waypoints, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_names, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_toml, m)?)?;
    m.add_function(wrap_pyfunction!(read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(write_csv, m)?)?;
    m.add_function(wrap_pyfunction!(run_path, m)?)?;
    m.add_function(wrap_pyfunction!(table_kind, m)?)?;
    m.add_function(wrap_pyfunction!(figure_panels, m)?)?;
    m.add_function(wrap_pyfunction!(frame_plan, m)?)?;
    m.add_function(wrap_pyfunction!(default_body_m, m)?)?;
    m.add_function(wrap_pyfunction!(leaves_plane, m)?)?;
    orientation::register(m)?;
    Ok(())
}
