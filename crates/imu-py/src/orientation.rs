//! Orientation estimation for Python: the e-compass, every filter behind one class, and the
//! quaternion distance (the Python classes `imukit.ImuFilter`, `AhrsFilter`, … wrap these).
use imu_core::{Enu, Ned};
use imukit::io::conventions::NavFrameName;
use imukit::io::rows::SampleClock;
use imukit::orient::{
    AnyFilter, FilterKind, OrientRequest, ecompass_rows, frame_and_sign, quaternion_distances,
    run_rows, smooth_rows,
};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{array2, choice, choice_opt, flat_rows, vector};
use crate::errors::refused;

/// The nav-frame generic filter.
enum Filter {
    Enu(AnyFilter<Enu>),
    Ned(AnyFilter<Ned>),
}

/// One orientation filter (see `imukit.ImuFilter` and its siblings).
#[pyclass(module = "imukit._core", name = "OrientationFilter")]
pub(crate) struct PyOrientationFilter {
    filter: Filter,
    clock: SampleClock,
    gyroscope: bool,
    magnetometer: bool,
    /// The robust filter's bias and flags of the last call's estimates (empty for the others).
    last_status: Vec<[f64; 6]>,
    /// Each call is a whole run, smoothed (the robust filter only).
    smooth: bool,
}

type Estimates<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

