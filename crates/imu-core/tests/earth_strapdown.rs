//! The Earth-frame strapdown against physics: a body at rest stays at rest, a manoeuvring flight
//! is recovered from its ideal IMU, the increments scheme converges at second order, an
//! accelerometer bias excites the 84-minute Schuler oscillation, the free vertical channel
//! diverges with the e-folding time √(R/2g), and the baro loop holds it.
use imu_core::earth::Wgs84;
use imu_core::earth::ideal::EcefKinematics;
use imu_core::earth::rates::MAX_LATITUDE_RAD;
use imu_core::earth::{EarthMount, EarthTruth, Geodetic, normal_gravity_m_s2};
use imu_core::strapdown::{
    NavState, StrapdownError, StrapdownOptions, VerticalChannel, strapdown_increments,
    strapdown_rates_rk4,
};

type EarthNavState = NavState<Wgs84<Ned>>;
use imu_core::{Body, EulerZyx, Frd, NavFrame, Ned, Rotation, Vec3};

/// A level body at rest at 45° N, 100 m up.
fn rest_45() -> EarthTruth {
    EarthTruth {
        position: Geodetic::from_degrees(45.0, 10.0, 100.0),
        ..EarthTruth::default()
    }
}

fn nav_state(truth: &EarthTruth) -> EarthNavState {
    EarthNavState {
        t_s: truth.t_s,
        attitude: Ned::frd_to_body().inverse().then(&truth.attitude),
        velocity_m_s: truth.velocity_m_s,
        position: truth.position,
    }
}

/// Runs RK4 (2 substeps) over `n` samples at `rate_hz` of constant readings `gyro`, `accel`.
fn run_constant(
    start: &EarthNavState,
    gyro: Vec3<Body>,
    accel: Vec3<Body>,
    rate_hz: f64,
    n: usize,
    vertical: VerticalChannel,
    baro: Option<&[f64]>,
) -> Vec<EarthNavState> {
    let t: Vec<f64> = (0..n).map(|k| k as f64 / rate_hz).collect();
    let w = vec![gyro.to_array(); n];
    let f = vec![accel.to_array(); n];
    let mut out = vec![EarthNavState::default(); n];
    let options = StrapdownOptions {
        vertical,
        ..StrapdownOptions::default()
    };
    strapdown_rates_rk4(
        Wgs84::default(),
        &t,
        &w,
        &f,
        baro,
        *start,
        options,
        2,
        &mut out,
    )
    .unwrap();
    out
}

/// North and east displacement (m) of `p` from `p0` on the local NED axes at `p0`.
fn north_east_m(p0: &Geodetic, p: &Geodetic) -> (f64, f64) {
    let d = p.to_ecef() - p0.to_ecef();
    let ned = p0.ned_to_ecef().inverse().apply(d);
    (ned.x(), ned.y())
}

#[test]
fn a_body_at_rest_on_the_rotating_earth_stays_at_rest_for_an_hour() {
    let truth = rest_45();
    let r = EarthMount::default()
        .read(&truth, Vec3::zeros())
        .to_body::<Ned>();
    let out = run_constant(
        &nav_state(&truth),
        r.gyro_rad_s,
        r.accel_m_s2,
        10.0,
        36_001,
        VerticalChannel::Free,
        None,
    );
    let last = out.last().unwrap();
    let moved = (last.position.to_ecef() - truth.position.to_ecef()).norm();
    // The Earth rate (15°/h) is sensed and removed exactly: no drift beyond rounding.
    assert!(moved < 1e-6, "moved {moved:e} m");
    assert!(last.velocity_m_s.norm() < 1e-9);
}

