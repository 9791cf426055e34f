//! The mount's vibration (`[imu.vibration]`): sines added to the ideal inputs exactly, random
//! vibration with the PSD of its table (Welch), the same through a signal chain times the
//! chain's |H|² summed over the aliases, the truth left the vehicle's motion, runs seeded, and
//! the tables the scenario cannot have refused by key.
use core::f64::consts::PI;

use imukit::{Scenario, ScenarioSpec, Simulation};

/// A body at rest, level, at `rate_hz` for `seconds`, ideal accelerometer and gyroscope, with
/// `extra` TOML after the `[imu]` table.
fn at_rest(rate_hz: f64, seconds: f64, extra: &str) -> Scenario {
    let text = format!(
        "rate_hz = {rate_hz}\nduration_s = {seconds}\n\
         [trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\n\
         [imu]\nkind = \"accel-gyro\"\nseed = 5\n{extra}"
    );
    ScenarioSpec::from_toml(&text, "rest")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap()
}

fn column(sim: &Simulation, name: &str) -> Vec<f64> {
    sim.imu.column(name).unwrap()
}

/// Welch's one-sided PSD of `x` (sampled at `fs`) at `f`: Hann-windowed segments of `n`
/// samples, no overlap, averaged; also the number of segments.
fn welch(x: &[f64], fs: f64, n: usize, f: f64) -> (f64, usize) {
    let w: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos())
        .collect();
    let energy: f64 = w.iter().map(|v| v * v).sum();
    let segments = x.len() / n;
    let mut sum = 0.0;
    for s in 0..segments {
        let seg = &x[s * n..(s + 1) * n];
        let mean = seg.iter().sum::<f64>() / n as f64;
        let (mut re, mut im) = (0.0, 0.0);
        for (i, (&v, &wi)) in seg.iter().zip(&w).enumerate() {
            let (sin, cos) = (2.0 * PI * f * i as f64 / fs).sin_cos();
            re += wi * (v - mean) * cos;
            im -= wi * (v - mean) * sin;
        }
        sum += 2.0 * (re * re + im * im) / (fs * energy);
    }
    (sum / segments as f64, segments)
}

#[test]
fn sines_are_added_to_the_ideal_inputs_and_the_truth_stays_the_motion() {
    let sines = "[imu.vibration]\nsines = [\
                 { kind = \"acceleration\", axis = \"z\", frequency_hz = 7, amplitude = 2, phase_rad = 0.3 },\
                 { kind = \"angular-rate\", axis = \"x\", frequency_hz = 3, amplitude = 0.1 }]\n";
    let sim = at_rest(100.0, 3.0, sines).simulate().unwrap();
    let t = column(&sim, "t_s");
    let (az, gx, ax) = (
        column(&sim, "accel_z_m_s2"),
        column(&sim, "gyro_x_rad_s"),
        column(&sim, "accel_x_m_s2"),
    );
    for i in 0..t.len() {
        let expect_az = 9.81 + 2.0 * (2.0 * PI * 7.0 * t[i] + 0.3).sin();
        assert!(
            (az[i] - expect_az).abs() < 1e-12,
            "t = {}: {} vs {expect_az}",
            t[i],
            az[i]
        );
        assert!((gx[i] - 0.1 * (2.0 * PI * 3.0 * t[i]).sin()).abs() < 1e-12);
        assert_eq!(ax[i], 0.0);
    }
    let plain = at_rest(100.0, 3.0, "").simulate().unwrap();
    assert!(
        sim.truth == plain.truth,
        "the truth is the motion, without the vibration"
    );
}

#[test]
fn random_vibration_has_the_psd_of_its_table() {
    // 0.02 m²/s⁴/Hz from 1 to 40 Hz at 100 Hz: variance 0.02·39 = 0.78 (m/s²)².
    let random = "[imu.vibration]\nrandom = [\
                  { kind = \"acceleration\", axis = \"z\", psd = [[1, 0.02], [40, 0.02]] }]\n";
    let sim = at_rest(100.0, 2000.0, random).simulate().unwrap();
    let az: Vec<f64> = column(&sim, "accel_z_m_s2")
        .iter()
        .map(|a| a - 9.81)
        .collect();
    let n = az.len() as f64;
    let var = az.iter().map(|a| a * a).sum::<f64>() / n;
    // Correlated over about 1/(2·40 Hz): some 160 000 independent samples; 5σ.
    let tolerance = 5.0 * (2.0 / 160_000.0_f64).sqrt();
    assert!(
        (var / 0.78 - 1.0).abs() < tolerance + 0.01,
        "variance {var}"
    );
    for f in [5.0, 12.5, 25.0, 35.0] {
        let (psd, k) = welch(&az, 100.0, 256, f);
        // Each averaged periodogram's relative standard deviation is 1/√K; 5σ.
        let band = 5.0 / (k as f64).sqrt();
        assert!(
            (psd / 0.02 - 1.0).abs() < band,
            "{f} Hz: {psd} (band {band})"
        );
    }
    let (outside, _) = welch(&az, 100.0, 256, 47.0);
    assert!(outside < 0.002, "47 Hz: {outside}");
    // The gyroscope feels none of it; a Monte Carlo run draws its own numbers, the same each
    // time.
    assert!(column(&sim, "gyro_z_rad_s").iter().all(|w| *w == 0.0));
    let short = at_rest(100.0, 10.0, random);
    let run = |r| short.simulate_run(r).unwrap().imu;
    assert!(run(0) == run(0) && run(0) != run(1));
}

