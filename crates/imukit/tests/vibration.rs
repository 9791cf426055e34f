//! The mount's vibration (`[imu.vibration]`): sines added to the ideal inputs exactly in the
//! sensor's turned axes, the turn of coning as its closed form and a strapdown following the
//! sensor, random vibration with the PSD of its table (Welch), the same through a signal chain
//! times the chain's |H|² summed over the aliases, the truth the vehicle's motion and what the
//! vibration did (through the chain as the part reads it), runs seeded, and the tables the
//! scenario cannot have refused by key.
use core::f64::consts::PI;

use imukit::io::columns::VIBRATION_TRUTH_COLUMNS;
use imukit::run::navigate::{InitialState, NavScheme, NavSetup, integrate};
use imukit::{Scenario, ScenarioSpec, Simulation};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

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
fn sines_are_added_in_the_sensors_axes_and_the_truth_says_what_they_did() {
    // Rolling at 0.1·sin(2π·3t) rad/s turns the sensor by θ(t) = 0.1/(6π)·(1 − cos 6πt) about
    // x: its accelerometer reads gravity in its own axes, (0, g sin θ, g cos θ), plus its shake.
    let sines = "[imu.vibration]\nsines = [\
                 { kind = \"acceleration\", axis = \"z\", frequency_hz = 7, amplitude = 2, phase_rad = 0.3 },\
                 { kind = \"angular-rate\", axis = \"x\", frequency_hz = 3, amplitude = 0.1 }]\n";
    let sim = at_rest(100.0, 3.0, sines).simulate().unwrap();
    let t = column(&sim, "t_s");
    let [ax, ay, az, gx] = [
        "accel_x_m_s2",
        "accel_y_m_s2",
        "accel_z_m_s2",
        "gyro_x_rad_s",
    ]
    .map(|name| column(&sim, name));
    let truth = |name: &str| sim.truth.column(name).unwrap();
    let [vx, vy, vz, wx, turn] = [
        "vib_accel_x_m_s2",
        "vib_accel_y_m_s2",
        "vib_accel_z_m_s2",
        "vib_gyro_x_rad_s",
        "mount_rot_x_rad",
    ]
    .map(truth);
    let g = 9.81;
    for i in 0..t.len() {
        let theta = 0.1 / (6.0 * PI) * (1.0 - (6.0 * PI * t[i]).cos());
        let shake = 2.0 * (2.0 * PI * 7.0 * t[i] + 0.3).sin();
        let expect = [0.0, g * theta.sin(), g * theta.cos() + shake];
        for (got, want) in [ax[i], ay[i], az[i]].iter().zip(expect) {
            assert!((got - want).abs() < 1e-12, "t = {}: {got} vs {want}", t[i]);
        }
        assert!((gx[i] - 0.1 * (6.0 * PI * t[i]).sin()).abs() < 1e-12);
        // The truth: the sensor's turn, and the inputs less the vehicle's (0, 0, g).
        assert!(
            (turn[i] - theta).abs() < 1e-14,
            "t = {}: {} vs {theta}",
            t[i],
            turn[i]
        );
        assert!(vx[i] == 0.0 && (vy[i] - ay[i]).abs() < 1e-15);
        assert!((vz[i] - (az[i] - g)).abs() < 1e-14 && wx[i] == gx[i]);
    }
    let plain = at_rest(100.0, 3.0, "").simulate().unwrap();
    let width = plain.truth.columns.len();
    assert_eq!(sim.truth.columns[width..], VIBRATION_TRUTH_COLUMNS);
    for (row, motion) in sim
        .truth
        .data
        .chunks_exact(width + 9)
        .zip(plain.truth.data.chunks_exact(width))
    {
        assert!(
            row[..width] == *motion,
            "the vehicle's motion, without the vibration"
        );
    }
}

/// θ, Ω of the coning below: rates `θΩ·(0, cos Ωt, sin Ωt)`, 10 Hz.
const THETA: f64 = 0.01;
const CONE_HZ: f64 = 10.0;

/// The sensor's axes against the vehicle's under that coning, closed form:
/// `exp((w₀ + Ωx̂)t) ⊗ exp(−Ωt x̂)`, `w₀ = (0, θΩ, 0)` (`imu-core/tests/coning.rs`).
fn coned(t: f64) -> UnitQuaternion<f64> {
    let omega = 2.0 * PI * CONE_HZ;
    UnitQuaternion::from_scaled_axis(Vector3::new(omega, THETA * omega, 0.0) * t)
        * UnitQuaternion::from_scaled_axis(Vector3::new(-omega * t, 0.0, 0.0))
}

