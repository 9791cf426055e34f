//! How far an orientation estimate is from truth.
use crate::frame::Body;
use crate::math;
use crate::nav_frame::NavFrame;
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
    /// The sum of squares is `scale² · scaled_sum_sq`, kept so (as LAPACK's `dnrm2`) to stay
    /// finite for any finite distances: 1e308 squared would overflow.
    scale: f64,
    scaled_sum_sq: f64,
    max: f64,
    last: f64,
}

impl DistanceStats {
    /// Adds one distance.
    pub fn push(&mut self, d: f64) {
        self.count += 1;
        let a = math::abs(d);
        if a > self.scale {
            let r = self.scale / a;
            self.scaled_sum_sq = 1.0 + self.scaled_sum_sq * r * r;
            self.scale = a;
        } else if a > 0.0 {
            let r = a / self.scale;
            self.scaled_sum_sq += r * r;
        } else if a.is_nan() {
            self.scaled_sum_sq = f64::NAN;
        }
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
            self.scale * math::sqrt(self.scaled_sum_sq / self.count as f64)
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

#[cfg(test)]
mod tests {
    use super::DistanceStats;

    fn stats(values: &[f64]) -> DistanceStats {
        let mut s = DistanceStats::default();
        for v in values {
            s.push(*v);
        }
        s
    }

    #[test]
    fn the_rms_is_the_root_mean_square_and_finite_for_any_finite_distances() {
        assert_eq!(stats(&[]).rms(), 0.0);
        assert_eq!(stats(&[0.0, 0.0]).rms(), 0.0);
        assert!((stats(&[3.0, 4.0]).rms() - 12.5_f64.sqrt()).abs() < 1e-15);
        // Squares that overflow a double: the mean of equal values is the value.
        let big = stats(&[1e308, 1e308, 1e308]);
        assert!((big.rms() / 1e308 - 1.0).abs() < 1e-15, "{}", big.rms());
        assert!((stats(&[1e308, 0.0]).rms() / (1e308 / 2.0_f64.sqrt()) - 1.0).abs() < 1e-15);
        // The same as the plain formula where that does not overflow, in any order.
        let v: [f64; 6] = [0.5, 2.0, 1e-3, 7.25, 0.0, 3.0];
        let plain = (v.iter().map(|x| x * x).sum::<f64>() / 6.0).sqrt();
        let mut reversed = v;
        reversed.reverse();
        for s in [stats(&v), stats(&reversed)] {
            assert!((s.rms() / plain - 1.0).abs() < 4.0 * f64::EPSILON);
        }
    }
}
