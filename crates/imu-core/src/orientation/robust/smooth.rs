//! The robust filter after the fact: a forward pass, a backward pass over the same readings
//! from where the forward one ended, and their mean.
//!
//! A causal filter at time `t` knows only what came before: its inclination carries what the
//! low-pass still remembers of past accelerations and its bias and heading start from nothing.
//! Read backwards (gyroscope negated, intervals in reverse), the same filter knows only what
//! comes after; started from the forward pass's final state it has no start-up at all. Their
//! errors differ, so their mean — the normalised weighted sum of the two attitudes — is better
//! than either (the forward–backward idea of offline orientation estimation, as in VQF's
//! offline variant and OxTS's post-processing). With a magnetometer the heading stays the
//! forward pass's: it is anchored where the run starts (the field the filter first learns, the
//! frame a user aligns a reference to), which a backward pass would move to where it ends.
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::{RobustFilter, RobustParams, RobustStatus};
use crate::frame::Body;
use crate::nav_frame::NavFrame;
use crate::orientation::{Estimate, FilterInput, OrientError, OrientationFilter};
use crate::rotation::Rotation;

/// Smooths a whole run: `out[i]` gets the estimate and status for `inputs[i]`
/// (`out.len() == inputs.len()`). The status's bias is the mean of both passes', its flags
/// those of either.
///
/// # Errors
/// The index of the first sample the filter refuses, with the reason; `params` out of range
/// (index 0).
///
/// # Panics
/// Never for `out.len() == inputs.len()`; a shorter `out` is left partly unwritten.
pub fn smooth<N: NavFrame>(
    params: RobustParams,
    inputs: &[FilterInput],
    out: &mut [(Estimate<N>, RobustStatus)],
) -> Result<(), (usize, OrientError)> {
    let mut forward = RobustFilter::new(params).map_err(|e| (0, e))?;
    for (i, (input, slot)) in inputs.iter().zip(out.iter_mut()).enumerate() {
        let estimate = OrientationFilter::<N>::update(&mut forward, input)
            .map_err(|e| (i, e))?
            .ok_or((i, OrientError::Singular))?;
        *slot = (estimate, forward.status());
    }
    let Some(mut backward) = forward.reversed() else {
        return Ok(());
    };
    let n = inputs.len().min(out.len());
    for i in (0..n.saturating_sub(1)).rev() {
        // From t[i+1] back to t[i]: the rate is the one read over that interval (reading i+1,
        // negated), gravity and field the ones read at t[i].
        let input = FilterInput {
            gyro_rad_s: inputs[i + 1].gyro_rad_s.map(|w| -w),
            interval_s: inputs[i + 1].interval_s,
            ..inputs[i]
        };
        let b = OrientationFilter::<N>::update(&mut backward, &input)
            .map_err(|e| (i, e))?
            .ok_or((i, OrientError::Singular))?;
        let (f, fs) = out[i];
        let bs = backward.status();
        out[i] = (
            Estimate {
                orientation: combine(&f.orientation, &b.orientation, params.magnetometer),
                angular_velocity_rad_s: mean(
                    f.angular_velocity_rad_s,
                    b.angular_velocity_rad_s.map(|w| -w),
                ),
            },
            RobustStatus {
                gyro_bias_rad_s: mean(fs.gyro_bias_rad_s, bs.gyro_bias_rad_s.map(|b| -b)),
                at_rest: fs.at_rest || bs.at_rest,
                accel_rejected: fs.accel_rejected || bs.accel_rejected,
                mag_disturbed: fs.mag_disturbed || bs.mag_disturbed,
            },
        );
    }
    Ok(())
}

fn mean(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    ((Vector3::from(a) + Vector3::from(b)) * 0.5).into()
}

/// The smoothed attitude: the midpoint of the forward and backward ones (their normalised sum in
/// one hemisphere); with a magnetometer, turned about the vertical to the forward pass's heading.
fn combine<N: NavFrame>(
    forward: &Rotation<Body, N>,
    backward: &Rotation<Body, N>,
    magnetometer: bool,
) -> Rotation<Body, N> {
    let (qf, qb) = (forward.quaternion(), backward.quaternion());
    let b: Quaternion<f64> = if qf.dot(qb) < 0.0 {
        -qb.into_inner()
    } else {
        qb.into_inner()
    };
    let mid = UnitQuaternion::new_normalize(qf.into_inner() + b);
    if !magnetometer {
        return Rotation::assume_from_quaternion(mid);
    }
    // The twist of `forward · mid⁻¹` about the navigation frame's vertical (z in ENU and NED).
    let e = qf * mid.inverse();
    let twist = Quaternion::new(e.w, 0.0, 0.0, e.k);
    let twist = if twist.norm() > 0.0 {
        UnitQuaternion::new_normalize(twist)
    } else {
        UnitQuaternion::identity()
    };
    Rotation::assume_from_quaternion(twist * mid)
}
