//! Exact sources against closed-form truth and IMU values (≤ 1e-9 relative to the largest
//! magnitude of each quantity), in ENU and NED.
use imu_core::{AccelSign, Body, Enu, EulerZyx, ImuMount, NavFrame, Ned, Rotation, Truth, Vec3};
use imukit::motion::analytic::{AnalyticOptions, Motion, Scalar, truth_from_motion};
use num_dual::{Dual2, DualStruct};

const REL_TOL: f64 = 1e-9;
const G: f64 = 9.81;

fn max_abs(rows: &[[f64; 3]]) -> f64 {
    rows.iter()
        .flatten()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(1.0)
}

/// Asserts two series agree to REL_TOL relative to the largest magnitude of `expected` (at least
/// one unit, so identically zero quantities are held to REL_TOL absolute).
fn assert_series(name: &str, got: &[[f64; 3]], expected: &[[f64; 3]]) {
    let scale = max_abs(expected);
    for (i, (g, e)) in got.iter().zip(expected).enumerate() {
        for k in 0..3 {
            let err = (g[k] - e[k]).abs() / scale;
            assert!(
                err <= REL_TOL,
                "{name}[{i}][{k}]: got {} expected {} (rel {err:e})",
                g[k],
                e[k]
            );
        }
    }
}

fn times(n: usize, dt: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 * dt).collect()
}

fn run<M: Motion, N: NavFrame>(m: &M, t: &[f64]) -> Vec<Truth<N>> {
    let mut out = vec![Truth::<N>::default(); t.len()];
    truth_from_motion(m, t, AnalyticOptions::default(), &mut out).expect("truth");
    out
}

/// Level circle, radius R, counter-clockwise in the x-y plane at rate W, nose along the path.
struct LevelCircle;
const R: f64 = 3.0;
const W: f64 = 0.7;
impl Motion for LevelCircle {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let a = t * W;
        [a.cos() * R, a.sin() * R, D::from(1.5)]
    }
    fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
        None
    }
}

fn level_circle_case<N: NavFrame>() {
    let t = times(400, 0.01);
    let truth = run::<_, N>(&LevelCircle, &t);
    let lever = [0.2, -0.1, 0.05];
    let mount = ImuMount::<N> {
        lever_arm_m: Vec3::from_array(lever),
        ..ImuMount::default()
    };
    let z_up = N::Z_UP;
    let mut exp_p = vec![];
    let (mut exp_v, mut exp_a, mut exp_w, mut exp_al, mut exp_f, mut exp_m, mut exp_e) =
        (vec![], vec![], vec![], vec![], vec![], vec![], vec![]);
    for &ti in &t {
        let (s, c) = (W * ti).sin_cos();
        exp_p.push([R * c, R * s, 1.5]);
        exp_v.push([-R * W * s, R * W * c, 0.0]);
        exp_a.push([-R * W * W * c, -R * W * W * s, 0.0]);
        exp_w.push([0.0, 0.0, W]);
        exp_al.push([0.0, 0.0, 0.0]);
        // Body y points at the centre in both frames (left in FLU, right in FRD for this sense).
        let wr = [-W * W * lever[0], -W * W * lever[1], 0.0];
        exp_f.push([wr[0], R * W * W + wr[1], z_up * G]);
        let yaw = W * ti + std::f64::consts::FRAC_PI_2;
        let m = N::default_magnetic_field_ut().to_array();
        let (sy, cy) = yaw.sin_cos();
        exp_m.push([cy * m[0] + sy * m[1], -sy * m[0] + cy * m[1], m[2]]);
        exp_e.push([yaw, 0.0, 0.0]);
    }
    let col = |f: &dyn Fn(&Truth<N>) -> [f64; 3]| truth.iter().map(f).collect::<Vec<_>>();
    assert_series("p", &col(&|s| s.position_m.to_array()), &exp_p);
    assert_series("v", &col(&|s| s.velocity_m_s.to_array()), &exp_v);
    assert_series("a", &col(&|s| s.acceleration_m_s2.to_array()), &exp_a);
    assert_series("euler", &col(&|s| s.euler.to_array()), &exp_e);
    assert_series("omega", &col(&|s| s.omega_b_rad_s.to_array()), &exp_w);
    assert_series("alpha", &col(&|s| s.alpha_b_rad_s2.to_array()), &exp_al);
    let readings: Vec<_> = truth.iter().map(|s| mount.read(s)).collect();
    let f: Vec<_> = readings.iter().map(|r| r.accel_m_s2.to_array()).collect();
    assert_series("f_b", &f, &exp_f);
    let m: Vec<_> = readings.iter().map(|r| r.mag_ut.to_array()).collect();
    assert_series("m_b", &m, &exp_m);
    // Without lever arm only the centripetal term of S remains.
    let bare = ImuMount::<N>::default();
    let f0: Vec<_> = truth
        .iter()
        .map(|s| bare.read(s).accel_m_s2.to_array())
        .collect();
    let exp0: Vec<_> = t.iter().map(|_| [0.0, R * W * W, z_up * G]).collect();
    assert_series("f_b without lever arm", &f0, &exp0);
}

