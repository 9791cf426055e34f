//! The logger's clock (`[imu.clock]`): the readings' stamps carry its offset, drift and jitter,
//! the readings and the truth keep the true instants, and the jitter is seeded.
use imukit::run::pipeline::RunThreads;
use imukit::{Scenario, ScenarioSpec};

fn turning(clock: &str) -> Scenario {
    let text = format!(
        "rate_hz = 200\nduration_s = 50\n\
         [trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\nyaw_rad = \"0.3*t\"\n\
         [imu]\nkind = \"accel-gyro\"\nseed = 9\n{clock}"
    );
    ScenarioSpec::from_toml(&text, "clock")
        .unwrap()
        .resolve(std::path::Path::new("."))
        .unwrap()
}

#[test]
fn the_stamps_carry_the_clocks_offset_drift_and_jitter() {
    let plain = turning("").simulate().unwrap();
    let t = plain.imu.column("t_s").unwrap();
    let skewed = turning("[imu.clock]\noffset_s = 0.5\ndrift_ppm = 100\n")
        .simulate()
        .unwrap();
    let stamps = skewed.imu.column("t_s").unwrap();
    for (ti, si) in t.iter().zip(&stamps) {
        assert!((si - (ti + 0.5 + 1e-4 * ti)).abs() < 1e-12, "{ti}: {si}");
    }
    // The readings are the same, taken at the true instants; the truth keeps its times.
    assert_eq!(
        skewed.imu.column("gyro_z_rad_s"),
        plain.imu.column("gyro_z_rad_s")
    );
    assert!(skewed.truth == plain.truth);
    // Jitter of 20 µs: the stamps' scatter about the true times, within 5σ of its sampling
    // error (10 001 stamps).
    let sc = turning("[imu.clock]\njitter_s = 2e-5\n");
    let jittered = sc.simulate().unwrap();
    let residual: Vec<f64> = jittered
        .imu
        .column("t_s")
        .unwrap()
        .iter()
        .zip(&t)
        .map(|(s, ti)| s - ti)
        .collect();
    let n = residual.len() as f64;
    let mean = residual.iter().sum::<f64>() / n;
    let sd = (residual.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    assert!((sd / 2e-5 - 1.0).abs() < 5.0 / (2.0 * n).sqrt(), "sd {sd}");
    assert!(mean.abs() < 5.0 * 2e-5 / n.sqrt(), "mean {mean}");
    // Seeded: streamed on two threads the same stamps; another run other ones.
    assert!(sc.simulate_streamed(None, RunThreads::Two).unwrap() == jittered);
    let run = |r| sc.simulate_run(r).unwrap().imu.column("t_s").unwrap();
    assert!(run(3) == run(3) && run(3) != run(4));
}

#[test]
fn a_clock_that_cannot_be_is_refused_by_its_key() {
    for (clock, key) in [
        ("jitter_s = -1e-6", "imu.clock.jitter_s: must be ≥ 0"),
        ("drift_ppm = -2e6", "imu.clock.drift_ppm"),
        ("offset = 1", "unknown field `offset`"),
    ] {
        let text = format!(
            "rate_hz = 10\nduration_s = 1\n[trajectory]\ntype = \"expression\"\nposition_m = [0, 0, 0]\n\
             [imu]\n[imu.clock]\n{clock}\n"
        );
        let e = ScenarioSpec::from_toml(&text, "s")
            .and_then(|s| s.resolve(std::path::Path::new(".")))
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "{clock}: {e}");
    }
}
