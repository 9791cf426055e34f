//! WGS-84 in ENU and in NED is one engine seen in two sets of axes: the same readings (FLU
//! under ENU, FRD under NED), the same start, the same fixes give the same trajectory, the
//! same filter estimate and the same one-sigmas, to rounding, over ten minutes of a turning,
//! climbing flight — for both strapdown schemes and the 15-state filter.
use imu_core::earth::{EarthModel, Geodetic, Wgs84};
use imu_core::fusion::gate::Gate;
use imu_core::fusion::{BASE_STATES, Eskf, EskfNoise, EskfState, GnssFix, InitialSigma};
use imu_core::strapdown::{
    NavState, StrapdownOptions, VerticalChannel, strapdown_increments, strapdown_rates_rk4,
};
use imu_core::{Body, Enu, EulerZyx, NavFrame, Ned, Rotation, Vec3};

const RATE_HZ: f64 = 100.0;
const SECONDS: f64 = 600.0;

/// Readings in FRD of an aircraft at 46° N that turns, pitches and pushes: smooth, and large
/// enough that every term of the equations matters.
fn readings_frd() -> (Vec<f64>, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = (SECONDS * RATE_HZ) as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / RATE_HZ).collect();
    let w = t
        .iter()
        .map(|&t| {
            [
                0.02 * (0.3 * t).sin(),
                0.01 * (0.11 * t).cos(),
                0.03 * (0.05 * t).sin() + 1e-4,
            ]
        })
        .collect();
    let f = t
        .iter()
        .map(|&t| {
            [
                0.5 * (0.07 * t).sin() + 0.2,
                0.3 * (0.13 * t).cos(),
                -9.806 + 0.2 * (0.09 * t).sin(),
            ]
        })
        .collect();
    (t, w, f)
}

fn start_ned() -> NavState<Wgs84<Ned>> {
    NavState {
        t_s: 0.0,
        attitude: Rotation::from_euler(EulerZyx::new(0.7, 0.05, -0.02)),
        velocity_m_s: Vec3::new(60.0, 30.0, -2.0),
        position: Geodetic::from_degrees(46.0, 8.0, 1500.0),
    }
}

/// The same state in ENU with FLU body axes.
fn to_enu(s: &NavState<Wgs84<Ned>>) -> NavState<Wgs84<Enu>> {
    NavState {
        t_s: s.t_s,
        // FLU → FRD → NED's body axes (the same, typed) → NED → ENU.
        attitude: Enu::frd_to_body()
            .inverse()
            .then(&Ned::frd_to_body())
            .then(&s.attitude)
            .then(&Enu::from_ned()),
        velocity_m_s: Enu::from_ned_axes(s.velocity_m_s),
        position: s.position,
    }
}

fn flu(v: &[[f64; 3]]) -> Vec<[f64; 3]> {
    v.iter().map(|a| [a[0], -a[1], -a[2]]).collect()
}

/// The largest differences between the two runs: position (m), velocity (m/s), attitude (rad).
fn differences(ned: &[NavState<Wgs84<Ned>>], enu: &[NavState<Wgs84<Enu>>]) -> [f64; 3] {
    let earth = Wgs84::<Ned>::default();
    let mut worst = [0.0_f64; 3];
    for (a, b) in ned.iter().zip(enu) {
        let b_as_ned = to_enu(a);
        let dp = earth
            .displacement_m(
                &Wgs84::<Ned>::coordinates(&a.position),
                &Wgs84::<Enu>::coordinates(&b.position),
            )
            .norm();
        let dv = (b.velocity_m_s - b_as_ned.velocity_m_s).norm();
        let da = b
            .attitude
            .quaternion()
            .angle_to(b_as_ned.attitude.quaternion());
        worst = [worst[0].max(dp), worst[1].max(dv), worst[2].max(da)];
    }
    worst
}

#[test]
fn strapdown_on_wgs84_is_the_same_in_enu_and_ned() {
    let (t, w, f) = readings_frd();
    let (w_flu, f_flu) = (flu(&w), flu(&f));
    let s0 = start_ned();
    let options = StrapdownOptions {
        vertical: VerticalChannel::Hold,
        ..StrapdownOptions::default()
    };
    let mut ned = vec![NavState::default(); t.len()];
    let mut enu = vec![NavState::default(); t.len()];
    strapdown_rates_rk4(
        Wgs84::<Ned>::default(),
        &t,
        &w,
        &f,
        None,
        s0,
        options,
        4,
        &mut ned,
    )
    .unwrap();
    strapdown_rates_rk4(
        Wgs84::<Enu>::default(),
        &t,
        &w_flu,
        &f_flu,
        None,
        to_enu(&s0),
        options,
        4,
        &mut enu,
    )
    .unwrap();
    let rk4 = differences(&ned, &enu);
    // Increments: the trapezoid of the rates.
    let inc = |v: &[[f64; 3]]| -> Vec<[f64; 3]> {
        (0..v.len())
            .map(|k| match k {
                0 => [0.0; 3],
                _ => std::array::from_fn(|i| 0.5 / RATE_HZ * (v[k - 1][i] + v[k][i])),
            })
            .collect()
    };
    strapdown_increments(
        Wgs84::<Ned>::default(),
        &t,
        &inc(&w),
        &inc(&f),
        None,
        s0,
        options,
        &mut ned,
    )
    .unwrap();
    strapdown_increments(
        Wgs84::<Enu>::default(),
        &t,
        &inc(&w_flu),
        &inc(&f_flu),
        None,
        to_enu(&s0),
        options,
        &mut enu,
    )
    .unwrap();
    let increments = differences(&ned, &enu);
    let end = &ned[ned.len() - 1].position;
    let travelled = Wgs84::<Ned>::default()
        .displacement_m(
            &Wgs84::<Ned>::coordinates(&s0.position),
            &Wgs84::<Ned>::coordinates(end),
        )
        .norm();
    eprintln!("travelled {travelled:.0} m; ENU − NED, RK4: {rk4:?}; increments: {increments:?}");
    assert!(
        travelled > 20e3,
        "the flight must go somewhere: {travelled} m"
    );
    for (scheme, d) in [("rk4", rk4), ("increments", increments)] {
        // Rounding of the geodetic coordinates (1e-16 rad is 0.6 nm) grows over 60 000 steps.
        assert!(
            d[0] < 1e-6 && d[1] < 1e-9 && d[2] < 1e-12,
            "{scheme}: position {:e} m, velocity {:e} m/s, attitude {:e} rad",
            d[0],
            d[1],
            d[2]
        );
    }
}