#[test]
fn level_circle_matches_closed_form_enu() {
    level_circle_case::<Enu>();
}

#[test]
fn level_circle_matches_closed_form_ned() {
    level_circle_case::<Ned>();
}

/// A helix with sinusoidal roll and yaw following the circle: explicit Euler angles.
struct RollingHelix;
const A: f64 = 0.4;
const OM: f64 = 2.3;
const CLIMB: f64 = 0.25;
impl Motion for RollingHelix {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let a = t * W;
        [a.cos() * R, a.sin() * R, t * CLIMB]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        Some([t * W, (t * 0.9).sin() * 0.3, (t * OM).sin() * A])
    }
}

/// C_nb = Rz·Ry·Rx over any scalar, for an independent check of ω_b and α_b.
fn dcm<D: Scalar>(yaw: D, pitch: D, roll: D) -> [[D; 3]; 3] {
    let (sy, cy) = (yaw.sin(), yaw.cos());
    let (sp, cp) = (pitch.sin(), pitch.cos());
    let (sr, cr) = (roll.sin(), roll.cos());
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

#[test]
fn helix_body_rate_matches_the_definition_from_the_dcm_derivative() {
    // [ω×] = Cᵀ Ċ and [α×] = d/dt(Cᵀ Ċ) = Ċᵀ Ċ + Cᵀ C̈, with C differentiated exactly
    // over second-order dual numbers — independent of the Euler-rate formula under test.
    let t = times(300, 0.013);
    let truth_enu = run::<_, Enu>(&RollingHelix, &t);
    let truth_ned = run::<_, Ned>(&RollingHelix, &t);
    let (mut exp_w, mut exp_al, mut got_w, mut got_al) = (vec![], vec![], vec![], vec![]);
    for (i, &ti) in t.iter().enumerate() {
        let e = RollingHelix.euler(Dual2::new(ti, 1.0, 0.0)).unwrap();
        let c = dcm(e[0], e[1], e[2]);
        let m = |r: usize, k: usize, f: fn(&Dual2<f64>) -> f64| f(&c[r][k]);
        let mut omega = [[0.0; 3]; 3];
        let mut alpha = [[0.0; 3]; 3];
        for r in 0..3 {
            for k in 0..3 {
                for j in 0..3 {
                    omega[r][k] += m(j, r, |d| d.re()) * m(j, k, |d| d.v1);
                    alpha[r][k] += m(j, r, |d| d.v1) * m(j, k, |d| d.v1)
                        + m(j, r, |d| d.re()) * m(j, k, |d| d.v2);
                }
            }
        }
        exp_w.push([omega[2][1], omega[0][2], omega[1][0]]);
        exp_al.push([alpha[2][1], alpha[0][2], alpha[1][0]]);
        got_w.push(truth_enu[i].omega_b_rad_s.to_array());
        got_al.push(truth_enu[i].alpha_b_rad_s2.to_array());
        assert_eq!(truth_enu[i].omega_b_rad_s, truth_ned[i].omega_b_rad_s);
    }
    assert_series("omega", &got_w, &exp_w);
    assert_series("alpha", &got_al, &exp_al);
}

#[test]
fn helix_with_pure_yaw_and_roll_matches_hand_closed_form() {
    struct YawRoll;
    impl Motion for YawRoll {
        fn position<D: Scalar>(&self, t: D) -> [D; 3] {
            RollingHelix.position(t)
        }
        fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
            Some([t * W, D::from(0.0), (t * OM).sin() * A])
        }
    }
    let t = times(250, 0.02);
    let truth = run::<_, Enu>(&YawRoll, &t);
    let (mut w, mut al, mut ew, mut eal) = (vec![], vec![], vec![], vec![]);
    for (s, &ti) in truth.iter().zip(&t) {
        let r = A * (OM * ti).sin();
        let rd = A * OM * (OM * ti).cos();
        let rdd = -A * OM * OM * (OM * ti).sin();
        ew.push([rd, W * r.sin(), W * r.cos()]);
        eal.push([rdd, W * rd * r.cos(), -W * rd * r.sin()]);
        w.push(s.omega_b_rad_s.to_array());
        al.push(s.alpha_b_rad_s2.to_array());
    }
    assert_series("omega", &w, &ew);
    assert_series("alpha", &al, &eal);
    let v: Vec<_> = truth.iter().map(|s| s.velocity_m_s.to_array()).collect();
    let ev: Vec<_> = t
        .iter()
        .map(|&ti| [-R * W * (W * ti).sin(), R * W * (W * ti).cos(), CLIMB])
        .collect();
    assert_series("v", &v, &ev);
}

