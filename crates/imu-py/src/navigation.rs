//! Navigation: planar dead reckoning, 3D strapdown, and errors against truth.
use std::path::Path;

use imu_core::strapdown::planar::{PlanarSample, PlanarScheme};
use imukit::Table;
use imukit::choice::Choice;
use imukit::compare as comparison;
use imukit::navigate::{InitialState, NavAsked, NavRequest, SchemeName, VerticalName, integrate};
use imukit::planar::{self, EXERCISE_POSITION0_M, PlanarRequest};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{
    DescribedIn, DescribedOut, TableOut, check_len, choice, choice_opt, described_in,
    described_out, fixed, fixed_opt, non_negative, table_in, table_out,
};
use crate::errors::refused;

/// Planar dead reckoning of (t, a_x, a_y, ω_z) into a navigation table.
#[pyfunction]
#[pyo3(signature = (t_s, accel_x_m_s2, accel_y_m_s2, gyro_z_rad_s, *, scheme = PlanarScheme::default_name(),
                    position0_m = EXERCISE_POSITION0_M.to_vec(), heading0_rad = 0.0, velocity0_m_s = vec![0.0, 0.0]))]
#[allow(clippy::too_many_arguments)]
fn planar_dead_reckon<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    accel_x_m_s2: PyReadonlyArray1<'py, f64>,
    accel_y_m_s2: PyReadonlyArray1<'py, f64>,
    gyro_z_rad_s: PyReadonlyArray1<'py, f64>,
    scheme: &str,
    position0_m: Vec<f64>,
    heading0_rad: f64,
    velocity0_m_s: Vec<f64>,
) -> PyResult<TableOut<'py>> {
    let position0_m = fixed::<2>("position0_m", &position0_m)?;
    let velocity0_m_s = fixed::<2>("velocity0_m_s", &velocity0_m_s)?;
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
    let request = PlanarRequest {
        scheme: choice("scheme", scheme)?,
        position0_m,
        heading0_rad,
        velocity0_m_s,
    };
    let table = py.detach(|| request.run(&samples)).map_err(refused)?;
    table_out(py, table)
}

/// Planar IMU samples from a CSV or `.dat` file, as a table with `t_s, accel_x_m_s2,
/// accel_y_m_s2, gyro_z_rad_s`.
#[pyfunction]
fn read_planar<'py>(py: Python<'py>, path: &str) -> PyResult<TableOut<'py>> {
    let samples = planar::read_planar(Path::new(path)).map_err(refused)?;
    table_out(py, planar::samples_table(&samples))
}

/// The settings a table's description may fix, as the keywords give them (`None`: left out).
fn nav_asked(
    nav_frame: Option<&str>,
    accel_sign: Option<&str>,
    gravity_m_s2: Option<f64>,
    earth: Option<&str>,
    earth_gravity: Option<&str>,
) -> PyResult<NavAsked> {
    Ok(NavAsked {
        nav_frame: choice_opt("nav_frame", nav_frame)?,
        accel_sign: choice_opt("accel_sign", accel_sign)?,
        gravity_m_s2,
        earth: choice_opt("earth", earth)?,
        earth_gravity: choice_opt("earth_gravity", earth_gravity)?,
        conventions: None,
    })
}

