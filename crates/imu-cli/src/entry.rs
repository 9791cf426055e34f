//! The whole command line as one call, shared by the `imukit` binary and the `imukit` command
//! that the Python wheel installs (which calls it from its extension module).
use std::ffi::OsString;
use std::io::Write;

use clap::Parser;
use imukit::io::output::OutputGroup;

use crate::{CliError, cli, commands, interrupt};

/// Parses `args` (the program's name first), runs the command and returns the process's exit
/// status: 0 on success, clap's 2 for a usage error, 65 for bad input data and 74 for I/O
/// (`CliError::exit_code`). Errors are printed to standard error with their chain of causes.
/// Standard output and standard error are flushed before it returns, because a caller that is
/// not a Rust `main` (the Python entry point) does not flush Rust's buffers at exit.
pub fn main_with_args<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let status = match cli::Cli::try_parse_from(args) {
        Ok(parsed) => run_parsed(parsed),
        Err(e) => {
            // `--help` and `--version` are "errors" that print to standard output and succeed.
            drop(e.print());
            u8::try_from(e.exit_code()).unwrap_or(2)
        }
    };
    drop(std::io::stdout().flush());
    drop(std::io::stderr().flush());
    status
}

fn run_parsed(args: cli::Cli) -> u8 {
    interrupt::clean_up_on_signals();
    // Every output of the command is put in place at its end, all or none.
    let outputs = OutputGroup::begin();
    match commands::run(args).and_then(|()| outputs.commit().map_err(CliError::from)) {
        Ok(()) => 0,
        Err(e) => {
            crate::err_line!("imukit: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                // The scenario errors already include their sources in their message.
                if !e.to_string().contains(&s.to_string()) {
                    crate::err_line!("  caused by: {s}");
                }
                source = s.source();
            }
            e.exit_code()
        }
    }
}
