//! Orientation from IMU readings: the e-compass on a grid of attitudes, every filter on ideal
//! static data, gyroscope-bias estimation by the Kalman filters, refusals.
use imu_core::orientation::{
    Complementary, DistanceStats, Estimate, FilterInput, KalmanFilter, KalmanParams, Madgwick,
    Mahony, OrientError, OrientationFilter, ecompass, quaternion_distance,
};
use imu_core::{AccelSign, Body, Enu, EulerZyx, NavFrame, Ned, Rotation, Vec3};

const G: f64 = 9.81;

/// Ideal readings of a body at rest with attitude `r` in a field `field_n` (nav frame).
fn at_rest<N: NavFrame>(r: &Rotation<Body, N>, field_n: Vec3<N>, sign: AccelSign) -> FilterInput {
    let to_body = r.inverse();
    let f = to_body.apply(-N::gravity(G)).to_array();
    FilterInput {
        accel_m_s2: match sign {
            AccelSign::SpecificForce => f,
            AccelSign::Matlab => f.map(|v| -v),
        },
        gyro_rad_s: [0.0; 3],
        mag_ut: to_body.apply(field_n).to_array(),
        interval_s: None,
    }
}

/// A field of 50 µT pointing to true north, 60° below the horizon, in `N`.
fn north_field<N: NavFrame>() -> Vec3<N> {
    let ned = Vec3::<Ned>::new(25.0, 0.0, 50.0 * 60f64.to_radians().sin());
    N::from_ned().apply(ned)
}

fn grid() -> impl Iterator<Item = EulerZyx> {
    (0..11).flat_map(|i| {
        (0..9).flat_map(move |j| {
            (0..10).map(move |k| {
                EulerZyx::new(
                    (-170.0 + 34.0 * i as f64).to_radians(),
                    (-80.0 + 20.0 * j as f64).to_radians(),
                    (-175.0 + 35.0 * k as f64).to_radians(),
                )
            })
        })
    })
}

fn ecompass_grid<N: NavFrame>() {
    let mut worst = 0.0f64;
    for sign in [AccelSign::SpecificForce, AccelSign::Matlab] {
        for e in grid() {
            let truth = Rotation::<Body, N>::from_euler(e);
            let s = at_rest(&truth, north_field::<N>(), sign);
            let got = ecompass::<N>(s.accel_m_s2, s.mag_ut, sign).unwrap();
            worst = worst.max(quaternion_distance(&got, &truth));
        }
    }
    assert!(worst <= 1e-9, "{}: worst error {worst:e} rad", N::NAME);
}

#[test]
fn ecompass_returns_the_true_attitude_over_a_grid_in_ned_and_enu_with_both_signs() {
    ecompass_grid::<Ned>();
    ecompass_grid::<Enu>();
}

#[test]
fn ecompass_yaw_is_measured_from_magnetic_north() {
    // MATLAB's default field: declination atan2(−2.4169, 27.5550) = −5.013°.
    let field = Ned::default_magnetic_field_ut();
    let declination = (-2.4169f64).atan2(27.5550);
    let truth = Rotation::<Body, Ned>::from_euler(EulerZyx::new(0.7, 0.1, -0.2));
    let s = at_rest(&truth, field, AccelSign::Matlab);
    let got = ecompass::<Ned>(s.accel_m_s2, s.mag_ut, AccelSign::Matlab)
        .unwrap()
        .to_euler();
    assert!((got.yaw_rad - (0.7 - declination)).abs() < 1e-12, "{got:?}");
    assert!((got.pitch_rad - 0.1).abs() < 1e-12 && (got.roll_rad + 0.2).abs() < 1e-12);
}

#[test]
fn ecompass_refuses_degenerate_readings() {
    let e = |a, m| ecompass::<Ned>(a, m, AccelSign::Matlab).unwrap_err();
    assert!(
        matches!(e([0.0; 3], [1.0, 0.0, 0.0]), OrientError::Degenerate { what } if what.contains("accelerometer reading is zero"))
    );
    assert!(
        matches!(e([0.0, 0.0, 9.81], [0.0; 3]), OrientError::Degenerate { what } if what.contains("magnetometer reading is zero"))
    );
    assert!(
        matches!(e([0.0, 0.0, 9.81], [0.0, 0.0, 40.0]), OrientError::Degenerate { what } if what.contains("parallel"))
    );
    assert_eq!(
        e([f64::NAN, 0.0, 9.81], [1.0, 0.0, 0.0]),
        OrientError::NotFinite {
            field: "accelerometer"
        }
    );
    let msg = e([0.0, 0.0, 9.81], [0.0, 0.0, -40.0]).to_string();
    assert!(msg.contains("parallel to gravity"), "{msg}");
}

