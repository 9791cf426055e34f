//! Scenarios on the WGS-84 Earth end to end: a body at rest senses the Earth rate and normal
//! gravity, a climbing turn's readings agree with an independent derivation from the ECEF
//! positions of its own truth file, ENU and NED agree, and bad origins are refused by name.
use std::path::Path;

use imu_core::earth::wgs84::OMEGA_IE_RAD_S;
use imu_core::earth::{Geodetic, normal_gravity_m_s2};
use imukit::io::columns::EARTH_TRUTH_COLUMNS;
use imukit::{Error, ScenarioSpec, Simulation};

fn run(text: &str) -> Result<Simulation, Error> {
    ScenarioSpec::from_toml(text, "earth.toml")?
        .resolve(Path::new("."))?
        .simulate()
}

fn rest(frame: &str) -> String {
    format!(
        "rate_hz = 10.0\nduration_s = 1.0\nnav_frame = \"{frame}\"\nearth = \"wgs84\"\n\
         origin = {{ latitude_deg = 45.0, longitude_deg = 7.0, height_m = 250.0 }}\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n"
    )
}

fn col(sim: &Simulation, table: &str, name: &str) -> Vec<f64> {
    let t = if table == "imu" { &sim.imu } else { &sim.truth };
    t.column(name).unwrap_or_else(|| panic!("no column {name}"))
}

#[test]
fn at_rest_the_imu_senses_the_earth_rate_and_normal_gravity_in_both_frames() {
    let ned = run(&rest("NED")).unwrap();
    let enu = run(&rest("ENU")).unwrap();
    let gamma = normal_gravity_m_s2(&Geodetic::from_degrees(45.0, 7.0, 250.0));
    let (s, c) = (45f64.to_radians().sin(), 45f64.to_radians().cos());
    // NED, body FRD: f = [0, 0, −γ], ω = Ω [cos φ, 0, −sin φ].
    let want_ned = [
        ("accel_x_m_s2", 0.0),
        ("accel_y_m_s2", 0.0),
        ("accel_z_m_s2", -gamma),
        ("gyro_x_rad_s", OMEGA_IE_RAD_S * c),
        ("gyro_y_rad_s", 0.0),
        ("gyro_z_rad_s", -OMEGA_IE_RAD_S * s),
    ];
    // ENU, body FLU: f = [0, 0, +γ], ω = Ω [0, cos φ, sin φ].
    let want_enu = [
        ("accel_x_m_s2", 0.0),
        ("accel_y_m_s2", 0.0),
        ("accel_z_m_s2", gamma),
        ("gyro_x_rad_s", 0.0),
        ("gyro_y_rad_s", OMEGA_IE_RAD_S * c),
        ("gyro_z_rad_s", OMEGA_IE_RAD_S * s),
    ];
    for (sim, want) in [(&ned, want_ned), (&enu, want_enu)] {
        for (name, v) in want {
            for got in col(sim, "imu", name) {
                let tol = if name.starts_with("gyro") {
                    1e-18
                } else {
                    1e-13
                };
                assert!((got - v).abs() <= tol, "{name}: {got} vs {v}");
            }
        }
    }
    let lat = col(&ned, "truth", "lat_rad");
    assert!(lat.iter().all(|l| (l - 45f64.to_radians()).abs() < 1e-15));
    assert_eq!(
        ned.truth.columns[23..],
        EARTH_TRUTH_COLUMNS.map(String::from)
    );
}

/// A climbing, banking turn over 4 km in the tangent plane at 30° S, 2 km up, at 100 Hz.
const TURN: &str = r#"
rate_hz = 100.0
duration_s = 60.0
nav_frame = "NED"
earth = "wgs84"
origin = { latitude_deg = -30.0, longitude_deg = 140.0, height_m = 2000.0 }
[trajectory]
type = "expression"
position_m = ["2000*sin(0.05*t)", "2000*(1 - cos(0.05*t))", "-5*t - 0.02*t^2"]
yaw_rad = "0.05*t"
pitch_rad = "0.04 + 0.001*t"
roll_rad = "0.2*sin(0.1*t)"
[imu]
kind = "accel-gyro"
"#;

