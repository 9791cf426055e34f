//! The rest detector: a still log with large biases is still up to where motion starts; vibration
//! above the noise is not rest.
use imu_core::stillness::{ReadingNoise, initial_rest};

use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

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
    let still = initial_rest([&ax, &ay, &az], [&gx, &gy, &gz], noise, 50);
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
        initial_rest([&shaking, &quiet, &quiet], [&g, &g, &g], noise, 50),
        0
    );
    assert_eq!(
        initial_rest([&quiet, &quiet, &quiet], [&g, &g, &g], noise, 1),
        0
    );
}
