//! Orientation estimation for Python: the e-compass, every filter behind one class, and the
//! quaternion distance (the Python classes `imukit.ImuFilter`, `AhrsFilter`, … wrap these).
use imu_core::orientation::quaternion_distance as distance;
use imu_core::{AccelSign, Body, Enu, NavFrame, Ned, Rotation};
use imukit::run::orient::{AnyFilter, FilterKind, FilterSpec, run_rows};
use imukit::scenario::{AccelSignName, NavFrameName, parse_name};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::{ImuError, array2, flat_rows, frame, refused};

fn sign(name: &str) -> PyResult<AccelSign> {
    Ok(parse_name::<AccelSignName>("accel_sign", name)
        .map_err(refused)?
        .into())
}

/// The nav-frame generic filter.
enum Filter {
    Enu(AnyFilter<Enu>),
    Ned(AnyFilter<Ned>),
}

/// One orientation filter (see `imukit.ImuFilter` and its siblings).
#[pyclass(module = "imukit._core", name = "OrientationFilter")]
pub(crate) struct PyOrientationFilter {
    filter: Filter,
    gyroscope: bool,
    magnetometer: bool,
}

type Estimates<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

#[pymethods]
impl PyOrientationFilter {
    #[new]
    #[pyo3(signature = (kind, *, sample_rate, reference_frame = "NED", accel_sign = "matlab",
                        magnetometer = false, settings = Vec::new(), initial_process_noise = None))]
    fn new(
        kind: &str,
        sample_rate: f64,
        reference_frame: &str,
        accel_sign: &str,
        magnetometer: bool,
        settings: Vec<(String, f64)>,
        initial_process_noise: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let kind = FilterKind::parse(kind).map_err(refused)?;
        let mut spec = FilterSpec::new(kind, sign(accel_sign)?);
        spec.magnetometer = kind.magnetometer().unwrap_or(magnetometer);
        spec.settings = settings;
        spec.initial_process_noise = initial_process_noise;
        let filter = match frame("reference_frame", reference_frame)? {
            NavFrameName::ENU => Filter::Enu(spec.build(sample_rate).map_err(refused)?),
            NavFrameName::NED => Filter::Ned(spec.build(sample_rate).map_err(refused)?),
        };
        Ok(Self {
            filter,
            gyroscope: kind != FilterKind::Ecompass,
            magnetometer: spec.magnetometer,
        })
    }

    /// Readings (N, 3) → `(q_nb (M, 4), angular velocity (M, 3))`, M = N / decimation; the
    /// state carries over to the next call.
    #[pyo3(signature = (accel, gyro = None, mag = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        accel: PyReadonlyArray2<'py, f64>,
        gyro: Option<PyReadonlyArray2<'py, f64>>,
        mag: Option<PyReadonlyArray2<'py, f64>>,
    ) -> PyResult<Estimates<'py>> {
        let a = flat_rows::<3>("accel", &accel)?;
        let g = match (&gyro, self.gyroscope) {
            (Some(g), _) => Some(flat_rows::<3>("gyro", g)?),
            (None, true) => return Err(PyValueError::new_err("this filter needs gyro readings")),
            (None, false) => None,
        };
        let m = match (&mag, self.magnetometer) {
            (Some(m), true) => Some(flat_rows::<3>("mag", m)?),
            (None, true) => {
                return Err(PyValueError::new_err(
                    "this filter uses a magnetometer: give mag readings",
                ));
            }
            (Some(_), false) => {
                return Err(PyValueError::new_err(
                    "this filter was made without a magnetometer (has_magnetometer=False): mag readings are not used",
                ));
            }
            (None, false) => None,
        };
        let filter = &mut self.filter;
        let out = py
            .detach(|| match filter {
                Filter::Enu(f) => run_rows(f, a, g, m),
                Filter::Ned(f) => run_rows(f, a, g, m),
            })
            .map_err(refused)?;
        let rows = out.quaternions.len();
        Ok((
            array2(py, rows, 4, out.quaternions.concat())?,
            array2(py, rows, 3, out.angular_velocity_rad_s.concat())?,
        ))
    }

    /// Back to the state before the first sample.
    fn reset(&mut self) {
        use imu_core::orientation::OrientationFilter;
        match &mut self.filter {
            Filter::Enu(f) => f.reset(),
            Filter::Ned(f) => f.reset(),
        }
    }

    /// The gyroscope offset estimate of a Kalman filter, rad/s (None for the others).
    #[getter]
    fn gyroscope_offset(&self) -> Option<[f64; 3]> {
        match &self.filter {
            Filter::Enu(AnyFilter::Kalman(k)) => Some(k.state().gyroscope_offset()),
            Filter::Ned(AnyFilter::Kalman(k)) => Some(k.state().gyroscope_offset()),
            _ => None,
        }
    }
}