#[pymethods]
impl PyOrientationFilter {
    #[new]
    #[pyo3(signature = (kind, *, sample_rate, conventions = None, reference_frame = None,
                        accel_sign = None, magnetometer = false, settings = Vec::new(),
                        initial_process_noise = None, smooth = false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        kind: &str,
        sample_rate: f64,
        conventions: Option<&str>,
        reference_frame: Option<&str>,
        accel_sign: Option<&str>,
        magnetometer: bool,
        settings: Vec<(String, f64)>,
        initial_process_noise: Option<Vec<f64>>,
        smooth: bool,
    ) -> PyResult<Self> {
        let request = OrientRequest {
            filter: choice("kind", kind)?,
            conventions: choice_opt("conventions", conventions)?.unwrap_or_default(),
            nav_frame: choice_opt("reference_frame", reference_frame)?,
            accel_sign: choice_opt("accel_sign", accel_sign)?,
            settings,
            use_magnetometer: magnetometer,
            smooth,
        };
        let (mut spec, nav) = request.resolve();
        let kind = spec.kind;
        if smooth && kind != FilterKind::Robust {
            return Err(PyValueError::new_err(format!(
                "smooth: only the robust filter smooths, not {kind}"
            )));
        }
        spec.magnetometer = kind.magnetometer().unwrap_or(magnetometer);
        spec.initial_process_noise = initial_process_noise;
        let filter = match nav {
            NavFrameName::ENU => Filter::Enu(spec.build(sample_rate).map_err(refused)?),
            NavFrameName::NED => Filter::Ned(spec.build(sample_rate).map_err(refused)?),
        };
        Ok(Self {
            filter,
            clock: SampleClock::default(),
            gyroscope: kind != FilterKind::Ecompass,
            magnetometer: spec.magnetometer,
            last_status: Vec::new(),
            smooth,
        })
    }

    /// Readings (N, 3) and their times (N,) when known → `(q_nb (M, 4), angular velocity
    /// (M, 3))`, M = N / decimation; the state and the last time carry over to the next call.
    #[pyo3(signature = (accel, gyro = None, mag = None, t_s = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        accel: PyReadonlyArray2<'py, f64>,
        gyro: Option<PyReadonlyArray2<'py, f64>>,
        mag: Option<PyReadonlyArray2<'py, f64>>,
        t_s: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Estimates<'py>> {
        let t = t_s.as_ref().map(vector);
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
        let (filter, clock, smooth) = (&mut self.filter, &mut self.clock, self.smooth);
        let out = py
            .detach(|| match filter {
                Filter::Enu(AnyFilter::Robust(r)) if smooth => {
                    smooth_rows::<Enu>(*r.params(), a, g.unwrap_or_default(), m, t.as_deref())
                }
                Filter::Ned(AnyFilter::Robust(r)) if smooth => {
                    smooth_rows::<Ned>(*r.params(), a, g.unwrap_or_default(), m, t.as_deref())
                }
                Filter::Enu(f) => run_rows(f, clock, a, g, m, t.as_deref()),
                Filter::Ned(f) => run_rows(f, clock, a, g, m, t.as_deref()),
            })
            .map_err(refused)?;
        let rows = out.quaternions.len();
        self.last_status = out.status;
        Ok((
            array2(py, rows, 4, out.quaternions.concat())?,
            array2(py, rows, 3, out.angular_velocity_rad_s.concat())?,
        ))
    }

    /// Back to the state before the first sample.
    fn reset(&mut self) {
        use imu_core::orientation::OrientationFilter;
        self.clock = SampleClock::default();
        match &mut self.filter {
            Filter::Enu(f) => f.reset(),
            Filter::Ned(f) => f.reset(),
        }
    }

    /// The robust filter's gyroscope bias (rad/s) and flags (at rest, accelerometer rejected,
    /// magnetic disturbance; 1 or 0) for each estimate of the last call, (M, 6); `None` for the
    /// other filters.
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        if !matches!(
            self.filter,
            Filter::Enu(AnyFilter::Robust(_)) | Filter::Ned(AnyFilter::Robust(_))
        ) {
            return Ok(None);
        }
        let rows = self.last_status.len();
        array2(py, rows, 6, self.last_status.concat()).map(Some)
    }

    /// The gyroscope offset estimate of a Kalman filter, rad/s (None for the others).
    /// The navigation frame the filter estimates in, as resolved: `"ENU"` or `"NED"`.
    #[getter]
    fn reference_frame(&self) -> &'static str {
        match self.filter {
            Filter::Enu(_) => "ENU",
            Filter::Ned(_) => "NED",
        }
    }

    #[getter]
    fn gyroscope_offset(&self) -> Option<[f64; 3]> {
        match &self.filter {
            Filter::Enu(AnyFilter::Kalman(k)) => Some(k.state().gyroscope_offset()),
            Filter::Ned(AnyFilter::Kalman(k)) => Some(k.state().gyroscope_offset()),
            Filter::Enu(AnyFilter::Robust(r)) | Filter::Ned(AnyFilter::Robust(r)) => {
                Some(r.status().gyro_bias_rad_s)
            }
            _ => None,
        }
    }
}

/// Orientation `q_nb` (N, 4) from accelerometer and magnetometer rows (N, 3).
#[pyfunction]
#[pyo3(signature = (accel, mag, *, conventions = None, reference_frame = None, accel_sign = None))]
fn ecompass<'py>(
    py: Python<'py>,
    accel: PyReadonlyArray2<'py, f64>,
    mag: PyReadonlyArray2<'py, f64>,
    conventions: Option<&str>,
    reference_frame: Option<&str>,
    accel_sign: Option<&str>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = flat_rows::<3>("accel", &accel)?;
    let m = flat_rows::<3>("mag", &mag)?;
    let (nav, s) = frame_and_sign(
        choice_opt("conventions", conventions)?.unwrap_or_default(),
        choice_opt("reference_frame", reference_frame)?,
        choice_opt("accel_sign", accel_sign)?,
    );
    let q = py.detach(|| ecompass_rows(a, m, s, nav)).map_err(refused)?;
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
    let d = quaternion_distances(a, b).map_err(refused)?;
    Ok(PyArray1::from_vec(py, d))
}

/// Adds this module's classes and functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOrientationFilter>()?;
    m.add_function(wrap_pyfunction!(ecompass, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion_distance, m)?)?;
    Ok(())
}
