//! Sines, cosines and arctangents of many numbers at once, four to a vector register.
//!
//! The exact-truth path takes the sines and cosines of every sample's angles and formula
//! arguments, and the tangent attitude two arctangents: one C-library call each was most of its
//! time (10 ns a call on our machines). These kernels evaluate four values together with the
//! `wide` crate's polynomial `sin_cos` and `atan2` (Agner Fog's vector class library, after
//! Cephes). The sine and cosine take 3.3–3.5 ns a value on x86-64's SSE2 baseline and 2.0 ns
//! with AVX2, against 5.1–5.4 ns for `wide`'s own `sin_cos` (same results bit for bit, see
//! `sin_cos_reduced!`) and 9.7–9.9 ns for glibc's `sincos` (`cargo bench -p imu-benches --bench
//! truth -- sin_cos`); `atan2` about 4.8 ns against glibc's 10.3 ns.
//!
//! **Accuracy.** Each result is within [`MAX_ULP`] units in the last place of the correctly
//! rounded value (the library's own functions are within one). `tests/trig.rs` checks this
//! against CORE-MATH's correctly rounded functions (the `pxfm` crate) on random arguments of
//! every range the kernels take; arguments the polynomial's range reduction does not cover
//! (`|x| ≥ 2²⁶`, see [`SIN_COS_MAX_ARG`]) and non-finite ones go to the library function one by
//! one, so no input gets a worse answer. Signed zeros are exact: `sin(±0) = ±0`, `cos(±0) = 1`,
//! `atan2(±0, +0) = ±0`, `atan2(±0, −0) = ±π`.
//!
//! **Reproducibility.** A value's result depends on that value alone, not on its neighbours, on
//! where a slice starts or on its length, so a run gives the same numbers in one call, in chunks
//! and on any number of threads. The kernels are plain IEEE arithmetic (no fused multiply-add),
//! so unlike the C library's functions, which choose an FMA variant by CPU at run time, a
//! build's results do not depend on the x86-64 CPU that runs it. The sine and cosine kernel has
//! a second copy in AVX2's instructions, which runs where the CPU has AVX2 ([`crate::cpu`]): the
//! same operations in the same order, so the same results bit for bit (`tests/trig.rs` runs both
//! copies). It never fuses a multiply-add, on any target; `wide`'s arctangent does where the
//! build has FMA (`-C target-cpu=native`) or on AArch64, and its results can then differ within
//! the bound.
use wide::f64x4;

use crate::math;

/// The largest error of [`sin_cos_into`] and [`atan2_into`], in units in the last place of the
/// correctly rounded result.
pub const MAX_ULP: u32 = 2;

/// Arguments of [`sin_cos_into`] at or above this magnitude (2²⁶ rad) are evaluated by the
/// library's `sin_cos`: the kernel's three-part reduction by π/2 keeps its accuracy below it.
pub const SIN_COS_MAX_ARG: f64 = 67_108_864.0;

/// Lanes of the kernels' vectors.
const LANES: usize = 4;

/// `sin[i], cos[i] = sin x[i], cos x[i]` (radians) for every `i` of the shortest of the three
/// slices. On an x86-64 CPU with AVX2 the kernel runs four values to a register instead of two,
/// with the same results bit for bit ([`crate::cpu`]).
pub fn sin_cos_into(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    if crate::cpu::avx2_in_use() {
        // SAFETY: the CPU has AVX2 and the operating system saves its registers (checked just
        // above).
        #[allow(unsafe_code)]
        unsafe {
            avx2::sin_cos_into(x, sin, cos);
        }
        return;
    }
    sin_cos_slices(x, sin, cos, |v| {
        let (s, c) = baseline::sin_cos_reduced(f64x4::from(v));
        (s.to_array(), c.to_array())
    });
}

/// [`sin_cos_into`] with `kernel` for each vector of [`LANES`] values (the reduced-range kernel of
/// the instruction set the caller is compiled for).
#[inline(always)]
fn sin_cos_slices(
    x: &[f64],
    sin: &mut [f64],
    cos: &mut [f64],
    kernel: impl Fn([f64; LANES]) -> ([f64; LANES], [f64; LANES]),
) {
    let n = x.len().min(sin.len()).min(cos.len());
    let (x, sin, cos) = (&x[..n], &mut sin[..n], &mut cos[..n]);
    let whole = n - n % LANES;
    let lanes = x[..whole].chunks_exact(LANES);
    let outs = sin[..whole]
        .chunks_exact_mut(LANES)
        .zip(cos[..whole].chunks_exact_mut(LANES));
    for (v, (s, c)) in lanes.zip(outs) {
        sin_cos_lanes(v, s, c, &kernel);
    }
    if whole == n {
        return;
    }
    // The last values padded with zeros to a whole vector (fixed-size copies above: a
    // variable-length copy per vector was a `memcpy` call each).
    let mut v = [0.0; LANES];
    v[..n - whole].copy_from_slice(&x[whole..]);
    let (mut s, mut c) = ([0.0; LANES], [0.0; LANES]);
    sin_cos_lanes(&v, &mut s, &mut c, &kernel);
    sin[whole..].copy_from_slice(&s[..n - whole]);
    cos[whole..].copy_from_slice(&c[..n - whole]);
}

