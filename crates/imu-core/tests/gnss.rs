//! The GNSS receiver's error model: MATLAB gpsSensor's filter and its statistics, the
//! Gauss–Markov alternative, white velocity noise, parameters named when refused.
use imu_core::aiding::{GnssModel, GnssParams, GnssState, PositionNoise};
use imu_core::sensor::SeededNormals;

fn series(params: &GnssParams, n: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let model = GnssModel::new(params).unwrap();
    let mut state = GnssState::default();
    let mut noise = SeededNormals::new(seed);
    (0..n).map(|_| model.step(&mut state, &mut noise)).unzip()
}

/// Standard deviation and lag-1 autocorrelation of axis `i` of `x`, from sample `skip` on.
fn stats(x: &[[f64; 3]], i: usize, skip: usize) -> (f64, f64) {
    let v: Vec<f64> = x[skip..].iter().map(|r| r[i]).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / n;
    let cov = v
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum::<f64>()
        / (n - 1.0);
    (var.sqrt(), cov / var)
}

#[test]
fn matlabs_decay_factor_sets_the_deviation_and_the_correlation_as_its_filter_does() {
    // x_k = k x_{k−1} + σ√(2(1 − k)) w: stationary deviation σ√(2/(1 + k)), lag-1
    // correlation k. Tolerances: 4 standard errors of the estimates for the effective sample
    // size n(1 − k)/(1 + k).
    let n = 200_000;
    for k in [0.0, 0.5, 0.9] {
        let p = GnssParams {
            horizontal_accuracy_m: 2.0,
            vertical_accuracy_m: 5.0,
            position_noise: PositionNoise::DecayFactor(k),
            ..GnssParams::default()
        };
        let (pos, vel) = series(&p, n, 11);
        let effective = n as f64 * (1.0 - k) / (1.0 + k);
        for (axis, sigma) in [(0, 2.0), (1, 2.0), (2, 5.0)] {
            let (sd, rho) = stats(&pos, axis, 1000);
            let want = sigma * (2.0 / (1.0 + k)).sqrt();
            assert!(
                (sd / want - 1.0).abs() < 4.0 / (2.0 * effective).sqrt(),
                "k = {k}, axis {axis}: {sd} vs {want}"
            );
            // The lag-1 estimate's standard error is about √((1 − k²)/n) (Bartlett).
            let tol = 4.0 * ((1.0 - k * k) / n as f64).sqrt() + 1e-3;
            assert!((rho - k).abs() < tol, "k = {k}: ρ = {rho}");
        }
        let (sd_v, rho_v) = stats(&vel, 0, 0);
        assert!(
            (sd_v / 0.1 - 1.0).abs() < 4.0 / (2.0 * n as f64).sqrt(),
            "{sd_v}"
        );
        assert!(rho_v.abs() < 4.0 / (n as f64).sqrt(), "{rho_v}");
    }
    // k = 1: MATLAB's scaling √(2(1 − k)) is 0, the error stays where it started (0).
    let (pos, _) = series(
        &GnssParams {
            position_noise: PositionNoise::DecayFactor(1.0),
            ..GnssParams::default()
        },
        100,
        3,
    );
    assert!(pos.iter().all(|p| *p == [0.0; 3]));
}

#[test]
fn a_gauss_markov_error_starts_stationary_with_the_set_deviation_and_correlation_time() {
    let p = GnssParams {
        rate_hz: 5.0,
        horizontal_accuracy_m: 1.5,
        vertical_accuracy_m: 3.0,
        position_noise: PositionNoise::GaussMarkov {
            correlation_time_s: 2.0,
        },
        ..GnssParams::default()
    };
    let n = 200_000;
    let (pos, _) = series(&p, n, 5);
    let phi = (-1.0f64 / (5.0 * 2.0)).exp();
    let effective = n as f64 * (1.0 - phi) / (1.0 + phi);
    let (sd, rho) = stats(&pos, 2, 0);
    assert!(
        (sd / 3.0 - 1.0).abs() < 4.0 / (2.0 * effective).sqrt(),
        "{sd}"
    );
    assert!(
        (rho - phi).abs() < 4.0 * ((1.0 - phi * phi) / n as f64).sqrt() + 1e-3,
        "{rho} vs {phi}"
    );
    // Stationary from the first fix: over many receivers, the first error has deviation σ.
    let first: Vec<[f64; 3]> = (0..4000).map(|s| series(&p, 1, 100 + s).0[0]).collect();
    let (sd0, _) = stats(&first, 0, 0);
    assert!(
        (sd0 / 1.5 - 1.0).abs() < 4.0 / (2.0f64 * 4000.0).sqrt(),
        "{sd0}"
    );
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let bad = |p: GnssParams| GnssModel::new(&p).unwrap_err().to_string();
    let d = GnssParams::default();
    assert_eq!(
        bad(GnssParams { rate_hz: 0.0, ..d }),
        "rate_hz must be a finite number > 0, got 0"
    );
    assert_eq!(
        bad(GnssParams {
            horizontal_accuracy_m: -1.0,
            ..d
        }),
        "horizontal_accuracy_m must be a finite number ≥ 0, got -1"
    );
    assert_eq!(
        bad(GnssParams {
            position_noise: PositionNoise::DecayFactor(1.5),
            ..d
        }),
        "decay_factor must be within [0, 1], got 1.5"
    );
    assert_eq!(
        bad(GnssParams {
            position_noise: PositionNoise::GaussMarkov {
                correlation_time_s: f64::NAN
            },
            ..d
        }),
        "correlation_time_s must be a finite number > 0, got NaN"
    );
    assert_eq!(
        bad(GnssParams {
            velocity_accuracy_m_s: f64::INFINITY,
            ..d
        }),
        "velocity_accuracy_m_s must be a finite number ≥ 0, got inf"
    );
}
