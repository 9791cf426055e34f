//! The sensor error model's random parts: each noise type's statistics against theory with
//! tolerances from the sample size, seeded streams, and the fractal (flicker) filter's closed-form
//! impulse response.
use imu_core::sensor::{
    Environment, FilterBuffer, InlineBuffer, NoiseSource, NoiseType, ParamError, SeededNormals,
    SensorModel, SensorState,
};

/// The core's own storage for filters, named once so struct literals need no annotation.
type SensorParams = imu_core::sensor::SensorParams<InlineBuffer>;
type FilterCoefficients = imu_core::sensor::FilterCoefficients<InlineBuffer>;

/// Mean and variance of a sample.
fn moments(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    (
        mean,
        x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0),
    )
}

fn series(params: &SensorParams, rate: f64, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let model = SensorModel::new(params, rate).unwrap();
    let mut state = SensorState::default();
    let mut noise = SeededNormals::new(seed);
    (0..n)
        .map(|_| model.measure([0.0; 3], &Environment::default(), &mut state, &mut noise))
        .collect()
}

#[test]
fn white_noise_standard_deviation_per_noise_type() {
    // σ = N·√β with β = fs (single-sided) or fs/2 (double-sided). For n normal samples the
    // sample variance has relative standard deviation √(2/(n−1)); allow 5 of those.
    let (rate, n) = (200.0, 100_000);
    for (noise_type, beta) in [
        (NoiseType::SingleSided, rate),
        (NoiseType::DoubleSided, rate / 2.0),
    ] {
        let p = SensorParams {
            noise_density: [0.01, 0.02, 0.03],
            noise_type,
            ..SensorParams::default()
        };
        let y = series(&p, rate, n, 11);
        for axis in 0..3 {
            let x: Vec<f64> = y.iter().map(|r| r[axis]).collect();
            let (mean, var) = moments(&x);
            let sigma2 = (p.noise_density[axis] * beta.sqrt()).powi(2);
            let tol = 5.0 * (2.0 / (n as f64 - 1.0)).sqrt();
            assert!(
                (var / sigma2 - 1.0).abs() < tol,
                "{noise_type:?} axis {axis}: {var} vs {sigma2}"
            );
            assert!(mean.abs() < 5.0 * (sigma2 / n as f64).sqrt());
        }
    }
}

#[test]
fn random_walk_variance_grows_linearly() {
    // Var(x_k) = k·K²/β. Over M independent runs the sample variance at step k has relative
    // standard deviation √(2/(M−1)); 3 axes give 3M samples.
    let (rate, k_steps, runs) = (100.0, 400, 3000);
    let k_rw = 0.05;
    let p = SensorParams {
        random_walk: [k_rw; 3],
        ..SensorParams::default()
    };
    let model = SensorModel::new(&p, rate).unwrap();
    let mut at = [Vec::new(), Vec::new()];
    for run in 0..runs {
        let mut state = SensorState::default();
        let mut noise = SeededNormals::for_run(5, run);
        for step in 1..=k_steps {
            let y = model.measure([0.0; 3], &Environment::default(), &mut state, &mut noise);
            if step == k_steps / 4 {
                at[0].extend(y);
            }
            if step == k_steps {
                at[1].extend(y);
            }
        }
    }
    let m = (3 * runs) as f64;
    let tol = 5.0 * (2.0 / (m - 1.0)).sqrt();
    for (samples, k) in at.iter().zip([k_steps / 4, k_steps]) {
        let (_, var) = moments(samples);
        let expected = k as f64 * k_rw * k_rw / rate;
        assert!(
            (var / expected - 1.0).abs() < tol,
            "step {k}: {var} vs {expected}"
        );
    }
}

#[test]
fn bias_instability_with_matlabs_default_filter_has_variance_four_thirds_b_squared() {
    // y_k = 0.5·y_{k−1} + B·n_k is AR(1) with φ = 0.5: Var = B²/(1 − φ²) = 4B²/3. The sample
    // variance of an AR(1) series of length n has relative sd ≈ √(2(1+φ²)/((1−φ²)n)).
    let n = 200_000;
    let b = 0.02;
    let p = SensorParams {
        bias_instability: [b; 3],
        ..SensorParams::default()
    };
    let y = series(&p, 100.0, n, 3);
    let phi2: f64 = 0.25;
    let tol = 5.0 * (2.0 * (1.0 + phi2) / ((1.0 - phi2) * n as f64)).sqrt();
    for axis in 0..3 {
        let x: Vec<f64> = y.iter().map(|r| r[axis]).collect();
        let (_, var) = moments(&x);
        assert!(
            (var / (4.0 * b * b / 3.0) - 1.0).abs() < tol,
            "axis {axis}: {var}"
        );
        // Lag-1 autocorrelation is φ = 0.5.
        let (mean, _) = moments(&x);
        let c1: f64 = x
            .windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / (n as f64 - 1.0);
        assert!(
            (c1 / var - 0.5).abs() < 0.02,
            "axis {axis}: rho1 = {}",
            c1 / var
        );
    }
}

