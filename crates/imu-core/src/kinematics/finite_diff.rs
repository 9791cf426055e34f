//! Finite-difference derivatives on sampled series, without allocation.
//!
//! * Order 2 reproduces MATLAB `gradient`: central `(x[i+1] − x[i−1]) / (t[i+1] − t[i−1])` inside,
//!   one-sided first-order differences at the ends; the second derivative is the gradient of the
//!   gradient, as the MATLAB trajectory tool computes acceleration.
//! * Orders 4, 6 (default) and 8 use Fornberg weights (B. Fornberg, "Generation of finite
//!   difference formulas on arbitrarily spaced grids", Math. Comp. 51, 1988) on the actual sample
//!   times: centred `order + 1`-point stencils inside, and `order + 4`-point one-sided stencils
//!   near the ends (two more than the order needs, which shrinks their error constants), so both
//!   derivatives keep at least the stated order everywhere. A series needs `order + 4` samples.
//!
//! Series are read through a closure `x(j) -> [f64; D]` so callers can unwrap angles or align
//! quaternion signs locally around the evaluation point.
use crate::kinematics::KinematicsError;

/// The default finite-difference order.
pub const DEFAULT_ORDER: usize = 6;
/// The highest supported order.
pub const MAX_ORDER: usize = 8;
/// Extra points of the one-sided stencils near the ends, beyond the `order + 2` that order needs:
/// they shrink the one-sided error constants, which otherwise dominate second derivatives.
const END_EXTRA: usize = 2;
const MAX_POINTS: usize = MAX_ORDER + 2 + END_EXTRA;

/// Checks `order` and that `n` samples suffice for it.
///
/// # Errors
/// [`KinematicsError::UnsupportedOrder`] or [`KinematicsError::TooFewSamples`].
pub fn check_order(order: usize, n: usize) -> Result<(), KinematicsError> {
    let needed = match order {
        2 => 3,
        4 | 6 | 8 => order + 2 + END_EXTRA,
        _ => return Err(KinematicsError::UnsupportedOrder { order }),
    };
    if n < needed {
        return Err(KinematicsError::TooFewSamples { needed, got: n });
    }
    Ok(())
}

/// Fornberg weights for derivatives 0, 1, 2 at `z` on the points `x` (at most `MAX_POINTS`).
fn fornberg(x: &[f64], z: f64) -> [[f64; 3]; MAX_POINTS] {
    let mut c = [[0.0_f64; 3]; MAX_POINTS];
    let n = x.len();
    c[0][0] = 1.0;
    let mut c1 = 1.0;
    let mut c4 = x[0] - z;
    for i in 1..n {
        let mn = i.min(2);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = x[i] - z;
        for j in 0..i {
            let c3 = x[i] - x[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[i][k] = c1 * (k as f64 * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
                }
                c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
            }
            for k in (1..=mn).rev() {
                c[j][k] = (c4 * c[j][k] - k as f64 * c[j][k - 1]) / c3;
            }
            c[j][0] = c4 * c[j][0] / c3;
        }
        c1 = c2;
    }
    c
}

/// First derivative by MATLAB `gradient` at sample `i`.
fn gradient_at<const D: usize>(t: &[f64], i: usize, x: &impl Fn(usize) -> [f64; D]) -> [f64; D] {
    let n = t.len();
    let (lo, hi) = if i == 0 {
        (0, 1)
    } else if i == n - 1 {
        (n - 2, n - 1)
    } else {
        (i - 1, i + 1)
    };
    let (xl, xh) = (x(lo), x(hi));
    let dt = t[hi] - t[lo];
    core::array::from_fn(|k| (xh[k] - xl[k]) / dt)
}

/// First and second derivatives of the series `x` at sample `i`, with the given order.
///
/// `t` must be strictly increasing and long enough for `order` (see [`check_order`]); callers
/// check once per series. A caller differentiating many samples keeps a [`Stencils`] and calls
/// [`Stencils::derivatives_at`] instead: the same numbers, with the weights of recurring windows
/// computed once.
#[must_use]
pub fn derivatives_at<const D: usize>(
    t: &[f64],
    i: usize,
    order: usize,
    x: impl Fn(usize) -> [f64; D],
) -> ([f64; D], [f64; D]) {
    if order == 2 {
        return gradients_at(t, i, &x);
    }
    let (start, len, offsets) = window(t, i, order);
    combine(&fornberg(&offsets[..len], 0.0), len, start, x)
}

