//! Realistic sensors: MATLAB's `imuSensor` (`imukit.ImuSensor`), presets, parameter files,
//! datasheet units, Allan deviation with noise identification, the readings' spectrum and a
//! signal chain's response.
use std::path::Path;

use imukit::allan;
use imukit::imu_sensor::{ImuSensor, ImuSensorRequest, Orientation};
use imukit::io::params::Profile;
use imukit::io::part_file::{read_param_file, to_toml};
use imukit::io::{presets, units};
use imukit::scenario::ImuSpec;
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::{
    check_len, choice_opt, fixed_opt, flat_rows, matrices_in, non_negative, sensor_table,
};
use crate::errors::{refused, shape_error};

/// MATLAB-shaped IMU simulator (see the Python class `imukit.ImuSensor`).
#[pyclass(module = "imukit._core", name = "ImuSensor")]
struct PyImuSensor(ImuSensor);

#[pymethods]
impl PyImuSensor {
    #[new]
    #[pyo3(signature = (imu_type = None, *, reference_frame = None, sample_rate = None, temperature = None,
                        magnetic_field = None, accelerometer = None, gyroscope = None, magnetometer = None,
                        preset = None, seed = 0, profile = None, accel_sign = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        imu_type: Option<&str>,
        reference_frame: Option<&str>,
        sample_rate: Option<f64>,
        temperature: Option<f64>,
        magnetic_field: Option<Vec<f64>>,
        accelerometer: Option<&Bound<'_, PyAny>>,
        gyroscope: Option<&Bound<'_, PyAny>>,
        magnetometer: Option<&Bound<'_, PyAny>>,
        preset: Option<String>,
        seed: i64,
        profile: Option<&str>,
        accel_sign: Option<&str>,
    ) -> PyResult<Self> {
        // What is left out is MATLAB's default, as the library states it.
        let d = ImuSensorRequest::default();
        let request = ImuSensorRequest {
            imu_type: choice_opt("imu_type", imu_type)?.unwrap_or(d.imu_type),
            reference_frame: choice_opt("reference_frame", reference_frame)?
                .unwrap_or(d.reference_frame),
            sample_rate_hz: sample_rate.unwrap_or(d.sample_rate_hz),
            temperature_c: temperature.unwrap_or(d.temperature_c),
            magnetic_field_ut: fixed_opt::<3>("magnetic_field", magnetic_field)?,
            profile: choice_opt("profile", profile)?.unwrap_or(d.profile),
            accel_sign: choice_opt("accel_sign", accel_sign)?,
            params: ImuSpec {
                preset,
                seed: Some(non_negative("seed", seed)?),
                accelerometer: sensor_table("accelerometer", accelerometer)?,
                gyroscope: sensor_table("gyroscope", gyroscope)?,
                magnetometer: sensor_table("magnetometer", magnetometer)?,
                ..ImuSpec::default()
            },
        };
        ImuSensor::new(&request).map(Self).map_err(refused)
    }

    /// Readings for nav-frame acceleration (N, 3), angular velocity (N, 3) and attitude
    /// quaternions `q_nb` (N, 4) or MATLAB's rotation matrices `C_nbᵀ` (N, 3, 3); returns
    /// (N, 9) rows of accel, gyro, mag (absent sensors zero). State and noise stream carry over
    /// between calls. `out`, a C-contiguous writeable (N, 9) float64 array, receives the rows
    /// instead of a new array (a buffer reused across chunks is not page-faulted again).
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
        let n = a.len() / 3;
        check_len("angular_velocity", w.len() / 3, n)?;
        // The orientation stays in the caller's array; each sample's rotation is made in the loop.
        let matrices;
        let orientation = match (&quaternion, &dcm) {
            (Some(q), None) => Orientation::Quaternions(flat_rows::<4>("orientation", q)?),
            (None, Some(m)) => {
                matrices = matrices_in("orientation", m)?;
                Orientation::NavToBody(&matrices)
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
                return Err(shape_error(format!(
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
                .map_err(|e| shape_error(format!("out: {e}")))?;
            let o = guard
                .as_slice_mut()
                .map_err(|e| shape_error(format!("out must be C-contiguous: {e}")))?;
            let sensor = &mut self.0;
            py.detach(|| sensor.measure(a, w, orientation, o))
                .map_err(refused)?;
        }
        Ok(out)
    }

    /// Back to the initial state and the start of the seeded noise stream.
    fn reset(&mut self) {
        self.0.reset();
    }

    /// `"accel-gyro"`, `"accel-mag"` or `"accel-gyro-mag"`.
    #[getter]
    fn imu_type(&self) -> &'static str {
        imukit::choice::Choice::name(self.0.kind())
    }

    /// Temperature of all sensors, °C.
    #[getter]
    fn get_temperature(&self) -> f64 {
        self.0.temperature_c()
    }

    #[setter]
    fn set_temperature(&mut self, t: f64) -> PyResult<()> {
        self.0.set_temperature_c(t).map_err(refused)
    }
}

/// `(tau_s, adev)`.
type AllanOut<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// Overlapping Allan deviation of each column of `x` (N, k) at octave τ: returns
/// `(tau_s, adev)` with `adev` of shape (T, k).
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
        .detach(move || allan::allan(&series, sample_rate_hz))
        .map_err(refused)?;
    let t = result.table;
    let tau = t.column("tau_s").unwrap_or_default();
    let cols = t.columns.len() - 1;
    let adev: Vec<f64> = t
        .data
        .chunks(t.columns.len())
        .flat_map(|r| r[1..].to_vec())
        .collect();
    let adev =
        Array2::from_shape_vec((tau.len(), cols), adev).map_err(|e| shape_error(e.to_string()))?;
    Ok((PyArray1::from_vec(py, tau), adev.into_pyarray(py)))
}

