//! How much memory an in-memory read or run may take: a limit checked before anything is
//! allocated, so that a file's or a scenario's stated length cannot exhaust the machine.
use crate::error::{Result, invalid};

/// The memory an in-memory run may take unless `IMUKIT_MAX_MEMORY_GB` says otherwise, GB.
pub const DEFAULT_MAX_MEMORY_GB: f64 = 8.0;

/// The memory limit of in-memory runs, bytes: `IMUKIT_MAX_MEMORY_GB` (a positive number of
/// 10⁹ bytes) or [`DEFAULT_MAX_MEMORY_GB`].
#[must_use]
pub fn max_memory_bytes() -> f64 {
    std::env::var("IMUKIT_MAX_MEMORY_GB")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|g| g.is_finite() && *g > 0.0)
        .unwrap_or(DEFAULT_MAX_MEMORY_GB)
        * 1e9
}

/// Refuses, before anything is allocated, a run that would hold `samples` samples of
/// `bytes_per_sample` bytes in memory beyond [`max_memory_bytes`]; `field` names what set the
/// length (e.g. `duration_s`).
///
/// # Errors
/// [`crate::Error::Invalid`] with the estimate, the limit and the ways around it.
pub fn check_in_memory(
    samples: usize,
    bytes_per_sample: usize,
    field: impl Into<crate::error::Subject>,
) -> Result<()> {
    #[allow(clippy::cast_precision_loss)]
    let need = samples as f64 * bytes_per_sample as f64;
    let limit = max_memory_bytes();
    if need <= limit {
        return Ok(());
    }
    Err(invalid(
        field,
        format!(
            "{samples} samples would take about {:.1} GB in memory, more than the limit of {:.1} GB: \
             shorten the run, stream it with `imukit simulate` (its memory does not grow with the \
             duration), or raise the limit with IMUKIT_MAX_MEMORY_GB",
            need / 1e9,
            limit / 1e9
        ),
    ))
}
