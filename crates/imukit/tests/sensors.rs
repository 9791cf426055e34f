//! Realistic sensors in scenarios: parameter files in both dialects, profiles, seeds,
//! temperature profiles, MATLAB's documentation examples, and the errors users meet.
use std::path::Path;

use imu_core::sensor::NoiseType;
use imukit::io::params::Profile;
use imukit::io::part_file::{ParamFile, parse_any_document, read_param_file, to_toml};
use imukit::io::presets;
use imukit::sensor::{BiasInstabilityModel, SensorParams};
use imukit::{ScenarioSpec, Simulation};

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-sensors-{name}-"))
        .tempdir()
        .unwrap()
}

fn run(text: &str, dir: &Path) -> Result<Simulation, imukit::Error> {
    ScenarioSpec::from_toml(text, "test.toml")?
        .resolve(dir)?
        .simulate()
}

fn err(text: &str, dir: &Path) -> String {
    run(text, dir).expect_err("should fail").to_string()
}

const STATIC_NED: &str = r#"
rate_hz = 100.0
duration_s = 9.99
nav_frame = "NED"
[trajectory]
type = "builtin"
name = "static"
"#;

#[test]
fn matlab_stationary_example_reads_gravity_and_the_field() {
    // imuSensor('accel-gyro-mag') at rest, level, NED: accel [0 0 9.81] (MATLAB sign),
    // gyro 0, mag = the field [27.5550 −2.4169 −16.0849].
    let sim = run(
        &format!("{STATIC_NED}[imu]\nprofile = \"matlab\"\n"),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(sim.imu.rows(), 1000);
    for (c, v) in [
        ("accel_z_m_s2", 9.81),
        ("accel_x_m_s2", 0.0),
        ("gyro_y_rad_s", 0.0),
        ("mag_x_ut", 27.555),
        ("mag_z_ut", -16.0849),
    ] {
        assert!(
            sim.imu
                .column(c)
                .unwrap()
                .iter()
                .all(|x| (x - v).abs() < 1e-12),
            "{c}"
        );
    }
}

#[test]
fn platform_turn_shows_the_rotating_field() {
    let text = "[trajectory]\ntype = \"builtin\"\nname = \"platform-turn\"\n[imu]\nprofile = \"matlab\"\nkind = \"accel-mag\"\n";
    let sim = run(text, Path::new(".")).unwrap();
    let (t, mx, my) = (
        sim.imu.column("t_s").unwrap(),
        sim.imu.column("mag_x_ut").unwrap(),
        sim.imu.column("mag_y_ut").unwrap(),
    );
    let (bn, be) = (27.5550, -2.4169);
    for k in [0, 57, 250, 420, 599] {
        let yaw = if t[k] < 4.0 {
            std::f64::consts::FRAC_PI_2 * t[k]
        } else {
            2.0 * std::f64::consts::PI + std::f64::consts::PI * (t[k] - 4.0)
        };
        let (s, c) = yaw.sin_cos();
        assert!(
            (mx[k] - (c * bn + s * be)).abs() < 1e-9 && (my[k] - (-s * bn + c * be)).abs() < 1e-9,
            "k = {k}"
        );
    }
    assert!(!sim.imu.columns.iter().any(|c| c.starts_with("gyro")));
}

const SPEC_SHEET: &str = r#"
[imu.accelerometer]
MeasurementRange = 19.62
Resolution = 0.00059875
ConstantBias = 0.4905
AxesMisalignment = 2
NoiseDensity = 0.003924
BiasInstability = 0
TemperatureBias = [0.34335, 0.34335, 0.5886]
TemperatureScaleFactor = 0.02
"#;

#[test]
fn matlab_spec_sheet_accelerometer_with_noise_has_the_double_sided_spread() {
    // MATLAB profile: NoiseDensity is double-sided, σ = N·√(fs/2); the readings are quantised at
    // 0.00059875 (σ ≈ 0.0277, 46 LSB, so quantisation adds only LSB²/12 to the variance).
    let text = format!(
        "{STATIC_NED}[imu]\nprofile = \"matlab\"\nseed = 67\ntemperature_c = 35\n{SPEC_SHEET}"
    );
    let sim = run(&text, Path::new(".")).unwrap();
    let z = sim.imu.column("accel_z_m_s2").unwrap();
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let var = z.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    let scale = 1.0 + 10.0 * 0.02 / 100.0;
    let sigma2 = (scale * 0.003924 * (50f64).sqrt()).powi(2) + 0.00059875f64.powi(2) / 12.0;
    assert!(
        (var / sigma2 - 1.0).abs() < 5.0 * (2.0 / (n - 1.0)).sqrt(),
        "{var} vs {sigma2}"
    );
    // Mean: misaligned gravity + bias + temperature bias, scaled, as the deterministic formula.
    let expected_mean = scale * (0.02 * 0.0 + 9.81 + 0.4905 + 10.0 * 0.5886);
    assert!(
        (mean - expected_mean).abs() < 5.0 * (sigma2 / n).sqrt(),
        "{mean} vs {expected_mean}"
    );
    // Every reading sits on the quantisation grid.
    assert!(
        z.iter()
            .all(|v| ((v / 0.00059875) - (v / 0.00059875).round()).abs() < 1e-6)
    );
}

#[test]
fn same_seed_same_numbers_other_seed_other_numbers_and_runs_differ() {
    let base = format!(
        "{STATIC_NED}[imu]\nseed = SEED\n[imu.gyroscope]\nnoise_density_rad_s_per_rt_hz = 1e-3\n"
    );
    let a = run(&base.replace("SEED", "7"), Path::new(".")).unwrap();
    let b = run(&base.replace("SEED", "7"), Path::new(".")).unwrap();
    let c = run(&base.replace("SEED", "8"), Path::new(".")).unwrap();
    assert_eq!(a.imu, b.imu);
    assert_ne!(a.imu.column("gyro_x_rad_s"), c.imu.column("gyro_x_rad_s"));
    let sc = ScenarioSpec::from_toml(&base.replace("SEED", "7"), "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    assert_eq!(sc.simulate_run(3).unwrap(), sc.simulate_run(3).unwrap());
    assert_ne!(
        sc.simulate_run(3).unwrap().imu,
        sc.simulate_run(4).unwrap().imu
    );
    // The default profile's noise is single-sided: σ = N·√fs.
    let g = a.imu.column("gyro_x_rad_s").unwrap();
    let var = g.iter().map(|v| v * v).sum::<f64>() / g.len() as f64;
    assert!(
        (var / (1e-6 * 100.0) - 1.0).abs() < 5.0 * (2.0 / 1000.0f64).sqrt(),
        "{var}"
    );
}

#[test]
fn temperature_profile_file_drives_temperature_bias() {
    let dir = temp_dir("temp");
    let dir = dir.path();
    std::fs::write(
        dir.join("temps.csv"),
        "t_s,temperature_c,gyro_temperature_c\n0,25,25\n10,45,65\n",
    )
    .unwrap();
    let text = format!(
        "{STATIC_NED}[imu]\ntemperature_c = \"temps.csv\"\n[imu.accelerometer]\ntemperature_bias_m_s2_per_c = 0.01\n[imu.gyroscope]\ntemperature_bias_rad_s_per_c = 0.001\n"
    );
    let sim = run(&text, dir).unwrap();
    let (t, ax, gx) = (
        sim.imu.column("t_s").unwrap(),
        sim.imu.column("accel_x_m_s2").unwrap(),
        sim.imu.column("gyro_x_rad_s").unwrap(),
    );
    for k in [0, 500, 999] {
        assert!(
            (ax[k] - 0.01 * 2.0 * t[k]).abs() < 1e-12,
            "accel at {}",
            t[k]
        );
        assert!(
            (gx[k] - 0.001 * 4.0 * t[k]).abs() < 1e-12,
            "gyro at {}",
            t[k]
        );
    }
}

#[test]
fn parameter_files_round_trip_through_toml() {
    let mut file = ParamFile {
        present: [true, true, true],
        ..ParamFile::default()
    };
    file.info.insert("name".into(), "test part".into());
    file.params.accelerometer = SensorParams {
        measurement_range: 78.4,
        resolution: 0.0023,
        constant_bias: [0.1, -0.2, 0.3],
        axes_misalignment_pct: [[100.0, 0.1, 0.2], [0.3, 99.5, 0.4], [0.5, 0.6, 101.0]],
        noise_density: [1e-3; 3],
        bias_instability: [2e-4; 3],
        bias_instability_model: BiasInstabilityModel::Flicker {
            tau_min_s: 1.0,
            tau_max_s: 500.0,
        },
        random_walk: [1e-5; 3],
        temperature_bias: [1e-3, 2e-3, 3e-3],
        temperature_scale_factor_pct: [0.01; 3],
        scale_factor_nonlinearity: [1e-4, -2e-4, 3e-5],
        scale_factor_asymmetry_pct: [0.2; 3],
        ..SensorParams::default()
    };
    file.params.gyroscope = SensorParams {
        acceleration_bias: [1e-4; 3],
        acceleration_squared_bias: [1e-7, 0.0, -2e-7],
        resolution: 1e-4,
        quantization_carry: true,
        bias_instability_model: BiasInstabilityModel::GaussMarkov {
            correlation_time_s: 300.0,
        },
        noise_type: NoiseType::DoubleSided,
        ..SensorParams::default()
    };
    let text = to_toml(&file);
    let doc: imukit::io::params::ParamValue = toml::from_str(&text).unwrap();
    let back = parse_any_document(&doc, "round trip", None, Profile::Default).unwrap();
    assert_eq!(back, file, "{text}");
}

#[test]
fn matlab_loadparams_json_is_read_as_matlab_reads_it() {
    let dir = temp_dir("loadparams");
    let dir = dir.path();
    let json = r#"{
      "Part A": {
        "Accelerometer": {"MeasurementRange": "inf", "AxesMisalignment": [[100, 1, 2], [3, 100, 4], [5, 6, 100]],
                          "NoiseDensity": [0.001, 0.002, 0.003], "NoiseType": "double-sided"},
        "Gyroscope": {"ConstantBias": 0.01, "AccelerationBias": 0.0001,
                      "BiasInstabilityCoefficients": {"Numerator": [1], "Denominator": [1, -0.9]}}
      },
      "Part B": {"Magnetometer": {"ConstantBias": [1, 2, 3]}}
    }"#;
    let path = dir.join("params.json");
    std::fs::write(&path, json).unwrap();
    let a = read_param_file(&path, Some("Part A"), Profile::Default).unwrap();
    assert!(a.params.accelerometer.measurement_range.is_infinite());
    assert_eq!(
        a.params.accelerometer.axes_misalignment_pct[2],
        [5.0, 6.0, 100.0]
    );
    assert_eq!(a.params.accelerometer.noise_density, [0.001, 0.002, 0.003]);
    assert_eq!(a.params.accelerometer.noise_type, NoiseType::DoubleSided);
    assert_eq!(a.params.gyroscope.acceleration_bias, [1e-4; 3]);
    assert_eq!(a.present, [true, true, false]);
    let e = read_param_file(&path, None, Profile::Default)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("several parts") && e.contains("Part A") && e.contains("Part B"),
        "{e}"
    );
    let e = read_param_file(&path, Some("Part C"), Profile::Default)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no part \"Part C\""), "{e}");
    // A key MATLAB's coefficients do not have was ignored: now named.
    let misspelt = json.replace("\"Denominator\"", "\"Denominater\"");
    std::fs::write(&path, misspelt).unwrap();
    let e = read_param_file(&path, Some("Part A"), Profile::Default)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("BiasInstabilityCoefficients.Denominater: unknown key"),
        "{e}"
    );
    std::fs::write(&path, json).unwrap();
    // In a scenario: params + part, and an inline table overriding one key.
    let text = format!(
        "{STATIC_NED}[imu]\nparams = \"params.json\"\npart = \"Part A\"\n[imu.gyroscope]\nConstantBias = 0.02\n"
    );
    let sim = run(&text, dir).unwrap();
    // Default profile: the g-sensitivity sees the body specific force, −9.81 on z (FRD, at rest).
    assert!(
        sim.imu
            .column("gyro_z_rad_s")
            .unwrap()
            .iter()
            .all(|v| (v - (0.02 + 1e-4 * -9.81)).abs() < 1e-15)
    );
    assert!(
        sim.imu
            .column("gyro_y_rad_s")
            .unwrap()
            .iter()
            .all(|v| *v == 0.02)
    );
    // Malformed JSON names the file and line.
    std::fs::write(
        dir.join("bad.json"),
        "{\n  \"Part\": {\n    \"Gyroscope\": {\"ConstantBias\": 0.01,}\n  }\n}\n",
    )
    .unwrap();
    let e = err(&format!("{STATIC_NED}[imu]\nparams = \"bad.json\"\n"), dir);
    assert!(e.contains("bad.json") && e.contains("line 3"), "{e}");
}