#[test]
fn coning_turns_the_sensor_as_the_closed_form_and_a_strapdown_follows_the_sensor() {
    let a = THETA * 2.0 * PI * CONE_HZ;
    let cone = format!(
        "[imu.vibration]\nsines = [\
         {{ kind = \"angular-rate\", axis = \"y\", frequency_hz = {CONE_HZ}, amplitude = {a}, phase_rad = {} }},\
         {{ kind = \"angular-rate\", axis = \"z\", frequency_hz = {CONE_HZ}, amplitude = {a} }}]\n",
        PI / 2.0
    );
    let seconds = 60.0;
    let sim = at_rest(400.0, seconds, &cone).simulate().unwrap();
    let t = column(&sim, "t_s");
    let turn = sim
        .truth
        .triples(&["mount_rot_x_rad", "mount_rot_y_rad", "mount_rot_z_rad"])
        .unwrap();
    let accel = sim
        .imu
        .triples(&["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"])
        .unwrap();
    let mut worst: f64 = 0.0;
    for ((&ti, r), f) in t.iter().zip(&turn).zip(&accel) {
        let mount = UnitQuaternion::from_scaled_axis(Vector3::from(*r));
        worst = worst.max(mount.angle_to(&coned(ti)));
        // The accelerometer reads gravity in the sensor's turned axes.
        let up = mount.inverse() * Vector3::new(0.0, 0.0, 9.81);
        assert!((Vector3::from(*f) - up).norm() < 1e-12, "t = {ti}");
    }
    // The turn about x after 60 s is θ²Ω/2·T = 0.188 rad.
    let drift = THETA * THETA * 2.0 * PI * CONE_HZ / 2.0 * seconds;
    let last = turn[turn.len() - 1];
    assert!((last[0] / drift - 1.0).abs() < 1e-3, "{last:?} vs {drift}");
    assert!(
        worst < 1e-9,
        "the truth's turn departs from the closed form by {worst} rad"
    );
    // The readings integrated (fourth order) follow the sensor, not the vehicle, which is at
    // rest: the attitude is the truth's ⊗ the mount's turn, and the position stays put.
    let init = InitialState::from_table(&sim.truth).unwrap();
    let setup = NavSetup {
        scheme: NavScheme::Rk4 { substeps: 4 },
        ..NavSetup::default()
    };
    let nav = integrate(&sim.imu, &init, &setup).unwrap();
    let n = nav.rows() - 1;
    let q = ["q_w", "q_x", "q_y", "q_z"].map(|c| nav.column(c).unwrap()[n]);
    let estimate = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let sensor = UnitQuaternion::from_scaled_axis(Vector3::from(last));
    assert!(
        estimate.angle_to(&sensor) < 1e-7,
        "{}",
        estimate.angle_to(&sensor)
    );
    assert!((estimate.angle() / drift - 1.0).abs() < 1e-3);
    let p = ["pos_x_m", "pos_y_m", "pos_z_m"].map(|c| nav.column(c).unwrap()[n]);
    assert!(p.iter().all(|v| v.abs() < 1e-3), "{p:?}");
}

#[test]
fn through_a_chain_the_truth_has_the_shake_as_the_chain_reads_it() {
    // A 1130 Hz yaw shake through the gyroscope's 200 Hz low-pass at 8 kHz, read at 100 Hz.
    let text = "[imu.chain]\ninternal_rate_hz = 8000\n\
                gyroscope = { filter = \"butterworth\", order = 2, cutoff_hz = 200 }\n\
                [imu.vibration]\nsines = [\
                { kind = \"angular-rate\", axis = \"z\", frequency_hz = 1130, amplitude = 0.5 }]\n";
    let sc = at_rest(100.0, 4.0, text);
    let sim = sc.simulate().unwrap();
    let [_, gyro, _] = sc.imu.chain.as_ref().unwrap().chains(100.0).unwrap();
    let h = gyro.response(1130.0);
    let t = column(&sim, "t_s");
    let (gz, shaken, turn) = (
        column(&sim, "gyro_z_rad_s"),
        sim.truth.column("vib_gyro_z_rad_s").unwrap(),
        sim.truth.column("mount_rot_z_rad").unwrap(),
    );
    let omega = 2.0 * PI * 1130.0;
    for i in 0..t.len() {
        // The vehicle is at rest: all the gyroscope reads is the shake.
        assert_eq!(gz[i], shaken[i]);
        assert!((turn[i] - 0.5 / omega * (1.0 - (omega * t[i]).cos())).abs() < 1e-13);
        if t[i] >= 0.5 {
            let expect = 0.5 * h.gain * (omega * t[i] + h.phase_rad).sin();
            assert!(
                (shaken[i] - expect).abs() < 1e-6,
                "t = {}: {} vs {expect}",
                t[i],
                shaken[i]
            );
        }
    }
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

#[test]
fn readings_of_given_samples_shake_as_a_simulation_and_a_chain_is_refused() {
    let shake = "[imu.vibration]\nsines = [\
                 { kind = \"angular-rate\", axis = \"y\", frequency_hz = 4, amplitude = 0.3 },\
                 { kind = \"acceleration\", axis = \"x\", frequency_hz = 9, amplitude = 1.5 }]\n";
    let sc = at_rest(100.0, 2.0, shake);
    let sim = sc.simulate().unwrap();
    let truth = sc
        .trajectory
        .truth::<imukit::core::Enu>(&sc.t_s.to_vec())
        .unwrap();
    let readings = sc
        .imu
        .readings(&truth, sc.gravity_m_s2, sc.sample_rate_hz, None)
        .unwrap();
    let table = imukit::Table::from_readings(&column(&sim, "t_s"), &readings, sc.imu.kind);
    assert!(table == sim.imu);
    let chained = at_rest(
        100.0,
        1.0,
        "[imu.chain]\ninternal_rate_hz = 1000\n\
         accelerometer = { filter = \"moving_average\", taps = 10 }\n",
    );
    let e = chained
        .imu
        .readings(&truth, chained.gravity_m_s2, 100.0, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("imu.chain: a chain reads the motion at its internal rate"),
        "{e}"
    );
}
