//! The filter's starts without a reference (`imu_core::fusion::align`), on WGS-84 in ENU and
//! NED: at rest, levelling and gyrocompassing recover any attitude from ideal readings to
//! rounding, the errors of many drawn parts have the spread the stated one-sigmas claim, and
//! what cannot be aligned is refused; moving, the body's x axis lies along the velocity.
use imu_core::earth::{EarthModel, FlatEarth, Geodetic, Wgs84, normal_gravity_m_s2};
use imu_core::fusion::align::{self, AlignError, PartFigures};
use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::{Body, Enu, EulerZyx, NavFrame, Ned, Rotation, Vec3};

/// The mean specific force and body rate of a vehicle at rest with `attitude` at `position`.
fn at_rest_readings<E: EarthModel>(
    earth: &E,
    position: &E::Position,
    attitude: &Rotation<Body, E::Frame>,
) -> ([f64; 3], [f64; 3]) {
    let terms = earth.terms(&E::coordinates(position), &Vec3::zeros());
    let to_body = attitude.inverse();
    (
        to_body.apply(-terms.gravity_m_s2).to_array(),
        to_body.apply(terms.earth_rate_rad_s).to_array(),
    )
}

/// The angle between two attitudes, rad.
fn angle_between<N: NavFrame>(a: &Rotation<Body, N>, b: &Rotation<Body, N>) -> f64 {
    a.quaternion().angle_to(b.quaternion())
}

const EXACT: PartFigures = PartFigures {
    accel_bias_m_s2: 0.0,
    gyro_bias_rad_s: 0.0,
    accel_psd: 0.0,
    gyro_psd: 0.0,
};

fn recovers_every_attitude<N: NavFrame>()
where
    Wgs84<N>: EarthModel<Frame = N, Position = Geodetic>,
{
    let earth = Wgs84::<N>::default();
    let mut worst = 0.0_f64;
    for lat in [-70.0, -30.0, 0.5, 45.0, 80.0] {
        let position = Geodetic::from_degrees(lat, 7.0, 400.0);
        for yaw in (-170..=180).step_by(35) {
            for pitch in [-60.0, -10.0, 0.0, 25.0, 70.0] {
                for roll in [-150.0, -40.0, 0.0, 15.0, 120.0] {
                    let truth = Rotation::<Body, N>::from_euler(EulerZyx::new(
                        f64::from(yaw).to_radians(),
                        f64::to_radians(pitch),
                        f64::to_radians(roll),
                    ));
                    let (f, w) = at_rest_readings(&earth, &position, &truth);
                    let found = align::at_rest(&earth, &position, f, w, 60.0, &EXACT)
                        .unwrap_or_else(|e| panic!("{} at {lat}°: {e}", N::NAME));
                    worst = worst.max(angle_between(&found.attitude, &truth));
                }
            }
        }
    }
    assert!(
        worst < 1e-12,
        "{}: worst attitude error {worst:e} rad",
        N::NAME
    );
}

#[test]
fn at_rest_recovers_every_attitude_in_both_frames() {
    recovers_every_attitude::<Ned>();
    recovers_every_attitude::<Enu>();
}

