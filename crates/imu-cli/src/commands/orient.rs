//! `imukit orient IMU.csv --filter NAME [--param KEY=VALUE …] --out ORIENT.csv`.
use std::path::Path;

use imu_core::AccelSign;
use imukit::run::orient::{FilterKind, FilterSpec, orient_csv};
use imukit::scenario::{AccelSignName, NavFrameName, parse_name};

use super::CliError;

pub fn run(
    input: &Path,
    filter: &str,
    params: &[String],
    nav_frame: &str,
    accel_sign: &str,
    out: &Path,
) -> Result<(), CliError> {
    let nav: NavFrameName = parse_name("--nav-frame", &nav_frame.to_ascii_uppercase())?;
    let sign: AccelSign = parse_name::<AccelSignName>("--accel-sign", accel_sign)?.into();
    let mut spec = FilterSpec::new(FilterKind::parse(filter)?, sign);
    spec.settings = FilterSpec::parse_settings(params)?;
    let s = orient_csv(input, &spec, nav, out)?;
    println!(
        "imukit: {} samples at {} Hz through {filter}: {} orientations in {}",
        s.samples,
        (s.sample_rate_hz * 1e6).round() / 1e6,
        s.rows,
        out.display()
    );
    Ok(())
}
