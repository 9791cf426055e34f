//! How far an orientation estimate is from truth.
use crate::frame::{Body, NavFrame};
use crate::math;
use crate::rotation::Rotation;

/// The quaternion distance between two orientations, rad: the angle of the rotation that takes
/// one into the other, in `[0, π]` (MATLAB's `dist`). Computed as `2 atan2(|v|, |w|)` of
/// `a⁻¹ b`, which keeps full precision near zero where `2 acos(|w|)` does not.
#[must_use]
pub fn quaternion_distance<N: NavFrame>(a: &Rotation<Body, N>, b: &Rotation<Body, N>) -> f64 {
    let d = a.quaternion().inverse() * b.quaternion();
    let v = d.imag();
    let s = math::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    2.0 * math::atan2(s, math::abs(d.w))
}

/// Running RMS, maximum and last value of a distance over time (rad).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DistanceStats {
    count: usize,
    sum_sq: f64,
    max: f64,
    last: f64,
}

impl DistanceStats {
    /// Adds one distance.
    pub fn push(&mut self, d: f64) {
        self.count += 1;
        self.sum_sq += d * d;
        self.max = self.max.max(d);
        self.last = d;
    }

    /// Number of values.
    #[must_use]
    pub fn count(&self) -> usize {
        self.count
    }

    /// Root mean square (0 with no values).
    #[must_use]
    pub fn rms(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            math::sqrt(self.sum_sq / self.count as f64)
        }
    }

    /// Largest value.
    #[must_use]
    pub fn max(&self) -> f64 {
        self.max
    }

    /// The last value.
    #[must_use]
    pub fn last(&self) -> f64 {
        self.last
    }
}
