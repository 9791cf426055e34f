//! The readings' power spectral density (Welch): white noise of variance σ² at rate fs reads a
//! flat 2σ²/fs (within the estimate's spread, which falls as the square root of the segments);
//! any signal's density integrates to its variance (Parseval, with the Hann window's power
//! taken out); a part shaken above its output's Nyquist frequency shows its peak at the alias
//! the scenario's overlay names.
use imu_core::sensor::{NoiseSource, SeededNormals};
use imukit::spectrum::{overlay, spectrum_table, welch};
use imukit::{ScenarioSpec, Table};

#[test]
fn white_noise_reads_two_sigma_squared_over_the_rate() {
    let (fs, sigma) = (200.0, 0.3);
    let mut n = SeededNormals::new(11);
    let x: Vec<f64> = (0..200_000).map(|_| sigma * n.standard_normal()).collect();
    let (f, p) = welch(&x, fs, 400).unwrap();
    assert_eq!(f.len(), 201);
    assert_eq!(f[200], 100.0);
    let level = 2.0 * sigma * sigma / fs;
    // The mean over the inner bins: about 1000 segments of 200 bins, a spread far below 1 %.
    let mean = p[1..200].iter().sum::<f64>() / 199.0;
    assert!((mean / level - 1.0).abs() < 0.01, "{mean} vs {level}");
    // Each bin alone: χ² of about 2×999 degrees of freedom, within 5 of its σ (≈ 3.2 %); bin 1
    // shares the Hann window's main lobe with DC, whose power the segment's mean takes out.
    let worst = p[2..200]
        .iter()
        .map(|v| (v / level - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 0.16,
        "worst bin off by {worst}; bin 1: {}",
        p[1] / level
    );
}

#[test]
fn the_density_integrates_to_the_variance() {
    let fs = 100.0;
    let x: Vec<f64> = (0..20_000)
        .map(|k| {
            let t = k as f64 / fs;
            2.0 * (2.0 * std::f64::consts::PI * 7.3 * t).sin()
                + 0.5 * (2.0 * std::f64::consts::PI * 31.0 * t).cos()
        })
        .collect();
    let (f, p) = welch(&x, fs, 1000).unwrap();
    let df = f[1] - f[0];
    let total: f64 = p.iter().sum::<f64>() * df;
    let variance = 2.0 * 2.0 / 2.0 + 0.5 * 0.5 / 2.0;
    assert!(
        (total / variance - 1.0).abs() < 1e-3,
        "{total} vs {variance}"
    );
    // The peaks where the sines are.
    let peak = |lo: f64, hi: f64| {
        f.iter()
            .zip(&p)
            .filter(|(fk, _)| **fk >= lo && **fk <= hi)
            .map(|(fk, pk)| (*pk, *fk))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
            .1
    };
    assert!((peak(5.0, 10.0) - 7.3).abs() <= df);
    assert!((peak(25.0, 35.0) - 31.0).abs() <= df);
    assert!(welch(&x, fs, 4).is_err() && welch(&x, 0.0, 100).is_err());
}

#[test]
fn a_shake_above_nyquist_peaks_at_the_alias_the_overlay_names() {
    let text = "rate_hz = 100\nduration_s = 30\n[trajectory]\ntype = \"expression\"\n\
                position_m = [0, 0, 0]\n[imu]\nkind = \"accel-gyro\"\n\
                [imu.chain]\ninternal_rate_hz = 8000\n\
                gyroscope = { filter = \"butterworth\", order = 2, cutoff_hz = 200 }\n\
                [imu.vibration]\nsines = [{ kind = \"angular-rate\", axis = \"z\", frequency_hz = 1130, amplitude = 0.5 }]\n";
    let scenario = ScenarioSpec::from_toml(text, "s")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap();
    let sim = scenario.simulate().unwrap();
    let psd: Table = spectrum_table(&sim.imu, &["gyro_z_rad_s".into()], 4.0, "imu").unwrap();
    let (f, p) = (
        psd.column("frequency_hz").unwrap(),
        psd.column("psd_gyro_z_rad_s").unwrap(),
    );
    let at = p
        .iter()
        .enumerate()
        .fold(0, |best, (k, v)| if *v > p[best] { k } else { best });
    assert!((f[at] - 30.0).abs() < 0.3, "peak at {} Hz", f[at]);
    let o = overlay(&scenario, "gyro_z_rad_s").unwrap().unwrap();
    assert_eq!(o.aliases, vec![(1130.0, 30.0)]);
    assert_eq!(o.rate_hz, 100.0);
    // The response over the internal band: 1 at DC, −3 dB at 200 Hz, small at 1130 Hz.
    let gain = |hz: f64| {
        o.response
            .iter()
            .find(|(fr, _)| (*fr - hz).abs() < 5.0)
            .unwrap()
            .1
    };
    assert!((o.response[0].1 - 1.0).abs() < 1e-12);
    assert!((gain(200.0) - std::f64::consts::FRAC_1_SQRT_2).abs() < 0.02 && gain(1130.0) < 0.03);
    // The peak's power: the alias's amplitude is 0.5·|H(1130 Hz)|, its variance half its square.
    let df = f[1] - f[0];
    let power: f64 = p[at - 3..=at + 3].iter().sum::<f64>() * df;
    let amplitude = 0.5 * 0.027_399_47;
    assert!(
        (power / (amplitude * amplitude / 2.0) - 1.0).abs() < 0.02,
        "{power}"
    );
    assert!(
        overlay(&scenario, "accel_z_m_s2")
            .unwrap()
            .unwrap()
            .aliases
            .is_empty()
    );
}