#[test]
fn a_climbing_turn_reads_as_an_independent_ecef_derivation_of_its_truth_file_says() {
    // From the truth file alone: ECEF positions differentiated numerically (fourth-order
    // central differences), the attitude and its rate from the local-level columns, then
    // f = C_ebᵀ (a^e + 2Ω × v^e − g^e) and ω_ib = ω_nb + C_bn ω_in^n — compared with the IMU.
    let sim = run(TURN).unwrap();
    let x = col(&sim, "truth", "ecef_x_m");
    let y = col(&sim, "truth", "ecef_y_m");
    let z = col(&sim, "truth", "ecef_z_m");
    let lat = col(&sim, "truth", "lat_rad");
    let lon = col(&sim, "truth", "lon_rad");
    let h = col(&sim, "truth", "height_m");
    let q: Vec<[f64; 4]> = (0..x.len())
        .map(|i| ["q_w", "q_x", "q_y", "q_z"].map(|c| col(&sim, "truth", c)[i]))
        .collect();
    // Steps of 10 samples (0.1 s): rounding of 6e6 m coordinates stays near 1e-7 m/s².
    let (k, dt) = (10, 0.1);
    let d1 = |v: &[f64], i: usize| {
        (v[i - 2 * k] - 8.0 * v[i - k] + 8.0 * v[i + k] - v[i + 2 * k]) / (12.0 * dt)
    };
    let d2 = |v: &[f64], i: usize| {
        (-v[i - 2 * k] + 16.0 * v[i - k] - 30.0 * v[i] + 16.0 * v[i + k] - v[i + 2 * k])
            / (12.0 * dt * dt)
    };
    let (mut worst_f, mut worst_w) = (0.0_f64, 0.0_f64);
    for i in (100..x.len() - 100).step_by(250) {
        let p = Geodetic {
            latitude_rad: lat[i],
            longitude_rad: lon[i],
            height_m: h[i],
        };
        let c_en = p.ned_to_ecef().to_dcm();
        let v_e = [d1(&x, i), d1(&y, i), d1(&z, i)];
        let a_e = [d2(&x, i), d2(&y, i), d2(&z, i)];
        let omega = [0.0, 0.0, OMEGA_IE_RAD_S];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let cor = cross(omega, v_e);
        let gamma = normal_gravity_m_s2(&p);
        let g_e = [0, 1, 2].map(|r| c_en[r][2] * gamma);
        let f_e = [0, 1, 2].map(|r| a_e[r] + 2.0 * cor[r] - g_e[r]);
        // C_nb from the quaternion, then C_eb = C_en C_nb; f^b = C_ebᵀ f^e.
        let c_nb = imu_core::Rotation::<imu_core::Body, imu_core::Ned>::from_wxyz(q[i])
            .unwrap()
            .to_dcm();
        let c_eb: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|k| (0..3).map(|m| c_en[r][m] * c_nb[m][k]).sum())
        });
        let f_b = [0, 1, 2].map(|k| (0..3).map(|r| c_eb[r][k] * f_e[r]).sum::<f64>());
        let got = ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"].map(|c| col(&sim, "imu", c)[i]);
        worst_f = worst_f.max((0..3).map(|k| (got[k] - f_b[k]).abs()).fold(0.0, f64::max));
        // ω_ib^b = ω_eb^b + C_ebᵀ Ω, with ω_eb^b from the ECEF attitude's rate:
        // [ω_eb×] = C_ebᵀ dC_eb/dt (central difference of the attitude).
        let c_eb_at = |j: usize| {
            let pj = Geodetic {
                latitude_rad: lat[j],
                longitude_rad: lon[j],
                height_m: h[j],
            };
            let en = pj.ned_to_ecef().to_dcm();
            let nb = imu_core::Rotation::<imu_core::Body, imu_core::Ned>::from_wxyz(q[j])
                .unwrap()
                .to_dcm();
            let m: [[f64; 3]; 3] = std::array::from_fn(|r| {
                std::array::from_fn(|k| (0..3).map(|m| en[r][m] * nb[m][k]).sum())
            });
            m
        };
        let (a, b) = (c_eb_at(i - 1), c_eb_at(i + 1));
        let dc: [[f64; 3]; 3] =
            std::array::from_fn(|r| std::array::from_fn(|k| (b[r][k] - a[r][k]) / 0.02));
        let skew: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|k| (0..3).map(|m| c_eb[m][r] * dc[m][k]).sum())
        });
        let w_eb = [skew[2][1], skew[0][2], skew[1][0]];
        let w_ie_b = [0, 1, 2].map(|k| c_eb[2][k] * OMEGA_IE_RAD_S);
        let got_w =
            ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"].map(|c| col(&sim, "imu", c)[i]);
        worst_w = worst_w.max(
            (0..3)
                .map(|k| (got_w[k] - (w_eb[k] + w_ie_b[k])).abs())
                .fold(0.0, f64::max),
        );
    }
    // Fourth-order differences at 0.1 s: truncation and rounding near 1e-6 m/s²; the
    // attitude rate's central difference at 10 ms is second order (ω̈ Δt²/6 below 1e-8 rad/s);
    // the Coriolis term is 0.015 m/s² and the transport rate 1.6e-5 rad/s here.
    assert!(worst_f < 5e-6, "specific force differs by {worst_f:e} m/s²");
    assert!(worst_w < 5e-8, "angular rate differs by {worst_w:e} rad/s");
}

