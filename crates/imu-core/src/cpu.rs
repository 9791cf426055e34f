//! Wider vector instructions chosen at run time, with the same numbers.
//!
//! The crate is built for its target's baseline (on x86-64, SSE2: two `f64` lanes to a register),
//! so one build runs on every CPU of the target. On x86-64, a few hot loops are compiled a second
//! time with AVX2 enabled (four lanes, three-operand instructions) and that copy runs when the
//! CPU has AVX2, which is checked once per process with the `cpufeatures` crate (the CPU's
//! `cpuid` and the operating system's saving of the 256-bit registers):
//!
//! * the sine and cosine kernel, [`crate::trig::sin_cos_into`], written with AVX2's own
//!   instructions (`wide`'s four-lane type is two SSE2 registers in a baseline build): 3.3 → 2.0
//!   ns a value (`cargo bench -p imu-benches --bench truth -- sin_cos`);
//! * what a caller passes to [`with_avx2`], compiled for AVX2 by the compiler itself: the sensor
//!   model's block loop ([`crate::sensor::ImuModel::measure_many`]), whose scalar code gains
//!   from AVX's three-operand instructions.
//!
//! Together they took the formula job into one array from 6.0 to 6.5–6.8 M samples/s on one
//! thread (`cargo bench -p imu-benches --bench pipeline -- into_array`, which times both copies
//! in one run). Compiling the compiled formulas' and the truth stepper's loops for AVX2 the same
//! way was tried and gained nothing measurable, so they run as built.
//!
//! **Same numbers.** Fused multiply-add is not enabled, and Rust never fuses or reorders
//! floating-point operations on its own, so both copies do the same IEEE operations in the same
//! order: results are identical bit for bit on every x86-64 CPU, with or without AVX2
//! (`tests/trig.rs`, `tests/sensor.rs` and `imukit`'s `tests/compiled_formulas.rs` run both
//! copies and compare every bit). A build for a newer CPU (`-C target-cpu=…`) has AVX2
//! throughout and no second copy; where that CPU has FMA, `wide`'s arctangent fuses its
//! multiply-adds and its results can differ within [`crate::trig::MAX_ULP`].
//!
//! This module and [`crate::trig`]'s dispatch are the crate's only `unsafe` code: calling a
//! function compiled for AVX2 is sound only where the CPU has it, and each call sits right after
//! the check.

#[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
cpufeatures::new!(avx2_cpuid, "avx2");

/// Whether the AVX2 copies may run ([`allow_avx2`]).
#[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
static AVX2_ALLOWED: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(true);

/// Allows (the default) or forbids the AVX2 copies in this process, for every thread from the
/// next call on. The numbers are the same either way; this is for timing the two copies against
/// each other and for the tests that compare them. Does nothing where there is no second copy
/// (other architectures, or a build for AVX2).
pub fn allow_avx2(allowed: bool) {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    AVX2_ALLOWED.store(allowed, core::sync::atomic::Ordering::Relaxed);
    #[cfg(not(all(target_arch = "x86_64", not(target_feature = "avx2"))))]
    let _ = allowed;
}

/// Whether the AVX2 copies run: x86-64 with AVX2 that the operating system enables, unless
/// [`allow_avx2`]`(false)`. Always `true` in a build for AVX2, always `false` on other
/// architectures.
#[inline]
#[must_use]
pub fn avx2_in_use() -> bool {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    {
        AVX2_ALLOWED.load(core::sync::atomic::Ordering::Relaxed) && avx2_cpuid::get()
    }
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        true
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Work for [`with_avx2`]: a value holding its inputs, whose [`Work::run`] does the work.
///
/// Mark the implementation of `run` `#[inline(always)]`: the AVX2 copy covers what the compiler
/// inlines into it, and the attribute makes sure it does (a closure would be left to the
/// compiler's judgement, which declined for the sensor model's loop).
pub trait Work {
    /// What the work returns.
    type Output;
    /// Does the work.
    fn run(self) -> Self::Output;
}

/// `work.run()`, compiled with AVX2 enabled when it is in use ([`avx2_in_use`]), else as built.
/// Same result either way, bit for bit (see the module's documentation).
#[inline(always)]
pub fn with_avx2<W: Work>(work: W) -> W::Output {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    if avx2_in_use() {
        #[target_feature(enable = "avx2")]
        fn avx2<W: Work>(work: W) -> W::Output {
            work.run()
        }
        // SAFETY: the CPU has AVX2 and the operating system saves its registers (checked just
        // above by `cpufeatures`).
        #[allow(unsafe_code)]
        return unsafe { avx2(work) };
    }
    work.run()
}
