//! Losing the fixes and coming back to them: fixes rejected one after another reset the
//! filter to the last of them, and a filter that cannot be brought back is a divergence; the
//! filter's refusals as errors naming the row.
use imu_core::fusion::EskfError;
use imu_core::fusion::gate::Gate;

use crate::error::Data;
use crate::error::{Error, Result, Subject};

/// The filter's refusal of reading `index` (0-based) of `what` (GNSS data, odometer data, …)
/// as an error naming its row: a divergence as [`Error::Diverged`], bad input as invalid data.
pub(crate) fn filter_refusal(what: impl Into<Subject>, index: usize, e: EskfError) -> Error {
    let (context, row) = (what.into(), index + 2);
    match e {
        EskfError::Diverged { .. } => Error::Diverged {
            context,
            message: format!("row {row}: {e}"),
        },
        source => Error::Filter {
            context,
            row: Some(row),
            source,
        },
    }
}

/// Resets after which the fixes are still rejected, one after another, before the fusion is
/// a divergence: the filter could not be brought back to them.
pub const MAX_RESETS_IN_A_ROW: usize = 3;

/// Fixes rejected one after another before the filter is reset to the last of them
/// ([`Eskf::reset_to_gnss`](imu_core::fusion::Eskf::reset_to_gnss)).
pub const MAX_REJECTED_IN_A_ROW: usize = 10;

/// The fixes' acceptance, counted: rejected one after another, and the resets to them.
#[derive(Debug, Default)]
pub(super) struct Acceptance {
    /// Fixes rejected since the last accepted one (or reset).
    rejected_in_a_row: usize,
    /// Resets since the last accepted fix.
    resets_in_a_row: usize,
    /// Resets in all.
    pub(super) resets: usize,
}

impl Acceptance {
    /// Counts fix `index`'s outcome; `true` when it is the [`MAX_REJECTED_IN_A_ROW`]th rejected
    /// in a row: the filter is to be reset to it.
    ///
    /// # Errors
    /// The filter's refusal ([`filter_refusal`]); a divergence: as many fixes rejected in a row
    /// again after [`MAX_RESETS_IN_A_ROW`] resets.
    pub(super) fn count(
        &mut self,
        outcome: std::result::Result<imu_core::fusion::UpdateOutcome, EskfError>,
        index: usize,
        gate: Gate,
    ) -> Result<bool> {
        let outcome = outcome.map_err(|e| filter_refusal("GNSS", index, e))?;
        if outcome.accepted {
            self.rejected_in_a_row = 0;
            self.resets_in_a_row = 0;
            return Ok(false);
        }
        self.rejected_in_a_row += 1;
        if self.rejected_in_a_row < MAX_REJECTED_IN_A_ROW {
            return Ok(false);
        }
        if self.resets_in_a_row >= MAX_RESETS_IN_A_ROW {
            // Only a gate that is on rejects.
            let gate = match gate {
                Gate::ChiSquare(x) => x,
                Gate::Off => f64::INFINITY,
            };
            return Err(Error::Diverged {
                context: Data::Gnss.into(),
                message: format!(
                    "row {}: {MAX_REJECTED_IN_A_ROW} fixes in a row rejected by the innovation \
                     gate (the last with NIS {:.1} against {gate:.1}) after {MAX_RESETS_IN_A_ROW} \
                     resets to the fixes: the fixes have jumped, the data are in another frame \
                     or with another accelerometer sign than the filter was told (nav_frame, \
                     accel_sign), or the IMU is not the one described; nothing is written",
                    index + 2,
                    outcome.nis
                ),
            });
        }
        self.rejected_in_a_row = 0;
        self.resets_in_a_row += 1;
        self.resets += 1;
        Ok(true)
    }
}
