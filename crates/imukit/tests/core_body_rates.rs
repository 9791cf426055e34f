//! Body-rate trajectories (MATLAB kinematicTrajectory): exact cases, MATLAB's platform example,
//! and inverting the ideal IMU of a trajectory.
use crate::common;

use imu_core::kinematics::KinematicsError;
use imu_core::kinematics::body_rates::{BodyRateStart, truth_from_body_rates};
use imu_core::{Enu, Ned, Truth, Vec3};
use imukit::motion::analytic::{AnalyticOptions, truth_from_motion};

#[test]
fn constant_acceleration_and_rate_are_integrated_exactly() {
    let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
    let n = t.len();
    let mut out = vec![Truth::<Enu>::default(); n];
    truth_from_body_rates(
        &t,
        &vec![[0.3, -0.2, 0.1]; n],
        &vec![[0.0; 3]; n],
        None,
        BodyRateStart::default(),
        6,
        &mut out,
    )
    .unwrap();
    let last = out[n - 1];
    for (got, a) in last.position_m.to_array().iter().zip([0.3, -0.2, 0.1]) {
        assert!((got - 0.5 * a * 1.0).abs() < 1e-14, "{got}");
    }
    assert!((last.velocity_m_s.x() - 0.3).abs() < 1e-14);
}

#[test]
fn matlab_platform_example_turns_360_in_4_s_then_in_2_s() {
    // fs = 100; angVelBody(1:400, 3) = 2π/4; angVelBody(401:600, 3) = 2π/2.
    let t: Vec<f64> = (0..600).map(|k| k as f64 / 100.0).collect();
    let w: Vec<[f64; 3]> = (0..600)
        .map(|k| {
            [
                0.0,
                0.0,
                if k < 400 {
                    std::f64::consts::FRAC_PI_2
                } else {
                    std::f64::consts::PI
                },
            ]
        })
        .collect();
    let mut out = vec![Truth::<Ned>::default(); 600];
    truth_from_body_rates(
        &t,
        &vec![[0.0; 3]; 600],
        &w,
        None,
        BodyRateStart::default(),
        6,
        &mut out,
    )
    .unwrap();
    for k in [0, 1, 250, 400, 401, 599] {
        let tk = t[k];
        let yaw = if tk <= 4.0 {
            std::f64::consts::FRAC_PI_2 * tk
        } else {
            2.0 * std::f64::consts::PI + std::f64::consts::PI * (tk - 4.0)
        };
        assert!(
            (out[k].euler.yaw_rad - yaw).abs() < 1e-11,
            "k = {k}: {} vs {yaw}",
            out[k].euler.yaw_rad
        );
        assert_eq!(out[k].position_m.to_array(), [0.0; 3]);
    }
}

fn inversion_error(rate: f64) -> f64 {
    let n = (10.0 * rate) as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 / rate).collect();
    let mut truth = vec![Truth::<Enu>::default(); t.len()];
    truth_from_motion(
        &common::RollingHelix,
        &t,
        AnalyticOptions::default(),
        &mut truth,
    )
    .unwrap();
    // The kinematic acceleration and body rate an ideal IMU implies (specific force + gravity).
    let acc_b: Vec<[f64; 3]> = truth
        .iter()
        .map(|s| s.attitude.inverse().apply(s.acceleration_m_s2).to_array())
        .collect();
    let w_b: Vec<[f64; 3]> = truth.iter().map(|s| s.omega_b_rad_s.to_array()).collect();
    let start = BodyRateStart {
        position_m: truth[0].position_m,
        velocity_m_s: truth[0].velocity_m_s,
        attitude: truth[0].attitude,
    };
    let mut out = vec![Truth::<Enu>::default(); t.len()];
    truth_from_body_rates(&t, &acc_b, &w_b, None, start, 6, &mut out).unwrap();
    out.iter()
        .zip(&truth)
        .map(|(a, b)| (a.position_m - b.position_m).norm())
        .fold(0.0, f64::max)
}

#[test]
fn feeding_a_trajectorys_ideal_imu_returns_it_at_first_order() {
    let e = [
        inversion_error(100.0),
        inversion_error(200.0),
        inversion_error(400.0),
    ];
    eprintln!("body-rate inversion of a rolling helix, 10 s: max position error {e:?} m");
    assert!(e[2] < 0.05, "{e:?}");
    for k in 0..2 {
        let order = (e[k] / e[k + 1]).log2();
        assert!((order - 1.0).abs() < 0.2, "observed order {order} ({e:?})");
    }
}

#[test]
fn bad_body_rate_input_is_refused() {
    let t = [0.0, 0.1, 0.1];
    let mut out = vec![Truth::<Enu>::default(); 3];
    assert!(matches!(
        truth_from_body_rates(
            &t,
            &[[0.0; 3]; 3],
            &[[0.0; 3]; 3],
            None,
            BodyRateStart::default(),
            6,
            &mut out
        ),
        Err(KinematicsError::TimeNotIncreasing { index: 2, .. })
    ));
    let t = [0.0, 0.1, 0.2];
    let mut w = [[0.0; 3]; 3];
    w[1][2] = f64::NAN;
    assert_eq!(
        truth_from_body_rates(
            &t,
            &[[0.0; 3]; 3],
            &w,
            None,
            BodyRateStart::default(),
            6,
            &mut out
        ),
        Err(KinematicsError::NotFinite {
            field: "omega_body_rad_s",
            index: 1
        })
    );
    let _ = Vec3::<Enu>::zeros();
}