/// Draws `runs` parts (each axis's biases and the averaged white noise from `part`), aligns
/// each at rest and returns the sample standard deviation of the tilt (roll and pitch pooled)
/// and heading errors, with the one-sigmas the alignment states.
fn spread<N: NavFrame>(part: &PartFigures, runs: u64) -> ([f64; 2], [f64; 2])
where
    Wgs84<N>: EarthModel<Frame = N, Position = Geodetic>,
{
    let earth = Wgs84::<N>::default();
    let position = Geodetic::from_degrees(45.0, 7.0, 400.0);
    let duration_s: f64 = 60.0;
    let (mut tilt2, mut heading2) = (0.0, 0.0);
    let mut stated = [0.0; 2];
    for run in 0..runs {
        let mut n = SeededNormals::for_run(7, run);
        let truth = Rotation::<Body, N>::from_euler(EulerZyx::new(
            (run as f64 * 0.37).rem_euclid(6.0) - 3.0,
            0.0,
            0.0,
        ));
        let (f, w) = at_rest_readings(&earth, &position, &truth);
        let mut draw = |sigma: f64, white: f64| {
            let s = white / duration_s.sqrt();
            std::array::from_fn::<f64, 3, _>(|_| {
                sigma * n.standard_normal() + s * n.standard_normal()
            })
        };
        let (da, dw) = (
            draw(part.accel_bias_m_s2, part.accel_psd),
            draw(part.gyro_bias_rad_s, part.gyro_psd),
        );
        let f = std::array::from_fn(|i| f[i] + da[i]);
        let w = std::array::from_fn(|i| w[i] + dw[i]);
        let found = align::at_rest(&earth, &position, f, w, duration_s, part).unwrap();
        stated = [found.tilt_sigma_rad, found.heading_sigma_rad];
        let (e, t) = (found.attitude.to_euler(), truth.to_euler());
        let dyaw = (e.yaw_rad - t.yaw_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        tilt2 += (e.roll_rad - t.roll_rad).powi(2) + (e.pitch_rad - t.pitch_rad).powi(2);
        heading2 += dyaw * dyaw;
    }
    let runs = runs as f64;
    (
        [(tilt2 / (2.0 * runs)).sqrt(), (heading2 / runs).sqrt()],
        stated,
    )
}

#[test]
fn at_rest_errors_spread_as_stated() {
    // A tactical-grade part: 1 mg and 1 °/h of bias, with white noise averaged over a minute.
    let part = PartFigures {
        accel_bias_m_s2: 1e-2,
        gyro_bias_rad_s: 4.85e-6,
        accel_psd: 1e-3,
        gyro_psd: 5e-6,
    };
    // 800 runs: the sample deviation of a normal error is within ±4 × 1/√(2n) = ±10 % of the
    // truth (the heading's) or ±4 × 1/√(4n) = ±7 % (the tilt's, two per run).
    for (name, (measured, stated)) in [
        ("NED", spread::<Ned>(&part, 800)),
        ("ENU", spread::<Enu>(&part, 800)),
    ] {
        let ratio = [measured[0] / stated[0], measured[1] / stated[1]];
        assert!(
            (ratio[0] - 1.0).abs() < 0.07 && (ratio[1] - 1.0).abs() < 0.10,
            "{name}: measured/stated tilt {:.3}, heading {:.3}",
            ratio[0],
            ratio[1]
        );
    }
}

#[test]
fn at_rest_states_the_textbook_one_sigmas() {
    let part = PartFigures {
        accel_bias_m_s2: 2e-3,
        gyro_bias_rad_s: 1e-6,
        accel_psd: 4e-3,
        gyro_psd: 3e-5,
    };
    let earth = Wgs84::<Enu>::default();
    let position = Geodetic::from_degrees(-33.9, 151.2, 50.0);
    let truth = Rotation::<Body, Enu>::from_euler(EulerZyx::new(1.0, 0.05, -0.1));
    let (f, w) = at_rest_readings(&earth, &position, &truth);
    let found = align::at_rest(&earth, &position, f, w, 100.0, &part).unwrap();
    let gravity = normal_gravity_m_s2(&position);
    let horizontal = imu_core::earth::wgs84::OMEGA_IE_RAD_S * position.latitude_rad.cos();
    let tilt = (2e-3_f64 * 2e-3 + 4e-3 * 4e-3 / 100.0).sqrt() / gravity;
    let heading = (1e-6_f64 * 1e-6 + 3e-5 * 3e-5 / 100.0).sqrt() / horizontal;
    assert!((found.tilt_sigma_rad / tilt - 1.0).abs() < 1e-12);
    assert!((found.heading_sigma_rad / heading - 1.0).abs() < 1e-12);
}

#[test]
fn at_rest_refuses_what_it_cannot_align() {
    let position = Geodetic::from_degrees(45.0, 7.0, 400.0);
    let earth = Wgs84::<Ned>::default();
    let truth = Rotation::<Body, Ned>::identity();
    let (f, w) = at_rest_readings(&earth, &position, &truth);
    // Accelerating: 10 % more than gravity.
    let moving = f.map(|x| 1.1 * x);
    assert!(matches!(
        align::at_rest(&earth, &position, moving, w, 60.0, &EXACT),
        Err(AlignError::NotAtRest { .. })
    ));
    // A consumer gyroscope's bias (0.01 rad/s) hides the Earth's rate.
    let consumer = PartFigures {
        gyro_bias_rad_s: 1e-2,
        ..EXACT
    };
    assert!(matches!(
        align::at_rest(&earth, &position, f, w, 60.0, &consumer),
        Err(AlignError::NoNorth { .. })
    ));
    // The flat Earth does not turn: nothing to find north by, however good the part.
    let flat = FlatEarth::<Ned>::new(9.81);
    match align::at_rest(
        &flat,
        &Vec3::zeros(),
        [0.0, 0.0, -9.81],
        [0.0; 3],
        60.0,
        &EXACT,
    ) {
        Err(AlignError::NoNorth {
            horizontal_rate_rad_s,
            ..
        }) => assert_eq!(horizontal_rate_rad_s, 0.0),
        other => panic!("{other:?}"),
    }
}

fn nose_along_velocity<N: NavFrame>() {
    for (k, v) in [
        [10.0, 0.0, 0.0],
        [-3.0, 4.0, 0.5],
        [0.0, -7.0, -1.0],
        [5.0, 5.0, 2.0],
        [-20.0, -1.0, 0.0],
    ]
    .into_iter()
    .enumerate()
    {
        let v = Vec3::<N>::from_array(v);
        let c = align::moving(&v);
        let nose = c.apply(Vec3::new(1.0, 0.0, 0.0));
        let along = v * (1.0 / v.norm());
        assert!(
            (nose - along).norm() < 1e-15,
            "{} case {k}: nose {:?} against {:?}",
            N::NAME,
            nose,
            along
        );
        // No roll: the body's y axis is horizontal.
        assert!(c.apply(Vec3::new(0.0, 1.0, 0.0)).z().abs() < 1e-15);
    }
}

#[test]
fn moving_points_the_nose_along_the_velocity_in_both_frames() {
    nose_along_velocity::<Ned>();
    nose_along_velocity::<Enu>();
}

#[test]
fn level_recovers_roll_and_pitch_and_takes_the_heading_given() {
    let g = 9.81;
    let mut worst = 0.0_f64;
    for yaw in (-170..=180).step_by(35) {
        for pitch in [-60.0, -10.0, 0.0, 25.0, 70.0] {
            for roll in [-150.0, -40.0, 0.0, 15.0, 120.0] {
                let (yaw, pitch, roll) = (
                    f64::from(yaw).to_radians(),
                    f64::to_radians(pitch),
                    f64::to_radians(roll),
                );
                // NED: the attitude itself, to rounding.
                let truth = Rotation::<Body, Ned>::from_euler(EulerZyx::new(yaw, pitch, roll));
                let f = truth
                    .inverse()
                    .apply(Vec3::<Ned>::new(0.0, 0.0, -g))
                    .to_array();
                let found = align::level::<Ned>(f, g, yaw, 10.0, &EXACT).unwrap();
                worst = worst.max(angle_between(&found.attitude, &truth));
                // ENU: the same body, levelled; the given heading turns it about the vertical
                // and nothing else.
                let enu = Rotation::<Body, Enu>::from_euler(EulerZyx::new(yaw, pitch, roll));
                let f = enu
                    .inverse()
                    .apply(Vec3::<Enu>::new(0.0, 0.0, g))
                    .to_array();
                let a = align::level::<Enu>(f, g, 0.0, 10.0, &EXACT)
                    .unwrap()
                    .attitude;
                let b = align::level::<Enu>(f, g, 0.3, 10.0, &EXACT)
                    .unwrap()
                    .attitude;
                let up = a.apply(Vec3::<Body>::from_array(f)).to_array();
                worst = worst.max(up[0].hypot(up[1]) / g);
                let turn = b.then(&a.inverse());
                let axis_angle = turn.quaternion().angle();
                worst = worst.max((axis_angle - 0.3).abs());
            }
        }
    }
    assert!(worst < 1e-12, "worst {worst:e}");
    // The tilt's one-sigma is at_rest's; the heading's is the caller's.
    let part = PartFigures {
        accel_bias_m_s2: 0.05,
        gyro_bias_rad_s: 0.0,
        accel_psd: 0.002,
        gyro_psd: 0.0,
    };
    let l = align::level::<Ned>([0.0, 0.0, -g], g, 0.0, 4.0, &part).unwrap();
    assert!((l.tilt_sigma_rad - (0.05_f64.hypot(0.002 / 2.0)) / g).abs() < 1e-15);
    assert_eq!(l.heading_sigma_rad, 0.0);
    assert!(matches!(
        align::level::<Ned>([0.0, 5.0, -g], g, 0.0, 4.0, &part),
        Err(AlignError::NotAtRest { .. })
    ));
}
