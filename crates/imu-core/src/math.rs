//! Float functions that work with either `std` or `libm` (through `num_traits::Float`).
use num_traits::Float;

#[inline]
pub(crate) fn sin(x: f64) -> f64 {
    Float::sin(x)
}
#[inline]
pub(crate) fn cos(x: f64) -> f64 {
    Float::cos(x)
}
/// `(sin x, cos x)`. An angle of exactly zero (either sign) is answered without the library
/// call, as `(x, 1)`: what the call returns, bit for bit, without the 7 ns glibc's `sincos` takes
/// even for zero on our machines. Zero angles are common: the tangent attitude's roll, a level
/// or unrolled motion.
#[inline]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x == 0.0 {
        (x, 1.0)
    } else {
        Float::sin_cos(x)
    }
}
#[inline]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    Float::atan2(y, x)
}
#[inline]
pub(crate) fn sqrt(x: f64) -> f64 {
    Float::sqrt(x)
}
#[inline]
pub(crate) fn hypot(x: f64, y: f64) -> f64 {
    Float::hypot(x, y)
}
#[inline]
pub(crate) fn abs(x: f64) -> f64 {
    Float::abs(x)
}
/// `x` rounded to the nearest integer, halves away from zero: bit for bit `f64::round` (signed
/// zeros, NaN and infinities included) without its library call on targets that lack a rounding
/// instruction (x86-64 before SSE4.1, the portable baseline), where the call cost the sensor
/// model 15 % of its time.
///
/// For `a = |x| < 2⁵²`, `(a + 2⁵²) − 2⁵²` is `a` rounded to nearest with ties to even (the sum's
/// last bit is the units place); `a − r` is exact (Sterbenz, or `r = 0`), so a tie that went down
/// is seen as `+½` and moved up. Branch-free, because in noisy data the halves fall at random.
/// Larger magnitudes are integers already.
#[inline]
pub(crate) fn round(x: f64) -> f64 {
    const TWO_POW_52: f64 = 4_503_599_627_370_496.0;
    let a = abs(x);
    let r = (a + TWO_POW_52) - TWO_POW_52;
    let r = Float::copysign(r + f64::from(u8::from(a - r >= 0.5)), x);
    // A select, not an early return, so that the compiler can keep it branch-free.
    if a < TWO_POW_52 { r } else { x }
}

/// Adds the multiple of 2π to `angle` that brings it closest to `reference` (angle unwrapping):
/// `angle + 2π·round((reference − angle)/2π)`.
///
/// Where the two are within 3 rad of each other (consecutive samples of a yaw, nearly always),
/// the quotient is below ½ in magnitude and rounds to a zero of its sign, so the sum is
/// `angle + (±0)`: answered as that, bit for bit, without the division that made this the longest
/// link of a tracker's chain from one sample to the next (yaw unwrapped against the last one).
#[inline]
pub(crate) fn unwrap_near(angle: f64, reference: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    let d = reference - angle;
    if abs(d) <= 3.0 {
        return angle + Float::copysign(0.0, d);
    }
    angle + two_pi * round(d / two_pi)
}

#[inline]
pub(crate) fn exp(x: f64) -> f64 {
    Float::exp(x)
}
#[inline]
pub(crate) fn ln(x: f64) -> f64 {
    Float::ln(x)
}
#[inline]
pub(crate) fn powf(x: f64, y: f64) -> f64 {
    Float::powf(x, y)
}
#[inline]
pub(crate) fn ceil(x: f64) -> f64 {
    Float::ceil(x)
}
#[inline]
pub(crate) fn cbrt(x: f64) -> f64 {
    Float::cbrt(x)
}
#[inline]
pub(crate) fn tan(x: f64) -> f64 {
    Float::tan(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library rounding this module's `round` replaces.
    fn reference(x: f64) -> f64 {
        Float::round(x)
    }

    fn same_bits(x: f64) {
        let (got, want) = (round(x), reference(x));
        assert!(
            got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
            "round({x:e}) = {got:e}, library {want:e}"
        );
    }

    #[test]
    fn round_matches_the_library_on_edges() {
        let half_below = 0.5 - f64::EPSILON / 4.0; // 0.49999999999999994
        let two52 = 4_503_599_627_370_496.0;
        for x in [
            0.0,
            0.5,
            1.5,
            2.5,
            half_below,
            1.0 - f64::EPSILON / 2.0,
            two52 - 0.5,
            two52 - 1.5,
            two52,
            two52 + 1.0,
            9.3e18,
            1e300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
        ] {
            same_bits(x);
            same_bits(-x);
        }
    }

    #[test]
    fn round_matches_the_library_on_a_million_bit_patterns() {
        // SplitMix64 over raw bit patterns (every exponent) and over values near halves.
        let mut z: u64 = 0x1234_5678_9ABC_DEF0;
        let mut next = || {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut v = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            v = (v ^ (v >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            v ^ (v >> 31)
        };
        for _ in 0..500_000 {
            same_bits(f64::from_bits(next()));
            let k = (next() % 2_000_001) as f64 - 1e6;
            let ulps = (next() % 7) as i64 - 3;
            let h = k + 0.5;
            same_bits(f64::from_bits((h.to_bits() as i64 + ulps) as u64));
        }
    }

    /// The unwrapping's short cut gives the general formula's bits: near and far pairs, signed
    /// zeros, the 3 rad edge, whole turns, NaN.
    #[test]
    fn unwrap_near_is_the_formula_bit_for_bit() {
        let two_pi = 2.0 * core::f64::consts::PI;
        let formula = |a: f64, r: f64| a + two_pi * Float::round((r - a) / two_pi);
        let mut z: u64 = 0x0BAD_5EED;
        let mut uniform = |scale: f64| {
            z ^= z << 13;
            z ^= z >> 7;
            z ^= z << 17;
            ((z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
        };
        let edges = [
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (-0.0, 1e-300),
            (0.0, -1e-300),
            (-0.0, -1e-300),
            (1.0, 4.0),
            (1.0, -2.0),
            (0.0, 3.0),
            (0.0, -3.0),
            (0.0, 3.0 + f64::EPSILON * 2.0),
            (3.0, 3.0 + 2.0 * two_pi),
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
        ];
        let check = |a: f64, r: f64| {
            let (got, want) = (unwrap_near(a, r), formula(a, r));
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "unwrap_near({a:e}, {r:e}) = {got:e}, formula {want:e}"
            );
        };
        for (a, r) in edges {
            check(a, r);
        }
        for _ in 0..200_000 {
            let a = uniform(40.0);
            check(a, a + uniform(4.0));
            check(a, uniform(1e4));
        }
    }
}
