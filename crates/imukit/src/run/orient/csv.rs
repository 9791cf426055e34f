//! An orientation filter over an IMU file, streamed into an orientation table (`imukit orient`).
use crate::error::{Data, RequestOption, Result, invalid, refused};
use std::path::Path;

use imu_core::orientation::{FilterInput, OrientationFilter};
use imu_core::{Body, Enu, NavFrame, Ned, Rotation};

use super::{AnyFilter, FilterKind, FilterSpec, SIX_AXIS_FILTERS, robust_row};
use crate::choice::Choice;
use crate::io::Input;
use crate::io::columns::{
    ACCEL_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, ORIENT_COLUMNS, ROBUST_COLUMNS,
};
use crate::io::conventions::NavFrameName;
use crate::io::description::Description;
use crate::io::output::AtomicFile;
use crate::io::rows::{Gaps, Repeats, TimeWindow, TimedRows};
use crate::io::schema::TableKind;
use crate::run::navigate::euler_unwrapped;

/// One orientation output row in [`ORIENT_COLUMNS`] order (yaw unwrapped against `last_yaw`).
#[must_use]
pub fn orient_row<N: NavFrame>(
    t_s: f64,
    q: &Rotation<Body, N>,
    last_yaw: &mut Option<f64>,
) -> [f64; 8] {
    let [w, x, y, z] = q.to_wxyz();
    let e = euler_unwrapped(q, last_yaw);
    [t_s, w, x, y, z, e.yaw_rad, e.pitch_rad, e.roll_rad]
}

/// What [`orient_csv`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct OrientSummary {
    /// Rows read.
    pub samples: usize,
    /// Rows written (fewer with decimation).
    pub rows: usize,
    /// Samples at the end that do not fill a decimation block, so give no estimate (0 without
    /// decimation; MATLAB's filters refuse such a call, a file is read whole instead).
    pub unfinished: usize,
    /// The sample rate: the `SampleRate` setting, or the median rate of the file, Hz.
    pub sample_rate_hz: f64,
    /// Whether each sample was integrated over its own interval (no `SampleRate` setting) or
    /// at the fixed `SampleRate`, as MATLAB's filters do.
    pub per_sample: bool,
    /// The gaps in the sample times, integrated across.
    pub gaps: Gaps,
    /// The rows dropped as exact copies of the row before (a logger's repeats).
    pub repeats: Repeats,
    /// What the user should know about the run (a magnetometer the filter ignores).
    pub warnings: Vec<String>,
}

/// Runs the filter `spec` over the IMU CSV `input` (`accel_*`, `gyro_*` and, when used,
/// `mag_*` columns) into `out` ([`ORIENT_COLUMNS`]), streamed; `out` appears only when complete.
/// The sample rate is `SampleRate` if set, else the median interval of the first
/// [`GAP_WINDOW`](crate::io::rows::GAP_WINDOW) rows'. Whether the magnetometer is used follows the filter, or for those
/// that may use one, whether the file has `mag_*` columns (`spec.magnetometer` is set
/// accordingly). Only the rows of `window` are filtered.
///
/// # Errors
/// Missing columns, bad cells (file, row, column), times that do not increase, the filter's
/// refusals with the row, I/O errors.
pub fn orient_csv(
    input: impl Into<Input>,
    spec: &FilterSpec,
    nav: NavFrameName,
    window: TimeWindow,
    out: &Path,
) -> Result<OrientSummary> {
    let input = &input.into();
    match nav {
        NavFrameName::ENU => orient_csv_in::<Enu>(input, spec, nav, window, out),
        NavFrameName::NED => orient_csv_in::<Ned>(input, spec, nav, window, out),
    }
}

fn orient_csv_in<N: NavFrame>(
    input: &Input,
    spec: &FilterSpec,
    nav: NavFrameName,
    window: TimeWindow,
    out: &Path,
) -> Result<OrientSummary> {
    let header = crate::io::read::read_header(input)?;
    let mut spec = spec.clone();
    let warnings = choose_magnetometer(&mut spec, &header, input)?;
    if spec.smooth && spec.kind != FilterKind::Robust {
        return Err(refused(
            RequestOption::Smooth,
            format!(
                "only the robust filter smooths a run, not {}",
                spec.kind.name()
            ),
        ));
    }
    let gyro = spec.kind != FilterKind::Ecompass;
    let (columns, hint) = input_columns(&spec);
    let mut rows = TimedRows::open(input, &columns, &hint)?.within(window);
    let data_rate = rows.median_interval().map_or(f64::NAN, |m| 1.0 / m);
    let rate = spec.sample_rate_hz(data_rate)?;
    let per_sample = spec.fixed_rate_hz()?.is_none();
    if !(rate.is_finite() && rate > 0.0) {
        return Err(invalid(
            "SampleRate",
            "cannot be taken from a single row: give SampleRate=…",
        ));
    }
    let mut filter = spec.build::<N>(rate)?;
    let mut file = AtomicFile::create(out)?;
    let robust = spec.kind == FilterKind::Robust;
    let out_columns: Vec<String> = ORIENT_COLUMNS
        .iter()
        .chain(if robust { &ROBUST_COLUMNS[..] } else { &[] })
        .map(|c| (*c).to_string())
        .collect();
    file.begin_table(
        &out_columns,
        &Description {
            nav_frame: Some(nav),
            ..Description::of_kind(TableKind::Orientation)
        },
    )?;
    let (mut samples, mut written, mut last_yaw) = (0usize, 0usize, None);
    // Smoothing reads the whole run first: its samples and times.
    let mut run: Vec<(f64, FilterInput)> = Vec::new();
    let mut r = vec![0.0; columns.len()];
    while rows.next_row(&mut r)? {
        let three = |k: usize| [r[k], r[k + 1], r[k + 2]];
        let sample = FilterInput {
            accel_m_s2: three(1),
            gyro_rad_s: if gyro { three(4) } else { [0.0; 3] },
            mag_ut: if spec.magnetometer {
                three(if gyro { 7 } else { 4 })
            } else {
                [0.0; 3]
            },
            interval_s: rows.interval().filter(|_| per_sample),
        };
        samples += 1;
        if spec.smooth {
            run.push((r[0], sample));
            continue;
        }
        let estimate = filter
            .update(&sample)
            .map_err(|e| invalid(Data::Imu, format!("row {}: {e}", rows.last_row())))?;
        if let Some(est) = estimate {
            let row = orient_row(r[0], &est.orientation, &mut last_yaw);
            match filter.status() {
                Some(status) => file.write_row(&[&row[..], &robust_row(&status)].concat())?,
                None => file.write_row(&row)?,
            }
            written += 1;
        }
    }
    if spec.smooth {
        written = write_smoothed::<N>(&mut filter, &run, &mut file)?;
    }
    file.commit()?;
    Ok(OrientSummary {
        samples,
        rows: written,
        unfinished: samples - written * filter.decimation(),
        sample_rate_hz: rate,
        per_sample,
        gaps: rows.gaps(),
        repeats: rows.repeats(),
        warnings,
    })
}