/// Noise identification of the named columns of `x` (N, k) sampled at `sample_rate_hz`: a dict
/// with `tau_s` and (T, k) `adev`, `lower95`, `upper95`, `edf`, `fit`; `terms`, one tuple per
/// column and term `(column, term, symbol, value, lower, upper, resolved, needs_record_s,
/// unit, datasheet_unit, datasheet_factor)`; `scaled_terms`, one dict per Markov or sinusoid
/// term kept (`column`, `term`, `symbol`, `value`, `lower`, `upper`, `scale`, `scale_lower`,
/// `scale_upper`, `unit`, `scale_unit`, `chi2_drop`, `criterion`); `reduced_chi2` per column; `params_toml` (None
/// without gyroscope or accelerometer columns) and `kalibr_yaml` (None without both).
#[pyfunction]
#[pyo3(signature = (x, sample_rate_hz, names, source, *, kalibr_inflation = imukit::io::kalibr::DEFAULT_INFLATION, kalibr_topic = imukit::io::kalibr::DEFAULT_TOPIC))]
fn identify<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    sample_rate_hz: f64,
    names: Vec<String>,
    source: &str,
    kalibr_inflation: f64,
    kalibr_topic: &str,
) -> PyResult<Bound<'py, PyDict>> {
    use imukit::identify as id;
    let v = x.as_array();
    check_len("names", names.len(), v.ncols())?;
    let series: Vec<(String, Vec<f64>)> = names
        .iter()
        .enumerate()
        .map(|(k, n)| (n.clone(), v.column(k).to_vec()))
        .collect();
    let result = py
        .detach(move || allan::allan(&series, sample_rate_hz))
        .map_err(refused)?;
    let curve = id::curve_table(&result);
    let tau = curve.column("tau_s").unwrap_or_default();
    let d = PyDict::new(py);
    d.set_item("tau_s", PyArray1::from_vec(py, tau.clone()))?;
    for prefix in ["adev", "lower95", "upper95", "edf", "fit"] {
        let mut values = Vec::with_capacity(tau.len() * names.len());
        for i in 0..tau.len() {
            for n in &names {
                values.push(
                    curve
                        .column(&format!("{prefix}_{n}"))
                        .map_or(f64::NAN, |c| c[i]),
                );
            }
        }
        let a = Array2::from_shape_vec((tau.len(), names.len()), values)
            .map_err(|e| shape_error(e.to_string()))?;
        d.set_item(prefix, a.into_pyarray(py))?;
    }
    let terms: Vec<_> = id::term_rows(&result)
        .into_iter()
        .map(|r| {
            let e = r.estimate;
            (
                r.column,
                e.term.name(),
                e.term.symbol(),
                e.value,
                e.lower,
                e.upper,
                e.resolved,
                e.needs_record_s,
                r.unit,
                r.datasheet.map(|(u, _)| u),
                r.datasheet.map(|(_, f)| f),
            )
        })
        .collect();
    d.set_item("terms", terms)?;
    let scaled = PyList::empty(py);
    for r in id::scale_rows(&result) {
        let e = r.estimate;
        let row = PyDict::new(py);
        row.set_item("column", r.column)?;
        row.set_item("term", e.term.name())?;
        row.set_item("symbol", e.term.symbol())?;
        for (key, value) in [
            ("value", e.value),
            ("lower", e.lower),
            ("upper", e.upper),
            ("scale", e.scale),
            ("scale_lower", e.scale_lower),
            ("scale_upper", e.scale_upper),
        ] {
            row.set_item(key, value)?;
        }
        row.set_item("unit", r.unit)?;
        row.set_item("scale_unit", r.scale_unit)?;
        row.set_item("chi2_drop", e.chi2_drop)?;
        row.set_item("criterion", r.criterion)?;
        scaled.append(row)?;
    }
    d.set_item("scaled_terms", scaled)?;
    let chi2: Vec<f64> = result.noise.iter().map(|c| c.fit.reduced_chi2).collect();
    d.set_item("reduced_chi2", chi2)?;
    let mean: Vec<(f64, f64)> = result
        .noise
        .iter()
        .map(|c| (c.mean, c.mean_sigma))
        .collect();
    d.set_item("mean_at_rest", mean)?;
    let warnings: Vec<String> = result
        .noise
        .iter()
        .flat_map(|c| id::column_warnings(&result, c))
        .collect();
    d.set_item("warnings", warnings)?;
    let file = id::param_file(&result, source).ok();
    d.set_item(
        "params_toml",
        file.as_ref().map(imukit::io::part_file::to_toml),
    )?;
    let yaml = match &file {
        Some(f) if f.present[0] && f.present[1] => {
            Some(id::kalibr(&result, f, kalibr_inflation, kalibr_topic).map_err(refused)?)
        }
        _ => None,
    };
    d.set_item("kalibr_yaml", yaml)?;
    let filter: Vec<_> = file
        .as_ref()
        .map(|f| id::filter_noise(f, result.sample_rate_hz))
        .unwrap_or_default()
        .into_iter()
        .map(|(s, w, b)| (s.key(), w, b))
        .collect();
    d.set_item("filter_noise", filter)?;
    d.set_item("samples", result.samples)?;
    Ok(d)
}

