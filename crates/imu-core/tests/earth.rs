//! The WGS-84 Earth model against published constants and closed-form motions: the ellipsoid's
//! derived constants, normal gravity, geodetic ↔ ECEF, and the ideal IMU at rest, flying along a
//! parallel, and in a climbing turn (the NED formulas against the independent ECEF route).
use imu_core::earth::ideal::{EcefKinematics, earth_rate_ecef, ecef_specific_force_and_rate};
use imu_core::earth::wgs84::{A_M, B_M, E2, OMEGA_IE_RAD_S};
use imu_core::earth::{EarthMount, EarthTruth, Geodetic, GravityModel, normal_gravity_m_s2};
use imu_core::{AccelSign, Ecef, EulerZyx, Frd, Ned, Rotation, Vec3};

fn close<F: imu_core::Frame>(got: Vec3<F>, want: Vec3<F>, rel: f64, what: &str) {
    let scale = want.norm().max(1e-300);
    let err = (got - want).norm();
    assert!(
        err <= rel * scale,
        "{what}: {got:?} vs {want:?} (error {err:e}, {:e} relative)",
        err / scale
    );
}

#[test]
fn derived_constants_match_tr8350() {
    // NIMA TR8350.2, table 3.3: e² = 0.00669437999014, b = 6356752.3142 m; table 3.4:
    // m = 0.00344978650684, normal gravity at the pole 9.8321849378 m/s².
    assert!((E2 - 0.006_694_379_990_14).abs() < 5e-15);
    assert!((B_M - 6_356_752.314_2).abs() < 1e-4);
    assert!((imu_core::earth::gravity::M_RATIO - 0.003_449_786_506_84).abs() < 1e-15);
    let equator = normal_gravity_m_s2(&Geodetic::from_degrees(0.0, 0.0, 0.0));
    let pole = normal_gravity_m_s2(&Geodetic::from_degrees(90.0, 0.0, 0.0));
    assert!((equator - 9.780_325_335_9).abs() < 1e-10, "{equator}");
    assert!((pole - 9.832_184_937_8).abs() < 1e-9, "{pole}");
}

#[test]
fn normal_gravity_falls_with_height_by_the_free_air_gradient() {
    // dγ/dh at the surface ≈ −(2γ/a)(1 + f + m − 2f sin²φ) ≈ −3.086e-6 s⁻² at 45°.
    let p = |h: f64| normal_gravity_m_s2(&Geodetic::from_degrees(45.0, 0.0, h));
    let gradient = (p(1.0) - p(-1.0)) / 2.0;
    assert!((gradient + 3.086e-6).abs() < 0.002e-6, "{gradient:e}");
    // Somigliana at 45°: γ_e (1 + k/2)/√(1 − e²/2), written out.
    let k = imu_core::earth::gravity::SOMIGLIANA_K;
    let want =
        imu_core::earth::gravity::GAMMA_EQUATOR_M_S2 * (1.0 + k / 2.0) / (1.0 - E2 / 2.0).sqrt();
    assert!((p(0.0) - want).abs() < 1e-14, "{} vs {want}", p(0.0));
}

#[test]
fn geodetic_and_ecef_round_trip_everywhere_a_vehicle_can_be() {
    assert_eq!(
        Geodetic::from_degrees(0.0, 0.0, 0.0).to_ecef().to_array(),
        [A_M, 0.0, 0.0]
    );
    let pole = Geodetic::from_degrees(90.0, 0.0, 0.0).to_ecef();
    assert!(pole.x().abs() < 1e-9 && (pole.z() - B_M).abs() < 1e-9);
    let mut worst = (0.0_f64, 0.0_f64);
    for lat in (-90..=90).step_by(5) {
        for lon in (-180..=180).step_by(30) {
            for h in [-10_000.0, 0.0, 1.0, 11_000.0, 400_000.0, 35_786_000.0] {
                let g = Geodetic::from_degrees(f64::from(lat), f64::from(lon), h);
                let r = g.to_ecef();
                let back = Geodetic::from_ecef(r).unwrap();
                let again = back.to_ecef();
                worst.0 = worst.0.max((again - r).norm());
                worst.1 = worst.1.max((back.height_m - h).abs());
                assert!(
                    (back.latitude_rad - g.latitude_rad).abs() < 1e-14 * 4.0,
                    "{lat} {lon} {h}: {back:?}"
                );
            }
        }
    }
    // Well below a millimetre (the issue asks < 1 mm): rounding only.
    assert!(worst.0 < 1e-7 && worst.1 < 1e-7, "{worst:?}");
    assert!(Geodetic::from_ecef(Vec3::new(1000.0, 0.0, 0.0)).is_none());
    assert!(Geodetic::from_ecef(Vec3::new(f64::NAN, 0.0, 0.0)).is_none());
}