#[test]
fn bad_parameters_are_refused_with_sensor_and_field() {
    let dir = Path::new(".");
    let e = err(
        &format!("{STATIC_NED}[imu.accelerometer]\nnoise_density_m_s2_per_rt_hz = -1\n"),
        dir,
    );
    assert!(
        e.contains("imu.accelerometer") && e.contains("noise_density[0] must be ≥ 0"),
        "{e}"
    );
    let e = err(
        &format!("{STATIC_NED}[imu.gyroscope]\nconstant_bias_rad_s = nan\n"),
        dir,
    );
    assert!(
        e.contains("imu.gyroscope.constant_bias_rad_s") && e.contains("finite"),
        "{e}"
    );
    let e = err(
        &format!("{STATIC_NED}[imu.magnetometer]\nmeasurement_range_ut = 0\n"),
        dir,
    );
    assert!(e.contains("measurement_range must be > 0"), "{e}");
    let e = err(
        &format!("{STATIC_NED}[imu.accelerometer]\nnoise_density = 1\n"),
        dir,
    );
    assert!(
        e.contains("imu.accelerometer.noise_density")
            && e.contains("unknown parameter")
            && e.contains("noise_density_m_s2_per_rt_hz"),
        "{e}"
    );
    let e = err(
        &format!("{STATIC_NED}[imu.accelerometer]\nacceleration_bias_rad_s_per_m_s2 = 1\n"),
        dir,
    );
    assert!(e.contains("unknown parameter"), "{e}");
    let e = err(&format!("{STATIC_NED}[imu]\npreset = \"MPU-9999\"\n"), dir);
    assert!(
        e.contains("unknown preset \"MPU-9999\"") && e.contains("ideal"),
        "{e}"
    );
    let e = err(
        &format!("{STATIC_NED}[imu.gyroscope]\nbias_instability_flicker_tau_s = [10, 1]\n"),
        dir,
    );
    assert!(e.contains("bias_instability_tau_max_s"), "{e}");
    let e = err(&format!("{STATIC_NED}[imu]\nprofile = \"simulink\"\n"), dir);
    assert!(e.contains("profile") || e.contains("simulink"), "{e}");
}

