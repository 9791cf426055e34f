//! The filter's model of a part from the part's figures (`imu_core::fusion::process_noise`):
//! the closed forms of each term, and the simulator's own readings — their white noise's
//! variance per sample and their drift's variance growth — matching the PSDs the filter is told.
use imu_core::fusion::process_noise::{FLICKER_FLOOR, eskf_noise, triad_psd};
use imu_core::sensor::{
    BiasInstabilityModel, Environment, InlineBuffer, NoiseType, SeededNormals, SensorModel,
    SensorState,
};

type SensorParams = imu_core::sensor::SensorParams<InlineBuffer>;

const FS: f64 = 200.0;

fn close(a: f64, b: f64, what: &str) {
    assert!((a / b - 1.0).abs() < 1e-12, "{what}: {a} against {b}");
}

#[test]
fn each_term_has_its_closed_form() {
    let white = SensorParams {
        noise_density: [1e-3, -3e-3, 2e-3],
        ..SensorParams::default()
    };
    // The worst axis; single-sided: σ_d = N√fs, √q = N; double-sided: N/√2.
    close(triad_psd(&white, FS).0, 3e-3, "white, single-sided");
    let double = SensorParams {
        noise_type: NoiseType::DoubleSided,
        ..white.clone()
    };
    close(
        triad_psd(&double, FS).0,
        3e-3 / 2f64.sqrt(),
        "white, double-sided",
    );
    // Quantisation r: r²/12 per sample.
    let quantised = SensorParams {
        resolution: 0.01,
        ..white.clone()
    };
    close(
        triad_psd(&quantised, FS).0,
        (9e-6 + 1e-4 / 12.0 / FS).sqrt(),
        "quantisation",
    );
    // Random walk K: √q = K single-sided, K√2 double-sided.
    let walk = SensorParams {
        random_walk: [0.0, 4e-5, 0.0],
        ..SensorParams::default()
    };
    close(triad_psd(&walk, FS).1, 4e-5, "random walk");
    let walk_double = SensorParams {
        noise_type: NoiseType::DoubleSided,
        ..walk.clone()
    };
    close(
        triad_psd(&walk_double, FS).1,
        4e-5 * 2f64.sqrt(),
        "random walk, double-sided",
    );
    // Bias instability B: MATLAB's default filter 1/(1 − 0.5 z⁻¹) has gain 2 at 0 Hz.
    let b = 5e-4;
    let matlab = SensorParams {
        bias_instability: [b; 3],
        ..SensorParams::default()
    };
    close(
        triad_psd(&matlab, FS).0,
        (2.0 * b) / FS.sqrt(),
        "MATLAB's filter",
    );
    let markov = SensorParams {
        bias_instability: [b; 3],
        bias_instability_model: BiasInstabilityModel::GaussMarkov {
            correlation_time_s: 50.0,
        },
        ..SensorParams::default()
    };
    close(
        triad_psd(&markov, FS).1,
        (2.0 * b * b / 50.0).sqrt(),
        "Gauss–Markov",
    );
    let flicker = SensorParams {
        bias_instability: [b; 3],
        bias_instability_model: BiasInstabilityModel::Flicker {
            tau_min_s: 1.0,
            tau_max_s: 100.0,
        },
        ..SensorParams::default()
    };
    // A random walk's Allan deviation √(qτ/3) meets the floor 0.664·B at τ = 10 s.
    let q = triad_psd(&flicker, FS).1.powi(2);
    close((q * 10.0 / 3.0).sqrt(), FLICKER_FLOOR * b, "flicker");
    assert!((FLICKER_FLOOR - (2.0 * 2f64.ln() / std::f64::consts::PI).sqrt()).abs() < 1e-15);
    // Both triads.
    let n = eskf_noise(&white, &walk, FS);
    assert_eq!(
        [n.accel_psd, n.accel_bias_psd, n.gyro_psd, n.gyro_bias_psd],
        [triad_psd(&white, FS).0, 0.0, 0.0, triad_psd(&walk, FS).1]
    );
}

/// `count` readings at rest (zero input) of a triad with parameters `p`.
fn readings(p: &SensorParams, count: usize, seed: u64) -> Vec<[f64; 3]> {
    let model = SensorModel::new(p, FS).unwrap();
    let mut state = SensorState::default();
    let mut noise = SeededNormals::for_run(seed, 0);
    let env = Environment::default();
    (0..count)
        .map(|_| model.measure([0.0; 3], &env, &mut state, &mut noise))
        .collect()
}

#[test]
fn the_simulators_noise_has_the_psds_the_filter_is_told() {
    let n = 200_000;
    // White, double-sided: the variance per sample is q·fs.
    let white = SensorParams {
        noise_density: [2e-3; 3],
        noise_type: NoiseType::DoubleSided,
        ..SensorParams::default()
    };
    let (psd, _) = triad_psd(&white, FS);
    let r = readings(&white, n, 3);
    let var = r.iter().map(|x| x[0] * x[0]).sum::<f64>() / n as f64;
    // The sample variance of n normals is within 4·√(2/n) (1.3 %) of the truth.
    let tol = 4.0 * (2.0 / n as f64).sqrt();
    assert!(
        (var / (psd * psd * FS) - 1.0).abs() < tol,
        "white: {var} against {}",
        psd * psd * FS
    );
    // A random walk: the variance of one sample's step is q/fs.
    let walk = SensorParams {
        random_walk: [3e-4; 3],
        ..SensorParams::default()
    };
    let (_, drift) = triad_psd(&walk, FS);
    let r = readings(&walk, n, 4);
    let steps = r
        .windows(2)
        .map(|w| (w[1][1] - w[0][1]).powi(2))
        .sum::<f64>()
        / (n - 1) as f64;
    assert!(
        (steps / (drift * drift / FS) - 1.0).abs() < tol,
        "random walk: {steps} against {}",
        drift * drift / FS
    );
}