#[test]
fn ned_axes_are_north_east_down_in_ecef() {
    let g = Geodetic::from_degrees(45.0, 90.0, 0.0);
    let c = g.ned_to_ecef();
    let s = core::f64::consts::FRAC_1_SQRT_2;
    close(
        c.apply(Vec3::<Ned>::new(1.0, 0.0, 0.0)),
        Vec3::<Ecef>::new(0.0, -s, s),
        1e-15,
        "north",
    );
    close(
        c.apply(Vec3::<Ned>::new(0.0, 1.0, 0.0)),
        Vec3::<Ecef>::new(-1.0, 0.0, 0.0),
        1e-15,
        "east",
    );
    close(
        c.apply(Vec3::<Ned>::new(0.0, 0.0, 1.0)),
        Vec3::<Ecef>::new(0.0, -s, -s),
        1e-15,
        "down",
    );
}

#[test]
fn at_rest_at_45_degrees_north_the_gyro_reads_the_earth_rate_and_the_accelerometer_minus_gamma() {
    let truth = EarthTruth {
        position: Geodetic::from_degrees(45.0, 7.0, 0.0),
        ..EarthTruth::default()
    };
    let mount = EarthMount::default();
    let r = mount.read(&truth, Vec3::zeros());
    let s = core::f64::consts::FRAC_1_SQRT_2;
    close(
        r.gyro_rad_s,
        Vec3::new(OMEGA_IE_RAD_S * s, 0.0, -OMEGA_IE_RAD_S * s),
        1e-15,
        "gyro",
    );
    let gamma = normal_gravity_m_s2(&truth.position);
    close(r.accel_m_s2, Vec3::new(0.0, 0.0, -gamma), 1e-15, "accel");
    // MATLAB's sign, and a constant gravity.
    let matlab = EarthMount {
        accel_sign: AccelSign::Matlab,
        gravity: GravityModel::Constant(9.81),
        ..mount
    };
    close(
        matlab.read(&truth, Vec3::zeros()).accel_m_s2,
        Vec3::new(0.0, 0.0, 9.81),
        1e-15,
        "matlab",
    );
}

#[test]
fn flying_east_along_a_parallel_is_a_circle_about_the_polar_axis() {
    // At 30° N, 10 km up, 250 m/s due east at constant attitude: the body turns about the polar
    // axis at Ω + λ̇ with λ̇ = v/ρ, ρ = (R_E + h) cos φ, and its inertial acceleration is
    // −(Ω + λ̇)² ρ towards the axis. With gravitation = γ·down − Ω²ρ·(outward), the specific
    // force is (2Ωv + v²/ρ)·[sin φ, 0, cos φ] − γ·down (NED).
    let (phi, h, v) = (30f64.to_radians(), 10_000.0, 250.0);
    let position = Geodetic {
        latitude_rad: phi,
        longitude_rad: 0.3,
        height_m: h,
    };
    let attitude =
        Rotation::<Frd, Ned>::from_euler(EulerZyx::new(std::f64::consts::FRAC_PI_2, 0.02, -0.01));
    let truth = EarthTruth {
        position,
        velocity_m_s: Vec3::new(0.0, v, 0.0),
        attitude,
        ..EarthTruth::default()
    };
    let (_, r_e) = position.radii_m();
    let rho = (r_e + h) * phi.cos();
    let lambda_dot = v / rho;
    let gamma = normal_gravity_m_s2(&position);
    let c_bn = attitude.inverse();
    let f_want = c_bn.apply(
        Vec3::<Ned>::new(phi.sin(), 0.0, phi.cos()) * (2.0 * OMEGA_IE_RAD_S * v + v * v / rho)
            - Vec3::new(0.0, 0.0, gamma),
    );
    let w_want =
        c_bn.apply(Vec3::<Ned>::new(phi.cos(), 0.0, -phi.sin()) * (OMEGA_IE_RAD_S + lambda_dot));
    let mount = EarthMount::default();
    close(
        mount.specific_force(&truth),
        f_want,
        1e-12,
        "specific force",
    );
    close(
        mount.read(&truth, Vec3::zeros()).gyro_rad_s,
        w_want,
        1e-12,
        "gyro",
    );
    // The Coriolis and centripetal terms are large enough to matter: 0.0239 m/s² north
    // ((0.03646 + 0.01129)·sin 30°).
    let f_n = attitude.apply(mount.specific_force(&truth));
    assert!((f_n.x() - 0.0239).abs() < 0.0001, "{f_n:?}");
}

