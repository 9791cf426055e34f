//! # imu-cli — the `imukit` command line
//!
//! `main.rs` parses ([`cli`]), dispatches ([`commands`], one file per subcommand) and prints the
//! error chain with an exit code ([`CliError`]); a signal removes the outputs begun
//! ([`interrupt`]). The work is done by the `imukit` library and the
//! figures by `imu-plot`; this crate turns flags into their calls.
#![forbid(unsafe_code)]
#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod commands;
mod error;
#[doc(hidden)]
pub mod interrupt;

pub use error::{CliError, by_flag, flag, plot_by_flag};