#[test]
fn higher_order_filters_match_a_direct_recursion() {
    let coeffs = FilterCoefficients::new(&[0.5, 0.25, 0.125], &[2.0, -0.4, 0.1, 0.05]).unwrap();
    let p = SensorParams {
        bias_instability: [1.0; 3],
        bias_instability_model: imu_core::sensor::BiasInstabilityModel::Filter(coeffs),
        ..SensorParams::default()
    };
    let model = SensorModel::new(&p, 100.0).unwrap();
    let mut state = SensorState::default();
    let mut noise = SeededNormals::new(9);
    let mut replay = SeededNormals::new(9);
    let (b, a) = ([0.5, 0.25, 0.125], [2.0, -0.4, 0.1, 0.05]);
    let (mut xs, mut ys) = (Vec::<f64>::new(), Vec::<f64>::new());
    for _ in 0..200 {
        let y = model.measure([0.0; 3], &Environment::default(), &mut state, &mut noise)[0];
        let draws: Vec<f64> = (0..9).map(|_| replay.standard_normal()).collect();
        xs.push(draws[0]);
        let n = xs.len() - 1;
        let mut acc = 0.0;
        for (k, bk) in b.iter().enumerate() {
            if n >= k {
                acc += bk * xs[n - k];
            }
        }
        for (k, ak) in a.iter().enumerate().skip(1) {
            if n >= k {
                acc -= ak * ys[n - k];
            }
        }
        ys.push(acc / a[0]);
        assert!((y - ys[n]).abs() < 1e-12, "sample {n}: {y} vs {}", ys[n]);
    }
}

#[test]
fn seeds_give_identical_streams_and_runs_differ() {
    let draw = |mut n: SeededNormals| (0..5).map(|_| n.standard_normal()).collect::<Vec<_>>();
    assert_eq!(draw(SeededNormals::new(1)), draw(SeededNormals::new(1)));
    assert_ne!(
        draw(SeededNormals::for_run(1, 0)),
        draw(SeededNormals::for_run(1, 1))
    );
    assert_eq!(
        draw(SeededNormals::for_run(1, 7)),
        draw(SeededNormals::for_run(1, 7))
    );
}

#[test]
fn filling_a_slice_gives_the_numbers_of_as_many_single_draws_and_the_same_place_after() {
    // Lengths around the block's 216, and 20 000 numbers, which take in draws from the
    // ziggurat's rare slow path.
    for len in [0, 1, 9, 27, 215, 216, 20_000] {
        let mut one = SeededNormals::for_run(5, 3);
        let mut filled = one.clone();
        let singles: Vec<u64> = (0..len).map(|_| one.standard_normal().to_bits()).collect();
        let mut out = vec![f64::NAN; len];
        filled.fill_standard_normal(&mut out);
        let out: Vec<u64> = out.iter().map(|v| v.to_bits()).collect();
        assert!(out == singles, "length {len}: the numbers differ");
        assert_eq!(
            filled.standard_normal().to_bits(),
            one.standard_normal().to_bits(),
            "length {len}: the streams' places afterwards differ"
        );
    }
}

#[test]
fn gauss_markov_bias_has_the_set_standard_deviation_and_correlation_time() {
    // Steady-state variance B²; lag-1 correlation φ = exp(−1/(fs·T)). Start from zero, so skip
    // 10 correlation times; the sample variance of an AR(1) series of length n has relative sd
    // ≈ √(2(1+φ²)/((1−φ²)n)).
    let (fs, t_corr, b) = (50.0, 0.2, 0.03);
    let p = SensorParams {
        bias_instability: [b; 3],
        bias_instability_model: imu_core::sensor::BiasInstabilityModel::GaussMarkov {
            correlation_time_s: t_corr,
        },
        ..SensorParams::default()
    };
    let y = series(&p, fs, 210_000, 21);
    let x: Vec<f64> = y[100..].iter().map(|r| r[1]).collect();
    let phi: f64 = (-1.0 / (fs * t_corr)).exp();
    let (mean, var) = moments(&x);
    let tol = 5.0 * (2.0 * (1.0 + phi * phi) / ((1.0 - phi * phi) * x.len() as f64)).sqrt();
    assert!(
        (var / (b * b) - 1.0).abs() < tol,
        "{var} vs {} (tol {tol})",
        b * b
    );
    let c1: f64 = x
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum::<f64>()
        / (x.len() as f64 - 1.0);
    assert!((c1 / var - phi).abs() < 0.01, "rho1 {} vs {phi}", c1 / var);
    assert!(
        SensorModel::new(
            &SensorParams {
                bias_instability_model: imu_core::sensor::BiasInstabilityModel::GaussMarkov {
                    correlation_time_s: 0.0
                },
                ..SensorParams::default()
            },
            fs
        )
        .is_err()
    );
}