#[test]
fn enu_and_ned_scenarios_of_one_motion_read_the_same_up_to_axes() {
    let ned = run(TURN).unwrap();
    let enu_text = TURN
        .replace("nav_frame = \"NED\"", "nav_frame = \"ENU\"")
        // The same motion in ENU axes: (e, n, u) = (y, x, −z), yaw from east: π/2 − ψ,
        // pitch −θ, roll φ (body FLU).
        .replace(
            "position_m = [\"2000*sin(0.05*t)\", \"2000*(1 - cos(0.05*t))\", \"-5*t - 0.02*t^2\"]",
            "position_m = [\"2000*(1 - cos(0.05*t))\", \"2000*sin(0.05*t)\", \"5*t + 0.02*t^2\"]",
        )
        .replace("yaw_rad = \"0.05*t\"", "yaw_rad = \"pi/2 - 0.05*t\"")
        .replace(
            "pitch_rad = \"0.04 + 0.001*t\"",
            "pitch_rad = \"-(0.04 + 0.001*t)\"",
        );
    let enu = run(&enu_text).unwrap();
    // FLU = (x, −y, −z) of FRD.
    for (c, sign) in [("x", 1.0), ("y", -1.0), ("z", -1.0)] {
        for kind in ["accel", "gyro"] {
            let unit = if kind == "accel" { "m_s2" } else { "rad_s" };
            let name = format!("{kind}_{c}_{unit}");
            let (a, b) = (col(&ned, "imu", &name), col(&enu, "imu", &name));
            let worst = a
                .iter()
                .zip(&b)
                .map(|(p, q)| (p - sign * q).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-9, "{name}: {worst:e}");
        }
    }
    let (h1, h2) = (
        col(&ned, "truth", "height_m"),
        col(&enu, "truth", "height_m"),
    );
    assert!(h1.iter().zip(&h2).all(|(a, b)| (a - b).abs() < 1e-6));
}

