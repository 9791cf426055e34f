//! Waypoint trajectories: through the waypoints, C² joins, end conditions, velocities, attitude.
use std::path::Path;

use imu_core::{Enu, Truth};
use imukit::ScenarioSpec;
use imukit::motion::analytic::{AnalyticOptions, truth_from_motion};
use imukit::motion::waypoints::Waypoints;

const T: [f64; 5] = [0.0, 2.0, 3.5, 6.0, 8.0];
const P: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [10.0, 1.0, 0.5],
    [12.0, 6.0, 1.0],
    [5.0, 9.0, 1.5],
    [0.0, 4.0, 2.0],
];

fn truth(w: &Waypoints, t: &[f64]) -> Vec<Truth<Enu>> {
    let mut out = vec![Truth::<Enu>::default(); t.len()];
    truth_from_motion(w, t, AnalyticOptions::default(), &mut out).unwrap();
    out
}

#[test]
fn natural_spline_passes_through_the_waypoints_with_c2_joins() {
    let w = Waypoints::new(&T, &P, None, None).unwrap();
    let at = truth(&w, &T);
    for (s, p) in at.iter().zip(P) {
        assert!((s.position_m - imu_core::Vec3::from_array(p)).norm() < 1e-12);
    }
    // Natural ends: zero acceleration at the first and last waypoint.
    assert!(at[0].acceleration_m_s2.norm() < 1e-12 && at[4].acceleration_m_s2.norm() < 1e-12);
    // C²: acceleration just before and just after each interior knot agree.
    for &k in &T[1..4] {
        let pair = truth(&w, &[k - 1e-9, k + 1e-9]);
        assert!(
            (pair[0].acceleration_m_s2 - pair[1].acceleration_m_s2).norm() < 1e-6,
            "knot {k}"
        );
        assert!(
            (pair[0].velocity_m_s - pair[1].velocity_m_s).norm() < 1e-7,
            "knot {k}"
        );
    }
}

#[test]
fn collinear_even_waypoints_give_constant_velocity() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let p = [
        [0.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
        [4.0, 2.0, 0.0],
        [6.0, 3.0, 0.0],
    ];
    let w = Waypoints::new(&t, &p, None, None).unwrap();
    for s in truth(&w, &[0.0, 0.7, 1.5, 2.9]) {
        assert!(
            (s.velocity_m_s.to_array()[0] - 2.0).abs() < 1e-12
                && (s.velocity_m_s.to_array()[1] - 1.0).abs() < 1e-12
        );
        assert!(s.acceleration_m_s2.norm() < 1e-12);
        assert!(
            (s.euler.yaw_rad - 0.5f64.atan()).abs() < 1e-12,
            "tangent attitude"
        );
    }
}

#[test]
fn given_velocities_are_met_clamped_and_hermite() {
    let clamped = Waypoints::new(&T, &P, Some(&[[0.0, 0.0, 0.0], [-1.0, 0.5, 0.0]]), None).unwrap();
    let ends = truth(&clamped, &[T[0], T[4]]);
    assert!(ends[0].velocity_m_s.norm() < 1e-12);
    assert!((ends[1].velocity_m_s - imu_core::Vec3::new(-1.0, 0.5, 0.0)).norm() < 1e-12);
    let v: Vec<[f64; 3]> = (0..5).map(|i| [i as f64, 1.0 - i as f64, 0.2]).collect();
    let hermite = Waypoints::new(&T, &P, Some(&v), None).unwrap();
    for ((s, vi), p) in truth(&hermite, &T).iter().zip(&v).zip(P) {
        assert!((s.velocity_m_s - imu_core::Vec3::from_array(*vi)).norm() < 1e-12);
        assert!((s.position_m - imu_core::Vec3::from_array(p)).norm() < 1e-12);
    }
    // Still C²: position, velocity and acceleration continuous across interior knots.
    for &k in &T[1..4] {
        let pair = truth(&hermite, &[k - 1e-9, k + 1e-9]);
        assert!(
            (pair[0].acceleration_m_s2 - pair[1].acceleration_m_s2).norm() < 1e-6,
            "knot {k}"
        );
    }
}

#[test]
fn attitude_follows_the_given_angles_with_yaw_unwrapped() {
    let e = [
        [3.0, 0.1, 0.0],
        [-3.0, 0.0, 0.2],
        [-2.5, -0.1, 0.0],
        [-2.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
    ];
    let w = Waypoints::new(&T, &P, None, Some(&e)).unwrap();
    let at = truth(&w, &T);
    // −3.0 follows 3.0 as 2π − 3.0 (the short way round).
    let expected_yaw = [
        3.0,
        std::f64::consts::TAU - 3.0,
        std::f64::consts::TAU - 2.5,
        std::f64::consts::TAU - 2.0,
        std::f64::consts::TAU - 1.0,
    ];
    for (s, y) in at.iter().zip(expected_yaw) {
        assert!(
            (s.euler.yaw_rad - y).abs() < 1e-12,
            "{} vs {y}",
            s.euler.yaw_rad
        );
    }
    assert!((at[1].euler.roll_rad - 0.2).abs() < 1e-12);
}

#[test]
fn bad_waypoints_are_refused() {
    let e = |r: Result<Waypoints, imukit::Error>| r.unwrap_err().to_string();
    assert!(e(Waypoints::new(&[0.0], &[[0.0; 3]], None, None)).contains("at least 2"));
    assert!(e(Waypoints::new(&[0.0, 1.0, 1.0], &[[0.0; 3]; 3], None, None)).contains("time_s[2]"));
    assert!(e(Waypoints::new(&[0.0, 1.0], &[[0.0; 3]; 3], None, None)).contains("3 rows"));
    assert!(
        e(Waypoints::new(
            &[0.0, 1.0, 2.0],
            &[[0.0; 3]; 3],
            Some(&[[0.0; 3]; 2][..1]),
            None
        ))
        .contains("2 rows")
    );
    assert!(
        e(Waypoints::new(
            &[0.0, 1.0],
            &[[0.0; 3]; 2],
            None,
            Some(&[[0.0, std::f64::consts::FRAC_PI_2, 0.0]; 2])
        ))
        .contains("gimbal")
    );
}

#[test]
fn waypoint_scenarios_run() {
    let text = "rate_hz = 50.0\n[trajectory]\ntype = \"waypoints\"\ntime_s = [0, 2, 3.5, 6, 8]\n\
                position_m = [[0,0,0],[10,1,0.5],[12,6,1],[5,9,1.5],[0,4,2]]\nvelocity_m_s = [[1,0,0],[-1,0,0]]\n";
    let sim = ScenarioSpec::from_toml(text, "t")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    assert_eq!(sim.truth.rows(), 401);
    let x = sim.truth.column("pos_x_m").unwrap();
    assert!((x[100] - 10.0).abs() < 1e-12 && (x[400]).abs() < 1e-12);
    assert!(sim.imu.data.iter().all(|v| v.is_finite()));
}
