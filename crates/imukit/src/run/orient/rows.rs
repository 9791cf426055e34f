//! Orientation filters over readings in memory (the Python filter classes): a batch at a time
//! with state carried between calls, or a whole run smoothed.
use imu_core::orientation::{
    Estimate, FilterInput, OrientError, OrientationFilter, RobustParams, RobustStatus, robust,
};
use imu_core::{AccelSign, Body, Enu, NavFrame, Ned, Rotation};

use super::{AnyFilter, robust_row};
use crate::error::{Result, invalid};
use crate::io::conventions::NavFrameName;
use crate::io::rows::SampleClock;

/// Estimates of a batch: `q_nb` (w, x, y, z) and the bias-corrected body rate per estimate.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Estimates {
    /// Orientations, one per estimate.
    pub quaternions: Vec<[f64; 4]>,
    /// Angular velocities, rad/s.
    pub angular_velocity_rad_s: Vec<[f64; 3]>,
    /// The robust filter's bias and flags per estimate ([`crate::io::columns::ROBUST_COLUMNS`]); empty for the
    /// others.
    pub status: Vec<[f64; 6]>,
}

/// Runs `filter` over rows of readings given as flat slices (three values per row):
/// accelerometer, gyroscope and magnetometer (`None` for sensors the filter does not use), and
/// their times `t_s` when known: each sample is then integrated over its own interval, the
/// first from the last time `clock` holds (else at the filter's sample rate).
/// The filter and the clock carry their state into the next call, so a run in chunks equals a
/// run whole; on an error both are left as they were before the call. As in MATLAB's `imufilter` and
/// `ahrsfilter`, each call takes whole decimation blocks: the row count must be a multiple of
/// the `DecimationFactor`.
///
/// # Errors
/// Slices of different lengths, a row count that is not a multiple of the decimation factor,
/// times that are not finite or do not increase, the filter's refusals naming the row index
/// (non-finite readings among them), and estimates that are not finite.
pub fn run_rows<N: NavFrame>(
    filter: &mut AnyFilter<N>,
    clock: &mut SampleClock,
    accel: &[f64],
    gyro: Option<&[f64]>,
    mag: Option<&[f64]>,
    t_s: Option<&[f64]>,
) -> Result<Estimates> {
    let n = rows_of(accel, gyro, mag, t_s)?;
    let intervals = t_s.map(|t| clock.intervals(t)).transpose()?;
    let decimation = filter.decimation();
    if !n.is_multiple_of(decimation) {
        return Err(invalid(
            "readings",
            format!(
                "{n} rows is not a multiple of DecimationFactor = {decimation} (each call takes \
                 whole blocks of {decimation} samples, as MATLAB's imufilter and ahrsfilter do)"
            ),
        ));
    }
    let mut working = *filter;
    let estimates = n / decimation;
    let mut out = Estimates {
        quaternions: Vec::with_capacity(estimates),
        angular_velocity_rad_s: Vec::with_capacity(estimates),
        status: Vec::with_capacity(if working.status().is_some() {
            estimates
        } else {
            0
        }),
    };
    let three = |s: Option<&[f64]>, i: usize| {
        s.map_or([0.0; 3], |s| [s[3 * i], s[3 * i + 1], s[3 * i + 2]])
    };
    for i in 0..n {
        let input = FilterInput {
            accel_m_s2: three(Some(accel), i),
            gyro_rad_s: three(gyro, i),
            mag_ut: three(mag, i),
            interval_s: intervals.as_ref().and_then(|d| d[i]),
        };
        let estimate = working
            .update(&input)
            .map_err(|e| invalid("readings", format!("row {i}: {e}")))?;
        if let Some(e) = estimate {
            let (q, w) = (e.orientation.to_wxyz(), e.angular_velocity_rad_s);
            if !q.iter().chain(&w).all(|v| v.is_finite()) {
                return Err(invalid(
                    "readings",
                    format!(
                        "row {i}: the estimate is not finite (readings too large for the filter, \
                         or a sample rate too small)"
                    ),
                ));
            }
            out.quaternions.push(q);
            out.angular_velocity_rad_s.push(w);
            if let Some(status) = working.status() {
                out.status.push(robust_row(&status));
            }
        }
    }
    *filter = working;
    clock.advance(t_s);
    Ok(out)
}

/// The e-compass of each row: accelerometer and magnetometer rows (three values each, flat) in
/// frame `nav`, with the accelerometer sign `accel_sign`; four values `q_nb` per row.
///
/// # Errors
/// Slices of different lengths; a row the e-compass refuses (parallel or zero vectors), named
/// by its index.
pub fn ecompass_rows(
    accel: &[f64],
    mag: &[f64],
    accel_sign: AccelSign,
    nav: NavFrameName,
) -> Result<Vec<f64>> {
    fn rows<N: NavFrame>(a: &[f64], m: &[f64], s: AccelSign) -> Result<Vec<f64>> {
        let mut out = Vec::with_capacity(a.len() / 3 * 4);
        for (i, (a, m)) in a.chunks_exact(3).zip(m.chunks_exact(3)).enumerate() {
            let q = imu_core::orientation::ecompass::<N>([a[0], a[1], a[2]], [m[0], m[1], m[2]], s)
                .map_err(|source| crate::Error::Orientation {
                    context: format!("row {i}"),
                    source,
                })?;
            out.extend(q.to_wxyz());
        }
        Ok(out)
    }
    if accel.len() != mag.len() {
        return Err(invalid(
            "mag",
            format!("has {} rows, accel {}", mag.len() / 3, accel.len() / 3),
        ));
    }
    match nav {
        NavFrameName::ENU => rows::<Enu>(accel, mag, accel_sign),
        NavFrameName::NED => rows::<Ned>(accel, mag, accel_sign),
    }
}

