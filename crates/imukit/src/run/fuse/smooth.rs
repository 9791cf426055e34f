//! The smoothed estimate: the backward pass over the filter's epochs, and each sample's
//! filtered state corrected by the smoothed correction interpolated between the epochs.
use imu_core::fusion::smoother::{ErrorVector, rts_backward};
use imu_core::fusion::{EskfState, SensorErrorEstimate, corrected_state, has_sensor_errors};

use super::rows::push_fused_row;
use crate::io::table::Table;
use crate::run::nav_earth::NavEarth;

/// The longest propagation without an epoch the smoother keeps, s: the spacing of its estimate
/// through an outage (between epochs the correction is interpolated linearly).
pub const SMOOTHING_GAP_S: f64 = 0.5;

/// The smoothed table: the backward pass over `epochs`, each sample's filtered state
/// (`filtered`, at times `t`) corrected by the smoothed correction interpolated between the
/// epochs around it (none across a reset), its one-sigma likewise.
pub(super) fn smoothed_rows<E: NavEarth, const S: usize>(
    earth: &E,
    epochs: &crate::run::epochs::PackedEpochs<S>,
    filtered: &[(EskfState<E>, SensorErrorEstimate, usize)],
    t: &[f64],
    (table, row): (&mut Table, &mut Vec<f64>),
    origin: &E::Origin,
) {
    let n = epochs.len();
    let mut smoothed = vec![ErrorVector::<S>::zeros(); n];
    let mut variance = vec![ErrorVector::<S>::zeros(); n];
    rts_backward(epochs, |j, dx, p| {
        smoothed[j] = *dx;
        variance[j] = p.diagonal();
    });
    let mut last_yaw = None;
    let mut j = 0;
    for (i, (state, errors, resets)) in filtered.iter().enumerate() {
        let ti = t[i];
        while j + 1 < n && epochs.t_s(j + 1) <= ti {
            j += 1;
        }
        let (dx, var) = if j + 1 < n && !epochs.reset(j + 1) && epochs.t_s(j) <= ti {
            let span = epochs.t_s(j + 1) - epochs.t_s(j);
            let w = if span > 0.0 {
                (ti - epochs.t_s(j)) / span
            } else {
                0.0
            };
            let end = epochs.correction(j + 1) + smoothed[j + 1];
            (
                smoothed[j] * (1.0 - w) + end * w,
                variance[j] * (1.0 - w) + variance[j + 1] * w,
            )
        } else if j < n && epochs.t_s(j) <= ti {
            (smoothed[j], variance[j])
        } else {
            (ErrorVector::<S>::zeros(), ErrorVector::<S>::zeros())
        };
        let s = corrected_state(earth, state, dx.as_slice());
        let mut e = *errors;
        if has_sensor_errors(S) {
            for k in 0..9 {
                e.accel[k / 3][k % 3] += dx[15 + k];
                e.gyro[k / 3][k % 3] += dx[24 + k];
            }
            for k in 0..3 {
                e.gyro_g_sensitivity[k] += dx[33 + k];
            }
        }
        let sig: [f64; S] = core::array::from_fn(|k| var[k].max(0.0).sqrt());
        push_fused_row(table, row, (&s, &e, &sig), (origin, &mut last_yaw), *resets);
    }
}
