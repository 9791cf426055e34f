//! Python bindings of imukit (`imukit._core`), one file per area, each with its `register`:
//! convert the Python arguments ([`convert`]), release the GIL, call the `imukit` library (or
//! `imu-plot` for figure specs), convert back; refusals become `imukit.ImuError` with the field,
//! file, row and column they name ([`errors`]). No numerics here.
#![forbid(unsafe_code)]
mod calibration;
mod cli;
mod convert;
mod defaults;
mod errors;
mod figures;
mod io;
mod navigation;
mod orientation;
mod rotations;
mod sensor;
mod study;
mod truth;

use pyo3::prelude::*;

/// The extension's own allocations (a run's chunk buffers, tables, compiled programs) come from
/// mimalloc, which keeps freed pages for the next call. With glibc's allocator each call gave
/// its megabyte or two of chunk buffers back to the system and faulted them in again: 20 % of a
/// call of 4 096 samples in the kernel, 1.83 ms a call against 1.18 ms with mimalloc (10⁴
/// samples: 3.30 → 2.80 ms; 10⁵ and more unchanged). NumPy's arrays keep NumPy's allocator. The
/// command line keeps the system's: one run a process, its buffers reused from chunk to chunk;
/// mimalloc there doubled the streaming commands' peak memory (docs/design.md §1).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The compiled core of the `imukit` package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // One version for every package of the workspace (`imukit --version` prints the same).
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    defaults::register(m)?;
    truth::register(m)?;
    rotations::register(m)?;
    sensor::register(m)?;
    navigation::register(m)?;
    orientation::register(m)?;
    io::register(m)?;
    figures::register(m)?;
    study::register(m)?;
    calibration::register(m)?;
    cli::register(m)?;
    Ok(())
}
