//! What the figures show, shared with `imukit plot`: the kind of a table and its panels, the
//! animation's frame plan, default body and scene (box corners, edges, nose face) and the turn of
//! NED data into east-north-up. Python draws them with matplotlib (`imukit.plot`).
use imu_plot::scene::{BOX_EDGES, BOX_NOSE, box_corners_m, point_enu, pose_enu};
use imu_plot::spec::{self, TableKind};
use imukit::io::conventions::NavFrameName;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{check_len, choice, fixed, rows, rows_out};
use crate::errors::{refused, refused_figure, shape_error};

/// The kind key of a table with these columns (`truth`, `imu`, `navigation`, `allan`,
/// `errors`), or `None`.
#[pyfunction]
fn table_kind(columns: Vec<String>) -> Option<&'static str> {
    TableKind::detect(&columns).map(TableKind::key)
}

/// A panel for Python: `(title, y_label, scale, [(column, label)], [(sigma column, line index)])`
/// — the last list: ±3σ envelopes, drawn when the table has the column.
type PanelOut = (
    String,
    String,
    f64,
    Vec<(String, String)>,
    Vec<(String, usize)>,
);

/// The default panels of a kind.
#[pyfunction]
fn figure_panels(kind: &str) -> PyResult<Vec<PanelOut>> {
    let kind = TableKind::from_key(kind).map_err(refused_figure)?;
    Ok(kind
        .panels()
        .into_iter()
        .map(|p| {
            (
                p.title.to_string(),
                p.y_label.to_string(),
                p.scale,
                p.columns,
                p.envelopes,
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
        .map_err(|e| shape_error(format!("t_s: {e}")))?;
    let plan = spec::frame_plan(t, fps, speed, "t_s").map_err(refused_figure)?;
    Ok((plan.indices, plan.speed))
}

/// The default body box (length, width, height) for a path of this extent, m.
#[pyfunction]
fn default_body_m(extent_m: f64) -> [f64; 3] {
    spec::default_body_m(extent_m)
}

/// Whether a path (N, 3) is drawn in 3D.
#[pyfunction]
fn leaves_plane(points: PyReadonlyArray2<'_, f64>) -> PyResult<bool> {
    Ok(spec::leaves_plane(&rows::<3>("points", &points)?))
}

/// Corners (8, 3), edges, nose face.
type SceneOut<'py> = (Bound<'py, PyArray2<f64>>, Vec<(usize, usize)>, Vec<usize>);

/// Positions (N, 3) and quaternions (N, 4).
type PosesOut<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// The animated body box of size `body_m`: corners (8, 3) in the body frame, edges as corner
/// index pairs, the nose face's corners in drawing order.
#[pyfunction]
fn animation_scene<'py>(py: Python<'py>, body_m: Vec<f64>) -> PyResult<SceneOut<'py>> {
    let body_m = fixed::<3>("body_m", &body_m)?;
    Ok((
        rows_out(py, box_corners_m(body_m).to_vec())?,
        BOX_EDGES.to_vec(),
        BOX_NOSE.to_vec(),
    ))
}

/// Positions (N, 3) of frame `nav_frame` in east-north-up.
#[pyfunction]
fn points_enu<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    nav_frame: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let ned = choice::<NavFrameName>("nav_frame", nav_frame)? == NavFrameName::NED;
    let p = rows::<3>("points", &points)?;
    rows_out(py, p.into_iter().map(|x| point_enu(x, ned)).collect())
}

/// Poses to draw: positions (N, 3) and quaternions `q_nb` (N, 4) of frame `nav_frame` as
/// east-north-up positions and the quaternions that carry body points into east-north-up.
#[pyfunction]
fn poses_enu<'py>(
    py: Python<'py>,
    position_m: PyReadonlyArray2<'py, f64>,
    quaternion: PyReadonlyArray2<'py, f64>,
    nav_frame: &str,
) -> PyResult<PosesOut<'py>> {
    let ned = choice::<NavFrameName>("nav_frame", nav_frame)? == NavFrameName::NED;
    let p = rows::<3>("position_m", &position_m)?;
    let q = rows::<4>("quaternion", &quaternion)?;
    check_len("quaternion", q.len(), p.len())?;
    let (mut ps, mut qs) = (Vec::with_capacity(p.len()), Vec::with_capacity(p.len()));
    for (i, (p, q)) in p.into_iter().zip(q).enumerate() {
        let (p, q) = pose_enu(p, q, ned).ok_or_else(|| {
            refused(imukit::Error::BadQuaternion {
                field: format!("quaternion[{i}]"),
            })
        })?;
        ps.push(p);
        qs.push(q);
    }
    Ok((rows_out(py, ps)?, rows_out(py, qs)?))
}

/// Adds this module's functions.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(table_kind, m)?)?;
    m.add_function(wrap_pyfunction!(figure_panels, m)?)?;
    m.add_function(wrap_pyfunction!(frame_plan, m)?)?;
    m.add_function(wrap_pyfunction!(default_body_m, m)?)?;
    m.add_function(wrap_pyfunction!(leaves_plane, m)?)?;
    m.add_function(wrap_pyfunction!(animation_scene, m)?)?;
    m.add_function(wrap_pyfunction!(points_enu, m)?)?;
    m.add_function(wrap_pyfunction!(poses_enu, m)?)?;
    Ok(())
}
