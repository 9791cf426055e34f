//! The library's request defaults by keyword (`imukit._core.DEFAULTS`): the Python layer's
//! signatures take their defaults from here, so Python and the command line (whose flags take
//! theirs from the same requests) cannot disagree.
use imukit::choice::Choice;
use imukit::io::table::ImuKind;
use imukit::navigate::NavRequest;
use imukit::orient::{Conventions, FilterKind};
use imukit::planar::PlanarRequest;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Adds `DEFAULTS`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let d = PyDict::new(m.py());
    let nav = NavRequest::default();
    d.set_item("nav_frame", nav.nav_frame.name())?;
    d.set_item("accel_sign", nav.accel_sign.name())?;
    d.set_item("scheme", nav.scheme.name())?;
    d.set_item("substeps", nav.substeps)?;
    d.set_item("gravity_m_s2", nav.gravity_m_s2)?;
    d.set_item("coning", nav.coning)?;
    d.set_item("sculling", nav.sculling)?;
    d.set_item("earth", nav.earth.name())?;
    d.set_item("vertical", nav.vertical.name())?;
    d.set_item("baro_time_constant_s", nav.baro_time_constant_s)?;
    d.set_item("earth_gravity", nav.earth_gravity.name())?;
    d.set_item("planar_scheme", PlanarRequest::default().scheme.name())?;
    d.set_item("conventions", Conventions::default_name())?;
    d.set_item("filter", FilterKind::default_name())?;
    d.set_item("imu_type", ImuKind::default_name())?;
    d.set_item("segment_s", imukit::spectrum::DEFAULT_SEGMENT_S)?;
    d.set_item("kalibr_rate_hz", imukit::io::kalibr::DEFAULT_RATE_HZ)?;
    d.set_item("kalibr_topic", imukit::io::kalibr::DEFAULT_TOPIC)?;
    d.set_item("kalibr_inflation", imukit::io::kalibr::DEFAULT_INFLATION)?;
    d.set_item("animation_fps", imu_plot::spec::DEFAULT_FPS)?;
    d.set_item(
        "planar_position0_m",
        imukit::planar::EXERCISE_POSITION0_M.to_vec(),
    )?;
    d.set_item(
        "finite_difference_order",
        imukit::core::kinematics::finite_diff::DEFAULT_ORDER,
    )?;
    // Each orientation filter's settings by MATLAB name, as the library builds them (a filter
    // with a magnetometer where it takes one; Madgwick's gain without).
    let filters = PyDict::new(m.py());
    for (name, kind) in FilterKind::NAMES {
        let settings = PyDict::new(m.py());
        let magnetometer = kind.magnetometer().unwrap_or(false);
        for (setting, value) in kind.setting_defaults(magnetometer) {
            settings.set_item(setting, value)?;
        }
        filters.set_item(*name, settings)?;
    }
    d.set_item("filters", filters)?;
    // MATLAB imuSensor's defaults, as the library's request states them.
    let s = imukit::imu_sensor::ImuSensorRequest::default();
    let sensor = PyDict::new(m.py());
    sensor.set_item("imu_type", s.imu_type.name())?;
    sensor.set_item("reference_frame", s.reference_frame.name())?;
    sensor.set_item("sample_rate", s.sample_rate_hz)?;
    sensor.set_item("temperature", s.temperature_c)?;
    sensor.set_item("profile", s.profile.name())?;
    d.set_item("imu_sensor", sensor)?;
    d.set_item(
        "initial_process_noise",
        imukit::core::orientation::KalmanParams::default()
            .initial_process_noise
            .to_vec(),
    )?;
    m.add("DEFAULTS", d)
}
