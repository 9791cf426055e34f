//! `imukit orient IMU.csv --filter NAME [--param KEY=VALUE …] --out ORIENT.csv`.
use std::path::Path;

use imukit::io::Input;
use imukit::io::conventions::{AccelSignName, NavFrameName};
use imukit::io::described::Described;
use imukit::io::output::check_outputs;
use imukit::io::rows::TimeWindow;
use imukit::orient::{Conventions, FilterKind, FilterSpec, OrientRequest, orient_csv};

use crate::CliError;

/// The command's arguments.
pub struct Args<'a> {
    pub input: &'a Input,
    pub filter: FilterKind,
    /// `--param KEY=VALUE`.
    pub params: &'a [String],
    /// `--no-mag`: a 9-axis file run as 6D.
    pub no_mag: bool,
    /// `--smooth`: the whole run smoothed (robust only).
    pub smooth: bool,
    pub conventions: Conventions,
    pub nav_frame: Option<NavFrameName>,
    pub accel_sign: Option<AccelSignName>,
    /// `--start-s`, `--end-s`.
    pub window: TimeWindow,
    pub out: &'a Path,
}

pub fn run(a: &Args<'_>) -> Result<(), CliError> {
    let Args {
        input,
        filter,
        params,
        no_mag,
        smooth,
        conventions,
        nav_frame,
        accel_sign,
        window,
        out,
    } = *a;
    check_outputs(&[("input", input)], &[("--out", out)])?;
    imukit::io::output::check_table_outputs(&[("--out", out)])?;
    // The frame and sign the input says it has, unless the flags say (and do not contradict it).
    let (spec, nav) = OrientRequest {
        filter,
        conventions,
        nav_frame,
        accel_sign,
        settings: FilterSpec::parse_settings(filter, params)?,
        use_magnetometer: !no_mag,
        smooth,
    }
    .with_described(&Described::read(&[input])?)?
    .resolve();
    crate::report::warn_implausible(input);
    let s = orient_csv(input, &spec, nav, window, out).map_err(|e| match e {
        // The request's own field; other refusals name the file.
        e if e.data() == Some(imukit::error::Data::Imu) => {
            e.relabelled(input.display().to_string())
        }
        other => other,
    })?;
    for w in &s.warnings {
        crate::report::warn(w);
    }
    let rate = (s.sample_rate_hz * 1e6).round() / 1e6;
    let timing = if s.per_sample {
        format!("each over its own interval (median rate {rate} Hz)")
    } else {
        format!("at a fixed {rate} Hz (SampleRate)")
    };
    crate::note!(
        "imukit: {} samples, {timing}, through {filter}{}: {} orientations in {}",
        s.samples,
        if smooth { " (smoothed)" } else { "" },
        s.rows,
        out.display()
    );
    if let Some(m) = s.repeats.message(&input.display().to_string(), 2) {
        crate::report::warn(&m);
    }
    if let Some(m) = s.gaps.message(&input.display().to_string()) {
        crate::report::warn(&m);
    }
    if s.unfinished > 0 {
        crate::note!(
            "imukit: the last {} samples do not fill a block of DecimationFactor samples and \
             give no orientation",
            s.unfinished
        );
    }
    Ok(())
}
