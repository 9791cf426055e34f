//! An estimate on the WGS-84 Earth against a reference whose position is on the Earth
//! (latitude, longitude and height, or ECEF): errors north, east, down at the reference point.
use std::path::Path;

use super::{ErrorSummary, Parts, StateRow, compare_rows};
use crate::error::{Result, invalid};
use crate::io::Input;
use crate::io::columns::{GEODETIC_COLUMNS, Position};
use crate::io::conventions::NavFrameName;
use crate::io::output::AtomicFile;
use crate::io::read::CsvRows;
use crate::io::rows::TimeWindow;
use crate::run::reference::{Layout, ecef};

/// [`compare_csv`] of an estimate on the WGS-84 Earth against a reference whose position is
/// on the Earth (`layout`): ECEF points, errors north, east, down at the reference point;
/// velocities and attitudes where both have them, each table's in its own frame (its
/// description's, else ENU).
pub(super) fn compare_on_earth(
    truth: &Input,
    estimate: &Input,
    layout: Layout,
    (window, t0): (TimeWindow, f64),
    out: Option<&Path>,
) -> Result<ErrorSummary> {
    let frame_of = |p: &Path| -> Result<NavFrameName> {
        Ok(crate::io::description::Description::read(p)?
            .and_then(|d| d.nav_frame)
            .unwrap_or_default())
    };
    let (truth_frame, estimate_frame) = (frame_of(truth.path())?, frame_of(estimate.path())?);
    let header = crate::io::read::read_header(estimate)?;
    let own = Layout::of(&header, &[Position::GeodeticRad]).ok_or_else(|| {
        invalid(
            estimate.path().display().to_string(),
            format!(
                "the reference {} gives positions on the Earth: the estimate needs {} (an \
                 estimate on the WGS-84 Earth, as integrate and fuse write it)",
                truth.path().display(),
                GEODETIC_COLUMNS.join(", ")
            ),
        )
    })?;
    let parts = Parts {
        earth: true,
        velocity: layout.velocity.is_some() && own.velocity.is_some(),
        attitude: layout.attitude && own.attitude,
    };
    let (truth_columns, estimate_columns) = (layout.columns(), own.columns());
    let mut truth_rows = CsvRows::open(truth, &truth_columns, "")?.within(window, t0)?;
    let mut estimate_rows = CsvRows::open(estimate, &estimate_columns, "")?.within(window, t0)?;
    let (mut truth_buffer, mut estimate_buffer) = (
        vec![0.0; truth_columns.len()],
        vec![0.0; estimate_columns.len()],
    );
    let (truth_name, estimate_name) = (
        truth.path().display().to_string(),
        estimate.path().display().to_string(),
    );
    // A row of the Earth's terms as a state row: ECEF, NED velocity, FRD-to-NED attitude.
    let next = |rows: &mut CsvRows,
                buffer: &mut [f64],
                layout: &Layout,
                frame: NavFrameName,
                name: &str,
                state: &mut StateRow|
     -> Result<bool> {
        let Some(line) = rows.next_row(buffer)? else {
            return Ok(false);
        };
        let r = layout.earth_row(buffer, frame).ok_or_else(|| {
            invalid(
                format!("{name}, row {line}"),
                "not a point on the Earth (a latitude beyond ±90°), or a quaternion of zero norm",
            )
        })?;
        *state = [0.0; 11];
        state[0] = r.t_s;
        state[1..4].copy_from_slice(&ecef(&r.position));
        if let Some(v) = r.velocity_ned {
            state[4..7].copy_from_slice(&v);
        }
        if let Some(q) = r.attitude {
            state[7..].copy_from_slice(&q);
        }
        Ok(true)
    };
    let mut file = out.map(AtomicFile::create).transpose()?;
    if let Some(f) = file.as_mut() {
        f.write_header(&parts.columns())?;
    }
    let summary = compare_rows(
        parts,
        [&truth_name, &estimate_name],
        |row| {
            next(
                &mut truth_rows,
                &mut truth_buffer,
                &layout,
                truth_frame,
                &truth_name,
                row,
            )
        },
        |row| {
            next(
                &mut estimate_rows,
                &mut estimate_buffer,
                &own,
                estimate_frame,
                &estimate_name,
                row,
            )
        },
        |e| file.as_mut().map_or(Ok(()), |f| f.write_row(e)),
    )?;
    file.map_or(Ok(()), AtomicFile::commit)?;
    Ok(summary)
}
