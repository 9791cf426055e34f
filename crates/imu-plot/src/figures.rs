//! `imukit plot`: default figures for every kind of imukit CSV, several files overlaid.
use std::path::{Path, PathBuf};

use imukit::Table;
use imukit::allan::AllanResult;

use super::panels::{Panel, Series, Trace, draw_3d, draw_panel, draw_plan_view, is_3d};
use crate::PlotError;
use crate::allan::allan_figure;
use crate::draw::{FigureSize, err};
use crate::spec::{PanelSpec, TableKind};

fn stem(p: &Path) -> String {
    p.file_stem().map_or_else(
        || p.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// One panel of `spec` for every file; `None` when no file has any of its columns.
fn panel(files: &[(String, Table)], spec: &PanelSpec) -> Option<Panel> {
    let mut series = Vec::new();
    for (f, (name, t)) in files.iter().enumerate() {
        let Some(xs) = t.column("t_s") else { continue };
        for (k, (c, label)) in spec.columns.iter().enumerate() {
            if let Some(ys) = t.column(c) {
                let label = if files.len() > 1 {
                    format!("{label} ({name})")
                } else {
                    label.clone()
                };
                series.push(Series {
                    label,
                    points: xs
                        .iter()
                        .copied()
                        .zip(ys.iter().map(|y| y * spec.scale))
                        .collect(),
                    color: k,
                    style: f,
                });
            }
        }
        for (c, k) in &spec.envelopes {
            let Some(sigma) = t.column(c) else { continue };
            for sign in [3.0, -3.0] {
                series.push(Series {
                    label: if sign > 0.0 {
                        format!(
                            "±3σ {}",
                            spec.columns.get(*k).map_or("", |(_, l)| l.as_str())
                        )
                    } else {
                        String::new()
                    },
                    points: xs
                        .iter()
                        .copied()
                        .zip(sigma.iter().map(|s| sign * s * spec.scale))
                        .collect(),
                    color: *k,
                    style: 2,
                });
            }
        }
    }
    (!series.is_empty()).then(|| Panel {
        title: spec.title.into(),
        x_label: "t (s)".into(),
        y_label: spec.y_label.into(),
        series,
    })
}

/// Draws the default figure for `paths` (all of one kind) into `out` (SVG or PNG); with `ned`
/// the trajectory is drawn east, north, up.
///
/// # Errors
/// Unreadable or empty files, unknown kinds of CSV, files of different kinds, drawing errors.
pub fn plot_files(
    paths: &[PathBuf],
    out: &Path,
    ned: bool,
    size: FigureSize,
) -> Result<(), PlotError> {
    if paths.is_empty() {
        return Err(PlotError::Invalid {
            field: "plot".into(),
            message: "give at least one CSV file".into(),
        });
    }
    let tables = paths
        .iter()
        .map(|p| Ok((p.clone(), imukit::io::read::read_table(p)?)))
        .collect::<Result<Vec<_>, PlotError>>()?;
    plot_tables(&tables, out, ned, size)
}

/// Draws the default figure for tables (all of one kind, each with the file it is named by)
/// into `out`, as [`plot_files`] does for the files themselves.
///
/// # Errors
/// Unknown kinds of table, tables of different kinds, drawing errors.
pub fn plot_tables(
    tables: &[(PathBuf, Table)],
    out: &Path,
    ned: bool,
    size: FigureSize,
) -> Result<(), PlotError> {
    let mut files = Vec::new();
    let mut traces: Vec<Trace> = Vec::new();
    let mut kind: Option<TableKind> = None;
    for (p, t) in tables {
        let k = TableKind::of(&t.columns, &p.display().to_string())?;
        if let Some(first) = kind.filter(|first| !first.overlays(k)) {
            return Err(PlotError::Invalid {
                field: p.display().to_string(),
                message: format!(
                    "is {}, but the first file is {}: overlay files of one kind (or truth and \
                     navigation output)",
                    k.name(),
                    first.name()
                ),
            });
        }
        kind.get_or_insert(k);
        if k.has_trajectory() {
            let trace = Trace::from_table(&stem(p), t, ned).map_err(|e| match e {
                PlotError::Invalid { message, .. } => PlotError::Invalid {
                    field: p.display().to_string(),
                    message,
                },
                other => other,
            })?;
            traces.push(trace);
        }
        files.push((stem(p), t.clone()));
    }
    let kind = kind.unwrap_or(TableKind::Imu);
    let names: Vec<String> = tables
        .iter()
        .map(|(p, _)| {
            p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        })
        .collect();
    if kind == TableKind::Allan {
        return allan_from_tables(out, &files, &names.join(", "), size);
    }
    if kind == TableKind::Study {
        let [(_, table)] = files.as_slice() else {
            return Err(PlotError::Invalid {
                field: "plot".into(),
                message: "an outage study is drawn alone: give one study table".into(),
            });
        };
        return crate::study::study_figure(out, table);
    }
    let panels: Vec<Panel> = kind
        .panels()
        .iter()
        .filter_map(|spec| panel(&files, spec))
        .collect();
    if !kind.has_trajectory() {
        traces.clear();
    }
    let three_d = is_3d(&traces);
    let cells = panels.len() + usize::from(!traces.is_empty());
    let cols = if cells > 3 { 2 } else { 1 };
    let rows = cells.div_ceil(cols);
    let (w, h) = (560 * cols as u32, 40 + 320 * rows as u32);
    // The files drawn, their kind and, where positions or attitudes are drawn, their frame.
    let frame = if kind.has_frame() {
        format!(" — {}", if ned { "NED" } else { "ENU" })
    } else {
        String::new()
    };
    let title = format!("{} ({}){frame}", names.join(", "), kind.name());
    size.write(out, w, h, |root| {
        let root = root.titled(&title, ("sans-serif", 18)).map_err(err)?;
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

/// Allan tables: the curves (a table does not say how long its record was, so no terms are
/// fitted; `imukit identify` draws them).
fn allan_from_tables(
    out: &Path,
    files: &[(String, Table)],
    source: &str,
    size: FigureSize,
) -> Result<(), PlotError> {
    let mut columns = vec!["tau_s".to_string()];
    let first = &files[0].1;
    let tau = first.column("tau_s").unwrap_or_default();
    let mut curves = Vec::new();
    for (name, t) in files {
        for c in t.columns.iter().filter(|c| c.starts_with("adev_")) {
            let adev = t.column(c).unwrap_or_default();
            if adev.len() != tau.len() {
                return Err(PlotError::Invalid {
                    field: name.clone(),
                    message: "Allan tables to overlay need the same τ values".into(),
                });
            }
            let label = if files.len() > 1 {
                format!("{c} ({name})")
            } else {
                c.clone()
            };
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
            noise: Vec::new(),
            samples: 0,
            sample_rate_hz: 0.0,
        },
        source,
        size,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use imukit::io::columns::{TRUTH_COLUMNS, VIBRATION_TRUTH_COLUMNS};

    #[test]
    fn a_truth_with_vibration_gets_its_panels_and_a_plain_one_does_not() {
        let columns: Vec<&str> = TRUTH_COLUMNS
            .iter()
            .chain(&VIBRATION_TRUTH_COLUMNS)
            .copied()
            .collect();
        let mut shaken = Table::new(&columns);
        for t in [0.0, 0.01] {
            let mut row = vec![t; columns.len()];
            row[columns.len() - 3] = 0.01; // mount_rot_x_rad
            shaken.push_row(&row);
        }
        let titles = |table: Table| -> Vec<String> {
            let files = [("t".to_string(), table)];
            TableKind::Truth
                .panels()
                .iter()
                .filter_map(|spec| panel(&files, spec))
                .map(|p| p.title)
                .collect()
        };
        let with = titles(shaken.clone());
        assert_eq!(
            with[with.len() - 3..],
            [
                "Vibration: accelerometer input",
                "Vibration: gyroscope input",
                "Sensor's turn on its mount"
            ]
        );
        let files = [("t".to_string(), shaken)];
        let panels = TableKind::Truth.panels();
        let spec = panels
            .iter()
            .find(|s| s.title == "Sensor's turn on its mount")
            .unwrap();
        let turn = panel(&files, spec).unwrap();
        assert!((turn.series[0].points[0].1 - 0.01_f64.to_degrees()).abs() < 1e-12);
        let mut plain = Table::new(&TRUTH_COLUMNS);
        plain.push_row(&[0.0; TRUTH_COLUMNS.len()]);
        assert_eq!(titles(plain).len(), with.len() - 3);
    }
}