/// 3D strapdown of an IMU table (rates or increments) from an initial state: the first row of
/// a truth table (`initial_columns`, `initial_values`) or its parts.
#[pyfunction]
#[pyo3(signature = (columns, values, *, initial_columns = None, initial_values = None, position0_m = None,
                    velocity0_m_s = None, quaternion0 = None, euler0_rad = None,
                    nav_frame = None, gravity_m_s2 = None, coning = true, sculling = true,
                    accel_sign = None, scheme = SchemeName::default_name(),
                    substeps = imukit::navigate::DEFAULT_RK4_SUBSTEPS as i64,
                    earth = None, vertical = VerticalName::default_name(),
                    baro_time_constant_s = imukit::navigate::DEFAULT_BARO_TIME_CONSTANT_S,
                    earth_gravity = None, lat0_deg = None, lon0_deg = None, height0_m = None,
                    baro_columns = None, baro_values = None, described = Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn strapdown<'py>(
    py: Python<'py>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
    initial_columns: Option<Vec<String>>,
    initial_values: Option<PyReadonlyArray2<'py, f64>>,
    position0_m: Option<Vec<f64>>,
    velocity0_m_s: Option<Vec<f64>>,
    quaternion0: Option<Vec<f64>>,
    euler0_rad: Option<Vec<f64>>,
    nav_frame: Option<&str>,
    gravity_m_s2: Option<f64>,
    coning: bool,
    sculling: bool,
    accel_sign: Option<&str>,
    scheme: &str,
    substeps: i64,
    earth: Option<&str>,
    vertical: &str,
    baro_time_constant_s: f64,
    earth_gravity: Option<&str>,
    lat0_deg: Option<f64>,
    lon0_deg: Option<f64>,
    height0_m: Option<f64>,
    baro_columns: Option<Vec<String>>,
    baro_values: Option<PyReadonlyArray2<'py, f64>>,
    described: DescribedIn<'py>,
) -> PyResult<(DescribedOut<'py>, Vec<String>)> {
    let substeps = usize::try_from(non_negative("substeps", substeps)?).unwrap_or(usize::MAX);
    let asked = nav_asked(nav_frame, accel_sign, gravity_m_s2, earth, earth_gravity)?;
    let described = described_in(&described)?;
    // What the tables say they hold fills the settings left out, and refuses an argument that
    // contradicts it, as the command line does with its files.
    let setup = NavRequest {
        scheme: choice("scheme", scheme)?,
        substeps,
        coning,
        sculling,
        vertical: choice("vertical", vertical)?,
        baro_time_constant_s,
        barometer: baro_columns.is_some(),
        ..NavRequest::default()
    }
    .with_described(&asked, &described)
    .and_then(|r| r.setup())
    .map_err(refused)?;
    let mut imu = table_in("imu", columns, &values)?;
    if let (Some(c), Some(v)) = (baro_columns, &baro_values) {
        imu =
            imukit::navigate::with_baro_column(&imu, &table_in("baro", c, v)?).map_err(refused)?;
    }
    let initial = match (initial_columns, &initial_values) {
        (Some(c), Some(v)) => InitialState::from_table(&table_in("initial", c, v)?),
        _ => InitialState::from_parts(
            fixed_opt::<3>("position0_m", position0_m)?,
            fixed_opt::<3>("velocity0_m_s", velocity0_m_s)?,
            fixed_opt::<4>("quaternion0", quaternion0)?,
            fixed_opt::<3>("euler0_rad", euler0_rad)?,
        ),
    }
    .and_then(|s| s.with_geodetic0(lat0_deg, lon0_deg, height0_m))
    .and_then(|s| Ok(s.at_origin(described.origin()?)))
    .map_err(refused)?;
    let out = py
        .detach(|| integrate(&imu, &initial, &setup))
        .map_err(refused)?;
    // The gaps the integration bridged, as warnings (row 0 is the first sample).
    let t = imu.column("t_s").unwrap_or_default();
    let notes = imukit::io::rows::Gaps::of_times(&t, 0)
        .message("imu")
        .into_iter();
    Ok((
        described_out(py, out, &setup.description())?,
        notes.collect(),
    ))
}

/// Errors of an estimate against truth: (error table, summary dict).
#[pyfunction]
#[pyo3(signature = (truth_columns, truth, estimate_columns, estimate, described = Vec::new(),
                    align_heading = false))]
fn compare<'py>(
    py: Python<'py>,
    truth_columns: Vec<String>,
    truth: PyReadonlyArray2<'py, f64>,
    estimate_columns: Vec<String>,
    estimate: PyReadonlyArray2<'py, f64>,
    described: DescribedIn<'py>,
    align_heading: bool,
) -> PyResult<(TableOut<'py>, Bound<'py, PyDict>)> {
    comparison::check_comparable(&described_in(&described)?).map_err(refused)?;
    let t: Table = table_in("truth", truth_columns, &truth)?;
    let e: Table = table_in("estimate", estimate_columns, &estimate)?;
    let c = py
        .detach(move || {
            comparison::compare_with(&t, &e, comparison::CompareOptions { align_heading })
        })
        .map_err(refused)?;
    let d = PyDict::new(py);
    for (name, value) in c.summary.entries() {
        d.set_item(name, value)?;
    }
    Ok((table_out(py, c.table)?, d))
}