/// Order 2: MATLAB `gradient` and the gradient of the gradient.
fn gradients_at<const D: usize>(
    t: &[f64],
    i: usize,
    x: &impl Fn(usize) -> [f64; D],
) -> ([f64; D], [f64; D]) {
    let first = gradient_at(t, i, x);
    let g = |j: usize| gradient_at(t, j, x);
    (first, gradient_at(t, i, &g))
}

/// The stencil of sample `i` for `order` (4 and above): its first sample, its length and the
/// offsets `t[j] − t[i]` of its samples.
fn window(t: &[f64], i: usize, order: usize) -> (usize, usize, [f64; MAX_POINTS]) {
    let n = t.len();
    let half = order / 2;
    let (start, len) = if i >= half && i + half < n {
        (i - half, order + 1)
    } else if i < half {
        (0, order + 2 + END_EXTRA)
    } else {
        (n - (order + 2 + END_EXTRA), order + 2 + END_EXTRA)
    };
    let mut offsets = [0.0_f64; MAX_POINTS];
    for (k, o) in offsets.iter_mut().enumerate().take(len) {
        *o = t[start + k] - t[i];
    }
    (start, len, offsets)
}

/// Windows whose weights a [`Stencils`] keeps.
const KEPT: usize = 8;

/// The Fornberg weights of the most recent sample windows, kept to be used again.
///
/// The weights are a function of the window's offsets `t[j] − t[i]` alone, so a window whose
/// offsets are bit for bit those of a kept one takes the kept weights: the numbers are the ones
/// computing them again would give. On regular sample times the offsets recur: `k / rate` rounds
/// the same way in long runs, so a million samples at 100 Hz or 2 kHz have about 140 distinct
/// windows, and eight kept ones (replaced oldest first) serve 99.98 % of the samples. Computing
/// the weights was two thirds of the time of truth from sampled positions (about 80 divisions
/// a window).
#[derive(Clone, Debug)]
pub struct Stencils {
    /// The kept windows' offsets, as bits (−0 and +0 are different windows), and lengths.
    offsets: [[u64; MAX_POINTS]; KEPT],
    lens: [usize; KEPT],
    weights: [[[f64; 3]; MAX_POINTS]; KEPT],
    /// Windows kept so far (up to [`KEPT`]), the next one to replace, and the last one used.
    kept: usize,
    next: usize,
    last: usize,
}

impl Default for Stencils {
    fn default() -> Self {
        Self::new()
    }
}

impl Stencils {
    /// A cache with no windows yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            offsets: [[0; MAX_POINTS]; KEPT],
            lens: [0; KEPT],
            weights: [[[0.0; 3]; MAX_POINTS]; KEPT],
            kept: 0,
            next: 0,
            last: 0,
        }
    }

    /// The weights of the window `offsets`: a kept one's, or computed and kept.
    fn weights(&mut self, offsets: &[f64]) -> &[[f64; 3]; MAX_POINTS] {
        let len = offsets.len();
        // The last window used first: consecutive samples often share one. Compared value by
        // value (a comparison of whole arrays was a `memcmp` call, an eighth of the time).
        let same = |e: usize| {
            self.lens[e] == len
                && offsets
                    .iter()
                    .zip(&self.offsets[e])
                    .all(|(o, kept)| o.to_bits() == *kept)
        };
        let found = (0..self.kept)
            .map(|k| (self.last + k) % self.kept)
            .find(|&e| same(e));
        let e = found.unwrap_or_else(|| {
            let e = self.next;
            self.next = (self.next + 1) % KEPT;
            self.kept = (self.kept + 1).min(KEPT);
            for (kept, o) in self.offsets[e].iter_mut().zip(offsets) {
                *kept = o.to_bits();
            }
            self.lens[e] = len;
            self.weights[e] = fornberg(offsets, 0.0);
            e
        });
        self.last = e;
        &self.weights[e]
    }

    /// [`derivatives_at`] with the weights of recurring windows kept.
    #[must_use]
    pub fn derivatives_at<const D: usize>(
        &mut self,
        t: &[f64],
        i: usize,
        order: usize,
        x: impl Fn(usize) -> [f64; D],
    ) -> ([f64; D], [f64; D]) {
        if order == 2 {
            return gradients_at(t, i, &x);
        }
        let (start, len, offsets) = window(t, i, order);
        combine(self.weights(&offsets[..len]), len, start, x)
    }
}

