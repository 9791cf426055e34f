//! Euler ↔ DCM ↔ quaternion round trips and the sign anchors of docs/design.md §2.
use imu_core::{Body, Enu, EulerZyx, Ned, Rotation, Vec3};
use proptest::prelude::*;

const ANGLE_TOL_RAD: f64 = 1e-9;

fn wrap(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    a - tau * (a / tau).round()
}

proptest! {
    #[test]
    fn euler_dcm_quaternion_round_trip(
        yaw in -3.1f64..3.1, pitch in -1.55f64..1.55, roll in -3.1f64..3.1
    ) {
        let e = EulerZyx::new(yaw, pitch, roll);
        let r = Rotation::<Body, Enu>::from_euler(e);
        // The quaternion's DCM is the textbook Rz·Ry·Rx.
        let (a, b) = (r.to_dcm(), e.to_dcm());
        for i in 0..3 { for k in 0..3 { prop_assert!((a[i][k] - b[i][k]).abs() < 1e-12); } }
        // DCM → Euler → the same angles.
        let back = EulerZyx::from_dcm(&b);
        prop_assert!(wrap(back.yaw_rad - yaw).abs() < ANGLE_TOL_RAD);
        prop_assert!((back.pitch_rad - pitch).abs() < ANGLE_TOL_RAD);
        prop_assert!(wrap(back.roll_rad - roll).abs() < ANGLE_TOL_RAD);
        // Quaternion → DCM → quaternion (up to sign).
        let q = r.to_wxyz();
        let q2 = Rotation::<Body, Enu>::from_dcm(&a).to_wxyz();
        let dot: f64 = (0..4).map(|k| q[k] * q2[k]).sum();
        prop_assert!((dot.abs() - 1.0).abs() < 1e-12);
        // Inverse undoes apply.
        let v = Vec3::<Body>::new(0.3, -1.2, 2.0);
        let w = r.inverse().apply(r.apply(v));
        prop_assert!((w - v).norm() < 1e-12);
    }
}

proptest! {
    /// `Rotation::from_euler` forms nalgebra's products itself (to skip the library call for zero
    /// angles): the quaternion must stay nalgebra's bit for bit, zeros of either sign included.
    #[test]
    fn euler_quaternion_is_nalgebras_bit_for_bit(
        yaw in -7.0f64..7.0, pitch in -1.6f64..1.6, roll in -4.0f64..4.0, zeros in 0u8..27
    ) {
        // Each angle as drawn, +0 or −0 (the base-3 digits of `zeros`).
        let pick = |a: f64, digit: u8| [a, 0.0, -0.0][usize::from(digit % 3)];
        let e = EulerZyx::new(pick(yaw, zeros), pick(pitch, zeros / 3), pick(roll, zeros / 9));
        let ours = Rotation::<Body, Enu>::from_euler(e).to_wxyz();
        let q = nalgebra::UnitQuaternion::from_euler_angles(e.roll_rad, e.pitch_rad, e.yaw_rad);
        let theirs = [q.w, q.i, q.j, q.k];
        for k in 0..4 {
            prop_assert_eq!(ours[k].to_bits(), theirs[k].to_bits(), "component {} of {:?}", k, e);
        }
    }
}

#[test]
fn yaw_90_in_ned_maps_body_x_to_east() {
    let c = Rotation::<Body, Ned>::from_euler(EulerZyx::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
    let n = c.apply(Vec3::new(1.0, 0.0, 0.0)).to_array();
    assert!(n[0].abs() < 1e-15 && (n[1] - 1.0).abs() < 1e-15);
}

#[test]
fn positive_pitch_turns_body_x_towards_minus_z() {
    // Ry(+p) turns body x towards −z: nose down in ENU (z up), nose up in NED (z down), as the
    // right-hand rule dictates; the tangent attitude uses pitch = −asin(v_z/|v|) for this reason.
    let p = 0.3_f64;
    let enu = Rotation::<Body, Enu>::from_euler(EulerZyx::new(0.0, p, 0.0));
    assert!((enu.apply(Vec3::new(1.0, 0.0, 0.0)).z() + p.sin()).abs() < 1e-15);
}

#[test]
fn ned_to_enu_swaps_north_and_east_and_flips_down_to_up() {
    let r = Rotation::<Ned, Enu>::ned_to_enu();
    let v = r.apply(Vec3::<Ned>::new(1.0, 2.0, 3.0)).to_array();
    assert_eq!(v.map(|x| (x * 1e12).round() / 1e12), [2.0, 1.0, -3.0]);
    // A body heading east with yaw π/2 in NED heads east (yaw 0) in ENU.
    let east_ned =
        Rotation::<Body, Ned>::from_euler(EulerZyx::new(core::f64::consts::FRAC_PI_2, 0.0, 0.0));
    let nose = east_ned
        .then(&r)
        .apply(Vec3::<Body>::new(1.0, 0.0, 0.0))
        .to_array();
    assert!((nose[0] - 1.0).abs() < 1e-12 && nose[1].abs() < 1e-12 && nose[2].abs() < 1e-12);
}
