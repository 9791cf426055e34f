//! 3D strapdown: stationary, bias growth, classic coning (closed form), and round trips.
use imu_core::earth::FlatEarth;
use imu_core::kinematics::sampled::{SampledAttitude, SampledOptions, truth_from_samples};
use imu_core::strapdown::{
    NavState, RateIncrements, StrapdownError, StrapdownOptions, strapdown_increments,
    strapdown_rates,
};
use imu_core::{Body, Enu, IdealReading, ImuMount, NavFrame, Ned, Rotation, Truth, Vec3};

use crate::common;

const G: f64 = 9.81;

fn stationary_case<N: NavFrame>() {
    // Level, at rest: gyro 0, accelerometer −g_n (specific force), one hour at 100 Hz.
    let f = [0.0, 0.0, N::Z_UP * G];
    let mut nav = RateIncrements::new(
        FlatEarth::<N>::new(G),
        NavState::default(),
        StrapdownOptions::default(),
    )
    .unwrap();
    let mut last = NavState::default();
    for k in 0..=360_000 {
        last = nav.step(k as f64 / 100.0, [0.0; 3], f).unwrap();
    }
    // h·(f₀ + f₁) with h = Δt/2 equals g·Δt bit for bit, so nothing accumulates at all.
    assert_eq!(last.position.to_array(), [0.0; 3]);
    assert_eq!(last.velocity_m_s.to_array(), [0.0; 3]);
    assert_eq!(last.attitude.to_wxyz(), [1.0, 0.0, 0.0, 0.0]);
}

#[test]
fn stationary_ideal_input_keeps_the_initial_state_for_an_hour_enu() {
    stationary_case::<Enu>();
}

#[test]
fn stationary_ideal_input_keeps_the_initial_state_for_an_hour_ned() {
    stationary_case::<Ned>();
}

#[test]
fn accelerometer_bias_gives_half_b_t_squared() {
    let b = 0.01;
    let mut nav = RateIncrements::new(
        FlatEarth::<Enu>::new(G),
        NavState::default(),
        StrapdownOptions::default(),
    )
    .unwrap();
    let mut s = NavState::default();
    for k in 0..=6000 {
        s = nav.step(k as f64 / 100.0, [0.0; 3], [b, 0.0, G]).unwrap();
    }
    let t: f64 = 60.0;
    assert!(
        (s.position.x() - 0.5 * b * t * t).abs() < 1e-9,
        "{}",
        s.position.x()
    );
    assert!(s.position.y().abs() < 1e-12 && s.position.z().abs() < 1e-9);
}

#[test]
fn gyro_bias_gives_about_g_b_t_cubed_over_six() {
    // A bias about body x tilts the platform: the y error grows as g·b·t³/6 (small angles; the
    // exact value is g(t − sin(bt)/b)/b for a rotation at rate b).
    let b = 1e-4;
    let mut nav = RateIncrements::new(
        FlatEarth::<Enu>::new(G),
        NavState::default(),
        StrapdownOptions::default(),
    )
    .unwrap();
    let mut s = NavState::default();
    for k in 0..=6000 {
        s = nav
            .step(k as f64 / 100.0, [b, 0.0, 0.0], [0.0, 0.0, G])
            .unwrap();
    }
    let t: f64 = 60.0;
    let approx = G * b * t.powi(3) / 6.0;
    // Tilting about x by bt turns the measured +g towards −y (nav): sign negative.
    assert!(
        (s.position.y() + approx).abs() < 1e-3 * approx,
        "{} vs {}",
        s.position.y(),
        -approx
    );
}

// Classic coning: q(t) = [cos(a/2), 0, sin(a/2)cos Ωt, sin(a/2) sin Ωt] (docs/models.md §4).
const CONE_A: f64 = 0.1;
const CONE_W: f64 = 2.0 * std::f64::consts::PI * 5.0;

fn cone_q(t: f64) -> [f64; 4] {
    let (s, c) = (CONE_A / 2.0).sin_cos();
    [c, 0.0, s * (CONE_W * t).cos(), s * (CONE_W * t).sin()]
}