/// Every filter, with and without a magnetometer where it has one, in `N` and `sign`.
fn every_filter<N: NavFrame>(
    sign: AccelSign,
) -> Vec<(&'static str, bool, Box<dyn OrientationFilter<N>>)> {
    let p = KalmanParams {
        accel_sign: sign,
        ..KalmanParams::default()
    };
    vec![
        (
            "imufilter",
            false,
            Box::new(KalmanFilter::<N>::imu(p).unwrap()),
        ),
        (
            "ahrsfilter",
            true,
            Box::new(KalmanFilter::<N>::ahrs(p).unwrap()),
        ),
        (
            "complementary",
            true,
            Box::new(Complementary::new(100.0, 0.01, 0.01, true, sign).unwrap()),
        ),
        (
            "complementary (no mag)",
            false,
            Box::new(Complementary::new(100.0, 0.01, 0.01, false, sign).unwrap()),
        ),
        (
            "madgwick",
            true,
            Box::new(Madgwick::new(100.0, 0.041, true, sign).unwrap()),
        ),
        (
            "madgwick (no mag)",
            false,
            Box::new(Madgwick::new(100.0, 0.033, false, sign).unwrap()),
        ),
        (
            "mahony",
            true,
            Box::new(Mahony::new(100.0, 1.0, 0.3, true, sign).unwrap()),
        ),
        (
            "mahony (no mag)",
            false,
            Box::new(Mahony::new(100.0, 1.0, 0.3, false, sign).unwrap()),
        ),
    ]
}

fn static_hold<N: NavFrame>(sign: AccelSign) {
    let truth = Rotation::<Body, N>::from_euler(EulerZyx::new(0.5, 0.2, -0.3));
    // Without a magnetometer the heading is relative to the start: yaw 0.
    let level_yaw = Rotation::<Body, N>::from_euler(EulerZyx::new(0.0, 0.2, -0.3));
    let s = at_rest(&truth, north_field::<N>(), sign);
    for (name, mag, mut f) in every_filter::<N>(sign) {
        let expected = if mag { truth } else { level_yaw };
        let mut stats = DistanceStats::default();
        for _ in 0..2000 {
            let est: Estimate<N> = f.update(&s).unwrap().unwrap();
            stats.push(quaternion_distance(&est.orientation, &expected));
        }
        assert!(
            stats.max() < 1e-9,
            "{} {name} {sign:?}: max {:e} rad",
            N::NAME,
            stats.max()
        );
    }
}

#[test]
fn every_filter_holds_the_true_orientation_on_ideal_static_data() {
    for sign in [AccelSign::SpecificForce, AccelSign::Matlab] {
        static_hold::<Ned>(sign);
        static_hold::<Enu>(sign);
    }
}

/// Runs a level static IMU with gyroscope bias `bias` through a Kalman filter for `seconds`.
fn estimated_bias<N: NavFrame>(magnetometer: bool, bias: [f64; 3], seconds: f64) -> [f64; 3] {
    let p = KalmanParams::default();
    let mut f = if magnetometer {
        KalmanFilter::<N>::ahrs(p).unwrap()
    } else {
        KalmanFilter::<N>::imu(p).unwrap()
    };
    let mut s = at_rest(
        &Rotation::<Body, N>::identity(),
        north_field::<N>(),
        AccelSign::Matlab,
    );
    s.gyro_rad_s = bias;
    for _ in 0..(seconds * p.sample_rate_hz) as usize {
        f.update(&s).unwrap();
    }
    f.state().gyroscope_offset()
}

#[test]
fn kalman_filters_estimate_a_constant_gyroscope_bias() {
    // Level: the accelerometer sees roll and pitch errors, so the x and y biases are observable
    // to the IMU filter; the AHRS also sees heading, hence z.
    let bias = [0.02, -0.015, 0.01];
    for (frame, imu, ahrs) in [
        (
            "NED",
            estimated_bias::<Ned>(false, [bias[0], bias[1], 0.0], 60.0),
            estimated_bias::<Ned>(true, bias, 60.0),
        ),
        (
            "ENU",
            estimated_bias::<Enu>(false, [bias[0], bias[1], 0.0], 60.0),
            estimated_bias::<Enu>(true, bias, 60.0),
        ),
    ] {
        for k in 0..2 {
            assert!(
                (imu[k] / bias[k] - 1.0).abs() < 0.05,
                "{frame} imufilter {imu:?}"
            );
        }
        for k in 0..3 {
            assert!(
                (ahrs[k] / bias[k] - 1.0).abs() < 0.05,
                "{frame} ahrsfilter {ahrs:?}"
            );
        }
    }
}

