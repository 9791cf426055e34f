//! Sines, cosines and arctangents of many numbers at once, four to a vector register.
//!
//! The exact-truth path takes the sines and cosines of every sample's angles and formula
//! arguments, and the tangent attitude two arctangents: one C-library call each was most of its
//! time (10 ns a call on our machines). These kernels evaluate four values together with the
//! `wide` crate's polynomial `sin_cos` and `atan2` (Agner Fog's vector class library, after
//! Cephes): about 4.8 ns a value on x86-64's SSE2 baseline, against 10.3 ns for glibc's `sincos`
//! and `atan2`.
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
//! and on any number of threads. The kernels are plain IEEE arithmetic (no fused multiply-add on
//! the x86-64 baseline), so unlike the C library's functions, which choose an FMA variant by CPU
//! at run time, a build's results do not depend on the x86-64 CPU that runs it (by construction:
//! nothing is chosen at run time). Built for a CPU with FMA
//! (`-C target-cpu=native`) or for AArch64, `wide` fuses its multiply-adds and results can
//! differ within the bound.
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
/// slices.
pub fn sin_cos_into(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    let n = x.len().min(sin.len()).min(cos.len());
    let (x, sin, cos) = (&x[..n], &mut sin[..n], &mut cos[..n]);
    let whole = n - n % LANES;
    let lanes = x[..whole].chunks_exact(LANES);
    let outs = sin[..whole]
        .chunks_exact_mut(LANES)
        .zip(cos[..whole].chunks_exact_mut(LANES));
    for (v, (s, c)) in lanes.zip(outs) {
        sin_cos_lanes(v, s, c);
    }
    if whole == n {
        return;
    }
    // The last values padded with zeros to a whole vector (fixed-size copies above: a
    // variable-length copy per vector was a `memcpy` call each).
    let mut v = [0.0; LANES];
    v[..n - whole].copy_from_slice(&x[whole..]);
    let (mut s, mut c) = ([0.0; LANES], [0.0; LANES]);
    sin_cos_lanes(&v, &mut s, &mut c);
    sin[whole..].copy_from_slice(&s[..n - whole]);
    cos[whole..].copy_from_slice(&c[..n - whole]);
}

/// [`sin_cos_into`] of one vector's worth of values (`x`, `sin`, `cos` of length [`LANES`]).
#[inline(always)]
fn sin_cos_lanes(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    let v: [f64; LANES] = core::array::from_fn(|k| x[k]);
    let (s, c) = f64x4::from(v).sin_cos();
    let (s, c) = (s.to_array(), c.to_array());
    for k in 0..LANES {
        (sin[k], cos[k]) = if math::abs(v[k]) < SIN_COS_MAX_ARG {
            (s[k], c[k])
        } else {
            math::sin_cos(v[k])
        };
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
