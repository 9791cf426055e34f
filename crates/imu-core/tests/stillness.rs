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

/// A walking foot's readings, simplified: quiet stances (white noise on a biased gravity
/// reading) between swings whose motion is far above the noise; `quiet_share` of each second is
/// stance. Returns accelerometer and gyroscope rows and which samples are stance.
fn foot_like(
    seconds: usize,
    quiet_share: f64,
    noise: ReadingNoise,
    accel_bias: [f64; 3],
    seed: u64,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<bool>) {
    let n = seconds * 100;
    let nx: Vec<Vec<f64>> = (0..6)
        .map(|k| {
            let s = if k < 3 { noise.accel } else { noise.gyro };
            noisy(n, s, 0.0, seed * 10 + k)
        })
        .collect();
    let mut accel = Vec::with_capacity(n);
    let mut gyro = Vec::with_capacity(n);
    let mut quiet = Vec::with_capacity(n);
    #[allow(clippy::needless_range_loop)] // one sample of six noise streams
    for i in 0..n {
        let phase = (i % 100) as f64 / 100.0;
        let still = phase < quiet_share;
        // The swing: a bell of 20 m/s² and 6 rad/s over the rest of the second.
        let swing = if still {
            0.0
        } else {
            (std::f64::consts::PI * (phase - quiet_share) / (1.0 - quiet_share)).sin()
        };
        accel.push([
            accel_bias[0] + 20.0 * swing + nx[0][i],
            accel_bias[1] + 5.0 * swing + nx[1][i],
            accel_bias[2] + 9.81 - 10.0 * swing + nx[2][i],
        ]);
        gyro.push([nx[3][i], 6.0 * swing + nx[4][i], 0.5 * swing + nx[5][i]]);
        quiet.push(still);
    }
    (accel, gyro, quiet)
}

#[test]
fn the_noise_is_learnt_from_the_quiet_stretches_of_a_moving_log() {
    use imu_core::stillness::quiet_noise;
    // Three times the noise of a consumer preset, a 0.3 m/s² accelerometer bias, stances a
    // third of each stride: 120 s at 100 Hz, blocks of 10 samples (1200 blocks, ~360 quiet).
    let noise = ReadingNoise {
        accel: 0.03,
        gyro: 0.006,
    };
    let bias = [0.3, -0.1, 0.05];
    for seed in 1..=5 {
        let (accel, gyro, _) = foot_like(120, 0.35, noise, bias, seed);
        let mut room = vec![[0.0; 3]; accel.len() / 10];
        let q = quiet_noise(&accel, &gyro, 10, 9.81, &mut room).expect("quiet stretches");
        // ~330 quiet blocks × 27 degrees of freedom: a variance to about 1.7 %, a standard
        // deviation to 0.9 %; 5 % is more than five of its sigmas.
        for (learnt, truth) in [(q.noise.accel, noise.accel), (q.noise.gyro, noise.gyro)] {
            assert!(
                (learnt / truth - 1.0).abs() < 0.05,
                "seed {seed}: learnt {learnt:.5}, truth {truth}"
            );
        }
        // Gravity as this accelerometer reads it: |g + bias|, to the averaged noise.
        let read = (bias[0].powi(2) + bias[1].powi(2) + (9.81 + bias[2]).powi(2)).sqrt();
        assert!(
            (q.gravity_reading_m_s2 - read).abs() < 1e-3,
            "seed {seed}: {} against {read}",
            q.gravity_reading_m_s2
        );
        // Blocks wholly inside a stance: 3 of every 10 per stride (a few more partly still
        // blocks at the ends of a swing pass too, none far into one).
        assert!(
            (330..=480).contains(&q.quiet_blocks),
            "seed {seed}: {} quiet of {}",
            q.quiet_blocks,
            q.blocks
        );
    }
}

