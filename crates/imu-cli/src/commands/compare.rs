//! `imukit compare TRUTH.csv ESTIMATE.csv [--out ERR.csv]`: a navigation output (`imukit
//! integrate`) or an orientation output (`imukit orient`) against truth.
use std::path::Path;

use imu_core::orientation::DistanceStats;
use imukit::compare::{CompareOptions, compare_csv_with};
use imukit::io::Input;
use imukit::io::output::check_outputs;
use imukit::io::rows::TimeWindow;

use super::CliError;

/// Streams both files (memory does not grow with them).
pub fn run(
    truth_source: &Input,
    estimate_source: &Input,
    window: TimeWindow,
    options: CompareOptions,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let (truth, estimate) = (truth_source.path(), estimate_source.path());
    let inputs = [("truth file", truth), ("estimate file", estimate)];
    check_outputs(
        &inputs,
        &out.map(|o| ("--out", o)).into_iter().collect::<Vec<_>>(),
    )?;
    imukit::io::output::check_table_outputs(
        &out.map(|o| ("--out", o)).into_iter().collect::<Vec<_>>(),
    )?;
    let c = compare_csv_with(truth_source, estimate_source, window, options, out)?;
    crate::out_line!(
        "{:<10} {:>16} {:>16} {:>16}",
        "error",
        "RMS",
        "max",
        "final"
    );
    let line = |name: &str, s: &DistanceStats, scale: f64, unit: &str| {
        crate::out_line!(
            "{name:<10} {:>12.6e} {unit:<3} {:>12.6e} {unit:<3} {:>12.6e} {unit:<3}",
            s.rms() * scale,
            s.max() * scale,
            s.last() * scale
        );
    };
    if let Some(p) = &c.position {
        line("position", p, 1.0, "m");
    }
    if let Some(v) = &c.velocity {
        line("velocity", v, 1.0, "m/s");
    }
    if let Some(a) = &c.attitude {
        line("attitude", a, 1f64.to_degrees(), "deg");
    }
    if let Some(h) = &c.heading {
        line("heading", h, 1f64.to_degrees(), "deg");
    }
    if let Some(i) = &c.inclination {
        line("incl.", i, 1f64.to_degrees(), "deg");
    }
    crate::out_line!("({} rows compared)", c.rows());
    if let Some(offset) = c.heading_offset_rad
        && options.align_heading
    {
        crate::out_line!(
            "(a constant heading offset of {:.4} deg removed)",
            offset.to_degrees()
        );
    }
    if c.skipped > 0 {
        crate::report::warn(&format!(
            "{}: {} estimate rows skipped: the reference has no value or no time there",
            estimate.display(),
            c.skipped
        ));
    }
    if let Some(o) = out {
        crate::note!("imukit: errors over time written to {}", o.display());
    }
    Ok(())
}
