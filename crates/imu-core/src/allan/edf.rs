//! Equivalent degrees of freedom of the overlapping Allan variance, by Greenhall's algorithm
//! (C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
//! differences", PTTI 2003; the computation IEEE Std 1139 and Stable32 use).
//!
//! An estimate `σ̂²(τ)` from a record is distributed as `σ²(τ)·χ²_ν/ν`; `ν` depends on the noise
//! type, given by the exponent `α` of the rate's power spectral density `S(f) ∝ f^α` — white rate
//! noise (angle random walk) α = 0, flicker (bias instability) α = −1, rate random walk α = −2,
//! and white noise of the angle (quantisation) α = +2. In Greenhall's terms the overlapping Allan
//! variance is the unmodified (`F = m`), fully overlapped (`S = m`) variance of the second
//! difference (`d = 2`); `N` counts the integrated (phase) points.

use crate::math;

/// The largest sum computed term by term; longer records use Greenhall's asymptotic tables.
const J_MAX: usize = 100;

/// Greenhall's `sw(t)` (his eq. 7) for PSD exponent `alpha` (−4 … 2).
fn sw(t: f64, alpha: i32) -> f64 {
    let a = math::abs(t);
    let t_log = |power: i32| {
        if t == 0.0 {
            0.0
        } else {
            num_traits::Float::powi(t, power) * math::ln(a)
        }
    };
    match alpha {
        2 => -a,
        1 => t_log(2),
        0 => a * a * a,
        -1 => t_log(4),
        -2 => num_traits::Float::powi(a, 5),
        -3 => t_log(6),
        _ => num_traits::Float::powi(a, 7),
    }
}

/// `sx(t)` (eq. 8): the second difference of `sw` at step `1/F`; `F = ∞` as `None`.
fn sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
    }
}

/// `sz(t)` (eq. 9) for the second difference (`d = 2`).
fn sz(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    6.0 * sx(t, f, alpha) - 4.0 * sx(t - 1.0, f, alpha) - 4.0 * sx(t + 1.0, f, alpha)
        + sx(t - 2.0, f, alpha)
        + sx(t + 2.0, f, alpha)
}

/// The basic sum (eq. 10).
fn basic_sum(j: usize, m: f64, s: f64, f: Option<f64>, alpha: i32) -> f64 {
    let jf = j as f64;
    let first = num_traits::Float::powi(sz(0.0, f, alpha), 2);
    let second = (1.0 - jf / m) * num_traits::Float::powi(sz(jf / s, f, alpha), 2);
    let third: f64 = (1..j)
        .map(|i| {
            let i = i as f64;
            2.0 * (1.0 - i / m) * num_traits::Float::powi(sz(i / s, f, alpha), 2)
        })
        .sum();
    first + second + third
}

/// Greenhall's table 2 (`d = 2`): `(a0, a1)` of the asymptotic `1/edf = (a0 − a1/r)/r`.
fn table2(alpha: i32) -> (f64, f64) {
    match alpha {
        2 => (35.0 / 18.0, 1.0),
        1 => (790.0, 410.0),
        0 => (2.0 / 3.0, 1.0 / 3.0),
        -1 => (0.852, 0.375),
        _ => (1.079, 0.368),
    }
}

/// Equivalent degrees of freedom of the overlapping Allan variance at cluster size `m` from `n`
/// integrated points, for rate noise of PSD exponent `alpha` (2, 0, −1 or −2; other values are
/// taken as the nearest of these). `None` when `m` leaves no second difference (`n ≤ 2m`).
#[must_use]
pub fn overlapping_edf(alpha: i32, m: usize, n: usize) -> Option<f64> {
    if m == 0 || n <= 2 * m {
        return None;
    }
    let alpha = match alpha {
        a if a >= 1 => 2,
        0 => 0,
        -1 => -1,
        _ => -2,
    };
    let mf = m as f64;
    // Differences of span 2m: M of them, stride 1 (S = m in units of τ).
    let count = n - 2 * m;
    let big_m = count as f64;
    let s = mf;
    let r = big_m / s;
    if alpha == 2 {
        // White noise of the integral (quantisation), Greenhall's case 4.
        if math::ceil(r) <= 2.0 {
            // Too few clusters for his formula: the simple one of NIST SP 1065, table 5.
            let nf = n as f64;
            return Some((nf + 1.0) * (nf - 2.0 * mf) / (2.0 * (nf - mf)));
        }
        let (a0, a1) = (70.0 / 36.0, 1.0);
        return Some(1.0 / ((a0 - a1 / r) / big_m));
    }
    let j = count.min(3 * m);
    let inv = if j <= J_MAX {
        let f = (3 * m <= J_MAX).then_some(mf);
        basic_sum(j, big_m, s, f, alpha) / (num_traits::Float::powi(sz(0.0, f, alpha), 2) * big_m)
    } else if r > 3.0 {
        let (a0, a1) = table2(alpha);
        (a0 - a1 / r) / r
    } else {
        let jm = J_MAX as f64;
        basic_sum(J_MAX, jm, jm / r, None, alpha)
            / (num_traits::Float::powi(sz(0.0, None, alpha), 2) * jm)
    };
    Some(1.0 / inv)
}

/// The 95 % confidence interval of an Allan deviation `adev` estimated with `edf` degrees of
/// freedom: `σ̂·√(ν/χ²_{ν,0.975})` to `σ̂·√(ν/χ²_{ν,0.025})`. `(adev, adev)` if `edf` is not
/// positive.
#[must_use]
pub fn deviation_interval(adev: f64, edf: f64) -> (f64, f64) {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    match ChiSquared::new(edf) {
        Ok(chi) => (
            adev * math::sqrt(edf / chi.inverse_cdf(0.975)),
            adev * math::sqrt(edf / chi.inverse_cdf(0.025)),
        ),
        Err(_) => (adev, adev),
    }
}

#[cfg(test)]
mod tests {
    use super::overlapping_edf;

    #[test]
    fn white_rate_noise_tends_to_its_asymptote() {
        // For α = 0 and many clusters, 1/edf → (2/3 − 1/(3r))/r with r = (n − 2m)/m.
        let (m, n) = (1000, 10_000_000);
        let r = (n - 2 * m) as f64 / m as f64;
        let expect = r / (2.0 / 3.0 - 1.0 / (3.0 * r));
        let got = overlapping_edf(0, m, n).unwrap();
        assert!((got / expect - 1.0).abs() < 1e-12, "{got} vs {expect}");
    }

    #[test]
    fn the_exact_sum_meets_the_table_where_they_hand_over() {
        // m = 34 is the first size past the exact sum with m' = m; the table takes over for
        // long records, so both must agree where the record is long.
        for alpha in [0, -1, -2] {
            let exact = overlapping_edf(alpha, 33, 2_000_000).unwrap();
            let table = overlapping_edf(alpha, 34, 2_000_000).unwrap() * 34.0 / 33.0;
            assert!(
                (exact / table - 1.0).abs() < 0.03,
                "α = {alpha}: {exact} vs {table}"
            );
        }
    }

    #[test]
    fn no_difference_no_edf() {
        assert_eq!(overlapping_edf(0, 5, 10), None);
        assert_eq!(overlapping_edf(0, 0, 10), None);
        assert!(overlapping_edf(0, 4, 10).unwrap() > 0.0);
    }
}