/// A datasheet figure in imukit's SI units: `(value, unit, fitting parameters)`.
#[pyfunction]
fn convert(value: f64, unit: &str) -> PyResult<(f64, &'static str, &'static str)> {
    let c = units::convert(value, unit).map_err(refused)?;
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

/// A preset as Kalibr's `imu.yaml` text at `rate_hz` on `topic`.
#[pyfunction]
#[pyo3(signature = (name, *, rate_hz = imukit::io::kalibr::DEFAULT_RATE_HZ, topic = imukit::io::kalibr::DEFAULT_TOPIC))]
fn preset_kalibr_yaml(name: &str, rate_hz: f64, topic: &str) -> PyResult<String> {
    let file = presets::load(name).map_err(refused)?;
    let imu = imukit::io::kalibr::KalibrImu::from_params(&file, rate_hz, topic).map_err(refused)?;
    Ok(imu.to_yaml())
}

/// A parameter file (imukit TOML/JSON or MATLAB loadparams JSON) as imukit TOML text, with what
/// a MATLAB file had that was skipped (as MATLAB skips it).
#[pyfunction]
#[pyo3(signature = (path, *, part = None))]
fn load_params_toml(path: &str, part: Option<&str>) -> PyResult<(String, Vec<String>)> {
    let file = read_param_file(Path::new(path), part, Profile::Default).map_err(refused)?;
    Ok((to_toml(&file), file.warnings))
}

/// A signal chain's response (`imukit.chain_response`): `chain` the `[imu.chain]` table as a
/// dict, the output at `rate_hz`, a row per frequency (`imukit::scenario::chain::RESPONSE_COLUMNS`).
#[pyfunction]
fn chain_response<'py>(
    py: Python<'py>,
    chain: &Bound<'py, PyAny>,
    rate_hz: f64,
    frequencies_hz: Vec<f64>,
) -> PyResult<crate::convert::TableOut<'py>> {
    use imukit::scenario::chain::{ChainSetup, ChainSpec};
    let tree = crate::convert::value_tree(chain, "chain")?;
    let spec: ChainSpec = imukit::io::value_tree::read(&tree).map_err(|e| {
        refused(imukit::Error::Invalid {
            field: if e.path.is_empty() {
                "imu.chain".into()
            } else {
                format!("imu.chain.{}", e.path).into()
            },
            message: e.message,
        })
    })?;
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(refused(imukit::Error::Invalid {
            field: "rate_hz".into(),
            message: format!("{rate_hz} is not a rate (finite, > 0)"),
        }));
    }
    let t = ChainSetup::resolve(&spec, rate_hz)
        .and_then(|c| c.response_table(rate_hz, &frequencies_hz))
        .map_err(refused)?;
    crate::convert::table_out(py, t)
}

/// The power spectral density of `names` of the readings (`imukit.spectrum`).
#[pyfunction]
fn spectrum<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    names: Vec<String>,
    segment_s: f64,
    source: &str,
) -> PyResult<crate::convert::TableOut<'py>> {
    let t: imukit::Table = crate::convert::table_in("readings", columns, &values)?;
    let psd = py
        .detach(|| imukit::spectrum::spectrum_table(&t, &names, segment_s, source))
        .map_err(refused)?;
    crate::convert::table_out(py, psd)
}

/// Adds this module's classes and functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyImuSensor>()?;
    m.add_function(wrap_pyfunction!(allan_deviation, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(preset_toml, m)?)?;
    m.add_function(wrap_pyfunction!(preset_kalibr_yaml, m)?)?;
    m.add_function(wrap_pyfunction!(load_params_toml, m)?)?;
    m.add_function(wrap_pyfunction!(chain_response, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum, m)?)?;
    Ok(())
}