/// The quaternion distance (rad) between the rows of two flat lists of quaternions
/// `[w, x, y, z]` (four values per row).
///
/// # Errors
/// Lists of different lengths; a quaternion of zero norm or not finite, named `q1[i]`/`q2[i]`.
pub fn quaternion_distances(q1: &[f64], q2: &[f64]) -> Result<Vec<f64>> {
    if q1.len() != q2.len() {
        return Err(invalid(
            "q2",
            format!("has {} rows, q1 {}", q2.len() / 4, q1.len() / 4),
        ));
    }
    let rotation = |c: &[f64], name: &str, i: usize| {
        Rotation::<Body, Enu>::from_wxyz([c[0], c[1], c[2], c[3]]).ok_or_else(|| {
            crate::Error::BadQuaternion {
                field: format!("{name}[{i}]"),
            }
        })
    };
    q1.chunks_exact(4)
        .zip(q2.chunks_exact(4))
        .enumerate()
        .map(|(i, (a, b))| {
            Ok(imu_core::orientation::quaternion_distance(
                &rotation(a, "q1", i)?,
                &rotation(b, "q2", i)?,
            ))
        })
        .collect()
}

/// The robust filter with `params` over a whole run, smoothed (forward and backward passes,
/// [`imu_core::orientation::robust::smooth`]); readings as for [`run_rows`], times `t_s` when
/// known (else the filter's sample rate). Nothing carries over between calls: each is a run.
///
/// # Errors
/// As [`run_rows`].
pub fn smooth_rows<N: NavFrame>(
    params: RobustParams,
    accel: &[f64],
    gyro: &[f64],
    mag: Option<&[f64]>,
    t_s: Option<&[f64]>,
) -> Result<Estimates> {
    let n = rows_of(accel, Some(gyro), mag, t_s)?;
    let intervals = t_s
        .map(|t| SampleClock::default().intervals(t))
        .transpose()?;
    let three = |s: &[f64], i: usize| [s[3 * i], s[3 * i + 1], s[3 * i + 2]];
    let inputs: Vec<FilterInput> = (0..n)
        .map(|i| FilterInput {
            accel_m_s2: three(accel, i),
            gyro_rad_s: three(gyro, i),
            mag_ut: mag.map_or([0.0; 3], |m| three(m, i)),
            interval_s: intervals.as_ref().and_then(|d| d[i]),
        })
        .collect();
    let smoothed = smooth_inputs::<N>(params, &inputs)
        .map_err(|(i, e)| invalid("readings", format!("row {i}: {e}")))?;
    let mut out = Estimates::default();
    for (i, (e, status)) in smoothed.iter().enumerate() {
        let (q, w) = (e.orientation.to_wxyz(), e.angular_velocity_rad_s);
        if !q.iter().chain(&w).all(|v| v.is_finite()) {
            return Err(invalid(
                "readings",
                format!("row {i}: the estimate is not finite"),
            ));
        }
        out.quaternions.push(q);
        out.angular_velocity_rad_s.push(w);
        out.status.push(robust_row(status));
    }
    Ok(out)
}

/// The rows of readings given as flat slices (three values per row), checked to agree in
/// length with the times.
fn rows_of(
    accel: &[f64],
    gyro: Option<&[f64]>,
    mag: Option<&[f64]>,
    t_s: Option<&[f64]>,
) -> Result<usize> {
    let n = accel.len() / 3;
    if let Some(t) = t_s.filter(|t| t.len() != n) {
        return Err(invalid(
            "t_s",
            format!("has {} times, the accelerometer {n} rows", t.len()),
        ));
    }
    for (name, s) in [("gyroscope", gyro), ("magnetometer", mag)] {
        if let Some(s) = s.filter(|s| s.len() != accel.len()) {
            return Err(invalid(
                name,
                format!("has {} rows, the accelerometer {n}", s.len() / 3),
            ));
        }
    }
    Ok(n)
}

/// One smoothed sample: the estimate and the filter's status.
pub(super) type Smoothed<N> = (Estimate<N>, RobustStatus);

/// The robust filter with `params` smoothed over `inputs`: an estimate and status per input;
/// the index of a refused sample otherwise.
pub(super) fn smooth_inputs<N: NavFrame>(
    params: RobustParams,
    inputs: &[FilterInput],
) -> std::result::Result<Vec<Smoothed<N>>, (usize, OrientError)> {
    let blank = (
        Estimate {
            orientation: Rotation::<Body, N>::identity(),
            angular_velocity_rad_s: [0.0; 3],
        },
        RobustStatus::default(),
    );
    let mut smoothed = vec![blank; inputs.len()];
    robust::smooth(params, inputs, &mut smoothed)?;
    Ok(smoothed)
}