/// A noise source that is 1 on the very first draw and 0 afterwards: the model's output on one
/// axis is then the bias-instability filter's impulse response times `BiasInstability`.
struct Impulse(bool);

impl NoiseSource for Impulse {
    fn standard_normal(&mut self) -> f64 {
        let first = self.0;
        self.0 = false;
        if first { 1.0 } else { 0.0 }
    }
}

/// MATLAB's `fractalcoef(poles)` (Kasdin 1995, eq. 116): `Num = 1`, `Den = [1, a₁, …, a_p]`
/// with `a_k = (k − 1 − α/2)·a_{k−1}/k`, a 1/f^α generator.
fn fractal_denominator(poles: usize, alpha: f64) -> Vec<f64> {
    let mut den = vec![1.0];
    for k in 1..=poles {
        den.push((k as f64 - 1.0 - alpha / 2.0) * den[k - 1] / k as f64);
    }
    den
}

/// Filter storage on the heap, as a crate with `alloc` supplies it (the library crate `imukit`
/// has its own): any length up to 4096.
#[derive(Clone, Debug, Default, PartialEq)]
struct VecBuffer(Vec<f64>);

impl FilterBuffer for VecBuffer {
    const CAPACITY: usize = 4096;
    fn zeros(len: usize) -> Option<Self> {
        (len <= Self::CAPACITY).then(|| Self(vec![0.0; len]))
    }
    fn as_slice(&self) -> &[f64] {
        &self.0
    }
    fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.0
    }
}

/// MATLAB's `fractalcoef(poles)` run through the model with storage `B`: its impulse response
/// equals the moving-average expansion of (1 − z⁻¹)^{−α/2}, h_k = h_{k−1}·(k − 1 + α/2)/k,
/// exactly for k ≤ poles (the truncated AR terms only act beyond the filter's length); later
/// samples follow the recursion with the poles + 1 coefficients.
fn assert_fractal_impulse_response<B: FilterBuffer>(poles: usize, samples: usize) {
    let den = fractal_denominator(poles, 1.0);
    let coeffs = imu_core::sensor::FilterCoefficients::<B>::new(&[1.0], &den).unwrap();
    let p = imu_core::sensor::SensorParams::<B> {
        bias_instability: [2.0; 3],
        bias_instability_model: imu_core::sensor::BiasInstabilityModel::Filter(coeffs),
        ..Default::default()
    };
    let model = SensorModel::new(&p, 100.0).unwrap();
    let mut state = SensorState::default();
    let mut noise = Impulse(true);
    let mut h = vec![1.0_f64];
    for k in 0..samples {
        let y = model.measure([0.0; 3], &Environment::default(), &mut state, &mut noise)[0];
        if k > 0 {
            let next = if k <= poles {
                h[k - 1] * (k as f64 - 0.5) / k as f64
            } else {
                -(1..=poles).map(|j| den[j] * h[k - j]).sum::<f64>()
            };
            h.push(next);
        }
        let want = 2.0 * h[k];
        assert!(
            (y - want).abs() <= 1e-12 * want.abs().max(1e-3),
            "fractalcoef({poles}), sample {k}: {y} vs {want}"
        );
    }
}

#[test]
fn a_fractal_filter_has_the_closed_form_impulse_response() {
    // fractalcoef(7): 8 denominator coefficients, the most the core's inline storage holds.
    assert_fractal_impulse_response::<InlineBuffer>(7, 200);
}

#[test]
fn matlabs_fractalcoef_500_runs_with_heap_storage() {
    // MATLAB's own Allan example: 501 coefficients, memory in the buffer (beyond the inline 32).
    assert_fractal_impulse_response::<VecBuffer>(500, 1500);
    // A filter of 20 coefficients keeps its memory inline: the same closed form.
    assert_fractal_impulse_response::<VecBuffer>(19, 300);
}

#[test]
fn filters_longer_than_the_storage_are_refused_with_the_bound_named() {
    // fractalcoef(500) does not fit the core's inline storage: refused, the flicker model named.
    let den = fractal_denominator(500, 1.0);
    let err = FilterCoefficients::new(&[1.0], &den).unwrap_err();
    assert_eq!(
        err.to_string(),
        "bias_instability_coefficients: 501 coefficients, at most 8 taken (a 1/f floor is the \
         flicker model, at most 16 sections)"
    );
    assert!(FilterCoefficients::new(&[1.0], &den[..8]).is_ok());
    assert!(FilterCoefficients::new(&[1.0], &den[..9]).is_err());
    assert!(FilterCoefficients::new(&[], &den[..2]).is_err());
    let long = imu_core::sensor::FilterCoefficients::<VecBuffer>::new(&[1.0], &vec![1.0; 4097]);
    assert_eq!(
        long.unwrap_err(),
        ParamError::TooManyCoefficients {
            len: 4097,
            max: 4096
        }
    );
}