fn ecompass_in<N: NavFrame>(a: &[f64], m: &[f64], s: AccelSign) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(a.len() / 3 * 4);
    for (i, (a, m)) in a.chunks_exact(3).zip(m.chunks_exact(3)).enumerate() {
        let q = imu_core::orientation::ecompass::<N>([a[0], a[1], a[2]], [m[0], m[1], m[2]], s)
            .map_err(|e| format!("row {i}: {e}"))?;
        out.extend(q.to_wxyz());
    }
    Ok(out)
}

/// Orientation `q_nb` (N, 4) from accelerometer and magnetometer rows (N, 3).
#[pyfunction]
#[pyo3(signature = (accel, mag, *, reference_frame = "NED", accel_sign = "matlab"))]
fn ecompass<'py>(
    py: Python<'py>,
    accel: PyReadonlyArray2<'py, f64>,
    mag: PyReadonlyArray2<'py, f64>,
    reference_frame: &str,
    accel_sign: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = flat_rows::<3>("accel", &accel)?;
    let m = flat_rows::<3>("mag", &mag)?;
    if a.len() != m.len() {
        return Err(PyValueError::new_err(format!(
            "mag has {} rows, accel {}",
            m.len() / 3,
            a.len() / 3
        )));
    }
    let s = sign(accel_sign)?;
    let q = match frame("reference_frame", reference_frame)? {
        NavFrameName::ENU => ecompass_in::<Enu>(a, m, s),
        NavFrameName::NED => ecompass_in::<Ned>(a, m, s),
    }
    .map_err(ImuError::new_err)?;
    array2(py, a.len() / 3, 4, q)
}

/// Quaternion distance (rad) between rows of two (N, 4) arrays of quaternions `[w, x, y, z]`.
#[pyfunction]
fn quaternion_distance<'py>(
    py: Python<'py>,
    q1: PyReadonlyArray2<'py, f64>,
    q2: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (a, b) = (flat_rows::<4>("q1", &q1)?, flat_rows::<4>("q2", &q2)?);
    if a.len() != b.len() {
        return Err(PyValueError::new_err(format!(
            "q1 has {} rows, q2 {}",
            a.len() / 4,
            b.len() / 4
        )));
    }
    let rot = |c: &[f64], name: &str, i: usize| {
        Rotation::<Body, Enu>::from_wxyz([c[0], c[1], c[2], c[3]])
            .ok_or_else(|| ImuError::new_err(format!("{name}[{i}] has zero norm or is not finite")))
    };
    let d = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .enumerate()
        .map(|(i, (x, y))| Ok(distance(&rot(x, "q1", i)?, &rot(y, "q2", i)?)))
        .collect::<PyResult<Vec<f64>>>()?;
    Ok(PyArray1::from_vec(py, d))
}

/// Adds this module's classes and functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOrientationFilter>()?;
    m.add_function(wrap_pyfunction!(ecompass, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_distance, m)?)?;
    Ok(())
}
