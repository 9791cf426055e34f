//! `imukit orient IMU.csv --filter NAME [--param KEY=VALUE …] --out ORIENT.csv`.
use std::path::Path;

use imukit::io::description::Described;
use imukit::io::output::check_outputs;
use imukit::run::orient::{Conventions, FilterKind, FilterSpec, OrientRequest, orient_csv};
use imukit::scenario::{AccelSignName, NavFrameName};

use crate::CliError;

pub fn run(
    input: &Path,
    filter: FilterKind,
    params: &[String],
    conventions: Conventions,
    nav_frame: Option<NavFrameName>,
    accel_sign: Option<AccelSignName>,
    out: &Path,
) -> Result<(), CliError> {
    check_outputs(&[("input", input)], &[("--out", out)])?;
    // The frame and sign the input says it has, unless the flags say (and do not contradict it).
    let (spec, nav) = OrientRequest {
        filter,
        conventions,
        nav_frame,
        accel_sign,
        settings: FilterSpec::parse_settings(params)?,
    }
    .with_described(&Described::read(&[input])?)
    .map_err(crate::error::by_flag)?
    .resolve();
    let s = orient_csv(input, &spec, nav, out)?;
    println!(
        "imukit: {} samples at {} Hz through {filter}: {} orientations in {}",
        s.samples,
        (s.sample_rate_hz * 1e6).round() / 1e6,
        s.rows,
        out.display()
    );
    if s.unfinished > 0 {
        println!(
            "imukit: the last {} samples do not fill a block of DecimationFactor samples and \
             give no orientation",
            s.unfinished
        );
    }
    Ok(())
}