fn cone_w(t: f64) -> [f64; 3] {
    let sa = CONE_A.sin();
    [
        -2.0 * CONE_W * (CONE_A / 2.0).sin().powi(2),
        -CONE_W * sa * (CONE_W * t).sin(),
        CONE_W * sa * (CONE_W * t).cos(),
    ]
}

#[test]
fn coning_gyro_matches_the_closed_form_body_rate() {
    let t: Vec<f64> = (0..=400).map(|k| k as f64 / 2000.0).collect();
    let q: Vec<[f64; 4]> = t.iter().map(|&s| cone_q(s)).collect();
    let pos = vec![[0.0; 3]; t.len()];
    let mut out = vec![Truth::<Enu>::default(); t.len()];
    truth_from_samples(
        &t,
        &pos,
        SampledAttitude::Quaternion(&q),
        SampledOptions {
            order: 8,
            ..SampledOptions::default()
        },
        &mut out,
    )
    .unwrap();
    let gyro: Vec<IdealReading> = out
        .iter()
        .map(|s| ImuMount::<Enu>::default().read(s))
        .collect();
    let scale = CONE_W * CONE_A.sin();
    for (k, r) in gyro.iter().enumerate() {
        let got = r.gyro_rad_s.to_array();
        for (i, w) in cone_w(t[k]).iter().enumerate() {
            assert!((got[i] - w).abs() < 1e-8 * scale, "k = {k}, axis {i}");
        }
    }
}

/// Attitude error (rad) after 30 s of coning at 200 Hz from exact angle increments.
fn coning_attitude_error(coning: bool) -> f64 {
    let rate = 200.0;
    let n = (30.0 * rate) as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 / rate).collect();
    let sa = CONE_A.sin();
    // ∫ω_b dt in closed form over each interval.
    let dth: Vec<[f64; 3]> = (0..=n)
        .map(|k| {
            if k == 0 {
                return [0.0; 3];
            }
            let (t0, t1) = (t[k - 1], t[k]);
            [
                -2.0 * CONE_W * (CONE_A / 2.0).sin().powi(2) * (t1 - t0),
                sa * ((CONE_W * t1).cos() - (CONE_W * t0).cos()),
                sa * ((CONE_W * t1).sin() - (CONE_W * t0).sin()),
            ]
        })
        .collect();
    let f = vec![[0.0; 3]; n + 1];
    let initial = NavState::<FlatEarth<Enu>> {
        attitude: Rotation::from_wxyz(cone_q(0.0)).unwrap(),
        ..NavState::default()
    };
    let mut out = vec![NavState::<FlatEarth<Enu>>::default(); n + 1];
    let opts = StrapdownOptions {
        coning,
        ..StrapdownOptions::default()
    };
    strapdown_increments(
        FlatEarth::new(0.0),
        &t,
        &dth,
        &f,
        None,
        initial,
        opts,
        &mut out,
    )
    .unwrap();
    let truth = Rotation::<Body, Enu>::from_wxyz(cone_q(t[n])).unwrap();
    out[n].attitude.quaternion().angle_to(truth.quaternion())
}

#[test]
fn coning_correction_removes_the_coning_drift() {
    let (with, without) = (coning_attitude_error(true), coning_attitude_error(false));
    eprintln!(
        "classic coning, 30 s at 200 Hz: attitude error {with:e} rad with correction, {without:e} rad without"
    );
    assert!(without > 1e-3, "{without}");
    assert!(with < 1e-2 * without, "{with} vs {without}");
}

fn helix_error(rate: f64, seconds: f64) -> f64 {
    let common::HelixData {
        t,
        truth,
        gyro,
        accel: acc,
    } = common::helix(rate, seconds);
    let s0 = NavState {
        t_s: 0.0,
        attitude: truth[0].attitude,
        velocity_m_s: truth[0].velocity_m_s,
        position: truth[0].position_m,
    };
    let mut out = vec![NavState::<FlatEarth<Enu>>::default(); t.len()];
    strapdown_rates(
        FlatEarth::new(G),
        &t,
        &gyro,
        &acc,
        None,
        s0,
        StrapdownOptions::default(),
        &mut out,
    )
    .unwrap();
    out.iter()
        .zip(&truth)
        .map(|(a, b)| (a.position - b.position_m).norm())
        .fold(0.0, f64::max)
}

