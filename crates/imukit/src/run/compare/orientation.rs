//! Scoring an orientation estimate against a reference the way orientation benchmarks do
//! (BROAD's metric, Laidig et al., *Data* 6(7):72, 2021): the error rotation in the navigation
//! frame, `e = q_est ⊗ q_ref⁻¹`, split into its part about the vertical — the **heading** error,
//! `2·atan(|e_z / e_w|)` — and the rest — the **inclination** error,
//! `2·acos(√(e_w² + e_z²))` — beside its total angle.
//!
//! A real reference has holes: an optical system loses its markers (NaN in the quaternion) or
//! stops recording for a while (a gap in its times). Estimates there are **skipped**, not scored
//! against a slerp across the hole; so are estimates outside the reference's time span. A gap
//! is an interval longer than three times the reference's typical one (the median of its first
//! intervals).
//!
//! A 6D estimate has an arbitrary heading: **aligning** removes one constant heading offset — the
//! circular mean of the signed heading error over the scored rows — before scoring.
use imu_core::orientation::{DistanceStats, quaternion_distance};
use imu_core::{Body, Enu, Rotation};
use nalgebra::{Quaternion, UnitQuaternion};

use super::{Bracket, ErrorSummary, EstimateKind, StateRow, angle_difference};
use crate::error::{Result, invalid};

/// Reference intervals whose median is the typical interval.
const TYPICAL_OF: usize = 15;
/// An interval longer than this many typical ones is a gap.
const GAP_FACTOR: f64 = 3.0;

/// The split of an error rotation `e` (navigation frame) into heading and inclination angles,
/// and the signed heading angle, rad.
#[must_use]
pub fn heading_inclination(e: &UnitQuaternion<f64>) -> (f64, f64, f64) {
    let q = e.quaternion().normalize();
    let (w, z) = if q.w < 0.0 { (-q.w, -q.k) } else { (q.w, q.k) };
    let heading: f64 = 2.0 * z.atan2(w);
    let inclination = 2.0 * (w * w + z * z).sqrt().min(1.0).acos();
    (heading.abs(), inclination, heading)
}

/// A rotation by `angle` about the navigation frame's vertical (its z axis, in ENU and NED).
fn about_vertical(angle: f64) -> UnitQuaternion<f64> {
    let (s, c) = (0.5 * angle).sin_cos();
    UnitQuaternion::new_unchecked(Quaternion::new(c, 0.0, 0.0, s))
}

/// Orientation rows (`t_s` and `q_wxyz` at 7..11 of a [`StateRow`]) scored in time order:
/// each estimate row against the slerp of the reference rows that bracket it, skipped where
/// the reference has no value, a gap, or no time (see the module documentation); the heading
/// offset `align_rad` removed from every estimate first. Error rows
/// ([`crate::io::columns::ORIENTATION_ERROR_COLUMNS`]) go to `sink`.
pub(super) fn compare_orientation_rows(
    names: [&str; 2],
    mut read_truth: impl FnMut(&mut StateRow) -> Result<bool>,
    mut estimate: impl FnMut(&mut StateRow) -> Result<bool>,
    align_rad: Option<f64>,
    mut sink: impl FnMut(&[f64]) -> Result<()>,
) -> Result<ErrorSummary> {
    let [truth_name, estimate_name] = names;
    let (mut truth_rows, mut last_truth) = (0usize, f64::NEG_INFINITY);
    // The reference's first intervals, whose median is its typical interval.
    let intervals = std::cell::Cell::new([0.0; TYPICAL_OF]);
    let seen = std::cell::Cell::new(0usize);
    let mut truth = |row: &mut StateRow| -> Result<bool> {
        if !read_truth(row)? {
            return Ok(false);
        }
        truth_rows += 1;
        if !row[0].is_finite() || row[0] <= last_truth {
            return Err(invalid(
                format!("{truth_name}, row {}", truth_rows + 1),
                format!(
                    "reference time {} s does not increase (previous {last_truth} s)",
                    row[0]
                ),
            ));
        }
        if last_truth.is_finite() && seen.get() < TYPICAL_OF {
            let mut first = intervals.get();
            first[seen.get()] = row[0] - last_truth;
            intervals.set(first);
            seen.set(seen.get() + 1);
        }
        last_truth = row[0];
        Ok(true)
    };
    let mut bracket = Bracket::start(&mut truth, truth_name)?;
    let t_first = bracket.t0;
    let align = align_rad.map(|offset| about_vertical(-offset));
    let mut e = [0.0; 11];
    let mut score = Score::default();
    let (mut rows, mut skipped, mut previous_t) = (0usize, 0usize, f64::NEG_INFINITY);
    while estimate(&mut e)? {
        let (t, row) = (e[0], rows + skipped + 2);
        if !t.is_finite() || t < previous_t {
            return Err(invalid(
                estimate_name,
                format!(
                    "estimate time {t} s (row {row}) is not finite or goes back from {previous_t} s"
                ),
            ));
        }
        previous_t = t;
        bracket.advance(t, &mut truth)?;
        let w = bracket.weight(t);
        let (a, b) = (&bracket.a, &bracket.b);
        // An estimate at a reference sample needs only that sample; between two, both and no gap.
        let finite = |r: &StateRow| r[7..].iter().all(|v| v.is_finite());
        let outside = t < t_first - 1e-9 || (bracket.ended && t > b[0] + 1e-9);
        let hole = !finite(a) || (w > 0.0 && !finite(b));
        let gap = w > 0.0
            && seen.get() > 0
            && b[0] - a[0] > GAP_FACTOR * typical_interval(&intervals.get()[..seen.get()]);
        if outside || hole || gap {
            skipped += 1;
            continue;
        }
        let quaternion = |r: &StateRow, side: &str| {
            Rotation::<Body, Enu>::from_wxyz([r[7], r[8], r[9], r[10]])
                .ok_or_else(|| invalid(side, format!("zero quaternion near estimate row {row}")))
        };
        let qa = quaternion(a, truth_name)?;
        let qb = if w > 0.0 {
            quaternion(b, truth_name)?
        } else {
            qa
        };
        let mut qe = quaternion(&e, estimate_name)?;
        if let Some(turn) = align {
            qe = Rotation::assume_from_quaternion(turn * qe.quaternion());
        }
        // nalgebra's slerp leaves the norm off by up to ~1e-9, which the inclination's
        // acos(√(w² + z²)) near 1 would turn into 1e-5 rad: renormalised.
        let qt = Rotation::<Body, Enu>::assume_from_quaternion(UnitQuaternion::new_normalize(
            qa.quaternion().slerp(qb.quaternion(), w).into_inner(),
        ));
        sink(&score.push(t, &qe, &qt))?;
        rows += 1;
    }
    while !bracket.ended && truth(&mut bracket.next)? {}
    if rows == 0 {
        return Err(invalid(
            estimate_name,
            format!(
                "no estimate time ({} rows) has a reference value between {t_first} s and {last_truth} s",
                skipped
            ),
        ));
    }
    let Score {
        total,
        heading,
        inclination,
        sin_sum,
        cos_sum,
    } = score;
    let mean_heading = sin_sum.atan2(cos_sum);
    Ok(ErrorSummary {
        kind: EstimateKind::Orientation,
        position: None,
        velocity: None,
        attitude: Some(total),
        heading: Some(heading),
        inclination: Some(inclination),
        heading_offset_rad: Some(align_rad.map_or(mean_heading, |a| a + mean_heading)),
        skipped,
        rows,
    })
}

