//! The fixes' noise scaled from their innovations: a receiver worse than its stated accuracy
//! (multipath in a city, a data sheet's open-sky figure) shows as innovations larger than the
//! filter predicts. Every [`ADAPT_WINDOW`] fixes the normalised innovations squared (NIS) of
//! the window — accepted and rejected alike — are averaged per degree of freedom; when that
//! mean lies outside the two-sided 99 % range of a consistent filter's (χ² of the window's
//! degrees of freedom), the fixes' noise variance is multiplied by it, kept between 1 (the
//! stated accuracy) and the stated bound. The factor applies to each fix's one-sigmas (by its
//! square root) and, with the fix-error states, to the modelled error process
//! (`Eskf::scale_fix_errors`). When the NIS is dominated by the filter's own uncertainty the
//! mean moves less than the true factor; the next windows continue the correction. A window
//! of [`ADAPT_WINDOW`] fixes is shorter than the run of rejections that resets the filter
//! ([`MAX_REJECTED_IN_A_ROW`](super::MAX_REJECTED_IN_A_ROW)), so a receiver several times
//! worse than stated is scaled before the filter gives up on it.
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Fixes per window.
pub const ADAPT_WINDOW: usize = 8;

/// The default bound of the variance factor: one-sigmas at most five times the stated ones.
pub const DEFAULT_MAX_FIX_NOISE_SCALE: f64 = 25.0;

/// The running scale of the fixes' noise.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FixNoiseScale {
    max: f64,
    scale: f64,
    nis: f64,
    dof: usize,
    fixes: usize,
}

impl FixNoiseScale {
    /// A scale of 1 bounded by `max` (≥ 1; 1: off).
    pub(crate) fn new(max: f64) -> Self {
        Self {
            max: max.max(1.0),
            scale: 1.0,
            nis: 0.0,
            dof: 0,
            fixes: 0,
        }
    }

    /// The variance factor now.
    pub(crate) fn scale(&self) -> f64 {
        self.scale
    }

    /// Takes one fix's NIS over `dof` rows; at the end of a window, the factor by which the
    /// scale changed (`None`: unchanged).
    pub(crate) fn observe(&mut self, nis: f64, dof: usize) -> Option<f64> {
        if self.max <= 1.0 || !nis.is_finite() {
            return None;
        }
        self.nis += nis;
        self.dof += dof;
        self.fixes += 1;
        if self.fixes < ADAPT_WINDOW {
            return None;
        }
        #[allow(clippy::cast_precision_loss)]
        let mean = self.nis / self.dof as f64;
        let (lo, hi) = chi2_range_99(self.dof);
        (self.nis, self.dof, self.fixes) = (0.0, 0, 0);
        if (lo..=hi).contains(&mean) {
            return None;
        }
        let next = (self.scale * mean).clamp(1.0, self.max);
        let change = next / self.scale;
        self.scale = next;
        (change != 1.0).then_some(change)
    }
}

/// χ²'s two-sided 99 % range over its degrees of freedom `dof`: the range of a consistent
/// window's mean NIS per degree of freedom.
fn chi2_range_99(dof: usize) -> (f64, f64) {
    #[allow(clippy::cast_precision_loss)]
    let k = dof.max(1) as f64;
    match ChiSquared::new(k) {
        Ok(chi) => (chi.inverse_cdf(0.005) / k, chi.inverse_cdf(0.995) / k),
        Err(_) => (0.0, f64::INFINITY),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_range_is_chi_squares() {
        // χ²_{0.005}(48) = 26.511, χ²_{0.995}(48) = 76.969 (scipy.stats.chi2.ppf).
        let (lo, hi) = chi2_range_99(48);
        assert!((lo * 48.0 - 26.511).abs() < 1e-3, "{lo}");
        assert!((hi * 48.0 - 76.969).abs() < 1e-3, "{hi}");
    }

    #[test]
    fn a_window_too_large_scales_up_within_the_bound_and_back_down_to_one() {
        let mut s = FixNoiseScale::new(25.0);
        let mut changes = Vec::new();
        for _ in 0..ADAPT_WINDOW {
            changes.push(s.observe(9.0 * 6.0, 6));
        }
        assert_eq!(changes.iter().flatten().count(), 1);
        assert!((s.scale() - 9.0).abs() < 1e-12);
        for _ in 0..ADAPT_WINDOW {
            s.observe(10.0 * 6.0, 6);
        }
        assert_eq!(s.scale(), 25.0);
        for _ in 0..4 * ADAPT_WINDOW {
            s.observe(0.1 * 6.0, 6);
        }
        assert_eq!(s.scale(), 1.0);
        // A consistent window changes nothing; a bound of 1 is off.
        let mut s = FixNoiseScale::new(25.0);
        for _ in 0..ADAPT_WINDOW {
            assert_eq!(s.observe(6.0, 6), None);
        }
        let mut off = FixNoiseScale::new(1.0);
        for _ in 0..ADAPT_WINDOW {
            assert_eq!(off.observe(600.0, 6), None);
        }
    }
}