#[test]
fn an_accelerometer_bias_excites_the_schuler_oscillation() {
    // 1e-4 m/s² along north, level at 45° N, vertical channel held: the north error follows
    // (b/ω_s²)(1 − cos ω_s t), ω_s = √(γ/(R_N + h)), peaking at 2b/ω_s² ≈ 130 m after
    // 42.2 min and back near zero after the Schuler period, 84.4 min.
    let truth = rest_45();
    let r = EarthMount::default()
        .read(&truth, Vec3::zeros())
        .to_body::<Ned>();
    let bias = 1e-4;
    let accel = r.accel_m_s2 + Vec3::new(bias, 0.0, 0.0);
    let out = run_constant(
        &nav_state(&truth),
        r.gyro_rad_s,
        accel,
        1.0,
        5401,
        VerticalChannel::Hold,
        None,
    );
    let (r_n, _) = truth.position.radii_m();
    let gamma = normal_gravity_m_s2(&truth.position);
    let w_s = (gamma / (r_n + truth.position.height_m)).sqrt();
    let period_s = 2.0 * std::f64::consts::PI / w_s;
    assert!((period_s / 60.0 - 84.4).abs() < 0.1, "{}", period_s / 60.0);
    let peak = 2.0 * bias / (w_s * w_s);
    assert!((peak - 129.9).abs() < 0.5, "{peak}");
    let north = |t: usize| north_east_m(&truth.position, &out[t].position).0;
    let half = (period_s / 2.0).round() as usize;
    let full = period_s.round() as usize;
    // The peak: its size and its time within 5 %.
    let (t_max, n_max) = (0..out.len())
        .map(|t| (t, north(t)))
        .fold((0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    assert!(
        (n_max - peak).abs() < 0.05 * peak,
        "peak {n_max} m vs {peak} m"
    );
    assert!(
        (t_max as f64 - half as f64).abs() < 0.05 * half as f64,
        "peak at {t_max} s vs {half} s"
    );
    // Back near zero after one period; the closed form along the way.
    assert!(
        north(full).abs() < 0.05 * peak,
        "{} m at {full} s",
        north(full)
    );
    for t in (0..out.len()).step_by(300) {
        let want = bias / (w_s * w_s) * (1.0 - (w_s * t as f64).cos());
        assert!(
            (north(t) - want).abs() < 0.05 * peak,
            "{t} s: {} vs {want}",
            north(t)
        );
    }
}

#[test]
fn the_free_vertical_channel_diverges_with_the_e_folding_time_of_r_over_2g() {
    // Start 1 m too high with the readings of the true height: gravity is too small by
    // 2γ/R per metre, so δh = cosh(t/τ), τ = √(R/2γ) ≈ 570 s.
    let truth = rest_45();
    let r = EarthMount::default()
        .read(&truth, Vec3::zeros())
        .to_body::<Ned>();
    let mut start = nav_state(&truth);
    start.position.height_m += 1.0;
    let out = run_constant(
        &start,
        r.gyro_rad_s,
        r.accel_m_s2,
        1.0,
        3001,
        VerticalChannel::Free,
        None,
    );
    let dh = |t: usize| out[t].position.height_m - truth.position.height_m;
    // δh(t) = cosh(t/τ) for a 1 m start: τ from the height error after 1500 s and 3000 s.
    let tau_fit = |t: usize| t as f64 / dh(t).acosh();
    let (r_n, r_e) = truth.position.radii_m();
    let tau = ((r_n * r_e).sqrt() / (2.0 * normal_gravity_m_s2(&truth.position))).sqrt();
    assert!((tau - 570.0).abs() < 5.0, "{tau}");
    for t in [1500, 3000] {
        let fit = tau_fit(t);
        assert!(
            (fit - tau).abs() < 0.05 * tau,
            "fitted {fit} s vs {tau} s at {t} s"
        );
    }
    assert!(dh(3000) > 50.0, "{}", dh(3000));
}

#[test]
fn a_baro_loop_holds_the_height_against_an_accelerometer_bias() {
    let truth = rest_45();
    let r = EarthMount::default()
        .read(&truth, Vec3::zeros())
        .to_body::<Ned>();
    let accel = r.accel_m_s2 + Vec3::new(0.0, 0.0, 1e-3);
    let baro = vec![truth.position.height_m; 3001];
    let held = run_constant(
        &nav_state(&truth),
        r.gyro_rad_s,
        accel,
        1.0,
        3001,
        VerticalChannel::Baro {
            time_constant_s: 100.0,
        },
        Some(&baro),
    );
    let free = run_constant(
        &nav_state(&truth),
        r.gyro_rad_s,
        accel,
        1.0,
        3001,
        VerticalChannel::Free,
        None,
    );
    let dh =
        |o: &[EarthNavState], t: usize| (o[t].position.height_m - truth.position.height_m).abs();
    // Free: the bias alone gives ½bt² ≈ 4.5 km after 3000 s, more with the instability.
    assert!(dh(&free, 3000) > 4_000.0, "{}", dh(&free, 3000));
    // Held: a third-order loop removes a constant bias (the error decays as t²e^{−t/τ}: 0.7 mm
    // after 15 time constants); what is left after 30 is the horizontal channels' Coriolis
    // coupling of the transient, below a millimetre.
    assert!(dh(&held, 1500) < 2e-3, "{}", dh(&held, 1500));
    assert!(dh(&held, 3000) < 1e-3, "{}", dh(&held, 3000));
    // The loop's response to a step bias β is δh = −β t² e^{−t/τ}/2 (the three poles at
    // −1/τ), whose largest value 2βτ²/e² ≈ 2.71 m comes at t = 2τ.
    let (t_peak, peak) = (0..held.len())
        .map(|t| (t, dh(&held, t)))
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let want = 2.0 * 1e-3 * 100.0f64.powi(2) / std::f64::consts::E.powi(2);
    assert!(
        (peak - want).abs() < 0.05 * want,
        "peak {peak} m vs {want} m"
    );
    assert!((t_peak as f64 - 200.0).abs() < 10.0, "at {t_peak} s");
}

/// A manoeuvring flight over 50 km: circles of 3 km radius at 90 m/s drifting north at
/// 20 m/s, climbing and sinking, banked and pitched, given in the tangent plane (NED axes) at
/// 47° N, 8° E, 500 m, converted exactly through ECEF.
fn flight(t: f64) -> EarthTruth {
    let origin = Geodetic::from_degrees(47.0, 8.0, 500.0);
    let c_et = origin.ned_to_ecef();
    let (rc, wc) = (3000.0, 0.03);
    let (wz, az) = (0.01, 100.0);
    let (s, c) = ((wc * t).sin(), (wc * t).cos());
    let p = Vec3::<Ned>::new(rc * s + 20.0 * t, rc * (1.0 - c), -az * (wz * t).sin());
    let v = Vec3::<Ned>::new(rc * wc * c + 20.0, rc * wc * s, -az * wz * (wz * t).cos());
    let a = Vec3::<Ned>::new(
        -rc * wc * wc * s,
        rc * wc * wc * c,
        az * wz * wz * (wz * t).sin(),
    );
    let (pitch, roll) = (0.05, 0.3);
    let yaw = wc * t + 0.2;
    let c_tb = Rotation::<Frd, Ned>::from_euler(EulerZyx::new(yaw, pitch, roll));
    // z-y-x Euler rates with only ψ̇ = wc: ω_b = ψ̇ [−sin θ, sin φ cos θ, cos φ cos θ].
    let omega = Vec3::<Frd>::new(
        -pitch.sin(),
        roll.sin() * pitch.cos(),
        roll.cos() * pitch.cos(),
    ) * wc;
    let k = EcefKinematics {
        position_m: origin.to_ecef() + c_et.apply(p),
        velocity_m_s: c_et.apply(v),
        acceleration_m_s2: c_et.apply(a),
        attitude: c_tb.then(&c_et),
        omega_eb_b_rad_s: omega,
        alpha_eb_b_rad_s2: Vec3::zeros(),
    };
    EarthTruth::from_ecef(t, &k).unwrap()
}

#[test]
fn a_30_minute_flight_is_recovered_from_its_ideal_imu_by_the_fourth_order_scheme() {
    let rate = 20.0;
    let n = 30 * 60 * 20 + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
    let mount = EarthMount::default();
    let truth: Vec<EarthTruth> = t.iter().map(|&t| flight(t)).collect();
    let gyro: Vec<[f64; 3]> = truth
        .iter()
        .map(|s| s.inertial_rate().0.to_array())
        .collect();
    let accel: Vec<[f64; 3]> = truth
        .iter()
        .map(|s| mount.specific_force(s).to_array())
        .collect();
    let mut out = vec![EarthNavState::default(); n];
    strapdown_rates_rk4(
        Wgs84::default(),
        &t,
        &gyro,
        &accel,
        None,
        nav_state(&truth[0]),
        StrapdownOptions::default(),
        4,
        &mut out,
    )
    .unwrap();
    let worst = truth
        .iter()
        .zip(&out)
        .map(|(a, b)| (a.position.to_ecef() - b.position.to_ecef()).norm())
        .fold(0.0, f64::max);
    let travelled = (truth[n - 1].position.to_ecef() - truth[0].position.to_ecef()).norm();
    assert!(travelled > 30_000.0, "{travelled}");
    assert!(worst < 1e-3, "worst position error {worst:e} m");
    let last = out.last().unwrap();
    let att = last
        .attitude
        .inverse()
        .then(&nav_state(&truth[n - 1]).attitude);
    assert!(att.quaternion().angle() < 1e-8);
}

/// Increments over each interval by 5-point Gauss–Legendre quadrature of the flight's rates.
fn increments(t: &[f64]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let nodes = [
        (0.0, 128.0 / 225.0),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ];
    let mount = EarthMount::default();
    let mut dth = vec![[0.0; 3]];
    let mut dv = vec![[0.0; 3]];
    for k in 1..t.len() {
        let (a, b) = (t[k - 1], t[k]);
        let (mut th, mut v) = (Vec3::<Frd>::zeros(), Vec3::<Frd>::zeros());
        for (x, w) in nodes {
            let s = flight(0.5 * (a + b) + 0.5 * (b - a) * x);
            th += s.inertial_rate().0 * (w * 0.5 * (b - a));
            v += mount.specific_force(&s) * (w * 0.5 * (b - a));
        }
        dth.push(th.to_array());
        dv.push(v.to_array());
    }
    (dth, dv)
}

#[test]
fn the_increments_scheme_converges_at_second_order() {
    let error = |rate: f64| {
        let n = (300.0 * rate) as usize + 1;
        let t: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
        let (dth, dv) = increments(&t);
        let mut out = vec![EarthNavState::default(); n];
        strapdown_increments(
            Wgs84::default(),
            &t,
            &dth,
            &dv,
            None,
            nav_state(&flight(0.0)),
            StrapdownOptions::default(),
            &mut out,
        )
        .unwrap();
        (out[n - 1].position.to_ecef() - flight(t[n - 1]).position.to_ecef()).norm()
    };
    let (coarse, fine) = (error(10.0), error(20.0));
    let order = (coarse / fine).log2();
    assert!(
        (order - 2.0).abs() < 0.3,
        "order {order} ({coarse:e} m, {fine:e} m)"
    );
    assert!(fine < 0.05, "{fine}");
}

#[test]
fn the_poles_are_refused_by_sample() {
    let mut start = nav_state(&rest_45());
    start.position.latitude_rad = 89.95f64.to_radians();
    let err = strapdown_rates_rk4(
        Wgs84::default(),
        &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        &[[0.0; 3]; 6],
        &[[0.0, 0.0, -9.8]; 6],
        None,
        start,
        StrapdownOptions::default(),
        1,
        &mut [EarthNavState::default(); 6],
    )
    .unwrap_err();
    assert_eq!(err, StrapdownError::NearPole { index: 0 });
    assert!(err.to_string().contains("beyond ±89.9°"));
    // Flying north at 300 m/s from 89.8°: the 89.9° line (11 km on) is crossed at sample ~37.
    start.position.latitude_rad = 89.8f64.to_radians();
    start.velocity_m_s = Vec3::new(300.0, 0.0, 0.0);
    let n = 60;
    let t: Vec<f64> = (0..n).map(f64::from).collect();
    let g = normal_gravity_m_s2(&start.position);
    let mut out = vec![EarthNavState::default(); n as usize];
    let err = strapdown_rates_rk4(
        Wgs84::default(),
        &t,
        &vec![[0.0; 3]; n as usize],
        &vec![[0.0, 0.0, -g]; n as usize],
        None,
        start,
        StrapdownOptions {
            vertical: VerticalChannel::Hold,
            ..StrapdownOptions::default()
        },
        1,
        &mut out,
    )
    .unwrap_err();
    let StrapdownError::NearPole { index } = err else {
        panic!("{err:?}")
    };
    assert!((35..=40).contains(&index), "{index}");
    assert!((MAX_LATITUDE_RAD.to_degrees() - 89.9).abs() < 1e-12);
    // A baro channel needs heights.
    let err = strapdown_rates_rk4(
        Wgs84::default(),
        &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        &[[0.0; 3]; 6],
        &[[0.0; 3]; 6],
        None,
        nav_state(&rest_45()),
        StrapdownOptions {
            vertical: VerticalChannel::Baro {
                time_constant_s: 100.0,
            },
            ..StrapdownOptions::default()
        },
        1,
        &mut [EarthNavState::default(); 6],
    )
    .unwrap_err();
    assert!(matches!(err, StrapdownError::BadOption { .. }), "{err:?}");
}

#[test]
fn an_east_gyro_bias_gives_the_textbook_growing_schuler_response() {
    // ε = 0.01 °/h on the east gyro, level at 45° N, height held: the tilt it builds is fed back
    // through the Schuler loop and the north position error follows
    // −R ε (t − sin(ω_s t)/ω_s) (a tilt about east carries the platform south; Titterton &
    // Weston §12.3): a linear drift with the 84-minute ripple, 1.6 km after 90 minutes. The
    // Earth rate's coupling into heading bends it by 2.5 % at most over that time.
    let truth = rest_45();
    let r = EarthMount::default()
        .read(&truth, Vec3::zeros())
        .to_body::<Ned>();
    let eps = (0.01f64 / 3600.0).to_radians();
    let gyro = r.gyro_rad_s + Vec3::new(0.0, eps, 0.0);
    let out = run_constant(
        &nav_state(&truth),
        gyro,
        r.accel_m_s2,
        1.0,
        5401,
        VerticalChannel::Hold,
        None,
    );
    let (r_n, _) = truth.position.radii_m();
    let radius = r_n + truth.position.height_m;
    let w_s = (normal_gravity_m_s2(&truth.position) / radius).sqrt();
    let north = |t: usize| north_east_m(&truth.position, &out[t].position).0;
    let end = radius * eps * (5400.0 - (w_s * 5400.0).sin() / w_s);
    assert!((1500.0..2000.0).contains(&end.abs()), "{end}");
    for t in (600..=5400).step_by(600) {
        let want = radius * eps * (t as f64 - (w_s * t as f64).sin() / w_s);
        assert!(
            (north(t) + want).abs() < 0.03 * end.abs(),
            "{t} s: {} m vs {} m",
            north(t),
            -want
        );
    }
}