#[test]
fn a_log_that_never_rests_has_no_quiet_noise_and_a_still_log_is_all_quiet() {
    use imu_core::stillness::quiet_noise;
    let noise = ReadingNoise {
        accel: 0.01,
        gyro: 0.002,
    };
    let (accel, gyro, _) = foot_like(60, 0.0, noise, [0.0; 3], 7);
    let mut room = vec![[0.0; 3]; accel.len() / 10];
    assert_eq!(quiet_noise(&accel, &gyro, 10, 9.81, &mut room), None);
    // Still throughout: one population, every block (but the rare false alarm) quiet.
    let accel = rows(
        &noisy(6000, noise.accel, 0.0, 1),
        &noisy(6000, noise.accel, 0.0, 2),
        &noisy(6000, noise.accel, 9.81, 3),
    );
    let gyro = rows(
        &noisy(6000, noise.gyro, 0.01, 4),
        &noisy(6000, noise.gyro, 0.0, 5),
        &noisy(6000, noise.gyro, 0.0, 6),
    );
    let mut room = vec![[0.0; 3]; 600];
    let q = quiet_noise(&accel, &gyro, 10, 9.81, &mut room).unwrap();
    assert!(q.quiet_blocks >= 598, "{} of 600", q.quiet_blocks);
    assert!((q.noise.accel / noise.accel - 1.0).abs() < 0.05);
    assert!((q.noise.gyro / noise.gyro - 1.0).abs() < 0.05);
    // Too little room for the blocks: refused, not cut short.
    assert_eq!(quiet_noise(&accel, &gyro, 10, 9.81, &mut room[..599]), None);
}

/// A foot that rolls while it stands (heel to toe, about the sensor: up to 0.3 rad/s, no
/// velocity) reads rates 150 times its gyroscope's noise: the noise's threshold misses most of
/// its stances. Its stances and swings still form two populations of the SHOE statistic
/// decades apart, and the split between them finds the stances (at most 5 % of the stance
/// samples missed) without calling a moving foot still (at most 1 % of the swing).
/// A rolling foot's readings (see the tests below): `rest` samples standing still, then strides
/// of 1 s at 100 Hz, each a stance of 0.6 s in which the foot rolls heel to toe about the
/// sensor (pitch rate up to 0.3 rad/s, no velocity) and a swing of 0.4 s; the noise, the
/// specific forces, the rates, the speed and whether each sample is a stance (or the rest).
#[allow(clippy::type_complexity)]
fn rolling_foot(
    n: usize,
    rest: usize,
) -> (
    ReadingNoise,
    Vec<[f64; 3]>,
    Vec<[f64; 3]>,
    Vec<f64>,
    Vec<bool>,
) {
    let (fs, f, stride, lift, g, roll) = (100.0, 1.0, 1.4, 0.1, 9.81, 0.3);
    let noise = ReadingNoise {
        accel: 0.02,
        gyro: 0.002,
    };
    let accel_noise = noisy(3 * n, noise.accel, 0.0, 21);
    let gyro_noise = noisy(3 * n, noise.gyro, 0.0, 22);
    let rate = f / 0.4;
    let two_pi = 2.0 * std::f64::consts::PI;
    let (mut accel, mut gyro, mut speed, mut truth) = (vec![], vec![], vec![], vec![]);
    for i in 0..n {
        let u = i.saturating_sub(rest) as f64 / fs * f;
        let phase = u - u.floor();
        let (a, w, v, still) = if i < rest {
            ([0.0, 0.0, g], 0.0, 0.0, true)
        } else if phase < 0.6 {
            // Pitch rate roll·sin(2πφ/0.6), its angle from the integral.
            let x = two_pi * phase / 0.6;
            let theta = roll * 0.6 / (two_pi * f) * (1.0 - x.cos());
            (
                [-g * theta.sin(), 0.0, g * theta.cos()],
                roll * x.sin(),
                0.0,
                true,
            )
        } else {
            let p = (phase - 0.6) / 0.4;
            let ax = stride * (60.0 * p - 180.0 * p * p + 120.0 * p.powi(3)) * rate * rate;
            let az = lift * 32.0 * (1.0 - 6.0 * p + 6.0 * p * p) * rate * rate;
            let vx = stride * 30.0 * p * p * (1.0 - p).powi(2) * rate;
            let vz = lift * 32.0 * p * (1.0 - p) * (1.0 - 2.0 * p) * rate;
            (
                [ax, 0.0, az + g],
                3.0 * (two_pi * p).sin(),
                vx.hypot(vz),
                false,
            )
        };
        accel.push([
            a[0] + accel_noise[3 * i],
            a[1] + accel_noise[3 * i + 1],
            a[2] + accel_noise[3 * i + 2],
        ]);
        gyro.push([
            gyro_noise[3 * i],
            w + gyro_noise[3 * i + 1],
            gyro_noise[3 * i + 2],
        ]);
        speed.push(v);
        truth.push(still);
    }
    (noise, accel, gyro, speed, truth)
}