#[test]
fn a_bad_origin_or_a_trip_over_the_pole_is_refused_by_name() {
    let base = rest("NED");
    let cases = [
        (
            base.replace("earth = \"wgs84\"\n", ""),
            "origin: is used only with earth = \"wgs84\"",
        ),
        (
            base.replace(
                "origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 250.0 }\n",
                "",
            ),
            "origin: missing: earth = \"wgs84\" needs origin",
        ),
        (
            base.replace("latitude_deg = 45.0", "latitude_deg = 95.0"),
            "origin.latitude_deg: must be within ±89.9°",
        ),
        (
            base.replace("longitude_deg = 7.0", "longitude_deg = nan"),
            "origin.longitude_deg: must be within ±180°, got NaN",
        ),
        (
            base.replace("longitude_deg = 7.0", "longitude_deg = 187.0"),
            "origin.longitude_deg: must be within ±180°, got 187",
        ),
        // The height is needed (gravity and the radii depend on it): no silent 0.
        (
            base.replace(", height_m = 250.0", ""),
            "missing field `height_m`",
        ),
        // A latitude formula beyond the pole was wrapped over it (2 rad was placed at 65.4° N,
        // −174.3°), while the same number as an origin is refused.
        (
            base.replace(
                "[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
                "[trajectory]\ntype = \"expression\"\nlatitude_rad = \"2\"\n\
                 longitude_rad = \"0.1\"\nheight_m = \"0\"\n",
            ),
            "trajectory.latitude_rad: at t = 0 s the latitude is 2 rad (114.5916°)",
        ),
        (
            base.replace(
                "[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
                "[trajectory]\ntype = \"expression\"\nlatitude_rad = \"1.5 + 0.1*t\"\n\
                 longitude_rad = \"0.1\"\nheight_m = \"0\"\n",
            ),
            "at t = 0.7 s the latitude is 1.57 rad",
        ),
        (
            base.replace("earth = \"wgs84\"", "earth = \"round\""),
            "unknown variant `round`, expected `flat` or `wgs84`",
        ),
        (
            base.replace("height_m = 250.0 }", "height_m = 250.0, altitude = 3 }"),
            "unknown field `altitude`",
        ),
    ];
    for (text, want) in cases {
        let e = run(&text).unwrap_err().to_string();
        assert!(e.contains(want), "{e}\n-- wanted: {want}");
    }
    // North at 300 m/s from 89.8°: the 89.9° line is 11 km on, crossed after about 37 s.
    let polar = "rate_hz = 1.0\nduration_s = 60.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 89.8, longitude_deg = 0.0, height_m = 0.0 }\n[trajectory]\ntype = \"expression\"\n\
        position_m = [\"300*t\", \"0\", \"0\"]\n";
    let e = run(polar).unwrap_err().to_string();
    assert!(e.contains("beyond ±89.9°") && e.contains("at t = 3"), "{e}");
}

#[test]
fn the_world_magnetic_model_gives_the_field_at_each_position_and_date() {
    // At rest and level at 80° N, 0° E on the ellipsoid, 2025-01-01 (decimal year 2025.0): the
    // magnetometer (NED, FRD) reads NOAA's test value X = 6521.6, Y = 145.9, Z = 54791.5 nT.
    let text = "rate_hz = 1.0\nduration_s = 2.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 80.0, longitude_deg = 0.0, height_m = 0.0 }\n\
        magnetic_model = \"wmm2025\"\ndate = \"2025-01-01\"\n\
        [trajectory]\ntype = \"builtin\"\nname = \"static\"\n";
    let sim = run(text).unwrap();
    for (c, want_nt) in [
        ("mag_x_ut", 6521.6),
        ("mag_y_ut", 145.9),
        ("mag_z_ut", 54791.5),
    ] {
        let got = col(&sim, "imu", c)[0] * 1000.0;
        assert!(
            (got - want_nt).abs() <= 0.05 + 1e-6,
            "{c}: {got} nT vs {want_nt}"
        );
    }
    // ENU, level at zero yaw (body FLU along east, north, up): the same field on those axes.
    let enu = run(&text.replace("\"NED\"", "\"ENU\"")).unwrap();
    for (c, want_nt) in [
        ("mag_x_ut", 145.9),
        ("mag_y_ut", 6521.6),
        ("mag_z_ut", -54791.5),
    ] {
        let got = col(&enu, "imu", c)[0] * 1000.0;
        assert!(
            (got - want_nt).abs() <= 0.05 + 1e-6,
            "ENU {c}: {got} nT vs {want_nt}"
        );
    }
    // Moving 100 km east changes the field: the model is evaluated at each position.
    let moving = text
        .replace("duration_s = 2.0", "duration_s = 100.0")
        .replace(
            "[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
            "[trajectory]\ntype = \"expression\"\nposition_m = [\"0\", \"1000*t\", \"0\"]\n",
        );
    let m = run(&moving).unwrap();
    let y = col(&m, "imu", "mag_y_ut");
    assert!((y[100] - y[0]).abs() > 0.05, "{} → {}", y[0], y[100]);
}

