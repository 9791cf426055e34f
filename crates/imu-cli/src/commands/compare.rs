//! `imukit compare TRUTH.csv NAV.csv [--out ERR.csv]`.
use std::path::Path;

use imu_scenario::navigation::compare_csv;

use super::CliError;

/// Streams both files (memory does not grow with them).
pub fn run(truth: &Path, estimate: &Path, out: Option<&Path>) -> Result<(), CliError> {
    let c = compare_csv(truth, estimate, out)?;
    println!("{:<10} {:>14} {:>14}", "error", "RMS", "final");
    println!(
        "{:<10} {:>12.6e} m {:>12.6e} m",
        "position", c.position_rms_m, c.position_final_m
    );
    println!(
        "{:<10} {:>10.6e} m/s {:>10.6e} m/s",
        "velocity", c.velocity_rms_m_s, c.velocity_final_m_s
    );
    println!(
        "{:<10} {:>10.6e} deg {:>10.6e} deg",
        "attitude",
        c.attitude_rms_rad.to_degrees(),
        c.attitude_final_rad.to_degrees()
    );
    if let Some(o) = out {
        println!("\nErrors over time written to {}", o.display());
    }
    Ok(())
}