/// A filter's start with no bias estimate.
fn at_rest_biases<E: EarthModel>(nav: NavState<E>) -> EskfState<E> {
    EskfState {
        nav,
        accel_bias_m_s2: [0.0; 3],
        gyro_bias_rad_s: [0.0; 3],
    }
}

#[test]
fn the_filter_on_wgs84_is_the_same_in_enu_and_ned() {
    let (t, w, f) = readings_frd();
    let (w_flu, f_flu) = (flu(&w), flu(&f));
    let s0 = start_ned();
    // The fixes: the navigation of the same readings, a few metres off.
    let mut truth = vec![NavState::default(); t.len()];
    strapdown_rates_rk4(
        Wgs84::<Ned>::default(),
        &t,
        &w,
        &f,
        None,
        s0,
        StrapdownOptions::default(),
        4,
        &mut truth,
    )
    .unwrap();
    let noise = EskfNoise {
        accel_psd: 1e-3,
        gyro_psd: 1e-5,
        accel_bias_psd: 1e-5,
        gyro_bias_psd: 1e-7,
    };
    let sigma = InitialSigma {
        position_m: 3.0,
        velocity_m_s: 0.3,
        attitude_rad: [0.01, 0.01, 0.05],
        accel_bias_m_s2: 0.02,
        gyro_bias_rad_s: 1e-3,
    };
    let mut ned =
        Eskf::<Wgs84<Ned>, BASE_STATES>::new(Wgs84::default(), &at_rest_biases(s0), &sigma, noise)
            .unwrap();
    let mut enu = Eskf::<Wgs84<Enu>, BASE_STATES>::new(
        Wgs84::default(),
        &at_rest_biases(to_enu(&s0)),
        &sigma,
        noise,
    )
    .unwrap();
    let lever = Vec3::<Body>::new(0.5, 0.2, -0.8);
    let earth = Wgs84::<Ned>::default();
    let mut worst = [0.0_f64; 5];
    for k in 1..t.len() {
        ned.propagate(t[k], w[k], f[k]).unwrap();
        enu.propagate(t[k], w_flu[k], f_flu[k]).unwrap();
        if k % 100 == 0 {
            let off = Vec3::<Ned>::new(3.0 * (k as f64).sin(), 2.0 * (k as f64).cos(), 1.0);
            let position = Wgs84::<Ned>::position(
                earth.offset(&Wgs84::<Ned>::coordinates(&truth[k].position), &off),
            );
            let v = truth[k].velocity_m_s + Vec3::new(0.05, -0.05, 0.02);
            let fix_ned = GnssFix::<Wgs84<Ned>> {
                position,
                velocity_m_s: Some(v),
                lever_arm_m: lever,
                position_sigma_m: [2.0, 2.0, 4.0],
                velocity_sigma_m_s: [0.1; 3],
                age_s: 0.02,
            };
            let fix_enu = GnssFix::<Wgs84<Enu>> {
                position,
                velocity_m_s: Some(Enu::from_ned_axes(v)),
                lever_arm_m: Vec3::new(lever.x(), -lever.y(), -lever.z()),
                position_sigma_m: [2.0, 2.0, 4.0],
                velocity_sigma_m_s: [0.1; 3],
                age_s: 0.02,
            };
            let a = ned.update(&fix_ned, Gate::Off).unwrap();
            let b = enu.update(&fix_enu, Gate::Off).unwrap();
            worst[3] = worst[3].max((a.nis - b.nis).abs() / a.nis);
            let d = differences(&[ned.state().nav], &[enu.state().nav]);
            // One-sigmas: NED (N, E, D) against ENU (E, N, U) for position, velocity, attitude.
            let (sn, se) = (ned.sigmas(), enu.sigmas());
            let sigma_diff = (0..3)
                .flat_map(|b| {
                    [
                        (3 * b, 3 * b + 1),
                        (3 * b + 1, 3 * b),
                        (3 * b + 2, 3 * b + 2),
                    ]
                })
                .map(|(i, j)| (sn[i] - se[j]).abs() / sn[i])
                .fold(0.0_f64, f64::max);
            worst = [
                worst[0].max(d[0]),
                worst[1].max(d[1]),
                worst[2].max(d[2]),
                worst[3],
                worst[4].max(sigma_diff),
            ];
        }
    }
    eprintln!("filter, ENU − NED: {worst:?}");
    assert!(
        worst[0] < 1e-6
            && worst[1] < 1e-9
            && worst[2] < 1e-12
            && worst[3] < 1e-7
            && worst[4] < 1e-9,
        "position {:e} m, velocity {:e} m/s, attitude {:e} rad, relative NIS {:e}, relative \
         one-sigma {:e}",
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4]
    );
}