#[test]
fn a_magnetic_model_needs_the_earth_a_date_in_its_validity_and_no_constant_field() {
    let base = "rate_hz = 1.0\nduration_s = 2.0\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 0.0 }\n\
        magnetic_model = \"wmm2025\"\ndate = \"2026-06-01\"\n\
        [trajectory]\ntype = \"builtin\"\nname = \"static\"\n";
    assert!(run(base).is_ok());
    let cases = [
        (
            base.replace("earth = \"wgs84\"\n", "").replace(
                "origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 0.0 }\n",
                "",
            ),
            "magnetic_model: needs positions on the Earth",
        ),
        (base.replace("date = \"2026-06-01\"\n", ""), "date: missing"),
        (
            base.replace("2026-06-01", "2026-02-30"),
            "date: \"2026-02-30\"",
        ),
        (base.replace("2026-06-01", "June 1st"), "date: \"June 1st\""),
        (
            base.replace("2026-06-01", "2031-01-01"),
            "valid from 2025.0 to 2030.0",
        ),
        (
            base.replace("magnetic_model = \"wmm2025\"\n", ""),
            "date: is used by the magnetic model",
        ),
        (base.replace("wmm2025", "igrf"), "unknown variant `igrf`"),
        (
            format!("{base}[imu]\nmagnetic_field_ut = [20, 0, 40]\n"),
            "not both",
        ),
    ];
    for (text, want) in cases {
        let e = run(&text).unwrap_err().to_string();
        assert!(e.contains(want), "{e}\n-- wanted: {want}");
    }
}