#[test]
fn ideal_preset_changes_nothing() {
    let plain = run(STATIC_NED, Path::new(".")).unwrap();
    let ideal = run(
        &format!("{STATIC_NED}[imu]\npreset = \"ideal\"\nseed = 5\n"),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(plain, ideal);
    assert!(presets::names().contains(&"ideal"));
}

#[test]
fn every_preset_loads_validates_and_cites_its_source() {
    assert!(presets::names().len() >= 9, "{:?}", presets::names());
    for name in presets::names() {
        let file = presets::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        for key in ["name", "grade", "source"] {
            assert!(
                file.info.get(key).is_some_and(|v| !v.is_empty()),
                "{name}: {key}"
            );
        }
        // Presets state datasheet (single-sided) densities.
        for s in [
            file.params.accelerometer,
            file.params.gyroscope,
            file.params.magnetometer,
        ] {
            assert_eq!(s.noise_type, NoiseType::SingleSided, "{name}");
            s.validate().unwrap();
        }
        // Case-insensitive lookup, and a scenario can use it.
        assert!(presets::text(&name.to_uppercase()).is_ok());
        let sim = run(
            &format!("{STATIC_NED}[imu]\npreset = \"{name}\"\nseed = 1\n"),
            Path::new("."),
        )
        .unwrap();
        assert!(sim.imu.data.iter().all(|v| v.is_finite()), "{name}");
    }
}

#[test]
fn preset_numbers_match_their_datasheet_figures() {
    use imukit::io::units::{convert, datasheet_bias_instability};
    let rel = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs();
    let mpu = presets::load("mpu-6050").unwrap().params;
    assert!(rel(
        mpu.gyroscope.noise_density[0],
        convert(0.005, "°/s/√Hz").unwrap().value
    ));
    assert!(rel(
        mpu.accelerometer.noise_density[0],
        convert(400.0, "µg/√Hz").unwrap().value
    ));
    assert!(rel(
        mpu.gyroscope.acceleration_bias[0],
        convert(0.1, "°/s/g").unwrap().value
    ));
    assert!(rel(
        mpu.accelerometer.constant_bias[2],
        convert(80.0, "mg").unwrap().value
    ));
    let stim = presets::load("stim300").unwrap().params;
    assert!(rel(
        stim.gyroscope.noise_density[0],
        convert(0.15, "°/√h").unwrap().value
    ));
    assert!(rel(
        stim.accelerometer.noise_density[0],
        convert(0.06, "m/s/√h").unwrap().value
    ));
    assert!(rel(
        stim.gyroscope.bias_instability[0],
        datasheet_bias_instability(convert(0.5, "°/h").unwrap().value)
    ));
    let hg = presets::load("hg9900").unwrap().params;
    assert!(rel(
        hg.gyroscope.noise_density[0],
        convert(0.002, "°/√h").unwrap().value
    ));
    assert!(rel(
        hg.accelerometer.constant_bias[0],
        convert(25.0, "µg").unwrap().value
    ));
}

fn first_reading(sc: &imukit::Scenario, run: u64, column: &str) -> f64 {
    sc.simulate_run(run).unwrap().imu.column(column).unwrap()[0]
}

#[test]
fn perturbations_draw_per_run_with_the_stated_distributions() {
    // Noise-free static IMU: the reading is the perturbed parameter itself.
    let text = format!(
        "{STATIC_NED}[imu]\nseed = 3\n\
         [[imu.perturbations]]\nparameter = \"gyroscope.constant_bias_rad_s\"\ndistribution = \"normal\"\nmean = 0.01\nstd = 0.002\n\
         [[imu.perturbations]]\nparameter = \"accelerometer.constant_bias_m_s2\"\ndistribution = \"uniform\"\nlower = -0.1\nupper = 0.3\n\
         [[imu.perturbations]]\nparameter = \"magnetometer.constant_bias_ut\"\ndistribution = \"selection\"\nvalues = [1.0, 2.0]\nprobabilities = [0.25, 0.75]\n\
         [[imu.perturbations]]\nparameter = \"gyroscope.temperature_scale_factor_pct_per_c\"\ndistribution = \"truncated-normal\"\nmean = 0.0\nstd = 1.0\nlower = 0.0\nupper = 0.5\n"
    );
    let sc = ScenarioSpec::from_toml(&text, "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let runs = 400u64;
    let (mut g, mut a, mut twos) = (vec![], vec![], 0);
    for r in 0..runs {
        let sim = sc.simulate_run(r).unwrap();
        g.push(sim.imu.column("gyro_x_rad_s").unwrap()[0]);
        a.push(sim.imu.column("accel_y_m_s2").unwrap()[0]);
        let m = sim.imu.column("mag_x_ut").unwrap()[0] - 27.555;
        assert!((m - 1.0).abs() < 1e-9 || (m - 2.0).abs() < 1e-9, "{m}");
        twos += usize::from((m - 2.0).abs() < 1e-9);
    }
    let n = runs as f64;
    let mean = g.iter().sum::<f64>() / n;
    let sd = (g.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    assert!((mean - 0.01).abs() < 5.0 * 0.002 / n.sqrt(), "{mean}");
    assert!((sd / 0.002 - 1.0).abs() < 5.0 * (0.5 / n).sqrt(), "{sd}");
    assert!(a.iter().all(|v| (-0.1..=0.3).contains(v)));
    let a_mean = a.iter().sum::<f64>() / n;
    assert!(
        (a_mean - 0.1).abs() < 5.0 * (0.4 / 12f64.sqrt()) / n.sqrt(),
        "{a_mean}"
    );
    let p2 = twos as f64 / n;
    assert!((p2 - 0.75).abs() < 5.0 * (0.75 * 0.25 / n).sqrt(), "{p2}");
    // Deterministic per run, independent of the other runs.
    assert_eq!(
        first_reading(&sc, 17, "gyro_x_rad_s"),
        first_reading(&sc, 17, "gyro_x_rad_s")
    );
    assert_ne!(
        first_reading(&sc, 17, "gyro_x_rad_s"),
        first_reading(&sc, 18, "gyro_x_rad_s")
    );
    // Per axis, independent draws.
    let sim = sc.simulate_run(5).unwrap();
    assert_ne!(
        sim.imu.column("gyro_x_rad_s").unwrap()[0],
        sim.imu.column("gyro_y_rad_s").unwrap()[0]
    );
}

#[test]
fn bad_perturbations_are_refused() {
    let dir = Path::new(".");
    let p = |body: &str| format!("{STATIC_NED}[imu]\n[[imu.perturbations]]\n{body}");
    let e = err(
        &p("parameter = \"gyroscope.bias\"\ndistribution = \"normal\"\nmean = 0\nstd = 1\n"),
        dir,
    );
    assert!(
        e.contains("imu.perturbations[0].parameter") && e.contains("cannot perturb \"bias\""),
        "{e}"
    );
    let e = err(
        &p("parameter = \"gyroscope.constant_bias_rad_s\"\ndistribution = \"cauchy\"\n"),
        dir,
    );
    assert!(
        e.contains("line 11") && e.contains("unknown variant `cauchy`, expected one of `normal`"),
        "{e}"
    );
    let e = err(
        &p("parameter = \"gyroscope.constant_bias_rad_s\"\ndistribution = \"normal\"\nmean = 0\n"),
        dir,
    );
    assert!(e.contains("needs std"), "{e}");
    let e = err(
        &p(
            "parameter = \"accelerometer.constant_bias_m_s2\"\ndistribution = \"selection\"\nvalues = [1, 2]\nprobabilities = [0.5, 0.6]\n",
        ),
        dir,
    );
    assert!(e.contains("add up to 1"), "{e}");
    // A draw that makes a density negative names the run.
    let e = err(
        &p(
            "parameter = \"gyroscope.noise_density_rad_s_per_rt_hz\"\ndistribution = \"normal\"\nmean = 0\nstd = 1\n",
        ),
        dir,
    );
    assert!(
        e.contains("noise_density") && e.contains("must be ≥ 0"),
        "{e}"
    );
}

#[test]
fn increments_output_integrates_each_interval() {
    let text = "rate_hz = 100.0\nduration_s = 6.0\n[trajectory]\ntype = \"builtin\"\nname = \"platform-turn\"\n[imu]\noutput = \"increments\"\n";
    let sim = run(text, Path::new(".")).unwrap();
    assert_eq!(
        &sim.imu.columns[..7],
        [
            "t_s",
            "dv_x_m_s",
            "dv_y_m_s",
            "dv_z_m_s",
            "dtheta_x_rad",
            "dtheta_y_rad",
            "dtheta_z_rad"
        ]
    );
    let dz = sim.imu.column("dtheta_z_rad").unwrap();
    let dv = sim.imu.column("dv_z_m_s").unwrap();
    assert_eq!(dz[0], 0.0);
    // 360° in 4 s then 360° in 2 s: the increments add up to 4π over 6 s, less the half interval
    // the trapezoid spends across the rate step at t = 4 s.
    let total: f64 = dz.iter().sum();
    assert!(
        (total - 4.0 * std::f64::consts::PI).abs() < 0.5 * 0.01 * std::f64::consts::PI + 1e-9,
        "{total}"
    );
    assert!((dz[100] - std::f64::consts::FRAC_PI_2 * 0.01).abs() < 1e-12);
    assert!(dv[1..].iter().all(|v| (v + 9.81 * 0.01).abs() < 1e-12)); // NED at rest: −g·Δt on z
}

/// MATLAB's `fractalcoef(poles)` (Kasdin 1995): `Den = [1, a₁, …]`, `a_k = (k − 1 − ½)·a_{k−1}/k`.
fn fractal_denominator(poles: usize) -> Vec<f64> {
    let mut den = vec![1.0];
    for k in 1..=poles {
        den.push((k as f64 - 1.5) * den[k - 1] / k as f64);
    }
    den
}

#[test]
fn matlabs_fractalcoef_500_from_a_parameter_file_drives_the_scenario() {
    // MATLAB's Allan example puts fractalcoef(500) in BiasInstabilityCoefficients. From a MATLAB
    // JSON file into a scenario: with only bias instability on, the gyro reads
    // y = filter(1, den, B·n), and filtering y by the FIR `den` gives B·n back, white with σ = B,
    // only if all 501 coefficients act.
    let dir = temp_dir("fractal500");
    let dir = dir.path();
    let den = fractal_denominator(500);
    let b = 0.01;
    let doc = serde_json::json!({"Gyroscope": {
        "BiasInstability": b,
        "BiasInstabilityCoefficients": {"Numerator": [1.0], "Denominator": den},
    }});
    std::fs::write(dir.join("fractal.json"), doc.to_string()).unwrap();
    let text = STATIC_NED.replace("duration_s = 9.99", "duration_s = 99.99")
        + "[imu]\nkind = \"accel-gyro\"\nseed = 4\nparams = \"fractal.json\"\n";
    let sim = run(&text, dir).unwrap();
    let y = sim.imu.column("gyro_x_rad_s").unwrap();
    let n = y.len();
    assert_eq!(n, 10_000);
    let white: Vec<f64> = (0..n)
        .map(|k| (0..=k.min(500)).map(|j| den[j] * y[k - j]).sum::<f64>() / b)
        .collect();
    let mean = white.iter().sum::<f64>() / n as f64;
    let sd = (white.iter().map(|w| (w - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let lag1 = white
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum::<f64>()
        / ((n - 1) as f64 * sd * sd);
    // σ of a sample standard deviation is 1/√(2n), of a mean and a lag-1 correlation 1/√n: 5σ.
    let n_f = n as f64;
    assert!((sd - 1.0).abs() < 5.0 / (2.0 * n_f).sqrt(), "sd {sd}");
    assert!(mean.abs() < 5.0 / n_f.sqrt(), "mean {mean}");
    assert!(lag1.abs() < 5.0 / n_f.sqrt(), "lag-1 correlation {lag1}");
    // A parameter file written back keeps all 501 coefficients.
    let file = read_param_file(&dir.join("fractal.json"), None, Profile::Matlab).unwrap();
    let BiasInstabilityModel::Filter(c) = &file.params.gyroscope.bias_instability_model else {
        panic!("a filter was read");
    };
    assert_eq!(c.denominator(), den.as_slice());
    // One coefficient beyond the bound: refused with the file, the key and the bound.
    let den = fractal_denominator(4096);
    let doc = serde_json::json!({"Gyroscope": {
        "BiasInstabilityCoefficients": {"Numerator": [1.0], "Denominator": den},
    }});
    std::fs::write(dir.join("long.json"), doc.to_string()).unwrap();
    let e = read_param_file(&dir.join("long.json"), None, Profile::Matlab)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("long.json")
            && e.contains("Gyroscope: bias_instability_coefficients")
            && e.contains("4097 coefficients, at most 4096 taken"),
        "{e}"
    );
}

/// Every kind of value a scenario or parameter file holds is read as that kind, from JSON and
/// from TOML: integers stay integers (exactly, any `u64` too), numbers stay numbers,
/// `null` is `Null`, and lists and tables nest.
#[test]
fn param_values_are_read_as_their_own_kind() {
    use imukit::io::params::ParamValue as V;
    let json = r#"{"b": true, "i": -7, "big": 18446744073709551615, "x": 0.25, "s": "inf",
                   "n": null, "l": [1, 2.5, [false]], "t": {"a": "x"}}"#;
    let from_json: V = serde_json::from_str(json).unwrap();
    let want = |null: bool, big: V| {
        let mut t = std::collections::BTreeMap::new();
        t.insert("b".to_string(), V::Bool(true));
        t.insert("i".to_string(), V::Integer(-7));
        t.insert("big".to_string(), big);
        t.insert("x".to_string(), V::Number(0.25));
        t.insert("s".to_string(), V::Text("inf".into()));
        if null {
            t.insert("n".to_string(), V::Null);
        }
        let list = vec![V::Integer(1), V::Number(2.5), V::List(vec![V::Bool(false)])];
        t.insert("l".to_string(), V::List(list));
        let inner = std::iter::once(("a".to_string(), V::Text("x".into()))).collect();
        t.insert("t".to_string(), V::Table(inner));
        V::Table(t)
    };
    assert_eq!(from_json, want(true, V::Integer(u64::MAX.into())));
    // TOML has no null, and its integers end at i64 (the big one is written as a number there).
    let toml_text = "b = true\ni = -7\nbig = 18446744073709551615.0\nx = 0.25\ns = \"inf\"\n\
                     l = [1, 2.5, [false]]\nt = { a = \"x\" }\n";
    let from_toml: V = toml::from_str(toml_text).unwrap();
    assert_eq!(
        from_toml,
        want(false, V::Number(18_446_744_073_709_551_615.0))
    );
    // TOML's dates reach serde as one-entry tables, and read as such.
    assert!(matches!(
        toml::from_str::<V>("d = 1979-05-27").unwrap(),
        V::Table(_)
    ));
}
