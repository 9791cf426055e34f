//! `imukit simulate SCENARIO --out IMU.csv [--truth TRUTH.csv]`.
use std::path::Path;

use imu_scenario::Scenario;

use super::CliError;

pub fn run(scenario: &Path, out: &Path, truth: Option<&Path>) -> Result<(), CliError> {
    let sim = Scenario::from_file(scenario)?.simulate()?;
    sim.imu.write_csv(out)?;
    if let Some(t) = truth {
        sim.truth.write_csv(t)?;
    }
    eprintln!(
        "imukit: {} samples; IMU readings in {}{}",
        sim.imu.rows(),
        out.display(),
        truth
            .map(|t| format!(", truth in {}", t.display()))
            .unwrap_or_default()
    );
    Ok(())
}