#[test]
fn flying_east_along_a_parallel_given_by_latitude_longitude_height_formulas() {
    // 250 m/s due east at 30° N, 10 km up, level and heading east relative to the local level:
    // the specific force is (2Ωv + v²/ρ)·[sin φ, 0, cos φ] − [0, 0, γ] in NED (ρ = (R_E + h)
    // cos φ, the distance to the polar axis) and the body turns at (Ω + v/ρ) about the axis.
    let (phi, h, v) = (30f64.to_radians(), 10_000.0, 250.0);
    let p = Geodetic {
        latitude_rad: phi,
        longitude_rad: 0.1,
        height_m: h,
    };
    let (_, r_e) = p.radii_m();
    let rho = (r_e + h) * phi.cos();
    let text = format!(
        "rate_hz = 10.0\nduration_s = 60.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = {{ latitude_deg = 30.0, longitude_deg = 5.7295779513082321, height_m = 10000.0 }}\n\
         [trajectory]\ntype = \"expression\"\nconstants = {{ rho = {rho:.17e} }}\n\
         latitude_rad = \"{phi:.17e}\"\nlongitude_rad = \"0.1 + {v}*t/rho\"\nheight_m = \"{h}\"\n\
         yaw_rad = \"pi/2\"\npitch_rad = \"0\"\nroll_rad = \"0\"\n[imu]\nkind = \"accel-gyro\"\n"
    );
    let sim = run(&text).unwrap();
    let gamma = normal_gravity_m_s2(&p);
    let k = 2.0 * OMEGA_IE_RAD_S * v + v * v / rho;
    let (f_n, f_d) = (k * phi.sin(), k * phi.cos() - gamma);
    let w = OMEGA_IE_RAD_S + v / rho;
    // Body x east, y south, z down.
    let want = [
        ("accel_x_m_s2", 0.0, 1e-9),
        ("accel_y_m_s2", -f_n, 1e-9),
        ("accel_z_m_s2", f_d, 1e-9),
        ("gyro_x_rad_s", 0.0, 1e-16),
        ("gyro_y_rad_s", -w * phi.cos(), 1e-16),
        ("gyro_z_rad_s", -w * phi.sin(), 1e-16),
    ];
    for (name, value, tol) in want {
        for (i, got) in col(&sim, "imu", name).iter().enumerate() {
            assert!(
                (got - value).abs() <= tol + 1e-9 * value.abs(),
                "{name} at sample {i}: {got} vs {value}"
            );
        }
    }
    let ve = col(&sim, "truth", "vel_y_m_s");
    assert!(ve.iter().all(|x| (x - v).abs() < 1e-9), "{:?}", &ve[..3]);
    let lat = col(&sim, "truth", "lat_rad");
    assert!(lat.iter().all(|l| (l - phi).abs() < 1e-14));
    // The formulas need the Earth, and come as a set.
    let flat = text.replace("earth = \"wgs84\"\n", "").replace(
        "origin = { latitude_deg = 30.0, longitude_deg = 5.7295779513082321, height_m = 10000.0 }\n",
        "",
    );
    let e = run(&flat).unwrap_err().to_string();
    assert!(e.contains("trajectory.latitude_rad: latitude, longitude and height formulas need earth = \"wgs84\""), "{e}");
    let partial = text.replace("height_m = \"10000\"\n", "");
    let e = run(&partial).unwrap_err().to_string();
    assert!(e.contains("trajectory.height_m: missing"), "{e}");
    let tangent = text.replace(
        "yaw_rad = \"pi/2\"\npitch_rad = \"0\"\nroll_rad = \"0\"\n",
        "attitude = \"tangent\"\n",
    );
    // The tangent attitude (nose along the ground velocity, wings level in the local frame)
    // is the same heading east, level: the same readings.
    let along = run(&tangent).unwrap();
    for (name, _, _) in want {
        let (a, b) = (col(&sim, "imu", name), col(&along, "imu", name));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{name}: {worst:e}");
    }
}

#[test]
fn a_tangent_attitude_over_geodetic_formulas_follows_the_local_ground_velocity() {
    // Climbing at 3 m/s while drifting north-east: the nose along the ground velocity in the
    // local frame, in NED (yaw from north, climb nose-up) and ENU (yaw from east, the flat
    // tangent attitude's convention), from the truth's own velocity columns.
    for frame in ["NED", "ENU"] {
        let text = format!(
            "rate_hz = 10.0\nduration_s = 300.0\nnav_frame = \"{frame}\"\nearth = \"wgs84\"\n\
             origin = {{ latitude_deg = 52.0, longitude_deg = 4.0, height_m = 0.0 }}\n\
             [trajectory]\ntype = \"expression\"\n\
             latitude_rad = \"0.9075712110370514 + 1e-5*t + 2e-8*t^2\"\n\
             longitude_rad = \"0.06981317007977318 + 2e-5*sin(0.01*t)\"\nheight_m = \"500 + 3*t\"\n\
             attitude = \"tangent\"\n"
        );
        let sim = run(&text).unwrap();
        let v: Vec<Vec<f64>> = ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"]
            .iter()
            .map(|c| col(&sim, "truth", c))
            .collect();
        let (yaw, pitch, roll) = (
            col(&sim, "truth", "yaw_rad"),
            col(&sim, "truth", "pitch_rad"),
            col(&sim, "truth", "roll_rad"),
        );
        for i in (0..yaw.len()).step_by(53) {
            let (vx, vy, vz) = (v[0][i], v[1][i], v[2][i]);
            let want_yaw = vy.atan2(vx);
            let want_pitch = -vz.atan2(vx.hypot(vy));
            assert!(
                (yaw[i] - want_yaw).abs() < 1e-10,
                "{frame} {i}: {} vs {want_yaw}",
                yaw[i]
            );
            assert!(
                (pitch[i] - want_pitch).abs() < 1e-10,
                "{frame} {i}: {}",
                pitch[i]
            );
            assert!(roll[i].abs() < 1e-10, "{frame} {i}: roll {}", roll[i]);
        }
        if frame == "NED" {
            assert!(pitch[100] > 0.0, "a climb is nose-up in NED");
        }
    }
}

