//! `imukit plot`: default figures for every kind of imukit CSV, several files overlaid.
use std::path::{Path, PathBuf};

use imu_core::allan::identify_noise;
use imu_scenario::analysis::AllanResult;
use imu_scenario::table::{read_columns, read_header};
use imu_scenario::{Error, Table};

use super::panels::{Panel, Series, Trace, draw_3d, draw_panel, draw_plan_view, is_3d};
use super::{allan_figure, write_figure};
use crate::commands::CliError;

/// The kinds of CSV imukit writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Truth kinematics.
    Truth,
    /// IMU readings (rates or increments, planar included).
    Imu,
    /// A 3D or planar navigation output.
    Navigation,
    /// An Allan-deviation table.
    Allan,
    /// Errors against truth.
    Errors,
}

impl Kind {
    /// Whether files of the two kinds share a figure: one kind, or truth and navigation output
    /// (truth vs estimate).
    fn overlays(self, other: Self) -> bool {
        let motion = |k: Self| matches!(k, Self::Truth | Self::Navigation);
        self == other || (motion(self) && motion(other))
    }

    fn name(self) -> &'static str {
        match self {
            Self::Truth => "truth",
            Self::Imu => "IMU readings",
            Self::Navigation => "navigation output",
            Self::Allan => "Allan deviation",
            Self::Errors => "errors against truth",
        }
    }
}

/// Recognises a CSV by its columns.
fn detect(columns: &[String]) -> Option<Kind> {
    let has = |c: &str| columns.iter().any(|h| h == c);
    if has("tau_s") && columns.iter().any(|c| c.starts_with("adev_")) {
        Some(Kind::Allan)
    } else if has("pos_err_m") {
        Some(Kind::Errors)
    } else if has("pos_x_m") && has("acc_x_m_s2") && has("omega_x_rad_s") {
        Some(Kind::Truth)
    } else if has("pos_x_m") && has("pos_y_m") && has("yaw_rad") {
        Some(Kind::Navigation)
    } else if has("t_s")
        && (has("accel_x_m_s2") || has("dv_x_m_s") || has("gyro_z_rad_s") || has("mag_x_ut"))
    {
        Some(Kind::Imu)
    } else {
        None
    }
}

/// Reads every column of a CSV file.
pub fn read_table(path: &Path) -> Result<Table, CliError> {
    let header = read_header(path)?;
    let names: Vec<&str> = header.iter().map(String::as_str).collect();
    let cols = read_columns(path, &names, "")?;
    let mut t = Table::new(&names);
    for r in 0..cols.rows() {
        t.push_row(&names.iter().map(|n| cols.get(n)[r]).collect::<Vec<_>>());
    }
    Ok(t)
}