/// Of the rolling foot's statistics against `threshold`: the stance samples whose whole window
/// is a stance, how many of them it misses, the swing samples (faster than 5 cm/s) and how many
/// of them it calls still.
fn scored(
    statistic: &[f64],
    speed: &[f64],
    truth: &[bool],
    window: usize,
    threshold: f64,
) -> (usize, usize, usize, usize) {
    let n = statistic.len();
    let inner = |i: usize| (i.saturating_sub(window)..(i + window).min(n)).all(|j| truth[j]);
    let stance = (0..n).filter(|&i| inner(i)).count();
    let missed = (0..n)
        .filter(|&i| inner(i) && statistic[i] >= threshold)
        .count();
    let swing = (0..n).filter(|&i| speed[i] > 0.05).count();
    let false_stance = (0..n)
        .filter(|&i| speed[i] > 0.05 && statistic[i] < threshold)
        .count();
    (stance, missed, swing, false_stance)
}

/// A foot that rolls while it stands (heel to toe, about the sensor: up to 0.3 rad/s, no
/// velocity) reads rates 150 times its gyroscope's noise: the noise's threshold misses most of
/// its stances. Its stances and swings still form two populations of the SHOE statistic
/// decades apart, and the split between them finds the stances (at most 5 % of the stance
/// samples missed) without calling a moving foot still (at most 1 % of the swing).
#[test]
fn the_split_between_two_populations_finds_the_stances_of_a_rolling_foot() {
    use imu_core::stillness::{shoe_statistics, shoe_threshold, stance_threshold};
    let n = 6000;
    let (noise, accel, gyro, speed, truth) = rolling_foot(n, 0);
    let window = 5;
    let mut statistic = vec![0.0; n];
    shoe_statistics(&accel, &gyro, 9.81, noise, window, &mut statistic);
    let split = stance_threshold(&statistic).expect("two populations");
    let (stance, by_split, swing, false_stance) = scored(&statistic, &speed, &truth, window, split);
    let by_noise = shoe_threshold(window, 1e-3);
    let (_, missed_by_noise, _, _) = scored(&statistic, &speed, &truth, window, by_noise);
    eprintln!(
        "rolling stance: the noise's threshold {by_noise:.1} misses {missed_by_noise} of {stance} \
         stance samples; the split {split:.1} misses {by_split}, calls {false_stance} of {swing} \
         swing samples still",
    );
    assert!(missed_by_noise * 2 > stance);
    assert!(by_split * 20 <= stance);
    assert!(false_stance * 100 <= swing);
}

/// The same foot after a long rest (as real walks begin and end): the rest is a third
/// population, at the noise, and the split of all the statistics falls between it and the
/// rolling stances, missing most of them. The stances are the lower of the two populations
/// above that split, and the detector's threshold (their mean plus one standard deviation)
/// finds at least 95 % of the stance samples and calls at most 1 % of the swing still.
#[test]
fn a_long_rest_is_a_third_population_and_the_stances_are_still_found() {
    use imu_core::stillness::{shoe_statistics, stance_threshold, two_population_threshold};
    let (n, rest) = (9000, 3000);
    let (noise, accel, gyro, speed, truth) = rolling_foot(n, rest);
    let window = 5;
    let mut statistic = vec![0.0; n];
    shoe_statistics(&accel, &gyro, 9.81, noise, window, &mut statistic);
    let all = two_population_threshold(&statistic).expect("the rest and the rest of the walk");
    let walk = |i: usize| i >= rest + window;
    let walking: Vec<f64> = (0..n).filter(|&i| walk(i)).map(|i| statistic[i]).collect();
    let (speed_w, truth_w): (Vec<f64>, Vec<bool>) = (0..n)
        .filter(|&i| walk(i))
        .map(|i| (speed[i], truth[i]))
        .unzip();
    let (stance, missed_by_all, _, _) = scored(&walking, &speed_w, &truth_w, window, all);
    let learnt = stance_threshold(&statistic).expect("three populations");
    let (_, missed, swing, false_stance) = scored(&walking, &speed_w, &truth_w, window, learnt);
    eprintln!(
        "after a rest: the split of all {all:.1} misses {missed_by_all} of {stance} stance \
         samples; the stance threshold {learnt:.1} misses {missed}, calls {false_stance} of \
         {swing} swing samples still",
    );
    assert!(missed_by_all * 2 > stance);
    assert!(missed * 20 <= stance);
    assert!(false_stance * 100 <= swing);
}

/// A log all at rest, or all in motion, has no second population: no split is learnt.
#[test]
fn one_population_gives_no_split() {
    use imu_core::stillness::two_population_threshold;
    let still: Vec<f64> = noisy(5000, 1.0, 6.0, 31).iter().map(|x| x.abs()).collect();
    assert_eq!(two_population_threshold(&still), None);
    assert_eq!(two_population_threshold(&[]), None);
    assert_eq!(
        two_population_threshold(&[f64::NAN, f64::INFINITY, -1.0]),
        None
    );
}
