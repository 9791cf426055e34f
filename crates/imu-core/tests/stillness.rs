//! The rest detector: a still log with large biases is still up to where motion starts; vibration
//! above the noise is not rest.
use imu_core::stillness::{ReadingNoise, initial_rest};

use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// Three axes' readings as rows.
fn rows(x: &[f64], y: &[f64], z: &[f64]) -> Vec<[f64; 3]> {
    x.iter()
        .zip(y)
        .zip(z)
        .map(|((a, b), c)| [*a, *b, *c])
        .collect()
}

fn noisy(n: usize, sigma: f64, offset: f64, seed: u64) -> Vec<f64> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let z: f64 = StandardNormal.sample(&mut rng);
            offset + sigma * z
        })
        .collect()
}

#[test]
fn a_still_log_with_large_biases_is_still_and_a_start_of_motion_is_found() {
    let noise = ReadingNoise {
        accel: 0.04,
        gyro: 0.01,
    };
    // 20 s at 100 Hz still (gyroscope biases of 0.35 rad/s), then an acceleration that
    // grows at 0.5 m/s³ on x.
    let n = 3000;
    let mut ax = noisy(n, noise.accel, 0.2, 1);
    for (k, a) in ax.iter_mut().enumerate().skip(2000) {
        *a += 0.5 * (k - 2000) as f64 / 100.0;
    }
    let ay = noisy(n, noise.accel, -0.1, 2);
    let az = noisy(n, noise.accel, 9.81, 3);
    let (gx, gy, gz) = (
        noisy(n, noise.gyro, 0.35, 4),
        noisy(n, noise.gyro, -0.2, 5),
        noisy(n, noise.gyro, 0.1, 6),
    );
    let still = initial_rest(&rows(&ax, &ay, &az), &rows(&gx, &gy, &gz), noise, 50);
    // Found within two blocks of the true start (the last still block is left out).
    assert!((1850..=2000).contains(&still), "{still}");
}

#[test]
fn vibration_above_the_noise_is_not_rest() {
    let noise = ReadingNoise {
        accel: 0.01,
        gyro: 0.001,
    };
    let n = 2000;
    let shaking = noisy(n, 0.05, 0.0, 7);
    let quiet = noisy(n, noise.accel, 9.81, 8);
    let g = noisy(n, noise.gyro, 0.0, 9);
    assert_eq!(
        initial_rest(
            &rows(&shaking, &quiet, &quiet),
            &rows(&g, &g, &g),
            noise,
            50
        ),
        0
    );
    assert_eq!(
        initial_rest(&rows(&quiet, &quiet, &quiet), &rows(&g, &g, &g), noise, 1),
        0
    );
}

/// A foot walking at one stride a second: 60 % stance, then a swing forward 1.4 m with a quintic
/// profile and a 0.1 m lift. The SHOE detector on readings with white noise finds the stances
/// (few stance samples missed) and never calls a moving foot (faster than 0.05 m/s) still.
#[test]
fn shoe_finds_the_stances_of_a_walking_foot() {
    use imu_core::stillness::{detect_stance, shoe_threshold};
    let (fs, f, stride, lift, g) = (100.0, 1.0, 1.4, 0.1, 9.81);
    let noise = ReadingNoise {
        accel: 0.02,
        gyro: 0.002,
    };
    let n = 6000;
    let accel_noise = noisy(3 * n, noise.accel, 0.0, 11);
    let gyro_noise = noisy(3 * n, noise.gyro, 0.0, 12);
    let rate = f / 0.4;
    let (mut accel, mut gyro, mut speed, mut truth) = (vec![], vec![], vec![], vec![]);
    for i in 0..n {
        let u = i as f64 / fs * f;
        let phase = u - u.floor();
        let (ax, az, vx, vz, still) = if phase < 0.6 {
            (0.0, 0.0, 0.0, 0.0, true)
        } else {
            let p = (phase - 0.6) / 0.4;
            (
                stride * (60.0 * p - 180.0 * p * p + 120.0 * p.powi(3)) * rate * rate,
                lift * 32.0 * (1.0 - 6.0 * p + 6.0 * p * p) * rate * rate,
                stride * 30.0 * p * p * (1.0 - p).powi(2) * rate,
                lift * 32.0 * p * (1.0 - p) * (1.0 - 2.0 * p) * rate,
                false,
            )
        };
        accel.push([
            ax + accel_noise[3 * i],
            accel_noise[3 * i + 1],
            az + g + accel_noise[3 * i + 2],
        ]);
        gyro.push([
            gyro_noise[3 * i],
            gyro_noise[3 * i + 1],
            gyro_noise[3 * i + 2],
        ]);
        speed.push(vx.hypot(vz));
        truth.push(still);
    }
    let window = 5;
    let mut stance = vec![false; n];
    detect_stance(
        &accel,
        &gyro,
        g,
        noise,
        window,
        shoe_threshold(window, 1e-3),
        &mut stance,
    );
    // Stance samples a window or more from either end of their stance.
    let inner = |i: usize| (i.saturating_sub(window)..(i + window).min(n)).all(|j| truth[j]);
    let (stance_inner, missed) = (0..n)
        .filter(|&i| inner(i))
        .fold((0, 0), |(s, m), i| (s + 1, m + usize::from(!stance[i])));
    let false_stance = (0..n).filter(|&i| stance[i] && speed[i] > 0.05).count();
    eprintln!("SHOE: missed {missed} of {stance_inner} stance samples, {false_stance} false");
    assert!(
        missed * 100 <= stance_inner,
        "missed {missed} of {stance_inner}"
    );
    assert_eq!(false_stance, 0);
}