struct Tilted;
const TILT: [f64; 3] = [0.3, 0.2, -0.4];
impl Motion for Tilted {
    fn position<D: Scalar>(&self, _t: D) -> [D; 3] {
        [D::from(1.0), D::from(-2.0), D::from(0.5)]
    }
    fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
        Some(TILT.map(D::from))
    }
}

fn tilted_static_case<N: NavFrame>() {
    let t = times(5, 0.1);
    let truth = run::<_, N>(&Tilted, &t);
    let (sp, cp) = TILT[1].sin_cos();
    let (sr, cr) = TILT[2].sin_cos();
    // f_b = −C_nbᵀ g_n = Z_UP·g·(third row of C_nb).
    let expected = [
        N::Z_UP * G * -sp,
        N::Z_UP * G * cp * sr,
        N::Z_UP * G * cp * cr,
    ];
    for s in &truth {
        for sign in [AccelSign::SpecificForce, AccelSign::Matlab] {
            let mount = ImuMount::<N> {
                lever_arm_m: Vec3::new(0.3, 0.3, 0.3),
                accel_sign: sign,
                ..ImuMount::default()
            };
            let k = if sign == AccelSign::Matlab { -1.0 } else { 1.0 };
            assert_series(
                "f_b",
                &[mount.read(s).accel_m_s2.to_array()],
                &[expected.map(|c| k * c)],
            );
        }
        assert_eq!(s.omega_b_rad_s.to_array(), [0.0; 3]);
        assert_eq!(s.velocity_m_s.to_array(), [0.0; 3]);
    }
}

#[test]
fn tilted_static_body_reads_rotated_gravity_enu() {
    tilted_static_case::<Enu>();
}

#[test]
fn tilted_static_body_reads_rotated_gravity_ned() {
    tilted_static_case::<Ned>();
}

#[test]
fn level_static_imu_reads_plus_g_on_the_up_axis_and_minus_in_matlab_mode() {
    let level = Truth::<Enu>::default();
    let up = ImuMount::<Enu>::default()
        .read(&level)
        .accel_m_s2
        .to_array();
    assert_eq!(up, [0.0, 0.0, 9.81]);
    let matlab = ImuMount::<Enu> {
        accel_sign: AccelSign::Matlab,
        ..ImuMount::default()
    };
    assert_eq!(matlab.read(&level).accel_m_s2.to_array(), [0.0, 0.0, -9.81]);
    let level = Truth::<Ned>::default();
    assert_eq!(
        ImuMount::<Ned>::default()
            .read(&level)
            .accel_m_s2
            .to_array(),
        [0.0, 0.0, -9.81]
    );
    let matlab = ImuMount::<Ned> {
        accel_sign: AccelSign::Matlab,
        ..ImuMount::default()
    };
    assert_eq!(matlab.read(&level).accel_m_s2.to_array(), [0.0, 0.0, 9.81]);
}

#[test]
fn yaw_90_maps_body_x_to_north_and_north_to_body_x() {
    let c_nb =
        Rotation::<Body, Enu>::from_euler(EulerZyx::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
    let n = c_nb.apply(Vec3::new(1.0, 0.0, 0.0)).to_array();
    assert!((n[0]).abs() < 1e-15 && (n[1] - 1.0).abs() < 1e-15 && n[2].abs() < 1e-15);
    let b = c_nb.inverse().apply(Vec3::new(0.0, 1.0, 0.0)).to_array();
    assert!((b[0] - 1.0).abs() < 1e-15 && b[1].abs() < 1e-15 && b[2].abs() < 1e-15);
}

#[test]
fn tangent_attitude_holds_through_standstill_without_nan() {
    /// Starts at rest, moves, stops, moves on: x = t³ for t<1 style via smooth (1−cos).
    struct StopGo;
    impl Motion for StopGo {
        fn position<D: Scalar>(&self, t: D) -> [D; 3] {
            // Speed ∝ sin²(πt): zero at every integer time.
            let pi = std::f64::consts::PI;
            let s = t * 0.5 - (t * (2.0 * pi)).sin() / (4.0 * pi);
            [s * 0.6, s * 0.8, D::from(0.0)]
        }
        fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
            None
        }
    }
    let t = times(301, 0.01);
    let truth = run::<_, Enu>(&StopGo, &t);
    let yaw = (0.8_f64).atan2(0.6);
    for s in &truth {
        assert!(s.is_finite());
        assert!((s.euler.yaw_rad - yaw).abs() < 1e-12, "yaw at t={}", s.t_s);
    }
    // The first sample (at rest) took the first valid attitude.
    assert!((truth[0].euler.yaw_rad - yaw).abs() < 1e-12);
}
