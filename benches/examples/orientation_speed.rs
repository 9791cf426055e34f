//! The robust filter's per-sample update time on recorded readings, for a comparison with
//! another filter's core on the same file (`benches/broad/vqf_speed.cpp` reads the same format;
//! `benches/broad/broad.py --speed` runs both).
//!
//! Usage: `orientation_speed FILE RATE_HZ [REPEATS]`. FILE holds little-endian f64 rows of nine
//! values: accelerometer (m/s², specific force), gyroscope (rad/s), magnetometer (any unit), in
//! one body frame. Prints `6D <ns>` and `9D <ns>`: the best of REPEATS (default 10) runs over
//! the whole file, each sample one `update` call.
#![allow(missing_docs)]

use std::process::ExitCode;
use std::time::Instant;

use imu_core::Ned;
use imu_core::orientation::{FilterInput, OrientationFilter, RobustFilter, RobustParams};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(rate)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: orientation_speed FILE RATE_HZ [REPEATS]");
        return ExitCode::from(2);
    };
    let Ok(rate) = rate.parse::<f64>() else {
        eprintln!("RATE_HZ: not a number: {rate}");
        return ExitCode::from(2);
    };
    let repeats = match args.get(3).map(|r| r.parse::<usize>()) {
        None => 10,
        Some(Ok(r)) if r > 0 => r,
        Some(_) => {
            eprintln!("REPEATS: a positive whole number");
            return ExitCode::from(2);
        }
    };
    let bytes = match std::fs::read(path) {
        Ok(b) if b.len() % 72 == 0 && !b.is_empty() => b,
        Ok(b) => {
            eprintln!(
                "{path}: {} bytes is not a whole number of 9-value f64 rows",
                b.len()
            );
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("{path}: {e}");
            return ExitCode::from(2);
        }
    };
    let values: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    let rows: Vec<FilterInput> = values
        .chunks_exact(9)
        .map(|r| FilterInput {
            accel_m_s2: [r[0], r[1], r[2]],
            gyro_rad_s: [r[3], r[4], r[5]],
            mag_ut: [r[6], r[7], r[8]],
            interval_s: None,
        })
        .collect();
    for magnetometer in [false, true] {
        let params = RobustParams {
            sample_rate_hz: rate,
            magnetometer,
            ..RobustParams::default()
        };
        let mut best = f64::INFINITY;
        let mut sink = 0.0;
        for _ in 0..repeats {
            let Ok(mut filter) = RobustFilter::new(params) else {
                eprintln!("RATE_HZ: the filter refuses {rate}");
                return ExitCode::from(2);
            };
            let start = Instant::now();
            for row in &rows {
                match OrientationFilter::<Ned>::update(&mut filter, row) {
                    Ok(Some(e)) => sink += e.orientation.quaternion().w,
                    Ok(None) => {}
                    Err(e) => {
                        eprintln!("{path}: {e}");
                        return ExitCode::from(2);
                    }
                }
            }
            best = best.min(start.elapsed().as_secs_f64());
        }
        // The sum keeps the estimates from being optimised away.
        std::hint::black_box(sink);
        let name = if magnetometer { "9D" } else { "6D" };
        println!("{name} {:.1}", best / rows.len() as f64 * 1e9);
    }
    ExitCode::SUCCESS
}