#[test]
fn decimation_gives_one_estimate_per_block() {
    let p = KalmanParams {
        decimation: 4,
        ..KalmanParams::default()
    };
    let mut f = KalmanFilter::<Ned>::imu(p).unwrap();
    let s = at_rest(
        &Rotation::<Body, Ned>::identity(),
        north_field::<Ned>(),
        AccelSign::Matlab,
    );
    let outputs: Vec<bool> = (0..12).map(|_| f.update(&s).unwrap().is_some()).collect();
    assert_eq!(outputs.iter().filter(|o| **o).count(), 3);
    assert!(outputs[3] && outputs[7] && outputs[11]);
}

#[test]
fn bad_parameters_and_readings_are_named_and_leave_the_state_unchanged() {
    let bad = |p: KalmanParams| KalmanFilter::<Ned>::imu(p).unwrap_err().to_string();
    assert!(
        bad(KalmanParams {
            sample_rate_hz: 0.0,
            ..KalmanParams::default()
        })
        .contains("SampleRate = 0")
    );
    assert!(
        bad(KalmanParams {
            decimation: 0,
            ..KalmanParams::default()
        })
        .contains("DecimationFactor")
    );
    assert!(
        bad(KalmanParams {
            gyroscope_noise: -1.0,
            ..KalmanParams::default()
        })
        .contains("GyroscopeNoise = -1")
    );
    assert!(
        bad(KalmanParams {
            linear_acceleration_decay: 1.5,
            ..KalmanParams::default()
        })
        .contains("LinearAccelerationDecayFactor = 1.5: must be in [0, 1]")
    );
    assert!(Madgwick::new(f64::NAN, 0.1, false, AccelSign::Matlab).is_err());
    assert!(
        Complementary::new(100.0, 2.0, 0.01, true, AccelSign::Matlab)
            .unwrap_err()
            .to_string()
            .contains("AccelerometerGain")
    );
    let mut f = KalmanFilter::<Ned>::ahrs(KalmanParams::default()).unwrap();
    let s = at_rest(
        &Rotation::<Body, Ned>::identity(),
        north_field::<Ned>(),
        AccelSign::Matlab,
    );
    f.update(&s).unwrap();
    let before = *f.state();
    let mut nan = s;
    nan.mag_ut[1] = f64::NAN;
    assert_eq!(
        f.update(&nan).unwrap_err(),
        OrientError::NotFinite {
            field: "magnetometer"
        }
    );
    assert_eq!(*f.state(), before);
    for dt in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        let late = FilterInput {
            interval_s: Some(dt),
            ..s
        };
        let e = f.update(&late).unwrap_err().to_string();
        assert!(
            e.contains("sample interval") && e.contains("must be"),
            "{e}"
        );
        assert_eq!(*f.state(), before);
    }
}

#[test]
fn quaternion_distance_is_the_rotation_angle_to_full_precision() {
    let a = Rotation::<Body, Ned>::from_euler(EulerZyx::new(0.3, -0.2, 0.1));
    for angle in [1e-12, 1e-6, 0.5, 3.0] {
        let b = a.then(&Rotation::<Ned, Ned>::from_euler(EulerZyx::new(
            angle, 0.0, 0.0,
        )));
        let d = quaternion_distance(&a, &b);
        assert!((d - angle).abs() <= 1e-15 + 1e-13 * angle, "{angle}: {d}");
    }
    let mut stats = DistanceStats::default();
    for d in [3.0, 4.0] {
        stats.push(d);
    }
    assert_eq!((stats.count(), stats.max(), stats.last()), (2, 4.0, 4.0));
    assert!((stats.rms() - 12.5f64.sqrt()).abs() < 1e-15);
}

/// The attitude `Rz(ψ) Rx(φ)` with `ψ = 0.4 t`, `φ = 0.3 sin(0.5 t)` (rad), and its exact body
/// rate `(φ̇, ψ̇ sin φ, ψ̇ cos φ)`: `C_nbᵀ Ċ_nb = [ω×]` with `ω = Rxᵀ ẑ ψ̇ + x̂ φ̇`.
fn swaying(t: f64) -> (EulerZyx, [f64; 3]) {
    let (psi_dot, phi, phi_dot) = (0.4, 0.3 * (0.5 * t).sin(), 0.15 * (0.5 * t).cos());
    (
        EulerZyx::new(psi_dot * t, 0.0, phi),
        [phi_dot, psi_dot * phi.sin(), psi_dot * phi.cos()],
    )
}

/// Sample times over 20 s at a nominal 100 Hz: regular; or each moved by up to ±1 ms (every
/// interval within ±20 % of 10 ms) with ten gaps of 30 ms (two samples lost each).
fn stamps(jittered: bool) -> Vec<f64> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..=2000)
        .filter(|k| !jittered || !(k % 200 == 100 || k % 200 == 101))
        .map(|k| {
            let t = f64::from(k) / 100.0;
            if jittered && k > 0 {
                t + 1e-3 * uniform()
            } else {
                t
            }
        })
        .collect()
}

