//! Kalibr's `imu.yaml` from a parameter file: the figures against their closed forms.
use imu_core::sensor::{BiasInstabilityModel, NoiseType};
use imu_io::kalibr::read;
use imu_io::kalibr::{DEFAULT_RATE_HZ, DEFAULT_TOPIC, KalibrImu};
use imu_io::params::Profile;
use imu_io::part_file::read_param_file;
use imu_io::presets;

fn close(got: f64, want: f64) {
    assert!(
        (got - want).abs() <= 1e-15 * want.abs(),
        "{got:e} against {want:e}"
    );
}

/// The value of `key` in the file's text, read as a number.
fn value(yaml: &str, key: &str) -> f64 {
    let line = yaml
        .lines()
        .find(|l| l.starts_with(&format!("{key}:")))
        .unwrap_or_else(|| panic!("{key} missing in\n{yaml}"));
    let text = line[key.len() + 1..].split('#').next().unwrap_or("").trim();
    text.parse().unwrap_or_else(|_| panic!("{key}: {text:?}"))
}

#[test]
fn a_single_sided_part_keeps_its_densities_and_its_flicker_gives_the_random_walk() {
    let file = presets::load("stim300").expect("preset");
    let imu = KalibrImu::from_params(&file, 125.0, "/imu0").expect("figures");
    let gyro = &file.params.gyroscope;
    assert_eq!(gyro.noise_type, NoiseType::SingleSided);
    assert_eq!(imu.gyroscope.noise_density, gyro.noise_density[0]);
    let BiasInstabilityModel::Flicker { tau_max_s, .. } = gyro.bias_instability_model else {
        panic!("the STIM300 preset's bias instability is flicker");
    };
    // The random walk whose Allan deviation K·√(τ/3) meets the floor 0.664·B at τ₂.
    let k = imu.gyroscope.random_walk;
    close(
        k * (tau_max_s / 3.0).sqrt(),
        imu_core::allan::BIAS_INSTABILITY_FACTOR * gyro.bias_instability[0],
    );
    let yaml = imu.to_yaml();
    assert_eq!(value(&yaml, "update_rate"), 125.0);
    assert!(yaml.contains("rostopic: \"/imu0\"\n"));
    // Seven significant digits written.
    let written = value(&yaml, "gyroscope_random_walk");
    assert!((written - k).abs() <= 5e-7 * k, "{written:e} against {k:e}");
    assert!(yaml.contains("K = 0.664·B·√(3/τ₂)"), "{yaml}");
}

#[test]
fn double_sided_densities_are_turned_single_sided_and_gauss_markov_drift_gives_its_driving_noise() {
    let mut file = presets::load("stim300").expect("preset");
    let accel = &mut file.params.accelerometer;
    accel.noise_type = NoiseType::DoubleSided;
    accel.random_walk = [1e-5, 2e-5, 1.5e-5];
    let gyro = &mut file.params.gyroscope;
    gyro.bias_instability_model = BiasInstabilityModel::GaussMarkov {
        correlation_time_s: 300.0,
    };
    let (n_a, b_g) = (
        file.params.accelerometer.noise_density[0],
        file.params.gyroscope.bias_instability[0],
    );
    let imu = KalibrImu::from_params(&file, DEFAULT_RATE_HZ, DEFAULT_TOPIC).expect("figures");
    // Bandwidth fs/2: the same discrete σ = N·√(fs/2) = σ_c·√fs, and step K/√(fs/2) = σ_b/√fs.
    close(imu.accelerometer.noise_density, n_a / 2f64.sqrt());
    close(imu.accelerometer.random_walk, 2e-5 * 2f64.sqrt());
    assert!(
        imu.accelerometer
            .notes
            .iter()
            .any(|n| n.contains("largest axis"))
    );
    // x_k = φx + √(1−φ²)·B·n: over short times a random walk of step variance 2B²/(fs·T).
    close(imu.gyroscope.random_walk, b_g * (2.0 / 300.0f64).sqrt());
}

#[test]
fn a_part_without_drift_figures_says_the_random_walk_must_be_set() {
    let file = presets::load("mpu-6050").expect("preset");
    let imu = KalibrImu::from_params(&file, 100.0, DEFAULT_TOPIC).expect("figures");
    assert_eq!(imu.gyroscope.random_walk, 0.0);
    let yaml = imu.to_yaml();
    assert_eq!(value(&yaml, "gyroscope_random_walk"), 0.0);
    assert!(yaml.contains("random walk 0"), "{yaml}");
}

#[test]
fn a_rate_that_is_not_positive_is_refused_by_name() {
    let file = presets::load("stim300").expect("preset");
    for rate in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = KalibrImu::from_params(&file, rate, DEFAULT_TOPIC).expect_err("refused");
        assert!(e.to_string().contains("rate_hz"), "{e}");
    }
}

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, text).expect("written");
    path
}

#[test]
fn a_topic_is_written_quoted_and_a_file_that_says_a_key_twice_is_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let file = presets::load("stim300").expect("preset");
    for topic in ["a: b", "/imu # x", "two\nupdate_rate: 1.0", "\"quoted\""] {
        let written = KalibrImu::from_params(&file, 125.0, topic).expect("kalibr");
        let path = write(&dir, "imu.yaml", &written.to_yaml());
        let back = read(&path).expect("read back");
        assert_eq!(
            (back.rostopic.as_str(), back.update_rate_hz),
            (topic, 125.0)
        );
    }
    let good = KalibrImu::from_params(&file, 125.0, "/imu0")
        .expect("kalibr")
        .to_yaml();
    let twice = format!("{good}update_rate: 200.0\n");
    let e = read(&write(&dir, "twice.yaml", &twice))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("twice.yaml") && e.contains("key update_rate given twice"),
        "{e}"
    );
    let second = format!("{good}---\n{good}");
    let e = read(&write(&dir, "second.yaml", &second))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a second YAML document"), "{e}");
}

#[test]
fn a_written_file_reads_back_as_its_figures() {
    let dir = tempfile::tempdir().expect("dir");
    let file = presets::load("stim300").expect("preset");
    let written = KalibrImu::from_params(&file, 125.0, "/imu0").expect("kalibr");
    let path = write(&dir, "imu.yaml", &written.to_yaml());
    let back = read(&path).expect("read");
    assert_eq!(
        (back.update_rate_hz, back.rostopic.as_str()),
        (125.0, "/imu0")
    );
    for (a, b) in [
        (&written.accelerometer, &back.accelerometer),
        (&written.gyroscope, &back.gyroscope),
    ] {
        // Seven significant digits written.
        assert!((a.noise_density - b.noise_density).abs() <= 5e-7 * a.noise_density);
        assert!((a.random_walk - b.random_walk).abs() <= 5e-7 * a.random_walk);
    }
    // As a parameter file: the same figures on every axis, single-sided, nothing else.
    let params = read_param_file(&path, None, Profile::default()).expect("parameters");
    let g = &params.params.gyroscope;
    assert_eq!(g.noise_density, [back.gyroscope.noise_density; 3]);
    assert_eq!(g.random_walk, [back.gyroscope.random_walk; 3]);
    assert_eq!(g.noise_type, NoiseType::SingleSided);
    assert_eq!(g.bias_instability, [0.0; 3]);
    assert_eq!(
        params.params.accelerometer.random_walk,
        [back.accelerometer.random_walk; 3]
    );
}
