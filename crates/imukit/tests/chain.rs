//! A scenario's signal chain (`[imu.chain]`) end to end: a body shaking faster than the
//! output's Nyquist frequency reads, at the output rate, the alias the chain's response gives;
//! a rate below it passes with the response's gain and phase; the truth is the same rows with
//! or without a chain; a run is the same streamed on one thread or two and whole; and the
//! chains the scenario cannot have are refused by key.
use core::f64::consts::PI;

use imukit::io::columns::VIBRATION_TRUTH_COLUMNS;
use imukit::run::pipeline::RunThreads;
use imukit::scenario::chain::{ChainSetup, ChainSpec};
use imukit::{Scenario, ScenarioSpec};

/// A body yawing as `ω_z = W·sin(2πft)` (yaw `W/(2πf)·(1 − cos 2πft)`), 100 Hz for `seconds`,
/// ideal sensors, with the `chain` table given.
fn shaking(f: f64, seconds: f64, chain: &str) -> Scenario {
    shaking_on("", f, seconds, chain)
}

/// [`shaking`] on the Earth the top-level lines `earth` give.
fn shaking_on(earth: &str, f: f64, seconds: f64, chain: &str) -> Scenario {
    let text = format!(
        "rate_hz = 100\nduration_s = {seconds}\n{earth}\n\
         [trajectory]\ntype = \"expression\"\nconstants = {{ f = {f}, w = 0.5 }}\n\
         position_m = [0, 0, 0]\nyaw_rad = \"w/(2*pi*f)*(1 - cos(2*pi*f*t))\"\n\
         [imu]\nkind = \"accel-gyro\"\n{chain}"
    );
    ScenarioSpec::from_toml(&text, "shaking")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap()
}

const CHAIN: &str = "[imu.chain]\ninternal_rate_hz = 8000\n\
                     gyroscope = { filter = \"butterworth\", order = 2, cutoff_hz = 200 }\n";

