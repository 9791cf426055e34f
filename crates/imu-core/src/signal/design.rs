//! The low-pass filters data sheets describe, as rational sections at the internal rate.
use super::FilterBuffer;
use super::{MAX_SECTIONS, Section, SignalError};

/// A digital low-pass as a data sheet names it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LowPass<'a> {
    /// No filter: every internal sample as it is (decimation alone).
    None,
    /// Butterworth of `order` (1 to 2·[`MAX_SECTIONS`]) with its −3 dB point at `cutoff_hz`,
    /// by the bilinear transform with the cutoff prewarped (the gain at `cutoff_hz` is exactly
    /// `1/√2`); a first order is a one-pole IIR low-pass.
    Butterworth {
        /// Order (poles).
        order: usize,
        /// The −3 dB frequency, Hz.
        cutoff_hz: f64,
    },
    /// The mean of the last `taps` internal samples (a boxcar, "averaging" or "sinc" filter;
    /// zeros at multiples of internal rate / taps).
    MovingAverage {
        /// Samples averaged.
        taps: usize,
    },
    /// A Bartlett (triangular) window: two moving averages of `taps` in a row, `2·taps − 1`
    /// samples long, as ADIS parts' Bartlett filter banks.
    Bartlett {
        /// Samples of each of the two averages.
        taps: usize,
    },
    /// The two figures a data sheet gives for a filter whose structure it does not publish:
    /// the −3 dB `bandwidth_hz` and the `delay_s` (the group delay at zero frequency). Realised
    /// as the one second-order section with a Butterworth denominator and one zero,
    /// `ω_n²(1 + κs)/(s² + √2ω_n s + ω_n²)`, that has both, by the bilinear transform with the
    /// bandwidth prewarped (both figures exact at the internal rate). Between and beyond them
    /// the response is this section's, not the part's.
    BandwidthDelay {
        /// The −3 dB frequency, Hz.
        bandwidth_hz: f64,
        /// The group delay at zero frequency, s (≥ 0).
        delay_s: f64,
    },
    /// A finite impulse response given by its coefficients (`h₀` first), used as given.
    Fir {
        /// The impulse response.
        coefficients: &'a [f64],
    },
    /// A rational filter `b(z⁻¹)/a(z⁻¹)` given by its coefficients.
    Rational {
        /// `b₀ … b_m`.
        numerator: &'a [f64],
        /// `a₀ … a_n`, `a₀ ≠ 0`.
        denominator: &'a [f64],
    },
}

/// Hands each section of `low_pass` at `fs` Hz to `take`, in order.
pub(super) fn sections<B: FilterBuffer>(
    low_pass: &LowPass<'_>,
    fs: f64,
    take: &mut impl FnMut(Section<B>) -> Result<(), SignalError>,
) -> Result<(), SignalError> {
    match *low_pass {
        LowPass::None => Ok(()),
        LowPass::Butterworth { order, cutoff_hz } => butterworth(order, cutoff_hz, fs, take),
        LowPass::MovingAverage { taps } => take(average(taps)?),
        LowPass::Bartlett { taps } => {
            take(average(taps)?)?;
            take(average(taps)?)
        }
        LowPass::BandwidthDelay {
            bandwidth_hz,
            delay_s,
        } => take(bandwidth_delay(bandwidth_hz, delay_s, fs)?),
        LowPass::Fir { coefficients } => take(Section::new(coefficients, &[1.0])?),
        LowPass::Rational {
            numerator,
            denominator,
        } => take(Section::new(numerator, denominator)?),
    }
}

/// The mean of `taps` samples as one section.
fn average<B: FilterBuffer>(taps: usize) -> Result<Section<B>, SignalError> {
    let bad = SignalError::BadLength {
        field: "taps",
        value: taps,
        max: B::CAPACITY,
    };
    if taps == 0 || taps > B::CAPACITY {
        return Err(bad);
    }
    #[allow(clippy::cast_precision_loss)]
    let h = 1.0 / taps as f64;
    let mut b = B::zeros(taps).ok_or(bad)?;
    b.as_mut_slice().fill(h);
    let mut a = B::zeros(taps).ok_or(bad)?;
    a.as_mut_slice()[0] = 1.0;
    Ok(Section { b, a })
}

