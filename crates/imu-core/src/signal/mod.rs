//! A sensor's signal chain: what a MEMS part does between its transducer and its output
//! register. It samples at an internal rate, filters digitally (a low-pass, [`LowPass`], as data
//! sheets describe it) and keeps every `M`-th sample (decimation to the output rate); whatever
//! the filter lets through above the output's Nyquist frequency folds into the band (aliasing),
//! and the filter delays what it passes ([`Chain::group_delay_s`]).
//!
//! A [`Chain`] is the validated design, a cascade of at most [`MAX_SECTIONS`] rational sections
//! `b(z⁻¹)/a(z⁻¹)` run in transposed direct form II; [`ChainState`] holds each axis's memory,
//! so one chain serves many runs. The response (gain, phase, group delay) is computed in closed
//! form from the same coefficients that filter ([`Chain::response`]).
//!
//! Coefficients and memory live in a [`FilterBuffer`] as the sensor model's do: the core's
//! [`InlineBuffer`] holds up to 8 coefficients per section (a Butterworth of order 8, short
//! averages); a crate with a heap supplies a longer buffer for long averages and FIR filters.
mod buffer;
mod design;
mod response;

pub use buffer::{FilterBuffer, InlineBuffer, MAX_FILTER_COEFFICIENTS};
pub use design::LowPass;
pub use response::Response;

use core::fmt;

/// Most rational sections a chain's filter has (a Butterworth low-pass of order 2·this).
pub const MAX_SECTIONS: usize = 4;

/// Why a chain cannot be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SignalError {
    /// A rate or frequency that is not a finite number > 0.
    NotPositive {
        /// What it is.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// The internal rate is not a whole multiple of the output rate.
    NotWholeMultiple {
        /// The internal rate, Hz.
        internal_rate_hz: f64,
        /// The output rate, Hz.
        output_rate_hz: f64,
    },
    /// A low-pass cutoff at or above the internal rate's Nyquist frequency.
    CutoffAboveNyquist {
        /// The cutoff, Hz.
        cutoff_hz: f64,
        /// Half the internal rate, Hz.
        nyquist_hz: f64,
    },
    /// A filter order or a number of taps outside what the chain holds.
    BadLength {
        /// What it is (`order`, `taps`, `coefficients`).
        field: &'static str,
        /// The value.
        value: usize,
        /// The most the chain takes.
        max: usize,
    },
    /// A coefficient that is not finite, a leading denominator coefficient of zero, or a
    /// filter whose gain at zero frequency is zero or not finite.
    BadCoefficients {
        /// What is wrong.
        reason: &'static str,
    },
}

impl fmt::Display for SignalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotPositive { field, value } => {
                write!(f, "{field} must be a finite number > 0, got {value}")
            }
            Self::NotWholeMultiple {
                internal_rate_hz,
                output_rate_hz,
            } => write!(
                f,
                "the internal rate {internal_rate_hz} Hz is not a whole multiple of the output \
                 rate {output_rate_hz} Hz: the chain keeps every M-th internal sample"
            ),
            Self::CutoffAboveNyquist {
                cutoff_hz,
                nyquist_hz,
            } => write!(
                f,
                "cutoff_hz {cutoff_hz} must lie below half the internal rate ({nyquist_hz} Hz)"
            ),
            Self::BadLength { field, value, max } => {
                write!(f, "{field} must be from 1 to {max}, got {value}")
            }
            Self::BadCoefficients { reason } => f.write_str(reason),
        }
    }
}

impl core::error::Error for SignalError {}

/// One rational section `b(z⁻¹)/a(z⁻¹)`, `a₀ = 1`, `b` and `a` of equal length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section<B: FilterBuffer = InlineBuffer> {
    b: B,
    a: B,
}