/// Sets whether `spec`'s filter uses the magnetometer: a filter that may use one uses one when
/// the file (its `header`) has it; a file with only some of the mag_* columns is a mistake to
/// name, not a reason to drop the magnetometer silently. Returns the warnings to give.
fn choose_magnetometer(
    spec: &mut FilterSpec,
    header: &[String],
    input: &Input,
) -> Result<Vec<String>> {
    let has = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
    let some_mag = MAG_COLUMNS.iter().any(|c| header.iter().any(|h| h == c));
    let name = spec.kind.name();
    let mut warnings = Vec::new();
    spec.magnetometer = match (spec.kind.magnetometer(), spec.use_magnetometer) {
        (Some(true), false) => {
            return Err(refused(
                RequestOption::UseMagnetometer,
                format!("the {name} filter needs a magnetometer; for 6D use {SIX_AXIS_FILTERS}"),
            ));
        }
        (Some(true), true) => true,
        (Some(false), _) => {
            if some_mag && spec.use_magnetometer {
                warnings.push(format!(
                    "{}: the {name} filter uses no magnetometer: the file's mag_* columns are \
                     ignored and the heading is not held (robust, ahrsfilter, madgwick, mahony \
                     and complementary use them; --no-mag says you mean 6D)",
                    input.path().display()
                ));
            }
            false
        }
        (None, use_it) => some_mag && use_it,
    };
    if spec.magnetometer && !has(&MAG_COLUMNS) {
        let missing = MAG_COLUMNS
            .iter()
            .filter(|c| !header.iter().any(|h| h == *c))
            .map(|c| (*c).to_string())
            .collect();
        let hint = if some_mag {
            format!(
                "; the {name} filter uses all three magnetometer columns when the file has any \
                 (--no-mag ignores them)"
            )
        } else {
            format!(
                "; the {name} filter needs a magnetometer and this file has none: for 6D use \
                 {SIX_AXIS_FILTERS}"
            )
        };
        return Err(crate::Error::MissingColumns {
            file: input.path().into(),
            missing,
            hint,
        });
    }
    Ok(warnings)
}

/// The columns `spec`'s filter reads, and the hint a file without them is given.
fn input_columns(spec: &FilterSpec) -> (Vec<&'static str>, String) {
    let gyro = spec.kind != FilterKind::Ecompass;
    let mut columns = vec!["t_s"];
    columns.extend(ACCEL_COLUMNS);
    if gyro {
        columns.extend(GYRO_COLUMNS);
    }
    if spec.magnetometer {
        columns.extend(MAG_COLUMNS);
    }
    let hint = format!(
        "; the {} filter needs t_s, accel_*{}{}",
        spec.kind.name(),
        if gyro { ", gyro_*" } else { "" },
        if spec.magnetometer { ", mag_*" } else { "" }
    );
    (columns, hint)
}

/// Smooths the whole `run` (times and samples) with the robust filter `filter` and writes its
/// rows; returns how many.
fn write_smoothed<N: NavFrame>(
    filter: &mut AnyFilter<N>,
    run: &[(f64, FilterInput)],
    file: &mut AtomicFile,
) -> Result<usize> {
    let AnyFilter::Robust(robust) = filter else {
        return Err(refused(
            RequestOption::Smooth,
            "only the robust filter smooths a run",
        ));
    };
    let inputs: Vec<FilterInput> = run.iter().map(|(_, s)| *s).collect();
    let smoothed = super::rows::smooth_inputs::<N>(*robust.params(), &inputs)
        .map_err(|(i, e)| invalid(Data::Imu, format!("sample {}: {e}", i + 1)))?;
    let mut last_yaw = None;
    for ((t, _), (estimate, status)) in run.iter().zip(&smoothed) {
        let row = orient_row(*t, &estimate.orientation, &mut last_yaw);
        file.write_row(&[&row[..], &robust_row(status)].concat())?;
    }
    Ok(smoothed.len())
}