/// The first and second derivatives from the weights `w` of the `len` samples from `start`.
#[inline]
fn combine<const D: usize>(
    w: &[[f64; 3]; MAX_POINTS],
    len: usize,
    start: usize,
    x: impl Fn(usize) -> [f64; D],
) -> ([f64; D], [f64; D]) {
    let mut first = [0.0; D];
    let mut second = [0.0; D];
    for (k, wk) in w.iter().enumerate().take(len) {
        let xk = x(start + k);
        for d in 0..D {
            first[d] += wk[1] * xk[d];
            second[d] += wk[2] * xk[d];
        }
    }
    (first, second)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fornberg_reproduces_the_classic_five_point_stencils() {
        let w = fornberg(&[-2.0, -1.0, 0.0, 1.0, 2.0], 0.0);
        let first = [1.0 / 12.0, -2.0 / 3.0, 0.0, 2.0 / 3.0, -1.0 / 12.0];
        let second = [-1.0 / 12.0, 4.0 / 3.0, -5.0 / 2.0, 4.0 / 3.0, -1.0 / 12.0];
        for k in 0..5 {
            assert!((w[k][1] - first[k]).abs() < 1e-15, "first {k}");
            assert!((w[k][2] - second[k]).abs() < 1e-14, "second {k}");
        }
    }

    #[test]
    fn order_two_is_matlab_gradient_including_the_ends() {
        let t = [0.0, 0.5, 1.5, 3.0];
        let x = [1.0, 2.0, 5.0, 4.0];
        let f = |j: usize| [x[j]];
        let g: [f64; 4] = core::array::from_fn(|i| derivatives_at(&t, i, 2, f).0[0]);
        // MATLAB: gradient([1 2 5 4], [0 .5 1.5 3]) = [2, 8/3, 2/2.5, -2/3]
        let expected = [2.0, 4.0 / 1.5, 2.0 / 2.5, -1.0 / 1.5];
        for i in 0..4 {
            assert!((g[i] - expected[i]).abs() < 1e-15);
        }
        let gg0 = derivatives_at(&t, 0, 2, f).1[0];
        assert!((gg0 - (g[1] - g[0]) / 0.5).abs() < 1e-14);
    }

    #[test]
    fn high_order_stencils_are_exact_on_polynomials_of_their_degree() {
        // Non-uniform grid; order 6 is exact for degree ≤ 6 (first) everywhere.
        let t: [f64; 12] = core::array::from_fn(|k| k as f64 * 0.1 + 0.003 * (k as f64).sin());
        let p = |s: f64| 1.0 + s - 2.0 * s * s + 0.5 * s.powi(3) + s.powi(6);
        let dp = |s: f64| 1.0 - 4.0 * s + 1.5 * s * s + 6.0 * s.powi(5);
        let ddp = |s: f64| -4.0 + 3.0 * s + 30.0 * s.powi(4);
        for i in 0..t.len() {
            let (d1, d2) = derivatives_at(&t, i, 6, |j| [p(t[j])]);
            assert!((d1[0] - dp(t[i])).abs() < 1e-9, "first at {i}");
            assert!((d2[0] - ddp(t[i])).abs() < 1e-7, "second at {i}");
        }
    }

    #[test]
    fn orders_and_lengths_are_checked() {
        assert_eq!(
            check_order(3, 100),
            Err(KinematicsError::UnsupportedOrder { order: 3 })
        );
        assert_eq!(
            check_order(6, 9),
            Err(KinematicsError::TooFewSamples { needed: 10, got: 9 })
        );
        assert!(check_order(6, 10).is_ok());
        assert!(check_order(2, 3).is_ok());
    }
}