/// A climbing, turning, rolling aircraft state at 52° N.
fn climbing_turn() -> EarthTruth {
    let euler = EulerZyx::new(0.7, 0.12, 0.35);
    EarthTruth {
        t_s: 12.0,
        position: Geodetic::from_degrees(52.0, -1.3, 3_000.0),
        velocity_m_s: Vec3::new(150.0, 120.0, -8.0),
        acceleration_m_s2: Vec3::new(-9.5, 11.8, -0.4),
        attitude: Rotation::from_euler(euler),
        euler,
        omega_nb_b_rad_s: Vec3::new(0.01, 0.03, 0.075),
        alpha_nb_b_rad_s2: Vec3::new(0.002, -0.001, 0.004),
    }
}

#[test]
fn a_climbing_turn_reads_the_same_through_ned_and_through_ecef() {
    let truth = climbing_turn();
    let k = truth.to_ecef();
    for gravity in [GravityModel::Normal, GravityModel::Constant(9.81)] {
        let mount = EarthMount {
            gravity,
            ..EarthMount::default()
        };
        let (f_e, w_e) = ecef_specific_force_and_rate(&k, &gravity).unwrap();
        close(mount.specific_force(&truth), f_e, 1e-12, "specific force");
        close(truth.inertial_rate().0, w_e, 1e-12, "inertial rate");
    }
    // The inertial angular acceleration two ways: α_ib = α_eb − ω_eb × C_be Ω^e (ECEF).
    let c_be = k.attitude.inverse();
    let alpha_e = k.alpha_eb_b_rad_s2 - k.omega_eb_b_rad_s.cross(&c_be.apply(earth_rate_ecef()));
    close(
        truth.inertial_rate().1,
        alpha_e,
        1e-12,
        "inertial angular acceleration",
    );
    // And back: NED → ECEF → NED is the identity.
    let back = EarthTruth::from_ecef(truth.t_s, &k).unwrap();
    close(back.velocity_m_s, truth.velocity_m_s, 1e-13, "velocity");
    close(
        back.acceleration_m_s2,
        truth.acceleration_m_s2,
        1e-12,
        "acceleration",
    );
    close(
        back.omega_nb_b_rad_s,
        truth.omega_nb_b_rad_s,
        1e-12,
        "omega",
    );
    close(
        back.alpha_nb_b_rad_s2,
        truth.alpha_nb_b_rad_s2,
        1e-10,
        "alpha",
    );
    assert!((back.position.height_m - truth.position.height_m).abs() < 1e-8);
}

#[test]
fn a_lever_arm_adds_the_rigid_body_terms_of_the_inertial_rate() {
    let truth = climbing_turn();
    let r = Vec3::<Frd>::new(1.2, -0.4, 0.3);
    let at_arm = EarthMount {
        lever_arm_m: r,
        ..EarthMount::default()
    };
    let (w, alpha) = truth.inertial_rate();
    let want =
        EarthMount::default().specific_force(&truth) + w.cross(&w.cross(&r)) + alpha.cross(&r);
    close(at_arm.specific_force(&truth), want, 1e-14, "lever arm");
}

/// Finite-difference check of the Earth-fixed conversion: a constant-acceleration motion in
/// ECEF, converted sample by sample, has `v̇^n` equal to the central difference of `v^n`.
#[test]
fn the_ned_velocity_derivative_is_the_derivative_of_the_converted_velocity() {
    let r0 = Geodetic::from_degrees(40.0, 20.0, 500.0).to_ecef();
    let v0 = Vec3::<Ecef>::new(120.0, -80.0, 60.0);
    let a = Vec3::<Ecef>::new(1.5, 2.0, -0.5);
    let at = |t: f64| {
        EarthTruth::from_ecef(
            t,
            &EcefKinematics {
                position_m: r0 + v0 * t + a * (0.5 * t * t),
                velocity_m_s: v0 + a * t,
                acceleration_m_s2: a,
                attitude: Rotation::identity(),
                omega_eb_b_rad_s: Vec3::zeros(),
                alpha_eb_b_rad_s2: Vec3::zeros(),
            },
        )
        .unwrap()
    };
    let h = 1e-2;
    let (before, now, after) = (at(5.0 - h), at(5.0), at(5.0 + h));
    let numeric = (after.velocity_m_s - before.velocity_m_s) * (1.0 / (2.0 * h));
    close(now.acceleration_m_s2, numeric, 1e-7, "v̇^n");
    let numeric_omega_rate = (after.omega_nb_b_rad_s - before.omega_nb_b_rad_s) * (1.0 / (2.0 * h));
    close(now.alpha_nb_b_rad_s2, numeric_omega_rate, 1e-5, "α_nb");
}