#[test]
fn round_trip_on_a_rolling_helix_converges_at_second_order() {
    let e = [
        helix_error(100.0, 20.0),
        helix_error(200.0, 20.0),
        helix_error(400.0, 20.0),
    ];
    eprintln!("rolling helix, 20 s: max position error {e:?} m at 100/200/400 Hz");
    assert!(e[2] < 1e-3, "{e:?}");
    for k in 0..2 {
        let order = (e[k] / e[k + 1]).log2();
        assert!((order - 2.0).abs() < 0.25, "observed order {order} ({e:?})");
    }
}

#[test]
fn bad_strapdown_input_is_refused_with_its_index() {
    let mut nav = RateIncrements::new(
        FlatEarth::<Enu>::new(G),
        NavState::default(),
        StrapdownOptions::default(),
    )
    .unwrap();
    nav.step(0.0, [0.0; 3], [0.0, 0.0, G]).unwrap();
    assert_eq!(
        nav.step(0.0, [0.0; 3], [0.0, 0.0, G]),
        Err(StrapdownError::TimeNotIncreasing { index: 1 })
    );
    assert_eq!(
        nav.step(0.01, [f64::NAN, 0.0, 0.0], [0.0, 0.0, G]),
        Err(StrapdownError::NotFinite { index: 1 })
    );
    let mut out = vec![NavState::<FlatEarth<Enu>>::default(); 2];
    assert!(matches!(
        strapdown_rates(
            FlatEarth::new(G),
            &[0.0, 0.1],
            &[[0.0; 3]],
            &[[0.0; 3]; 2],
            None,
            NavState::default(),
            StrapdownOptions::default(),
            &mut out
        ),
        Err(StrapdownError::LengthMismatch {
            field: "gyro_rad_s",
            ..
        })
    ));
    let _ = Vec3::<Enu>::zeros();
}

fn helix_error_rk4(rate: f64, seconds: f64, substeps: usize) -> f64 {
    use imu_core::strapdown::rk4::strapdown_rates_rk4;
    let common::HelixData {
        t,
        truth,
        gyro,
        accel: acc,
    } = common::helix(rate, seconds);
    let s0 = NavState {
        t_s: 0.0,
        attitude: truth[0].attitude,
        velocity_m_s: truth[0].velocity_m_s,
        position: truth[0].position_m,
    };
    let mut out = vec![NavState::<FlatEarth<Enu>>::default(); t.len()];
    strapdown_rates_rk4(
        FlatEarth::new(G),
        &t,
        &gyro,
        &acc,
        None,
        s0,
        StrapdownOptions::default(),
        substeps,
        &mut out,
    )
    .unwrap();
    out.iter()
        .zip(&truth)
        .map(|(a, b)| (a.position - b.position_m).norm())
        .fold(0.0, f64::max)
}

#[test]
fn rk4_round_trip_converges_at_fourth_order_and_meets_1e_6_m_after_60_s_at_1_khz() {
    let e = [
        helix_error_rk4(25.0, 20.0, 1),
        helix_error_rk4(50.0, 20.0, 1),
        helix_error_rk4(100.0, 20.0, 1),
    ];
    eprintln!("rolling helix, RK4, 20 s: max position error {e:?} m at 25/50/100 Hz");
    for k in 0..2 {
        let order = (e[k] / e[k + 1]).log2();
        assert!(order > 3.7, "observed order {order} ({e:?})");
    }
    let long = helix_error_rk4(1000.0, 60.0, 4);
    eprintln!("rolling helix, RK4 (4 substeps), 60 s at 1 kHz: {long:e} m");
    assert!(long <= 1e-6, "{long}");
    let mut out = vec![NavState::<FlatEarth<Enu>>::default(); 5];
    assert!(
        imu_core::strapdown::rk4::strapdown_rates_rk4(
            FlatEarth::new(G),
            &[0.0, 1.0, 2.0, 3.0, 4.0],
            &[[0.0; 3]; 5],
            &[[0.0; 3]; 5],
            None,
            NavState::default(),
            StrapdownOptions::default(),
            1,
            &mut out
        )
        .is_err()
    );
}