#[test]
fn angles_given_relative_to_the_local_level_come_back_in_the_truth() {
    // A climbing, turning path by latitude, longitude and height; the attitude written relative
    // to the local level at each position is what the truth reports (the motion goes through
    // the tangent plane and back, exactly), in NED and in ENU.
    for frame in ["NED", "ENU"] {
        let text = format!(
            "rate_hz = 10.0\nduration_s = 300.0\nnav_frame = \"{frame}\"\nearth = \"wgs84\"\n\
             origin = {{ latitude_deg = 52.0, longitude_deg = 4.0, height_m = 0.0 }}\n\
             [trajectory]\ntype = \"expression\"\n\
             latitude_rad = \"0.9075712110370514 + 1e-5*t + 2e-8*t^2\"\n\
             longitude_rad = \"0.06981317007977318 + 2e-5*sin(0.01*t)\"\nheight_m = \"500 + 3*t\"\n\
             yaw_rad = \"0.3 + 0.01*t\"\npitch_rad = \"0.05\"\nroll_rad = \"0.1*sin(t)\"\n"
        );
        let sim = run(&text).unwrap();
        let t = col(&sim, "truth", "t_s");
        let (yaw, pitch, roll) = (
            col(&sim, "truth", "yaw_rad"),
            col(&sim, "truth", "pitch_rad"),
            col(&sim, "truth", "roll_rad"),
        );
        let lat = col(&sim, "truth", "lat_rad");
        let h = col(&sim, "truth", "height_m");
        for i in (0..t.len()).step_by(97) {
            let s = t[i];
            let want = [0.3 + 0.01 * s, 0.05, 0.1 * s.sin()];
            for (got, w) in [yaw[i], pitch[i], roll[i]].iter().zip(want) {
                assert!((got - w).abs() < 1e-10, "{frame} t = {s}: {got} vs {w}");
            }
            assert!((lat[i] - (0.907_571_211_037_051_4 + 1e-5 * s + 2e-8 * s * s)).abs() < 1e-13);
            assert!((h[i] - (500.0 + 3.0 * s)).abs() < 1e-6);
        }
    }
}

#[test]
fn geodetic_waypoints_are_passed_exactly_on_the_earth() {
    let text = "rate_hz = 10.0\nduration_s = 300.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 47.0, longitude_deg = 8.0, height_m = 400.0 }\n\
        [trajectory]\ntype = \"waypoints\"\ntime_s = [0, 100, 200, 300]\n\
        geodetic = [\n  { latitude_deg = 47.0, longitude_deg = 8.0, height_m = 400.0 },\n\
          { latitude_deg = 47.05, longitude_deg = 8.05, height_m = 900.0 },\n\
          { latitude_deg = 47.12, longitude_deg = 8.06, height_m = 1500.0 },\n\
          { latitude_deg = 47.15, longitude_deg = 8.2, height_m = 1200.0 },\n]\n";
    let sim = run(text).unwrap();
    let (lat, lon, h) = (
        col(&sim, "truth", "lat_rad"),
        col(&sim, "truth", "lon_rad"),
        col(&sim, "truth", "height_m"),
    );
    for (k, (la, lo, he)) in [
        (47.0, 8.0, 400.0),
        (47.05, 8.05, 900.0),
        (47.12, 8.06, 1500.0),
        (47.15, 8.2, 1200.0),
    ]
    .into_iter()
    .enumerate()
    {
        let i = k * 1000;
        assert!(
            (lat[i] - f64::to_radians(la)).abs() < 1e-12,
            "{k}: {}",
            lat[i]
        );
        assert!(
            (lon[i] - f64::to_radians(lo)).abs() < 1e-12,
            "{k}: {}",
            lon[i]
        );
        assert!((h[i] - he).abs() < 1e-6, "{k}: {}", h[i]);
    }
    let flat = text.replace("earth = \"wgs84\"\n", "").replace(
        "origin = { latitude_deg = 47.0, longitude_deg = 8.0, height_m = 400.0 }\n",
        "",
    );
    let e = run(&flat).unwrap_err().to_string();
    assert!(
        e.contains("trajectory.geodetic: geodetic waypoints need earth"),
        "{e}"
    );
    let polar = text.replace("latitude_deg = 47.15", "latitude_deg = 95");
    let e = run(&polar).unwrap_err().to_string();
    assert!(
        e.contains("trajectory.geodetic[3]: needs a latitude within ±89.9°"),
        "{e}"
    );
}