impl<B: FilterBuffer> Section<B> {
    /// The section `numerator / denominator` (normalised to `a₀ = 1`, the shorter list padded
    /// with zeros).
    ///
    /// # Errors
    /// Empty or too long lists, values that are not finite, `a₀ = 0`.
    pub fn new(numerator: &[f64], denominator: &[f64]) -> Result<Self, SignalError> {
        let len = numerator.len().max(denominator.len());
        if numerator.is_empty() || denominator.is_empty() || len > B::CAPACITY {
            return Err(SignalError::BadLength {
                field: "coefficients",
                value: len,
                max: B::CAPACITY,
            });
        }
        if numerator.iter().chain(denominator).any(|c| !c.is_finite()) {
            return Err(SignalError::BadCoefficients {
                reason: "the filter's coefficients must be finite numbers",
            });
        }
        let a0 = denominator[0];
        if a0 == 0.0 {
            return Err(SignalError::BadCoefficients {
                reason: "the filter's leading denominator coefficient must not be 0",
            });
        }
        let too_long = SignalError::BadLength {
            field: "coefficients",
            value: len,
            max: B::CAPACITY,
        };
        let (mut b, mut a) = (
            B::zeros(len).ok_or(too_long)?,
            B::zeros(len).ok_or(too_long)?,
        );
        for (to, from) in b.as_mut_slice().iter_mut().zip(numerator) {
            *to = from / a0;
        }
        for (to, from) in a.as_mut_slice().iter_mut().zip(denominator) {
            *to = from / a0;
        }
        Ok(Self { b, a })
    }

    /// The numerator, `a₀ = 1` scale.
    #[must_use]
    pub fn numerator(&self) -> &[f64] {
        self.b.as_slice()
    }

    /// The denominator, `a₀ = 1`.
    #[must_use]
    pub fn denominator(&self) -> &[f64] {
        self.a.as_slice()
    }

    /// The gain at zero frequency, `Σb / Σa`.
    fn dc_gain(&self) -> f64 {
        self.b.as_slice().iter().sum::<f64>() / self.a.as_slice().iter().sum::<f64>()
    }

    /// The memory (`len − 1` values) this section holds after a constant input `x` forever.
    fn settle(&self, x: f64, z: &mut [f64]) {
        let (b, a) = (self.b.as_slice(), self.a.as_slice());
        let y = self.dc_gain() * x;
        // Transposed direct form II at rest: z[k−1] = Σ_{i ≥ k} (b_i x − a_i y).
        let mut acc = 0.0;
        for k in (1..b.len()).rev() {
            acc += b[k] * x - a[k] * y;
            if let Some(zk) = z.get_mut(k - 1) {
                *zk = acc;
            }
        }
    }
}

/// A validated signal chain: internal rate, low-pass sections and the decimation to the output
/// rate.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain<B: FilterBuffer = InlineBuffer> {
    internal_rate_hz: f64,
    decimation: usize,
    sections: [Section<B>; MAX_SECTIONS],
    count: usize,
}