#[test]
fn random_vibration_through_a_chain_has_the_input_psd_times_the_response_over_its_aliases() {
    // Flat 0.01 m²/s⁴/Hz from 1 to 450 Hz sampled at 1 kHz, a second-order low-pass at 30 Hz,
    // every 10th sample kept: at f the output holds every alias f + k·100 Hz ≤ 500 Hz.
    let text = "[imu.chain]\ninternal_rate_hz = 1000\n\
                accelerometer = { filter = \"butterworth\", order = 2, cutoff_hz = 30 }\n\
                [imu.vibration]\nrandom = [\
                { kind = \"acceleration\", axis = \"z\", psd = [[1, 0.01], [450, 0.01]] }]\n";
    let sc = at_rest(100.0, 2000.0, text);
    let sim = sc.simulate().unwrap();
    let az: Vec<f64> = column(&sim, "accel_z_m_s2")
        .iter()
        .map(|a| a - 9.81)
        .collect();
    let [accel, _, _] = sc.imu.chain.as_ref().unwrap().chains(100.0).unwrap();
    // Away from the table's 1 Hz edge, which the shaping filter's 2 Hz bins at 1 kHz round off.
    for f in [12.0, 20.0, 35.0] {
        let expected: f64 = (0..5)
            .flat_map(|k| [100.0 * k as f64 + f, 100.0 * (k + 1) as f64 - f])
            .filter(|&g| (1.0..=450.0).contains(&g))
            .map(|g| 0.01 * accel.response(g).gain.powi(2))
            .sum();
        let (psd, k) = welch(&az, 100.0, 256, f);
        let band = 5.0 / (k as f64).sqrt();
        assert!(
            (psd / expected - 1.0).abs() < band,
            "{f} Hz: {psd} vs {expected}"
        );
    }
    // Streamed on two threads, the same numbers.
    let streamed = sc
        .simulate_streamed(None, imukit::run::pipeline::RunThreads::Two)
        .unwrap();
    assert!(streamed == sim);
}

#[test]
fn vibration_the_scenario_cannot_have_is_refused_by_its_key() {
    let refused = |extra: &str| {
        match ScenarioSpec::from_toml(
        &format!(
            "rate_hz = 100\nduration_s = 1\n[trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\n[imu]\n{extra}"
        ),
        "s",
    )
    .and_then(|s| s.resolve(std::path::Path::new(".")))
    {
        Ok(_) => panic!("{extra} accepted"),
        Err(e) => e.to_string(),
    }
    };
    let e = refused(
        "[imu.vibration]\nrandom = [{ kind = \"acceleration\", axis = \"z\", psd = [[10, 1], [60, 1]] }]\n",
    );
    assert!(
        e.starts_with("imu.vibration.random[0].psd: reaches 60 Hz")
            && e.contains("internal_rate_hz"),
        "{e}"
    );
    let e = refused(
        "[imu.vibration]\nrandom = [{ kind = \"acceleration\", axis = \"z\", psd = [[10, 1], [5, 1]] }]\n",
    );
    assert!(
        e.starts_with("imu.vibration.random[0].psd[1]: frequencies must increase"),
        "{e}"
    );
    let e = refused(
        "[imu.vibration]\nsines = [{ kind = \"acceleration\", axis = \"w\", frequency_hz = 5, amplitude = 1 }]\n",
    );
    assert!(e.contains("unknown variant `w`"), "{e}");
    let e = refused(
        "[imu.vibration]\nsines = [{ kind = \"acceleration\", axis = \"z\", frequency_hz = -5, amplitude = 1 }]\n",
    );
    assert!(e.starts_with("imu.vibration.sines[0].frequency_hz"), "{e}");
}