/// Loosely coupled INS/GNSS fusion with the filter's model from a scenario (a dict, as
/// `simulate_dict` takes, or TOML/JSON text), optionally with odometer and barometer readings
/// and the non-holonomic constraints: (estimate table, updates applied, updates rejected).
#[pyfunction]
#[pyo3(signature = (imu_columns, imu_values, gnss_columns, gnss_values, initial_columns, initial_values,
                    scenario, *, format = "dict", base_dir = ".", gate = true, align = None,
                    odometer_columns = None, odometer_values = None, baro_columns = None,
                    baro_values = None, nhc_sigma_m_s = None, covariance_interval_s = None,
                    sensor_errors = None, rest_s = None, smooth = false, zupt = false, gnss_adaptive = false,
                    imu_model = None, part = None,
                    gnss_horizontal_accuracy_m = None, gnss_vertical_accuracy_m = None,
                    gnss_velocity_accuracy_m_s = None, gnss_lever_arm_m = None,
                    gnss_decay_factor = None, gnss_correlation_time_s = None, gnss_latency_s = None,
                    gnss_uere_m = None,
                    nav_frame = None, earth = None, earth_gravity = None, accel_sign = None,
                    gravity_m_s2 = None, described = Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn fuse<'py>(
    py: Python<'py>,
    imu_columns: Vec<String>,
    imu_values: PyReadonlyArray2<'py, f64>,
    gnss_columns: Vec<String>,
    gnss_values: PyReadonlyArray2<'py, f64>,
    initial_columns: Option<Vec<String>>,
    initial_values: Option<PyReadonlyArray2<'py, f64>>,
    scenario: &Bound<'py, PyAny>,
    format: &str,
    base_dir: &str,
    gate: bool,
    align: Option<String>,
    odometer_columns: Option<Vec<String>>,
    odometer_values: Option<PyReadonlyArray2<'py, f64>>,
    baro_columns: Option<Vec<String>>,
    baro_values: Option<PyReadonlyArray2<'py, f64>>,
    nhc_sigma_m_s: Option<f64>,
    covariance_interval_s: Option<f64>,
    sensor_errors: Option<bool>,
    rest_s: Option<f64>,
    smooth: bool,
    zupt: bool,
    gnss_adaptive: bool,
    imu_model: Option<String>,
    part: Option<String>,
    gnss_horizontal_accuracy_m: Option<f64>,
    gnss_vertical_accuracy_m: Option<f64>,
    gnss_velocity_accuracy_m_s: Option<f64>,
    gnss_lever_arm_m: Option<Vec<f64>>,
    gnss_decay_factor: Option<f64>,
    gnss_correlation_time_s: Option<f64>,
    gnss_latency_s: Option<f64>,
    gnss_uere_m: Option<f64>,
    nav_frame: Option<&str>,
    earth: Option<&str>,
    earth_gravity: Option<&str>,
    accel_sign: Option<&str>,
    gravity_m_s2: Option<f64>,
    described: DescribedIn<'py>,
) -> PyResult<(DescribedOut<'py>, usize, usize, Vec<String>)> {
    use imukit::fuse::{AidTables, FuseRequest, Start, fuse_with};
    let asked = nav_asked(nav_frame, accel_sign, gravity_m_s2, earth, earth_gravity)?;
    let described = described_in(&described)?;
    let gnss = imukit::scenario::gnss::GnssSpec {
        horizontal_accuracy_m: gnss_horizontal_accuracy_m,
        vertical_accuracy_m: gnss_vertical_accuracy_m,
        velocity_accuracy_m_s: gnss_velocity_accuracy_m_s,
        lever_arm_m: fixed_opt::<3>("gnss_lever_arm_m", gnss_lever_arm_m)?,
        decay_factor: gnss_decay_factor,
        correlation_time_s: gnss_correlation_time_s,
        latency_s: gnss_latency_s,
        ..Default::default()
    };
    let model = model_of(scenario, format, imu_model, part, gnss)?;
    let imu = table_in("imu", imu_columns, &imu_values)?;
    let gnss = table_in("gnss", gnss_columns, &gnss_values)?;
    let gnss = match gnss_uere_m {
        Some(uere) => imukit::io::nmea::with_uere(&gnss, uere).map_err(refused)?,
        None => gnss,
    };
    let initial = match (initial_columns, &initial_values) {
        (Some(c), Some(v)) => {
            Some(InitialState::from_table(&table_in("initial", c, v)?).map_err(refused)?)
        }
        _ => None,
    };
    let align = choice_opt("align", align.as_deref())?;
    let odometer = optional_table("odometer", odometer_columns, odometer_values.as_ref())?;
    let baro = optional_table("baro", baro_columns, baro_values.as_ref())?;
    let base = base_dir.to_string();
    let (table, summary, description) = py
        .detach(move || {
            let request = FuseRequest {
                start: Start::of(initial.as_ref(), align)?
                    .or_else(|| Start::when_not_given(!gnss.columns.is_empty())),
                earth: None,
                gate,
                nhc_sigma_m_s,
                covariance_interval_s,
                sensor_errors,
                rest_s,
                smooth,
                zupt,
                adapt_fixes: gnss_adaptive,
            };
            let (setup, start) = match model {
                Model::Scenario(spec) => {
                    let scenario = spec.resolve(Path::new(&base))?;
                    // Tables or arguments in another frame, on another Earth or with the other
                    // sign than the scenario's are not the scenario's data.
                    described.check_fixed(
                        &scenario.description(None),
                        &asked.as_description(),
                        "the scenario",
                    )?;
                    request.setup(&scenario)?
                }
                Model::Part(part) => {
                    request.apply(part.setup_described(&asked, &described, &imu)?)?
                }
            };
            let aids = AidTables {
                odometer: odometer.as_ref(),
                baro: baro.as_ref(),
            };
            let description = setup.description();
            fuse_with(&imu, &gnss, aids, start, &setup).map(|(t, s)| (t, s, description))
        })
        .map_err(refused)?;
    Ok((
        described_out(py, table, &description)?,
        summary.updates,
        summary.rejected,
        fuse_warnings(&summary),
    ))
}