impl<B: FilterBuffer> Chain<B> {
    /// A part sampling at `internal_rate_hz`, filtering with `low_pass` and writing every
    /// `internal_rate_hz / output_rate_hz`-th filtered sample.
    ///
    /// # Errors
    /// Rates that are not finite and positive, an internal rate that is not a whole multiple of
    /// the output rate (within 1e-9), a filter the chain cannot hold or whose gain at zero
    /// frequency is not finite and non-zero.
    pub fn new(
        internal_rate_hz: f64,
        output_rate_hz: f64,
        low_pass: &LowPass<'_>,
    ) -> Result<Self, SignalError> {
        for (field, value) in [
            ("internal_rate_hz", internal_rate_hz),
            ("output_rate_hz", output_rate_hz),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SignalError::NotPositive { field, value });
            }
        }
        let ratio = internal_rate_hz / output_rate_hz;
        let decimation = crate::math::round(ratio);
        if decimation < 1.0 || crate::math::abs(ratio - decimation) > 1e-9 * ratio {
            return Err(SignalError::NotWholeMultiple {
                internal_rate_hz,
                output_rate_hz,
            });
        }
        let mut chain = Self {
            internal_rate_hz,
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            decimation: decimation as usize,
            sections: Default::default(),
            count: 0,
        };
        design::sections(low_pass, internal_rate_hz, &mut |section| {
            let slot = chain
                .sections
                .get_mut(chain.count)
                .ok_or(SignalError::BadLength {
                    field: "sections",
                    value: chain.count + 1,
                    max: MAX_SECTIONS,
                })?;
            *slot = section;
            chain.count += 1;
            Ok(())
        })?;
        let dc = chain.dc_gain();
        if !(dc.is_finite() && dc != 0.0) {
            return Err(SignalError::BadCoefficients {
                reason: "the filter's gain at zero frequency must be finite and not 0",
            });
        }
        Ok(chain)
    }

    /// The internal sampling rate, Hz.
    #[must_use]
    pub fn internal_rate_hz(&self) -> f64 {
        self.internal_rate_hz
    }

    /// The output rate, Hz.
    #[must_use]
    pub fn output_rate_hz(&self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let m = self.decimation as f64;
        self.internal_rate_hz / m
    }

    /// Internal samples per output sample.
    #[must_use]
    pub fn decimation(&self) -> usize {
        self.decimation
    }

    /// The filter's sections.
    #[must_use]
    pub fn sections(&self) -> &[Section<B>] {
        &self.sections[..self.count]
    }

    /// The filter's gain at zero frequency.
    #[must_use]
    pub fn dc_gain(&self) -> f64 {
        self.sections().iter().map(Section::dc_gain).product()
    }

    /// The filter's response at `f_hz` (any frequency; the response repeats every internal
    /// rate).
    #[must_use]
    pub fn response(&self, f_hz: f64) -> Response {
        response::of_sections(self.sections(), f_hz / self.internal_rate_hz)
    }

    /// The filter's group delay at `f_hz`, s: `−dφ/dω`, in closed form from the coefficients.
    #[must_use]
    pub fn group_delay_s(&self, f_hz: f64) -> f64 {
        response::group_delay_samples(self.sections(), f_hz / self.internal_rate_hz)
            / self.internal_rate_hz
    }

    /// The frequency at which a sine of `f_hz` appears in the output (in `[0, output rate / 2]`).
    #[must_use]
    pub fn alias_hz(&self, f_hz: f64) -> f64 {
        let fs = self.output_rate_hz();
        let folded = f_hz - fs * crate::math::round(f_hz / fs);
        crate::math::abs(folded)
    }

    /// Filters one internal sample `x` (three axes) and returns the output sample when this one
    /// is kept: the first sample after [`ChainState::settled`] is, then every
    /// [`Self::decimation`]-th.
    pub fn push(&self, state: &mut ChainState<B>, x: [f64; 3]) -> Option<[f64; 3]> {
        let mut v = x;
        for (s, memory) in self.sections().iter().zip(&mut state.memory) {
            let (b, a) = (s.b.as_slice(), s.a.as_slice());
            for (axis, z) in memory.iter_mut().enumerate() {
                v[axis] = iir_step(b, a, v[axis], z.as_mut_slice());
            }
        }
        let kept = state.phase == 0;
        state.phase = (state.phase + 1) % self.decimation;
        kept.then_some(v)
    }
}

/// A chain's memory: each section's, per axis, and where the decimation stands.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChainState<B: FilterBuffer = InlineBuffer> {
    memory: [[B; 3]; MAX_SECTIONS],
    phase: usize,
}

impl<B: FilterBuffer> ChainState<B> {
    /// The state of `chain` after the constant input `x0` forever (no start-up transient), the
    /// next sample kept.
    #[must_use]
    pub fn settled(chain: &Chain<B>, x0: [f64; 3]) -> Self {
        let mut state = Self::default();
        let mut v = x0;
        for (s, memory) in chain.sections().iter().zip(&mut state.memory) {
            for (axis, z) in memory.iter_mut().enumerate() {
                *z = B::zeros(s.b.as_slice().len().saturating_sub(1)).unwrap_or_default();
                s.settle(v[axis], z.as_mut_slice());
                v[axis] *= s.dc_gain();
            }
        }
        state
    }
}

/// One step of `filter(b, a, ·)` in transposed direct form II (`b`, `a` of equal length,
/// `a₀ = 1`) with memory `z` (`len − 1` values; a shorter memory shortens the filter).
#[inline]
pub(crate) fn iir_step(b: &[f64], a: &[f64], x: f64, z: &mut [f64]) -> f64 {
    let n = b.len().min(a.len()).min(z.len() + 1);
    if n == 0 {
        return 0.0;
    }
    let y = b[0] * x + if n > 1 { z[0] } else { 0.0 };
    for k in 1..n {
        let next = if k + 1 < n { z[k] } else { 0.0 };
        z[k - 1] = b[k] * x + next - a[k] * y;
    }
    y
}
