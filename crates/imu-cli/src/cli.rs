//! Command-line arguments.
use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// A fast, exact and reproducible IMU simulator.
#[derive(Debug, Parser)]
#[command(name = "imukit", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Truth kinematics and ideal IMU readings of a scenario file (TOML or JSON).
    Simulate {
        /// The scenario file.
        scenario: PathBuf,
        /// Where to write the IMU readings (CSV).
        #[arg(long)]
        out: PathBuf,
        /// Where to write the truth (CSV).
        #[arg(long)]
        truth: Option<PathBuf>,
        /// Monte Carlo: this many runs, in parallel on all cores, one output per run
        /// (`IMU_run0000.csv`, …); run r draws its noise from (seed, r).
        #[arg(long)]
        runs: Option<u64>,
    },
    /// Lists the sensor presets, or prints one as a parameter file.
    Presets {
        /// Name of a preset.
        name: Option<String>,
    },
    /// Converts a datasheet figure to imukit's SI parameter units (single-sided densities,
    /// g = 9.80665 m/s²), e.g. `imukit convert 0.15 "°/√h"`.
    Convert {
        /// The value.
        value: f64,
        /// Its unit (°/√h, °/h, °/s/√Hz, µg/√Hz, m/s/√h, mg, ppm, …).
        unit: String,
    },
    /// Allan deviation of IMU columns (octave τ) with N, K and B identified.
    Allan {
        /// IMU readings CSV (with `t_s`).
        input: PathBuf,
        /// Columns to analyse (default: every gyro and accel column present).
        #[arg(long = "column")]
        columns: Vec<String>,
        /// Where to write `tau_s, adev_<column>…` (CSV).
        #[arg(long)]
        out: PathBuf,
        /// Also draw the curves with the fitted lines into this SVG file.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Runs a built-in scenario (default: the seed's figure-8 with its lever arm) and writes the
    /// scenario, truth, IMU readings and a summary into a folder.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "imukit-demo")]
        out_dir: PathBuf,
        /// Built-in scenario to run.
        #[arg(long, default_value = imu_scenario::builtin::DEMO)]
        scenario: String,
    },
    /// Lists the built-in scenarios, or prints one as an editable scenario file.
    Scenario {
        /// Name of a built-in scenario.
        name: Option<String>,
    },
}
