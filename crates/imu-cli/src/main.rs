//! `imukit`: IMU simulation and navigation from the command line.
#![forbid(unsafe_code)]
use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(imu_cli::main_with_args(std::env::args_os()))
}
