//! Runs one bench's workload a fixed number of times, for a profiler or an instruction count
//! (see the crate's documentation). Usage: `workload NAME [REPEATS]`; the names are listed
//! when NAME is not one of them.
#![allow(missing_docs)]

use imu_benches::{BenchEarth, StrapdownInput, earth_start, propagate};
use imu_core::earth::{FlatEarth, Wgs84};
use imu_core::fusion::{BASE_STATES, FULL_STATES};
use imu_core::strapdown::NavState;
use imu_core::{Enu, Ned};

const NAMES: [&str; 11] = [
    "strapdown/3d_rates",
    "strapdown/3d_increments_flat",
    "strapdown/3d_increments_earth",
    "fusion/propagate",
    "fusion/propagate_36_states",
    "fusion/propagate_covariance_20hz",
    "fusion/propagate_covariance_20hz_36_states",
    "fusion/propagate_earth",
    "fusion/propagate_36_states_earth",
    "fusion/propagate_covariance_20hz_earth",
    "fusion/propagate_covariance_20hz_36_states_earth",
];

/// One run of the workload; returns a number from its result so that none is optimised away.
fn run(name: &str) -> Option<f64> {
    let n = 100_000;
    let input = StrapdownInput::new(n);
    let mut flat_out = vec![NavState::<FlatEarth<Enu>>::default(); n];
    let mut earth_out = vec![NavState::<Wgs84<Ned>>::default(); n];
    Some(match name {
        "strapdown/3d_rates" => {
            input.rates_flat(&mut flat_out);
            flat_out[n - 1].velocity_m_s.x()
        }
        "strapdown/3d_increments_flat" => {
            let flat = FlatEarth::new(9.81);
            input.increments(flat, NavState::default(), &mut flat_out);
            flat_out[n - 1].velocity_m_s.x()
        }
        "strapdown/3d_increments_earth" => {
            input.increments(Wgs84::default(), earth_start(), &mut earth_out);
            earth_out[n - 1].velocity_m_s.x()
        }
        "fusion/propagate" => fused::<FlatEarth<Enu>, BASE_STATES>(0.0),
        "fusion/propagate_36_states" => fused::<FlatEarth<Enu>, FULL_STATES>(0.0),
        "fusion/propagate_covariance_20hz" => fused::<FlatEarth<Enu>, BASE_STATES>(0.05),
        "fusion/propagate_covariance_20hz_36_states" => fused::<FlatEarth<Enu>, FULL_STATES>(0.05),
        "fusion/propagate_earth" => fused::<Wgs84<Ned>, BASE_STATES>(0.0),
        "fusion/propagate_36_states_earth" => fused::<Wgs84<Ned>, FULL_STATES>(0.0),
        "fusion/propagate_covariance_20hz_earth" => fused::<Wgs84<Ned>, BASE_STATES>(0.05),
        "fusion/propagate_covariance_20hz_36_states_earth" => {
            fused::<Wgs84<Ned>, FULL_STATES>(0.05)
        }
        _ => return None,
    })
}

fn fused<E: BenchEarth, const S: usize>(interval_s: f64) -> f64 {
    propagate::<E, S>(10_000, interval_s).sigmas()[0]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_default();
    let repeats: usize = args.next().and_then(|r| r.parse().ok()).unwrap_or(10);
    let mut sum = 0.0;
    for _ in 0..repeats {
        match run(&name) {
            Some(x) => sum += x,
            None => {
                eprintln!("workload NAME [REPEATS]; NAME one of: {}", NAMES.join(", "));
                std::process::exit(2);
            }
        }
    }
    println!("{sum}");
}
