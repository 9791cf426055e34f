//! # imu-cli — the `imukit` command line
//!
//! [`main_with_args`] parses ([`cli`]), dispatches ([`commands`], one file per subcommand) and
//! prints the error chain with an exit code ([`CliError`]); a signal removes the outputs begun
//! ([`interrupt`]). The `imukit` binary and the `imukit` command of the Python wheel both call
//! it. The work is done by the `imukit` library and the
//! figures by `imu-plot`; this crate turns flags into their calls.
#![forbid(unsafe_code)]
#[doc(hidden)]
pub mod cli;
pub mod cli_characterise;
#[doc(hidden)]
pub mod commands;
mod entry;
mod error;
#[doc(hidden)]
pub mod interrupt;
#[doc(hidden)]
pub mod report;

pub use entry::main_with_args;
pub use error::CliError;
