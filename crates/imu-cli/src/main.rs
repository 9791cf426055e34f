//! `imukit`: IMU simulation and navigation from the command line.
#![forbid(unsafe_code)]
use imu_cli::{CliError, cli, commands, interrupt};
use imukit::io::output::OutputGroup;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    interrupt::clean_up_on_signals();
    // Every output of the command is put in place at its end, all or none.
    let outputs = OutputGroup::begin();
    match commands::run(args).and_then(|()| outputs.commit().map_err(CliError::from)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("imukit: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                // The scenario errors already include their sources in their message.
                if !e.to_string().contains(&s.to_string()) {
                    eprintln!("  caused by: {s}");
                }
                source = s.source();
            }
            ExitCode::from(e.exit_code())
        }
    }
}