/// The largest angle between a filter's estimates and the swaying truth at `times`, with each
/// sample's interval given (`timed`) or left to the filter's 100 Hz.
fn swaying_error<N: NavFrame>(f: &mut dyn OrientationFilter<N>, times: &[f64], timed: bool) -> f64 {
    let mut worst = 0.0f64;
    for (k, &t) in times.iter().enumerate() {
        let (euler, w) = swaying(t);
        let truth = Rotation::<Body, N>::from_euler(euler);
        let mut input = at_rest(&truth, north_field::<N>(), AccelSign::SpecificForce);
        input.gyro_rad_s = w;
        input.interval_s = (timed && k > 0).then(|| t - times[k - 1]);
        // Without a magnetometer the heading is relative to the start, which has yaw 0.
        let est = f.update(&input).unwrap().unwrap();
        worst = worst.max(quaternion_distance(&est.orientation, &truth));
    }
    worst
}

#[test]
fn regular_stamps_give_the_fixed_rate_estimates_to_rounding() {
    let times = stamps(false);
    let decimated = || {
        Box::new(
            KalmanFilter::<Ned>::ahrs(KalmanParams {
                decimation: 4,
                accel_sign: AccelSign::SpecificForce,
                ..KalmanParams::default()
            })
            .unwrap(),
        ) as Box<dyn OrientationFilter<Ned>>
    };
    let filters = || {
        let mut all: Vec<_> = every_filter::<Ned>(AccelSign::SpecificForce)
            .into_iter()
            .map(|(name, _, f)| (name, f))
            .collect();
        all.push(("ahrsfilter, DecimationFactor 4", decimated()));
        all
    };
    for ((name, mut timed), (_, mut fixed)) in filters().into_iter().zip(filters()) {
        let (mut worst, mut lag) = (0.0f64, 0.0f64);
        for (k, &t) in times.iter().enumerate() {
            let (euler, w) = swaying(t);
            let truth = Rotation::<Body, Ned>::from_euler(euler);
            let mut input = at_rest(&truth, north_field::<Ned>(), AccelSign::SpecificForce);
            input.gyro_rad_s = w;
            let b = fixed.update(&input).unwrap();
            input.interval_s = (k > 0).then(|| t - times[k - 1]);
            let a = timed.update(&input).unwrap();
            assert_eq!(a.is_some(), b.is_some(), "{name}");
            if let (Some(a), Some(b)) = (a, b) {
                worst = worst.max(quaternion_distance(&a.orientation, &b.orientation));
                lag = lag.max(quaternion_distance(&b.orientation, &truth));
            }
        }
        // The stamps k/100 differ from 1/100 s intervals by rounding (1e-17 s a sample). Only
        // Madgwick's step amplifies it: its gradient is normalised, so a misfit at rounding
        // level still turns the estimate by β·Δt, in a direction rounding decides; the two
        // runs then differ by less than the filter's own error.
        let bound = if name.starts_with("madgwick") {
            lag
        } else {
            1e-11
        };
        assert!(worst < bound, "{name}: {worst:e} rad");
    }
}

#[test]
fn each_sample_is_integrated_over_its_own_interval_through_jitter_and_gaps() {
    let (regular, jittered) = (stamps(false), stamps(true));
    let gaps = jittered.windows(2).filter(|w| w[1] - w[0] > 0.025).count();
    assert_eq!(gaps, 10);
    for (name, mag, _) in every_filter::<Ned>(AccelSign::SpecificForce) {
        let fresh = || {
            every_filter::<Ned>(AccelSign::SpecificForce)
                .into_iter()
                .find(|(n, ..)| *n == name)
                .unwrap()
                .2
        };
        let e_regular = swaying_error(fresh().as_mut(), &regular, true);
        let e_stamped = swaying_error(fresh().as_mut(), &jittered, true);
        let e_fixed = swaying_error(fresh().as_mut(), &jittered, false);
        // The regular run measures the filter's own lag on this motion (0.3–6 mrad); stamps
        // that jitter and skip change where the motion is sampled, not how it is integrated.
        assert!(
            e_stamped <= 2.5 * e_regular && e_stamped < 1e-2,
            "{name}: {e_stamped:e} rad with stamps, {e_regular:e} rad on the regular grid"
        );
        // Without a magnetometer nothing corrects the heading: taken at 100 Hz instead of over
        // each interval, it drifts by the time the stamps say passed (20 ms a gap).
        if !mag {
            assert!(
                e_fixed > 10.0 * e_stamped,
                "{name}: {e_fixed:e} rad at a fixed rate, {e_stamped:e} rad with stamps"
            );
        }
    }
}