/// The median of a reference's first intervals (0 when it has none yet).
fn typical_interval(first: &[f64]) -> f64 {
    let mut sorted = [0.0; TYPICAL_OF];
    let sorted = &mut sorted[..first.len().min(TYPICAL_OF)];
    sorted.copy_from_slice(&first[..sorted.len()]);
    sorted.sort_by(f64::total_cmp);
    sorted.get(sorted.len() / 2).copied().unwrap_or(0.0)
}

/// The scores of the rows so far: total, heading and inclination angles, and the sums whose
/// circular mean is the mean signed heading error.
#[derive(Default)]
struct Score {
    total: DistanceStats,
    heading: DistanceStats,
    inclination: DistanceStats,
    sin_sum: f64,
    cos_sum: f64,
}

impl Score {
    /// Scores estimate `qe` against reference `qt` at time `t`; returns the error row.
    fn push(&mut self, t: f64, qe: &Rotation<Body, Enu>, qt: &Rotation<Body, Enu>) -> [f64; 7] {
        let angle = quaternion_distance(qe, qt);
        let (h, i, signed) = heading_inclination(&(qe.quaternion() * qt.quaternion().inverse()));
        self.total.push(angle);
        self.heading.push(h);
        self.inclination.push(i);
        self.sin_sum += signed.sin();
        self.cos_sum += signed.cos();
        let (ee, et) = (qe.to_euler(), qt.to_euler());
        [
            t,
            angle,
            h,
            i,
            angle_difference(ee.yaw_rad, et.yaw_rad),
            angle_difference(ee.pitch_rad, et.pitch_rad),
            angle_difference(ee.roll_rad, et.roll_rad),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heading_and_inclination_split_an_error_rotation() {
        // 10° about the vertical, then 20° about north: heading 10°, inclination 20°.
        let e = UnitQuaternion::from_scaled_axis(nalgebra::Vector3::x() * 20f64.to_radians())
            * about_vertical(10f64.to_radians());
        let (h, i, s) = heading_inclination(&e);
        assert!((h.to_degrees() - 10.0).abs() < 1e-9, "{}", h.to_degrees());
        assert!((i.to_degrees() - 20.0).abs() < 1e-9, "{}", i.to_degrees());
        assert!((s - h).abs() < 1e-12);
        let (h, _, s) = heading_inclination(&about_vertical(-0.3));
        assert!((h - 0.3).abs() < 1e-12 && (s + 0.3).abs() < 1e-12);
        // The same rotation with the other sign of the quaternion.
        let flipped = UnitQuaternion::new_unchecked(-e.into_inner());
        let (h2, i2, _) = heading_inclination(&flipped);
        assert!((h2.to_degrees() - 10.0).abs() < 1e-9 && (i2.to_degrees() - 20.0).abs() < 1e-9);
    }
}