/// A Butterworth low-pass of `order` with its −3 dB point at `cutoff_hz` at rate `fs`, as
/// first- and second-order sections: the analogue prototype's poles at `ω_c·e^{jθ_k}`,
/// `θ_k = π/2 + (2k + 1)π/(2n)`, paired with their conjugates and mapped by the bilinear
/// transform `s = 2fs·(1 − z⁻¹)/(1 + z⁻¹)`, with `ω_c = 2fs·tan(π f_c/fs)` (prewarped).
fn butterworth<B: FilterBuffer>(
    order: usize,
    cutoff_hz: f64,
    fs: f64,
    take: &mut impl FnMut(Section<B>) -> Result<(), SignalError>,
) -> Result<(), SignalError> {
    if order == 0 || order > 2 * MAX_SECTIONS {
        return Err(SignalError::BadLength {
            field: "order",
            value: order,
            max: 2 * MAX_SECTIONS,
        });
    }
    if !(cutoff_hz.is_finite() && cutoff_hz > 0.0) {
        return Err(SignalError::NotPositive {
            field: "cutoff_hz",
            value: cutoff_hz,
        });
    }
    if cutoff_hz >= fs / 2.0 {
        return Err(SignalError::CutoffAboveNyquist {
            cutoff_hz,
            nyquist_hz: fs / 2.0,
        });
    }
    let c = 2.0 * fs;
    let wc = c * crate::math::tan(core::f64::consts::PI * cutoff_hz / fs);
    #[allow(clippy::cast_precision_loss)]
    let n = order as f64;
    for k in 0..order / 2 {
        #[allow(clippy::cast_precision_loss)]
        let theta = core::f64::consts::FRAC_PI_2
            + (2.0 * k as f64 + 1.0) * core::f64::consts::PI / (2.0 * n);
        // s² + a1·s + ω_c², a1 = −2ω_c·cos θ (> 0: the pole is in the left half plane).
        let a1 = -2.0 * wc * crate::math::cos(theta);
        let w2 = wc * wc;
        let d0 = c * c + a1 * c + w2;
        take(Section::new(
            &[w2, 2.0 * w2, w2],
            &[d0, 2.0 * (w2 - c * c), c * c - a1 * c + w2],
        )?)?;
    }
    if order % 2 == 1 {
        take(Section::new(&[wc, wc], &[c + wc, wc - c])?)?;
    }
    Ok(())
}

/// The section of [`LowPass::BandwidthDelay`] at rate `fs`. With `ω_b = 2fs·tan(πB/fs)` (the
/// bandwidth prewarped) and `y = ω_b/ω_n`, `t = ω_b·τ`, the group delay at zero frequency
/// `√2/ω_n − κ = τ` gives `κω_b = √2y − t`, and `|H(jω_b)|² = 1/2` gives
/// `g(y) = 1 + 2(√2y − t)² − y⁴ = 0`: `g(0) > 0` and `g → −∞`, so a root lies between; the
/// smallest positive one is taken (bisection). The bilinear transform `s = 2fs(1 − z⁻¹)/(1 + z⁻¹)`
/// keeps the gain at `B` and the delay at zero frequency.
fn bandwidth_delay<B: FilterBuffer>(
    bandwidth_hz: f64,
    delay_s: f64,
    fs: f64,
) -> Result<Section<B>, SignalError> {
    if !(bandwidth_hz.is_finite() && bandwidth_hz > 0.0) {
        return Err(SignalError::NotPositive {
            field: "bandwidth_hz",
            value: bandwidth_hz,
        });
    }
    if bandwidth_hz >= fs / 2.0 {
        return Err(SignalError::CutoffAboveNyquist {
            cutoff_hz: bandwidth_hz,
            nyquist_hz: fs / 2.0,
        });
    }
    if !(delay_s.is_finite() && delay_s >= 0.0 && delay_s * fs <= 1e6) {
        return Err(SignalError::BadCoefficients {
            reason: "delay_s must be a finite number ≥ 0 (and at most 10⁶ internal samples)",
        });
    }
    let k = 2.0 * fs;
    let wb = k * crate::math::tan(core::f64::consts::PI * bandwidth_hz / fs);
    let t = wb * delay_s;
    let r2 = core::f64::consts::SQRT_2;
    let g = |y: f64| 1.0 + 2.0 * (r2 * y - t) * (r2 * y - t) - y * y * y * y;
    let mut hi = 1.0;
    while g(hi) >= 0.0 {
        hi *= 2.0;
    }
    // The first sign change on a fine grid, then bisection.
    const STEPS: u32 = 1000;
    let mut lo = 0.0;
    for i in 1..=STEPS {
        let y = hi * f64::from(i) / f64::from(STEPS);
        if g(y) < 0.0 {
            hi = y;
            break;
        }
        lo = y;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let y = 0.5 * (lo + hi);
    let wn = wb / y;
    let kappa = (r2 * y - t) / wb;
    let w2 = wn * wn;
    Section::new(
        &[w2 * (1.0 + kappa * k), 2.0 * w2, w2 * (1.0 - kappa * k)],
        &[
            k * k + r2 * wn * k + w2,
            2.0 * (w2 - k * k),
            k * k - r2 * wn * k + w2,
        ],
    )
}