#[test]
fn samples_of_latitude_longitude_and_height_give_the_formulas_readings() {
    // The climbing, turning path by formulas, then the same path as samples of latitude,
    // longitude, height and local angles (no pos_* columns): the finite differences (sixth
    // order at 20 Hz) give the exact readings to their error, which here is the rounding of
    // positions carried from radians on a 6.4e6 m Earth (1e-9 m, amplified by 1/h²).
    let dir = tempfile::Builder::new()
        .prefix("imukit-earth-samples-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let head = "rate_hz = 20.0\nduration_s = 60.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 52.0, longitude_deg = 4.0, height_m = 0.0 }\n";
    let formulas = format!(
        "{head}[trajectory]\ntype = \"expression\"\n\
         latitude_rad = \"0.9075712110370514 + 1e-5*t + 2e-8*t^2\"\n\
         longitude_rad = \"0.06981317007977318 + 2e-5*sin(0.01*t)\"\nheight_m = \"500 + 3*t\"\n\
         yaw_rad = \"0.3 + 0.01*t\"\npitch_rad = \"0.05\"\nroll_rad = \"0.1*sin(t)\"\n\
         [imu]\nkind = \"accel-gyro\"\n"
    );
    let exact = run(&formulas).unwrap();
    let names = [
        "t_s",
        "lat_rad",
        "lon_rad",
        "height_m",
        "yaw_rad",
        "pitch_rad",
        "roll_rad",
    ];
    let cols: Vec<Vec<f64>> = names.iter().map(|c| col(&exact, "truth", c)).collect();
    let mut csv = names.join(",") + "\n";
    for i in 0..cols[0].len() {
        let row: Vec<String> = cols.iter().map(|c| format!("{:?}", c[i])).collect();
        csv += &(row.join(",") + "\n");
    }
    std::fs::write(dir.join("geodetic.csv"), csv).unwrap();
    let samples = format!(
        "{head}[trajectory]\ntype = \"samples\"\nfile = \"geodetic.csv\"\n[imu]\nkind = \"accel-gyro\"\n"
    );
    let sampled = ScenarioSpec::from_toml(&samples, "samples.toml")
        .unwrap()
        .resolve(dir)
        .unwrap()
        .simulate()
        .unwrap();
    // Away from the ends (one-sided differences there).
    for (name, tol) in [
        ("accel_x_m_s2", 1e-5),
        ("accel_y_m_s2", 1e-5),
        ("accel_z_m_s2", 1e-5),
        ("gyro_x_rad_s", 1e-10),
        ("gyro_y_rad_s", 1e-10),
        ("gyro_z_rad_s", 1e-10),
    ] {
        let (a, b) = (col(&exact, "imu", name), col(&sampled, "imu", name));
        let worst = (20..a.len() - 20)
            .map(|i| (a[i] - b[i]).abs())
            .fold(0.0, f64::max);
        assert!(worst < tol, "{name}: {worst:e}");
    }
    let flat = samples.replace("earth = \"wgs84\"\n", "").replace(
        "origin = { latitude_deg = 52.0, longitude_deg = 4.0, height_m = 0.0 }\n",
        "",
    );
    let e = ScenarioSpec::from_toml(&flat, "samples.toml")
        .unwrap()
        .resolve(dir)
        .unwrap_err()
        .to_string();
    assert!(e.contains("geodetic samples need earth = \"wgs84\""), "{e}");
}
