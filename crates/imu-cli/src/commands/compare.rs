//! `imukit compare TRUTH.csv NAV.csv [--out ERR.csv]`.
use std::path::Path;

use imu_scenario::Table;
use imu_scenario::navigation::{STATE_COLUMNS, compare};
use imu_scenario::table::read_table_columns;

use super::CliError;

fn read(path: &Path) -> Result<Table, CliError> {
    let hint = "; truth and estimate need t_s, pos_*, vel_*, q_*";
    Ok(read_table_columns(path, STATE_COLUMNS, hint)?)
}

pub fn run(truth: &Path, estimate: &Path, out: Option<&Path>) -> Result<(), CliError> {
    let c = compare(&read(truth)?, &read(estimate)?)?;
    if let Some(o) = out {
        c.table.write_csv(o)?;
    }
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
