//! One preset of each grade checked against its data sheet the way a user would check a part:
//! a static log of the simulated part, identified (`imukit identify`'s fit), and each noise
//! figure the data sheet gives compared with the identified coefficient's 95 % interval; each
//! bias instability the data sheet does not give is not resolved.
//!
//! A figure stands for any value that rounds to it (0.15 °/√h for 0.145–0.155), so the
//! comparison is between that span and the interval. Each axis is an independent 95 % interval:
//! a figure is met when at least two of the three axes' intervals reach it (a figure the model
//! reproduces fails that with probability 3·0.05² ≈ 0.7 %; the seeds are fixed, so the test is
//! deterministic). Rates are high enough for the quantisation of the consumer part to add under
//! 0.2 % to its white noise (`Δ²/(6 f_s)` to N²).
use std::path::Path;

use imu_core::allan::NoiseTerm;
use imukit::ScenarioSpec;
use imukit::io::datasheet::{Entry, Term};
use imukit::io::params::Sensor;
use imukit::io::presets;
use imukit::run::allan::allan;

const AXES: [&str; 3] = ["x", "y", "z"];

/// Identifies `preset` at rest for `duration_s` at `rate_hz` and compares every noise figure of
/// `sensors` with its data sheet. Returns how many figures were compared.
fn identified_as_its_data_sheet_says(
    preset: &str,
    rate_hz: f64,
    duration_s: f64,
    sensors: &[Sensor],
) -> usize {
    let text = format!(
        "rate_hz = {rate_hz}\nduration_s = {duration_s}\nnav_frame = \"NED\"\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu]\npreset = \"{preset}\"\nseed = 5\n"
    );
    let sim = ScenarioSpec::from_toml(&text, "static.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate_run(0)
        .unwrap();
    let file = presets::load(preset).unwrap();
    let sheet = file.datasheet.unwrap();
    let mut columns = Vec::new();
    for s in sensors {
        let (prefix, unit) = match s {
            Sensor::Gyroscope => ("gyro", "rad_s"),
            _ => ("accel", "m_s2"),
        };
        for a in AXES {
            let c = format!("{prefix}_{a}_{unit}");
            columns.push((c.clone(), sim.imu.column(&c).unwrap()));
        }
    }
    let result = allan(&columns, rate_hz).unwrap();
    let mut compared = 0;
    for (k, &sensor) in sensors.iter().enumerate() {
        let fits = &result.noise[3 * k..3 * k + 3];
        for (term, symbol) in [
            (Term::NoiseDensity, NoiseTerm::White),
            (Term::BiasInstability, NoiseTerm::BiasInstability),
        ] {
            let what = format!("{preset} {} {}", sensor.key(), term.key());
            match sheet.entry(sensor, term) {
                Some(Entry::Given(f)) => {
                    let mut low = f.clone();
                    let mut high = f.clone();
                    let r = f.rounding();
                    low.quoted = f.quoted.iter().map(|q| q - r).collect();
                    high.quoted = f.quoted.iter().map(|q| q + r).collect();
                    let (lo, hi) = (
                        low.model_value(term).unwrap()[0],
                        high.model_value(term).unwrap()[0],
                    );
                    let met: Vec<bool> = fits
                        .iter()
                        .map(|c| {
                            let e = c.fit.term(symbol);
                            e.resolved && e.lower <= hi && lo <= e.upper
                        })
                        .collect();
                    let shown: Vec<String> = fits
                        .iter()
                        .map(|c| {
                            let e = c.fit.term(symbol);
                            format!("{}: {:.4e} … {:.4e}", c.column, e.lower, e.upper)
                        })
                        .collect();
                    println!(
                        "{what}: data sheet {} {} → {lo:.4e} … {hi:.4e}; identified {shown:?}",
                        f.quoted[0], f.unit
                    );
                    assert!(
                        met.iter().filter(|&&m| m).count() >= 2,
                        "{what}: the data sheet's {} {} ({lo:.4e} … {hi:.4e} in the model) is \
                         outside the identified 95 % intervals {shown:?}",
                        f.quoted[0],
                        f.unit
                    );
                    compared += 1;
                }
                Some(Entry::NotGiven) if term == Term::BiasInstability => {
                    let resolved = fits.iter().filter(|c| c.fit.term(symbol).resolved).count();
                    println!("{what}: not given; resolved on {resolved} of 3 axes");
                    assert!(
                        resolved <= 1,
                        "{what}: not given, yet resolved on {resolved} axes"
                    );
                    compared += 1;
                }
                _ => {}
            }
        }
    }
    compared
}

#[test]
fn a_consumer_part_mpu_6050_is_identified_as_its_data_sheet_says() {
    let n = identified_as_its_data_sheet_says(
        "mpu-6050",
        100.0,
        3600.0,
        &[Sensor::Gyroscope, Sensor::Accelerometer],
    );
    assert_eq!(n, 4);
}

#[test]
fn an_industrial_part_mti_1_is_identified_as_its_data_sheet_says() {
    let n = identified_as_its_data_sheet_says(
        "mti-1",
        100.0,
        7200.0,
        &[Sensor::Gyroscope, Sensor::Accelerometer],
    );
    assert_eq!(n, 4);
}

#[test]
fn a_tactical_part_stim300_is_identified_as_its_data_sheet_says() {
    let n = identified_as_its_data_sheet_says(
        "stim300",
        10.0,
        4.0 * 3600.0,
        &[Sensor::Gyroscope, Sensor::Accelerometer],
    );
    assert_eq!(n, 4);
}

#[test]
fn a_navigation_part_hg9900_is_identified_as_its_data_sheet_says() {
    // The brochure gives the gyroscopes' angle random walk only (the accelerometers are
    // noise-free in the preset).
    let n = identified_as_its_data_sheet_says("hg9900", 100.0, 3600.0, &[Sensor::Gyroscope]);
    assert_eq!(n, 2);
}