/// [`sin_cos_into`] of one vector's worth of values (`x`, `sin`, `cos` of length [`LANES`]).
#[inline(always)]
fn sin_cos_lanes(
    x: &[f64],
    sin: &mut [f64],
    cos: &mut [f64],
    kernel: impl Fn([f64; LANES]) -> ([f64; LANES], [f64; LANES]),
) {
    let v: [f64; LANES] = core::array::from_fn(|k| x[k]);
    let (s, c) = kernel(v);
    for k in 0..LANES {
        (sin[k], cos[k]) = if math::abs(v[k]) < SIN_COS_MAX_ARG {
            (s[k], c[k])
        } else {
            math::sin_cos(v[k])
        };
    }
}

/// `wide`'s `f64x4::sin_cos` for finite arguments below [`SIN_COS_MAX_ARG`] in magnitude (other
/// lanes get meaningless numbers, which [`sin_cos_lanes`] replaces): the same floating-point
/// operations in the same order, so the same results bit for bit (`tests/trig.rs` compares the
/// two), without what the x86-64 baseline (SSE2) has no instruction for and `wide` therefore does
/// lane by lane: rounding to an integer, converting to one, and comparing 64-bit integers.
///
/// The quadrant `q = round(|x|·2/π)` (ties to even, as `wide` rounds) is the sum
/// `|x|·2/π + 2⁵²` itself: below 2²⁶, adding 2⁵² rounds the product to an integer, which the
/// sum's low mantissa bits hold, and subtracting 2⁵² again gives `q` as a float exactly. Bit 0 of
/// `q` swaps sine and cosine, bit 1 (and the sign of `x`) the sine's sign, bit 1 of `q + 1` the
/// cosine's; those bits are read from the sum's bits with shifts, masks and a 64-bit
/// subtraction, which SSE2 has. `wide`'s overflow and non-finite checks change nothing in this
/// range.
///
/// Written once, here, on the operations of a module that names its vector type `V`:
/// [`baseline`] (`wide`'s `f64x4`) and, on x86-64, [`avx2`] (AVX2's `__m256d`). The
/// multiply-adds are a product and a sum, rounded each, as `wide` does them without FMA.
macro_rules! sin_cos_reduced {
    ($(#[$attr:meta])*) => {
        $(#[$attr])*
        #[allow(
            clippy::excessive_precision,
            reason = "the coefficients' digits as Cephes and `wide` print them; they round to the same doubles"
        )]
        pub(super) fn sin_cos_reduced(x: V) -> (V, V) {
            // Agner Fog's coefficients and three-part π/2, as `wide` has them.
            const P0_SIN: f64 = -1.666_666_666_666_663_072_95E-1;
            const P1_SIN: f64 = 8.333_333_333_322_118_588_78E-3;
            const P2_SIN: f64 = -1.984_126_982_958_953_859_96E-4;
            const P3_SIN: f64 = 2.755_731_362_138_572_452_13E-6;
            const P4_SIN: f64 = -2.505_074_776_285_780_728_66E-8;
            const P5_SIN: f64 = 1.589_623_015_765_465_680_60E-10;
            const P0_COS: f64 = 4.166_666_666_666_659_292_18E-2;
            const P1_COS: f64 = -1.388_888_888_887_305_641_16E-3;
            const P2_COS: f64 = 2.480_158_728_885_170_453_48E-5;
            const P3_COS: f64 = -2.755_731_417_929_673_881_12E-7;
            const P4_COS: f64 = 2.087_570_084_197_473_167_78E-9;
            const P5_COS: f64 = -1.135_853_652_138_768_173_00E-11;
            const DP1: f64 = 7.853_981_554_508_209_228_515_625E-1 * 2.;
            const DP2: f64 = 7.946_627_356_147_928_367_14E-9 * 2.;
            const DP3: f64 = 3.061_616_997_868_382_943_07E-17 * 2.;
            const TWO_POW_52: f64 = 4_503_599_627_370_496.0;
            // `a·b + c` and `c − a·b`, each product and sum rounded.
            let mul_add = |a: V, b: V, c: V| add(mul(a, b), c);
            let mul_neg_add = |a: V, b: V, c: V| sub(c, mul(a, b));
            // `wide`'s `polynomial_5!`: c₃x + c₂, c₅x + c₄ and c₁x + c₀ combined with x² and x⁴.
            let polynomial_5 = |x: V, c: [f64; 6]| {
                let x2 = mul(x, x);
                let x4 = mul(x2, x2);
                mul_add(
                    mul_add(splat(c[3]), x, splat(c[2])),
                    x2,
                    mul_add(
                        mul_add(splat(c[5]), x, splat(c[4])),
                        x4,
                        mul_add(splat(c[1]), x, splat(c[0])),
                    ),
                )
            };
            let xa = abs(x);
            let shifted = add(mul(xa, splat(2.0 / core::f64::consts::PI)), splat(TWO_POW_52));
            let y = sub(shifted, splat(TWO_POW_52));
            let r = mul_neg_add(
                y,
                splat(DP3),
                mul_neg_add(y, splat(DP2), mul_neg_add(y, splat(DP1), xa)),
            );
            let r2 = mul(r, r);
            let s = polynomial_5(r2, [P0_SIN, P1_SIN, P2_SIN, P3_SIN, P4_SIN, P5_SIN]);
            let c = polynomial_5(r2, [P0_COS, P1_COS, P2_COS, P3_COS, P4_COS, P5_COS]);
            let s = mul_add(mul(r, r2), s, r);
            let c = mul_add(mul(r2, r2), c, mul_neg_add(r2, splat(0.5), splat(1.0)));
            // The quadrant's bits in `shifted`'s: all ones where q is odd (0 − (q & 1),
            // wrapping); bit 1 of q (with x's sign) in the sign bit for the sine; bit 1 of q + 1
            // there for the cosine.
            let q = shifted;
            let swap = bits_neg(bits_and_const(q, 1));
            let sin_sign = and(xor(bits_shl62(q), x), splat(-0.0));
            let cos_sign = bits_shl62(bits_and_const(bits_add_const(q, 1), 2));
            let sin = xor(or(and(swap, c), and_not(swap, s)), sin_sign);
            let cos = xor(or(and(swap, s), and_not(swap, c)), cos_sign);
            (sin, cos)
        }
    };
}