/// An aid's table, when both its columns and its values were given.
fn optional_table(
    name: &str,
    columns: Option<Vec<String>>,
    values: Option<&PyReadonlyArray2<'_, f64>>,
) -> PyResult<Option<imukit::Table>> {
    match (columns, values) {
        (Some(c), Some(v)) => table_in(name, c, v).map(Some),
        _ => Ok(None),
    }
}

/// The filter's model: the scenario's, or a part with the receiver's accuracies (one value,
/// made once per call: its size does not matter).
#[allow(clippy::large_enum_variant)]
enum Model {
    Scenario(imukit::ScenarioSpec),
    Part(imukit::fuse::PartModel),
}

/// The model `fuse` was given: `imu_model` (a preset or a file) with `part` and the receiver's
/// figures, the scenario in `format`, or neither (the noise learnt from the log).
fn model_of(
    scenario: &Bound<'_, PyAny>,
    format: &str,
    imu_model: Option<String>,
    part: Option<String>,
    gnss: imukit::scenario::gnss::GnssSpec,
) -> PyResult<Model> {
    use imukit::ScenarioSpec;
    use imukit::fuse::{Part, PartModel};
    Ok(match imu_model {
        None if scenario.is_none() => Model::Part(PartModel {
            imu: Part::Learnt,
            part,
            gnss,
        }),
        Some(imu) => Model::Part(PartModel {
            imu: Part::named(&imu),
            part,
            gnss,
        }),
        None => Model::Scenario(
            match format {
                "dict" => ScenarioSpec::from_tree(
                    &crate::convert::value_tree(scenario, "scenario")?,
                    "scenario dict",
                ),
                "toml" => ScenarioSpec::from_toml(&scenario.extract::<String>()?, "scenario"),
                "json" => ScenarioSpec::from_json(&scenario.extract::<String>()?, "scenario"),
                other => {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "format must be \"dict\", \"toml\" or \"json\", got {other:?}"
                    )));
                }
            }
            .map_err(refused)?,
        ),
    })
}

/// What a fuse run warns of: the IMU's repeated rows and a long stretch without stances.
fn fuse_warnings(summary: &imukit::fuse::FuseSummary) -> Vec<String> {
    summary
        .repeats
        .message("imu", 0)
        .into_iter()
        .chain(imukit::fuse::stance_gap_message("imu", summary.stance_gap))
        .collect()
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fuse, m)?)?;
    m.add_function(wrap_pyfunction!(planar_dead_reckon, m)?)?;
    m.add_function(wrap_pyfunction!(read_planar, m)?)?;
    m.add_function(wrap_pyfunction!(strapdown, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