/// Least-squares amplitude and phase of `y ≈ A·sin(2πft + φ)` at the times `t`.
fn sine_fit(t: &[f64], y: &[f64], f: f64) -> (f64, f64) {
    let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (&ti, &yi) in t.iter().zip(y) {
        let (s, c) = (2.0 * PI * f * ti).sin_cos();
        ss += s * s;
        sc += s * c;
        cc += c * c;
        ys += yi * s;
        yc += yi * c;
    }
    let det = ss * cc - sc * sc;
    let (a, b) = ((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
    (a.hypot(b), b.atan2(a))
}

/// The gyroscope's chain of [`CHAIN`] at 100 Hz.
fn gyro_chain() -> imukit::sensor::Chain {
    let spec: ChainSpec = toml::from_str(CHAIN.trim_start_matches("[imu.chain]\n")).unwrap();
    let [_, gyro, _] = ChainSetup::resolve(&spec, 100.0)
        .unwrap()
        .chains(100.0)
        .unwrap();
    gyro
}

#[test]
fn a_rate_above_the_output_nyquist_is_read_at_its_alias_with_the_chains_gain_and_phase() {
    let chain = gyro_chain();
    for f in [1130.0, 12.0] {
        let sim = shaking(f, 4.0, CHAIN).simulate().unwrap();
        let t = sim.imu.column("t_s").unwrap();
        let gz = sim.imu.column("gyro_z_rad_s").unwrap();
        assert_eq!(
            t.len(),
            401,
            "the output rate's samples, not the internal rate's"
        );
        // Past the filter's start-up (its poles' time constant is about 1 ms).
        let keep = t.iter().position(|&ti| ti >= 0.5).unwrap();
        let (amplitude, phase) = sine_fit(&t[keep..], &gz[keep..], f);
        let h = chain.response(f);
        assert!(
            (amplitude / (0.5 * h.gain) - 1.0).abs() < 1e-3,
            "{f} Hz: {amplitude} vs {}",
            0.5 * h.gain
        );
        assert!(
            (phase - h.phase_rad).abs() < 1e-3,
            "{f} Hz: {phase} vs {}",
            h.phase_rad
        );
        if f > 50.0 {
            // What a user sees: a 30 Hz wobble of 3 % of the motion's amplitude.
            assert_eq!(chain.alias_hz(f), 30.0);
            let (at_alias, _) = sine_fit(&t[keep..], &gz[keep..], 30.0);
            assert!((at_alias / amplitude - 1.0).abs() < 1e-6);
            assert!(h.gain < 0.04);
        }
    }
    // Without a chain the same motion is read at its instants: samples of the 1130 Hz sine at
    // 100 Hz, at full amplitude.
    let plain = shaking(1130.0, 4.0, "").simulate().unwrap();
    let (t, gz) = (
        plain.imu.column("t_s").unwrap(),
        plain.imu.column("gyro_z_rad_s").unwrap(),
    );
    let (amplitude, _) = sine_fit(&t, &gz, 1130.0);
    assert!((amplitude / 0.5 - 1.0).abs() < 1e-9, "{amplitude}");
}

#[test]
fn the_truth_is_the_same_with_a_chain_and_a_run_streamed_or_whole_is_the_same() {
    let with = shaking(1130.0, 12.0, CHAIN);
    let without = shaking(1130.0, 12.0, "");
    let whole = with.simulate().unwrap();
    assert!(
        whole.truth == without.simulate().unwrap().truth,
        "truth rows differ"
    );
    for threads in [RunThreads::One, RunThreads::Two] {
        let gathered = with.simulate_streamed(None, threads).unwrap();
        assert!(
            gathered == whole,
            "{threads:?}: streamed differs from whole"
        );
    }
}

#[test]
fn a_chain_the_scenario_cannot_have_is_refused_by_its_key() {
    let refused = |chain: &str, earth: &str| {
        let text = format!(
            "rate_hz = 100\nduration_s = 1\n{earth}\n[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\n\
             [imu]\n{chain}"
        );
        match ScenarioSpec::from_toml(&text, "s").and_then(|s| s.resolve(std::path::Path::new(".")))
        {
            Ok(_) => panic!("{chain} accepted"),
            Err(e) => e.to_string(),
        }
    };
    let e = refused("[imu.chain]\ninternal_rate_hz = 1e300\n", "");
    assert!(
        e.starts_with("imu.chain.internal_rate_hz: the motion sampled at these rates")
            && e.contains("3.00e300 samples"),
        "{e}"
    );
    let e = refused("[imu.chain]\ninternal_rate_hz = 1050\n", "");
    assert!(
        e.starts_with(
            "imu.chain.internal_rate_hz: the internal rate 1050 Hz is not a whole multiple"
        ),
        "{e}"
    );
    let e = refused(
        "[imu.chain]\ninternal_rate_hz = 1000\naccelerometer = { filter = \"butterworth\", order = 2, cutoff_hz = 600 }\n",
        "",
    );
    assert!(
        e.starts_with("imu.chain.accelerometer: cutoff_hz 600 must lie below"),
        "{e}"
    );
    let e = refused(
        "[imu.chain]\ninternal_rate_hz = 1000\ngyroscope = { filter = \"butterworth\", order = 2 }\n",
        "",
    );
    assert!(e.contains("cutoff_hz"), "{e}");
    let e = refused(
        "[imu.chain]\ninternal_rate_hz = 1000\ngyroscope = { filter = \"boxcar\", taps = 3 }\n",
        "",
    );
    assert!(e.contains("boxcar"), "{e}");
}

#[test]
fn on_the_wgs84_earth_the_chain_reads_the_alias_and_the_vibration_is_filtered_as_on_the_flat_one() {
    let chain = gyro_chain();
    let f = 1130.0;
    let shake = "[imu.vibration]\nsines = [{ kind = \"acceleration\", axis = \"z\", \
                 frequency_hz = 1130, amplitude = 10 }]\n";
    let scenario = shaking_on(
        "earth = \"wgs84\"\norigin = [45, 7, 100]",
        f,
        4.0,
        &format!("{CHAIN}{shake}"),
    );
    let sim = scenario.simulate().unwrap();
    let t = sim.imu.column("t_s").unwrap();
    assert_eq!(t.len(), 401);
    let keep = t.iter().position(|&ti| ti >= 0.5).unwrap();
    // Less the Earth's rate and gravity (constant here: the yaw swings by 7e-5 rad): the
    // shake's alias at the chain's gain and phase, as on the flat Earth.
    let centred = |name: &str| {
        let y = &sim.imu.column(name).unwrap()[keep..];
        let mean = y.iter().sum::<f64>() / y.len() as f64;
        y.iter().map(|v| v - mean).collect::<Vec<_>>()
    };
    let (amplitude, phase) = sine_fit(&t[keep..], &centred("gyro_z_rad_s"), f);
    let h = chain.response(f);
    assert!(
        (amplitude / (0.5 * h.gain) - 1.0).abs() < 1e-3,
        "{amplitude} vs {}",
        0.5 * h.gain
    );
    assert!((phase - h.phase_rad).abs() < 1e-3, "{phase}");
    // The accelerometer has no filter: decimation alone reads the shake's full amplitude at
    // its alias.
    let (amplitude, _) = sine_fit(&t[keep..], &centred("accel_z_m_s2"), f);
    assert!((amplitude / 10.0 - 1.0).abs() < 1e-3, "{amplitude}");
    // The truth is the WGS-84 truth of the scenario's rows, and then what the vibration did:
    // the shake itself at each row (the accelerometer has no filter), nothing else.
    let plain = shaking_on("earth = \"wgs84\"\norigin = [45, 7, 100]", f, 4.0, "")
        .simulate()
        .unwrap();
    let width = plain.truth.columns.len();
    assert_eq!(sim.truth.columns[..width], plain.truth.columns[..]);
    assert_eq!(sim.truth.columns[width..], VIBRATION_TRUTH_COLUMNS[..]);
    for (row, motion) in sim
        .truth
        .data
        .chunks_exact(width + 9)
        .zip(plain.truth.data.chunks_exact(width))
    {
        assert!(row[..width] == *motion, "truth rows differ");
        let shake = 10.0 * (2.0 * PI * f * row[0]).sin();
        assert!((row[width + 2] - shake).abs() < 1e-9, "{row:?}");
        assert!(
            row[width..]
                .iter()
                .enumerate()
                .all(|(k, v)| k == 2 || *v == 0.0)
        );
    }
    let streamed = scenario.simulate_streamed(None, RunThreads::Two).unwrap();
    assert!(
        streamed == sim,
        "streamed on two threads differs from whole"
    );
}

/// The mean x reading of an accelerometer with `K₂ = 1e-3 /(m/s²)` on x, shaken along x at
/// 1130 Hz with 20 m/s², at rest otherwise, over 5 s, with the `chain` table given.
fn rectified_mean(chain: &str) -> f64 {
    let text = format!(
        "rate_hz = 100\nduration_s = 5\n\
         [trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\n\
         [imu]\nkind = \"accel-gyro\"\n\
         [imu.accelerometer]\nscale_factor_nonlinearity_per_m_s2 = [1e-3, 0, 0]\n\
         [imu.vibration]\nsines = [{{ kind = \"acceleration\", axis = \"x\", frequency_hz = 1130, amplitude = 20 }}]\n\
         {chain}"
    );
    let sim = ScenarioSpec::from_toml(&text, "rectified")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    let ax = sim.imu.column("accel_x_m_s2").unwrap();
    // 4.9 s from 0.1 s: whole periods of the 30 Hz alias and the 60 Hz one of the rectified part.
    let kept = &ax[10..500];
    kept.iter().sum::<f64>() / kept.len() as f64
}

#[test]
fn vibration_rectifies_in_the_sensing_element_before_the_chain_filters_it() {
    // K₂A²/2 = 1e-3 · 400 / 2: the element sees the whole shake at the internal rate, so the
    // bias is the same with the chain as without, although the chain passes 3 % of the shake
    // itself (applied after the filter, the term would give 1.5e-4 m/s²).
    let expected = 1e-3 * 20.0 * 20.0 / 2.0;
    let chain = "[imu.chain]\ninternal_rate_hz = 8000\n\
                 accelerometer = { filter = \"butterworth\", order = 2, cutoff_hz = 200 }\n";
    for (name, mean) in [
        ("chain", rectified_mean(chain)),
        ("plain", rectified_mean("")),
    ] {
        assert!(
            (mean / expected - 1.0).abs() < 1e-3,
            "{name}: mean x reading {mean} against K₂A²/2 = {expected}"
        );
    }
}

#[test]
fn the_response_table_is_each_chains_closed_form_and_refuses_a_negative_frequency() {
    let spec: ChainSpec = toml::from_str(CHAIN.trim_start_matches("[imu.chain]\n")).unwrap();
    let setup = ChainSetup::resolve(&spec, 100.0).unwrap();
    let t = setup.response_table(100.0, &[0.0, 12.0, 1130.0]).unwrap();
    let gyro = gyro_chain();
    for (k, f) in [0.0, 12.0, 1130.0].into_iter().enumerate() {
        let h = gyro.response(f);
        assert_eq!(t.column("gyro_gain").unwrap()[k], h.gain);
        assert_eq!(t.column("gyro_phase_rad").unwrap()[k], h.phase_rad);
        assert_eq!(t.column("gyro_delay_s").unwrap()[k], gyro.group_delay_s(f));
        assert_eq!(t.column("alias_hz").unwrap()[k], gyro.alias_hz(f));
        // No accelerometer filter: decimated alone, gain 1 and no delay.
        assert_eq!(t.column("accel_gain").unwrap()[k], 1.0);
        assert_eq!(t.column("accel_delay_s").unwrap()[k], 0.0);
    }
    let e = setup
        .response_table(100.0, &[1.0, -3.0])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("frequencies_hz[1]: -3 is not a frequency"),
        "{e}"
    );
}

/// A part whose accelerometer samples inside at 4 kHz and averages 10 ms, and whose gyroscope
/// samples at `gyro_hz` and averages 5 ms (the SBG Pulse-40 states 4 kHz and 6.6 kHz), read at
/// 100 Hz, shaken along z at 1130 Hz and by random vibration along x.
fn two_rates(gyro_hz: u32) -> String {
    format!(
        "[imu.chain]\naccelerometer_internal_rate_hz = 4000\ngyroscope_internal_rate_hz = {gyro_hz}\n\
         accelerometer = {{ filter = \"moving_average\", taps = 40 }}\n\
         gyroscope = {{ filter = \"moving_average\", taps = {} }}\n\
         [imu.vibration]\nsines = [{{ kind = \"acceleration\", axis = \"z\", frequency_hz = 1130, amplitude = 10 }}]\n\
         random = [{{ kind = \"acceleration\", axis = \"x\", psd = [[20, 1e-2], [1500, 1e-2]] }}]\n",
        gyro_hz / 200
    )
}

#[test]
fn each_sensor_samples_at_its_own_internal_rate_and_reads_through_its_own_chain() {
    let scenario = shaking(1130.0, 4.0, &two_rates(6600));
    let setup = scenario.imu.chain.as_ref().unwrap();
    assert_eq!(setup.decimations, [40, 66, 1]);
    // One period holds the gyroscope's 66 instants and the accelerometer's 40: j/66 = i/40 only
    // where both are a whole number of halves, 0 and 1/2.
    let pattern = setup.motion_pattern();
    assert_eq!(pattern.offsets.len(), 66 + 40 - 2);
    assert_eq!(pattern.sampled[0], [true; 3]);
    let sampled = |k: usize| pattern.sampled.iter().filter(|s| s[k]).count();
    assert_eq!([sampled(0), sampled(1), sampled(2)], [40, 66, 1]);

    let sim = scenario.simulate().unwrap();
    let t = sim.imu.column("t_s").unwrap();
    assert_eq!(t.len(), 401);
    let [accel, gyro, _] = setup.chains(100.0).unwrap();
    let keep = t.iter().position(|&ti| ti >= 0.5).unwrap();
    let centred = |name: &str| {
        let y = &sim.imu.column(name).unwrap()[keep..];
        let mean = y.iter().sum::<f64>() / y.len() as f64;
        y.iter().map(|v| v - mean).collect::<Vec<_>>()
    };
    // The yaw shake through the gyroscope's 66-sample average at 6.6 kHz, the z shake
    // through the accelerometer's 40-sample average at 4 kHz: each at its own chain's gain.
    for (column, amplitude, chain) in [("gyro_z_rad_s", 0.5, &gyro), ("accel_z_m_s2", 10.0, &accel)]
    {
        let h = chain.response(1130.0);
        let (fitted, phase) = sine_fit(&t[keep..], &centred(column), 1130.0);
        assert!(
            (fitted / (amplitude * h.gain) - 1.0).abs() < 1e-3,
            "{column}: {fitted} vs {}",
            amplitude * h.gain
        );
        assert!((phase - h.phase_rad).abs() < 1e-3, "{column}: {phase}");
    }
    assert!((accel.response(1130.0).gain - gyro.response(1130.0).gain).abs() > 0.01);

    // The accelerometer's readings, its random vibration included, do not depend on the
    // gyroscope's rate: it draws its noise at its own instants only.
    let same_rates = shaking(1130.0, 4.0, &two_rates(4000));
    let other = same_rates.simulate().unwrap();
    for column in ["accel_x_m_s2", "accel_z_m_s2"] {
        assert_eq!(
            sim.imu.column(column).unwrap(),
            other.imu.column(column).unwrap(),
            "{column}"
        );
    }
    // Streamed on two threads, the same numbers.
    let streamed = scenario.simulate_streamed(None, RunThreads::Two).unwrap();
    assert!(streamed == sim);
}

#[test]
fn a_preset_carries_its_data_sheets_filter_settings_and_a_scenario_chooses_one() {
    // Every DLPF_CFG row of the MPU-6050 preset has the table's bandwidth and delay.
    let part = imukit::io::presets::load("mpu-6050").unwrap();
    let chains = part.chain.expect("the preset's [chain] table");
    assert_eq!(chains.register, "DLPF_CFG");
    assert!(chains.line.contains("register 26"));
    let table = [
        // (accelerometer Hz, s), (gyroscope Hz, s), gyroscope's internal rate
        ((260.0, 0.0), (256.0, 0.98e-3), 8000.0),
        ((184.0, 2.0e-3), (188.0, 1.9e-3), 1000.0),
        ((94.0, 3.0e-3), (98.0, 2.8e-3), 1000.0),
        ((44.0, 4.9e-3), (42.0, 4.8e-3), 1000.0),
        ((21.0, 8.5e-3), (20.0, 8.3e-3), 1000.0),
        ((10.0, 13.8e-3), (10.0, 13.4e-3), 1000.0),
        ((5.0, 19.0e-3), (5.0, 18.6e-3), 1000.0),
    ];
    assert_eq!(chains.settings.len(), table.len());
    for (k, (accel, gyro, gyro_rate)) in table.into_iter().enumerate() {
        let setup = ChainSetup::resolve(&chains.settings[&k.to_string()], 100.0).unwrap();
        // The part has no magnetometer: it takes internal_rate_hz where the row gives one.
        let mag_rate = if k == 0 { 100.0 } else { 1000.0 };
        assert_eq!(
            setup.internal_rates_hz,
            [1000.0, gyro_rate, mag_rate],
            "DLPF_CFG {k}"
        );
        let [a, g, _] = setup.chains(100.0).unwrap();
        for (chain, (bandwidth_hz, delay_s)) in [(&a, accel), (&g, gyro)] {
            assert!((chain.response(bandwidth_hz).gain - 0.5f64.sqrt()).abs() < 1e-9);
            assert!((chain.group_delay_s(0.0) - delay_s).abs() < 1e-12);
        }
    }

    // A scenario chooses a setting: a 12 Hz yaw read through DLPF_CFG = 3 lags by about the
    // table's 4.8 ms, exactly as that chain's response says.
    let scenario = |chain: &str| {
        let text = format!(
            "rate_hz = 100\nduration_s = 4\n\
             [trajectory]\ntype = \"expression\"\nconstants = {{ f = 12, w = 0.5 }}\n\
             position_m = [0, 0, 0]\nyaw_rad = \"w/(2*pi*f)*(1 - cos(2*pi*f*t))\"\n\
             [imu]\npreset = \"mpu-6050\"\n{chain}"
        );
        ScenarioSpec::from_toml(&text, "dlpf").and_then(|s| s.resolve(std::path::Path::new(".")))
    };
    let sc = scenario("[imu.chain]\nsetting = 3\n").unwrap();
    let [_, gyro, _] = sc.imu.chain.as_ref().unwrap().chains(100.0).unwrap();
    let sim = sc.simulate().unwrap();
    let t = sim.imu.column("t_s").unwrap();
    let keep = t.iter().position(|&ti| ti >= 0.5).unwrap();
    let gz = &sim.imu.column("gyro_z_rad_s").unwrap()[keep..];
    let mean = gz.iter().sum::<f64>() / gz.len() as f64;
    let centred: Vec<f64> = gz.iter().map(|v| v - mean).collect();
    let (amplitude, phase) = sine_fit(&t[keep..], &centred, 12.0);
    let h = gyro.response(12.0);
    // The part's noise (0.005 °/s/√Hz) and resolution leave about 1e-4 of the amplitude.
    assert!(
        (amplitude / (0.5 * h.gain) - 1.0).abs() < 2e-3,
        "{amplitude}"
    );
    assert!(
        (phase - h.phase_rad).abs() < 2e-3,
        "{phase} vs {}",
        h.phase_rad
    );
    let lag_s = -phase / (2.0 * PI * 12.0);
    assert!((lag_s / 4.8e-3 - 1.0).abs() < 0.05, "lag {lag_s} s");

    // A key given beside the setting takes its place; a setting the part lacks, or a setting
    // without a part that has them, is refused by its key with what would do.
    let own =
        scenario("[imu.chain]\nsetting = \"3\"\ngyroscope = { filter = \"none\" }\n").unwrap();
    let setup = own.imu.chain.unwrap();
    assert_eq!(
        setup.low_pass[1],
        imukit::scenario::chain::LowPassSpec::None
    );
    assert_eq!(setup.internal_rates_hz[1], 1000.0);
    let e = scenario("[imu.chain]\nsetting = 7\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("imu.chain.setting: preset mpu-6050's DLPF_CFG has no setting 7 (it has 0, 1, 2, 3, 4, 5, 6)"),
        "{e}"
    );
    let e = ScenarioSpec::from_toml(
        "rate_hz = 100\nduration_s = 1\n[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\n\
         [imu.chain]\nsetting = 3\n",
        "s",
    )
    .and_then(|s| s.resolve(std::path::Path::new(".")))
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with(
            "imu.chain.setting: the IMU without a preset or params has no chain settings"
        ) && e.contains("preset = \"mpu-6050\""),
        "{e}"
    );
}