/// The kernel on the baseline's vectors: `wide`'s `f64x4`, two SSE2 registers on x86-64.
mod baseline {
    use wide::bytemuck::cast;
    use wide::{f64x4, u64x4};

    type V = f64x4;
    #[inline(always)]
    fn splat(a: f64) -> V {
        V::splat(a)
    }
    #[inline(always)]
    fn add(a: V, b: V) -> V {
        a + b
    }
    #[inline(always)]
    fn sub(a: V, b: V) -> V {
        a - b
    }
    #[inline(always)]
    fn mul(a: V, b: V) -> V {
        a * b
    }
    #[inline(always)]
    fn abs(a: V) -> V {
        a.abs()
    }
    #[inline(always)]
    fn and(a: V, b: V) -> V {
        a & b
    }
    /// `!a & b`.
    #[inline(always)]
    fn and_not(a: V, b: V) -> V {
        !a & b
    }
    #[inline(always)]
    fn or(a: V, b: V) -> V {
        a | b
    }
    #[inline(always)]
    fn xor(a: V, b: V) -> V {
        a ^ b
    }
    #[inline(always)]
    fn bits(a: V) -> u64x4 {
        cast(a)
    }
    #[inline(always)]
    fn bits_and_const(a: V, k: u64) -> V {
        cast(bits(a) & u64x4::splat(k))
    }
    #[inline(always)]
    fn bits_add_const(a: V, k: u64) -> V {
        cast(bits(a) + u64x4::splat(k))
    }
    /// `0 − a` in 64-bit integers, wrapping.
    #[inline(always)]
    fn bits_neg(a: V) -> V {
        cast(u64x4::ZERO - bits(a))
    }
    #[inline(always)]
    fn bits_shl62(a: V) -> V {
        cast(bits(a) << 62)
    }

