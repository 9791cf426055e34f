//! The `imukit` command of the wheel: the command line of `imu-cli`, run inside this process.
use std::ffi::OsString;

use pyo3::prelude::*;

/// Runs the `imukit` command line with `argv` (the program's name first) and returns its exit
/// status. The work runs without the GIL; output goes straight to the process's standard output
/// and error. A signal (Ctrl-C, SIGTERM, SIGHUP) during a command removes the outputs begun and
/// ends the process with 128 plus the signal's number, as the binary does.
#[pyfunction]
fn cli_main(py: Python<'_>, argv: Vec<OsString>) -> u8 {
    py.detach(|| imu_cli::main_with_args(argv))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(cli_main, m)?)
}
