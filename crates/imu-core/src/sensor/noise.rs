//! Sources of standard normal numbers for the error models.
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Something that yields independent standard normal numbers.
pub trait NoiseSource {
    /// The next N(0, 1) number.
    fn standard_normal(&mut self) -> f64;

    /// The next `out.len()` numbers, in order: the same numbers as as many calls of
    /// [`Self::standard_normal`].
    fn fill_standard_normal(&mut self, out: &mut [f64]) {
        for o in out {
            *o = self.standard_normal();
        }
    }
}

/// Seeded, portable normals: xoshiro256++ with `rand_distr`'s ziggurat `StandardNormal`.
///
/// The same seed gives the same sequence on every platform and however the run is split into
/// calls. Monte Carlo run `r` of seed `s` uses [`SeededNormals::for_run`]`(s, r)`.
#[derive(Clone, Debug)]
pub struct SeededNormals {
    rng: Xoshiro256PlusPlus,
}

impl SeededNormals {
    /// A stream seeded from `seed` (expanded with SplitMix64).
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self {
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
        }
    }

    /// The stream of Monte Carlo run `run` of `seed`: the seed and the run index are mixed with
    /// SplitMix64's finaliser, so streams of different runs are unrelated and each run's numbers
    /// do not depend on how many runs there are or which thread runs them.
    #[must_use]
    pub fn for_run(seed: u64, run: u64) -> Self {
        Self::new(mix(seed, run))
    }

    /// The stream of another sensor of the same scenario (`stream` ≥ 1; the IMU's own streams
    /// are [`Self::new`] and [`Self::for_run`]), for the single run (`run = None`) or Monte Carlo
    /// run `r`: independent of the IMU's and of each other, and as reproducible.
    #[must_use]
    pub fn for_sensor(seed: u64, run: Option<u64>, stream: u64) -> Self {
        let key = mix(seed, u64::MAX - stream);
        Self::new(mix(key, run.unwrap_or(u64::MAX)))
    }
}

/// SplitMix64's finaliser of `seed` mixed with `index`.
fn mix(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ index.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl NoiseSource for SeededNormals {
    // Always inlined: as a call it was a fifth of the sensor model's time wherever the
    // compiler's heuristics declined to inline it (the Python extension).
    #[inline(always)]
    fn standard_normal(&mut self) -> f64 {
        StandardNormal.sample(&mut self.rng)
    }

    // The generator's state is copied into a local for the loop, so that it lives in registers
    // instead of being stored back through `self` after every number.
    #[inline(always)]
    fn fill_standard_normal(&mut self, out: &mut [f64]) {
        let mut rng = self.rng.clone();
        for o in out {
            *o = StandardNormal.sample(&mut rng);
        }
        self.rng = rng;
    }
}

/// A source of zeros: the deterministic part of a model alone.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoNoise;

impl NoiseSource for NoNoise {
    fn standard_normal(&mut self) -> f64 {
        0.0
    }
}
