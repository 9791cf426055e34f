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