fn stem(p: &Path) -> String {
    p.file_stem().map_or_else(
        || p.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// One panel of `columns` (labels `names`) against `x` for every file.
fn panel(
    files: &[(String, Table)],
    title: &str,
    y_label: &str,
    x: &str,
    columns: &[(&str, &str)],
    scale: f64,
) -> Option<Panel> {
    let mut series = Vec::new();
    for (f, (name, t)) in files.iter().enumerate() {
        let Some(xs) = t.column(x) else { continue };
        for (k, (c, label)) in columns.iter().enumerate() {
            if let Some(ys) = t.column(c) {
                let label = if files.len() > 1 {
                    format!("{label} ({name})")
                } else {
                    (*label).to_string()
                };
                series.push(Series {
                    label,
                    points: xs
                        .iter()
                        .copied()
                        .zip(ys.iter().map(|y| y * scale))
                        .collect(),
                    color: k,
                    dashed: f > 0,
                });
            }
        }
    }
    (!series.is_empty()).then(|| Panel {
        title: title.into(),
        x_label: "t (s)".into(),
        y_label: y_label.into(),
        series,
    })
}

const XYZ: [&str; 3] = ["x", "y", "z"];

fn xyz<'a>(prefix: &str, suffix: &str, buf: &'a mut Vec<String>) -> Vec<(&'a str, &'static str)> {
    *buf = XYZ
        .iter()
        .map(|a| format!("{prefix}_{a}_{suffix}"))
        .collect();
    buf.iter().map(String::as_str).zip(XYZ).collect()
}

/// Draws the default figure for `paths` (all of one kind) into `out` (SVG or PNG).
///
/// # Errors
/// Unreadable or empty files, unknown kinds of CSV, files of different kinds, drawing errors.
pub fn plot_files(paths: &[PathBuf], out: &Path) -> Result<(), CliError> {
    if paths.is_empty() {
        return Err(Error::Invalid {
            field: "plot".into(),
            message: "give at least one CSV file".into(),
        }
        .into());
    }
    let mut files = Vec::new();
    let mut kind = None;
    for p in paths {
        let t = read_table(p)?;
        let k = detect(&t.columns).ok_or_else(|| Error::Invalid {
            field: p.display().to_string(),
            message: format!(
                "unknown kind of CSV (columns: {}); imukit plots truth, IMU readings, navigation output, \
                 Allan deviation and error tables",
                t.columns.join(", ")
            ),
        })?;
        if kind.is_some_and(|prev: Kind| !prev.overlays(k)) {
            return Err(Error::Invalid {
                field: p.display().to_string(),
                message: format!(
                    "is {}, but the first file is {}: overlay files of one kind (or truth and navigation output)",
                    k.name(),
                    kind.map_or("", Kind::name)
                ),
            }
            .into());
        }
        kind = Some(k);
        files.push((stem(p), t));
    }
    let kind = kind.unwrap_or(Kind::Imu);
    let mut b = Vec::new();
    let mut panels: Vec<Panel> = Vec::new();
    let mut push = |p: Option<Panel>| panels.extend(p);
    match kind {
        Kind::Allan => return allan_from_tables(out, &files),
        Kind::Truth | Kind::Navigation => {
            push(panel(
                &files,
                "Position",
                "position (m)",
                "t_s",
                &xyz("pos", "m", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Velocity",
                "velocity (m/s)",
                "t_s",
                &xyz("vel", "m_s", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Acceleration (navigation frame)",
                "acceleration (m/s²)",
                "t_s",
                &xyz("acc", "m_s2", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Attitude (z-y-x Euler angles)",
                "angle (deg)",
                "t_s",
                &[
                    ("yaw_rad", "yaw"),
                    ("pitch_rad", "pitch"),
                    ("roll_rad", "roll"),
                ],
                180.0 / std::f64::consts::PI,
            ));
            push(panel(
                &files,
                "Body rate",
                "ω (rad/s)",
                "t_s",
                &xyz("omega", "rad_s", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Body angular acceleration",
                "α (rad/s²)",
                "t_s",
                &xyz("alpha", "rad_s2", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Body velocity (planar)",
                "velocity (m/s)",
                "t_s",
                &[("body_vel_x_m_s", "forward"), ("body_vel_y_m_s", "left")],
                1.0,
            ));
        }
        Kind::Imu => {
            push(panel(
                &files,
                "Accelerometer",
                "specific force (m/s²)",
                "t_s",
                &xyz("accel", "m_s2", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Gyroscope",
                "angular rate (rad/s)",
                "t_s",
                &xyz("gyro", "rad_s", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Velocity increments",
                "Δv (m/s)",
                "t_s",
                &xyz("dv", "m_s", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Angle increments",
                "Δθ (rad)",
                "t_s",
                &xyz("dtheta", "rad", &mut b),
                1.0,
            ));
            push(panel(
                &files,
                "Magnetometer",
                "magnetic field (µT)",
                "t_s",
                &xyz("mag", "ut", &mut b),
                1.0,
            ));
        }
        Kind::Errors => {
            let pos = [
                ("pos_err_x_m", "x"),
                ("pos_err_y_m", "y"),
                ("pos_err_z_m", "z"),
                ("pos_err_m", "norm"),
            ];
            push(panel(
                &files,
                "Position error",
                "error (m)",
                "t_s",
                &pos,
                1.0,
            ));
            let vel = [
                ("vel_err_x_m_s", "x"),
                ("vel_err_y_m_s", "y"),
                ("vel_err_z_m_s", "z"),
            ];
            push(panel(
                &files,
                "Velocity error",
                "error (m/s)",
                "t_s",
                &vel,
                1.0,
            ));
            push(panel(
                &files,
                "Attitude error",
                "angle (deg)",
                "t_s",
                &[("att_err_rad", "angle")],
                180.0 / std::f64::consts::PI,
            ));
        }
    }
    let traces: Vec<Trace> = if matches!(kind, Kind::Truth | Kind::Navigation) {
        files
            .iter()
            .map(|(name, t)| Trace::from_table(name, t))
            .collect()
    } else {
        Vec::new()
    };
    let three_d = is_3d(&traces);
    let cells = panels.len() + usize::from(!traces.is_empty());
    let cols = if cells > 3 { 2 } else { 1 };
    let rows = cells.div_ceil(cols);
    let (w, h) = (560 * cols as u32, 320 * rows as u32);
    write_figure(out, w, h, |root| {
        let areas = root.split_evenly((rows, cols));
        let mut next = areas.iter();
        if !traces.is_empty() {
            let area = next.next().ok_or("no room for the trajectory")?;
            if three_d {
                draw_3d(area, "Trajectory", &traces)?;
            } else {
                draw_plan_view(area, "Trajectory (top view)", &traces)?;
            }
        }
        for (p, area) in panels.iter().zip(next) {
            draw_panel(area, p)?;
        }
        Ok(())
    })
}

/// Allan tables: the curves with the noise lines identified from each curve.
fn allan_from_tables(out: &Path, files: &[(String, Table)]) -> Result<(), CliError> {
    let mut columns = vec!["tau_s".to_string()];
    let mut noise = Vec::new();
    let first = &files[0].1;
    let tau = first.column("tau_s").unwrap_or_default();
    let mut curves = Vec::new();
    for (name, t) in files {
        for c in t.columns.iter().filter(|c| c.starts_with("adev_")) {
            let adev = t.column(c).unwrap_or_default();
            if adev.len() != tau.len() {
                return Err(Error::Invalid {
                    field: name.clone(),
                    message: "Allan tables to overlay need the same τ values".into(),
                }
                .into());
            }
            let label = if files.len() > 1 {
                format!("{c} ({name})")
            } else {
                c.clone()
            };
            noise.push((label.clone(), identify_noise(&tau, &adev)));
            columns.push(label);
            curves.push(adev);
        }
    }
    let mut data = Vec::new();
    for (k, t) in tau.iter().enumerate() {
        data.push(*t);
        data.extend(curves.iter().map(|c| c[k]));
    }
    allan_figure(
        out,
        &AllanResult {
            table: Table { columns, data },
            noise,
        },
    )
}