    sin_cos_reduced!(#[inline(always)]);
}

/// The kernel on AVX2's four-lane registers, for CPUs that have it ([`crate::cpu`]).
#[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
mod avx2 {
    use core::arch::x86_64::{
        __m256d, _mm256_add_epi64, _mm256_add_pd, _mm256_and_pd, _mm256_and_si256,
        _mm256_andnot_pd, _mm256_castpd_si256, _mm256_castsi256_pd, _mm256_mul_pd, _mm256_or_pd,
        _mm256_set1_epi64x, _mm256_set1_pd, _mm256_setzero_si256, _mm256_slli_epi64,
        _mm256_sub_epi64, _mm256_sub_pd, _mm256_xor_pd,
    };

    use wide::bytemuck::cast;

    type V = __m256d;
    #[inline]
    #[target_feature(enable = "avx2")]
    fn splat(a: f64) -> V {
        _mm256_set1_pd(a)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn add(a: V, b: V) -> V {
        _mm256_add_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn sub(a: V, b: V) -> V {
        _mm256_sub_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn mul(a: V, b: V) -> V {
        _mm256_mul_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn abs(a: V) -> V {
        _mm256_andnot_pd(_mm256_set1_pd(-0.0), a)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn and(a: V, b: V) -> V {
        _mm256_and_pd(a, b)
    }
    /// `!a & b`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn and_not(a: V, b: V) -> V {
        _mm256_andnot_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn or(a: V, b: V) -> V {
        _mm256_or_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn xor(a: V, b: V) -> V {
        _mm256_xor_pd(a, b)
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits_and_const(a: V, k: u64) -> V {
        let k = _mm256_set1_epi64x(i64::from_ne_bytes(k.to_ne_bytes()));
        _mm256_castsi256_pd(_mm256_and_si256(_mm256_castpd_si256(a), k))
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits_add_const(a: V, k: u64) -> V {
        let k = _mm256_set1_epi64x(i64::from_ne_bytes(k.to_ne_bytes()));
        _mm256_castsi256_pd(_mm256_add_epi64(_mm256_castpd_si256(a), k))
    }
    /// `0 − a` in 64-bit integers, wrapping.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits_neg(a: V) -> V {
        _mm256_castsi256_pd(_mm256_sub_epi64(
            _mm256_setzero_si256(),
            _mm256_castpd_si256(a),
        ))
    }
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits_shl62(a: V) -> V {
        _mm256_castsi256_pd(_mm256_slli_epi64::<62>(_mm256_castpd_si256(a)))
    }

    sin_cos_reduced!(#[inline] #[target_feature(enable = "avx2")]);

    /// [`super::sin_cos_into`] with this kernel.
    #[target_feature(enable = "avx2")]
    pub(super) fn sin_cos_into(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
        super::sin_cos_slices(x, sin, cos, |v| {
            let (s, c) = sin_cos_reduced(cast(v));
            (cast(s), cast(c))
        });
    }
}

/// `out[i] = atan2(y[i], x[i])` (radians, in `[−π, π]`) for every `i` of the shortest of the
/// three slices.
pub fn atan2_into(y: &[f64], x: &[f64], out: &mut [f64]) {
    let n = y.len().min(x.len()).min(out.len());
    let (y, x, out) = (&y[..n], &x[..n], &mut out[..n]);
    let whole = n - n % LANES;
    let ins = y[..whole]
        .chunks_exact(LANES)
        .zip(x[..whole].chunks_exact(LANES));
    for ((vy, vx), o) in ins.zip(out[..whole].chunks_exact_mut(LANES)) {
        atan2_lanes(vy, vx, o);
    }
    if whole == n {
        return;
    }
    let (mut vy, mut vx, mut o) = ([0.0; LANES], [1.0; LANES], [0.0; LANES]);
    vy[..n - whole].copy_from_slice(&y[whole..]);
    vx[..n - whole].copy_from_slice(&x[whole..]);
    atan2_lanes(&vy, &vx, &mut o);
    out[whole..].copy_from_slice(&o[..n - whole]);
}

/// [`atan2_into`] of one vector's worth of values (`y`, `x`, `out` of length [`LANES`]).
#[inline(always)]
fn atan2_lanes(y: &[f64], x: &[f64], out: &mut [f64]) {
    let vy: [f64; LANES] = core::array::from_fn(|k| y[k]);
    let vx: [f64; LANES] = core::array::from_fn(|k| x[k]);
    let a = f64x4::from(vy).atan2(f64x4::from(vx)).to_array();
    for k in 0..LANES {
        out[k] = if vy[k].is_finite() && vx[k].is_finite() {
            a[k]
        } else {
            math::atan2(vy[k], vx[k])
        };
    }
}
