//! The GNSS receiver of a scenario end to end: fixes at the antenna (lever arm), stamped late
//! by the latency, none in outages, on the flat and the WGS-84 Earth; the streamed file equals
//! the in-memory table; bad `[gnss]` keys are named.
use std::path::Path;

use imu_core::{Body, Enu, Rotation, Vec3};
use imukit::{Error, ScenarioSpec, Simulation};

fn run(text: &str) -> Result<Simulation, Error> {
    ScenarioSpec::from_toml(text, "gnss.toml")?
        .resolve(Path::new("."))?
        .simulate()
}

const FIGURE8: &str =
    "rate_hz = 100.0\nduration_s = 30.0\n[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\n";

#[test]
fn exact_fixes_are_the_antennas_truth_stamped_late_and_none_in_an_outage() {
    let text = format!(
        "{FIGURE8}[gnss]\nrate_hz = 10.0\nhorizontal_accuracy_m = 0.0\nvertical_accuracy_m = 0.0\n\
         velocity_accuracy_m_s = 0.0\nlever_arm_m = [0.3, -0.2, 0.5]\nlatency_s = 0.2\n\
         [[gnss.outages]]\nstart_s = 10.0\nduration_s = 5.0\n"
    );
    let sim = run(&text).unwrap();
    let gnss = sim.gnss.as_ref().unwrap();
    let col = |t: &imukit::Table, c: &str| t.column(c).unwrap();
    let stamps = col(gnss, "t_s");
    // 301 epochs at 10 Hz over 30 s; 50 stamps fall in [10, 15); the last two (30.1, 30.2)
    // after the run's end.
    assert_eq!(stamps.len(), 301 - 50 - 2);
    assert!(stamps.iter().all(|t| !(10.0..15.0).contains(t)));
    let lever = Vec3::<Body>::new(0.3, -0.2, 0.5);
    let truth = &sim.truth;
    for (k, stamp) in stamps.iter().enumerate() {
        // The epoch is the stamp less the latency, an IMU sample (every 10th).
        let i = ((stamp - 0.2) * 100.0).round() as usize;
        assert!((col(truth, "t_s")[i] + 0.2 - stamp).abs() < 1e-12);
        let q = ["q_w", "q_x", "q_y", "q_z"].map(|c| col(truth, c)[i]);
        let c_nb = Rotation::<Body, Enu>::from_wxyz(q).unwrap();
        let w = Vec3::<Body>::from_array(
            ["omega_x_rad_s", "omega_y_rad_s", "omega_z_rad_s"].map(|c| col(truth, c)[i]),
        );
        let p =
            Vec3::<Enu>::from_array(["pos_x_m", "pos_y_m", "pos_z_m"].map(|c| col(truth, c)[i]))
                + c_nb.apply(lever);
        let v = Vec3::<Enu>::from_array(
            ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"].map(|c| col(truth, c)[i]),
        ) + c_nb.apply(w.cross(&lever));
        let got_p = ["pos_x_m", "pos_y_m", "pos_z_m"].map(|c| col(gnss, c)[k]);
        let got_v = ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"].map(|c| col(gnss, c)[k]);
        for j in 0..3 {
            assert!((got_p[j] - p.to_array()[j]).abs() < 1e-12, "fix {k}");
            assert!((got_v[j] - v.to_array()[j]).abs() < 1e-12, "fix {k}");
        }
    }
}

#[test]
fn on_the_earth_fixes_are_geodetic_and_their_errors_are_metres_north_east_down() {
    let base = "rate_hz = 10.0\nduration_s = 1999.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
        origin = { latitude_deg = 60.0, longitude_deg = 10.0, height_m = 100.0 }\n\
        [trajectory]\ntype = \"builtin\"\nname = \"static\"\n";
    let exact = run(&format!(
        "{base}[gnss]\nhorizontal_accuracy_m = 0.0\nvertical_accuracy_m = 0.0\nvelocity_accuracy_m_s = 0.0\n"
    ))
    .unwrap();
    let g = exact.gnss.unwrap();
    assert_eq!(
        g.columns,
        [
            "t_s",
            "lat_rad",
            "lon_rad",
            "height_m",
            "vel_n_m_s",
            "vel_e_m_s",
            "vel_d_m_s"
        ]
    );
    let lat = g.column("lat_rad").unwrap();
    assert!(lat.iter().all(|l| (l - 60f64.to_radians()).abs() < 1e-15));
    // White errors (decay factor 0: MATLAB's deviation σ√2): 2000 fixes at 1 Hz, σ_h = 1 m.
    let noisy = run(&format!(
        "{base}[gnss]\nhorizontal_accuracy_m = 1.0\nvertical_accuracy_m = 2.0\ndecay_factor = 0.0\n"
    ))
    .unwrap()
    .gnss
    .unwrap();
    let p = imu_core::earth::Geodetic::from_degrees(60.0, 10.0, 100.0);
    let (r_n, r_e) = p.radii_m();
    let n = noisy.rows() as f64;
    let sd = |v: Vec<f64>, scale: f64, centre: f64| {
        (v.iter()
            .map(|x| ((x - centre) * scale).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    let north = sd(
        noisy.column("lat_rad").unwrap(),
        r_n + 100.0,
        p.latitude_rad,
    );
    let east = sd(
        noisy.column("lon_rad").unwrap(),
        (r_e + 100.0) * p.latitude_rad.cos(),
        p.longitude_rad,
    );
    let down = sd(noisy.column("height_m").unwrap(), 1.0, 100.0);
    let tol = 4.0 / (2.0 * n).sqrt();
    for (got, want) in [
        (north, 2f64.sqrt()),
        (east, 2f64.sqrt()),
        (down, 2.0 * 2f64.sqrt()),
    ] {
        assert!((got / want - 1.0).abs() < tol, "{got} vs {want}");
    }
}

#[test]
fn the_streamed_file_equals_the_in_memory_table_and_runs_differ() {
    let text = FIGURE8.replace("duration_s = 30.0", "duration_s = 100.0");
    let text = format!("{text}[gnss]\nrate_hz = 20.0\n[imu]\nseed = 7\n");
    let spec = ScenarioSpec::from_toml(&text, "g.toml").unwrap();
    let sc = spec.resolve(Path::new(".")).unwrap();
    let dir = tempfile::Builder::new()
        .prefix("imukit-gnss-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let (imu, gnss) = (dir.join("imu.csv"), dir.join("gnss.csv"));
    // 10 001 samples: the stream crosses chunk boundaries (4096).
    sc.stream_to_files(
        None,
        imukit::run::pipeline::RunThreads::Auto,
        &imukit::run::simulate::StreamOutputs {
            imu: Some(&imu),
            gnss: Some(&gnss),
            ..Default::default()
        },
    )
    .unwrap();
    let from_file = imukit::io::read::read_table(&gnss).unwrap();
    let in_memory = sc.simulate().unwrap().gnss.unwrap();
    assert_eq!(from_file.columns, in_memory.columns);
    assert_eq!(from_file.data, in_memory.data);
    let run1 = sc.simulate_run(1).unwrap().gnss.unwrap();
    assert_ne!(run1.data, in_memory.data);
    assert_eq!(run1.data, sc.simulate_run(1).unwrap().gnss.unwrap().data);
    // The IMU's noise is not disturbed by the receiver: the same readings as without it.
    let without = ScenarioSpec::from_toml(&text.replace("[gnss]\nrate_hz = 20.0\n", ""), "g.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
        .simulate()
        .unwrap();
    assert_eq!(without.imu.data, sc.simulate().unwrap().imu.data);
}

#[test]
fn bad_gnss_keys_are_refused_by_name() {
    let cases = [
        (
            "rate_hz = 3.0",
            "gnss.rate_hz: must divide the scenario's rate_hz",
        ),
        ("rate_hz = 200.0", "gnss.rate_hz: must divide"),
        (
            "horizontal_accuracy_m = -1.0",
            "gnss.horizontal_accuracy_m: horizontal_accuracy_m must be a finite number ≥ 0",
        ),
        (
            "decay_factor = 2.0",
            "gnss.decay_factor: decay_factor must be within [0, 1]",
        ),
        (
            "decay_factor = 0.5\ncorrelation_time_s = 10.0",
            "gnss.correlation_time_s: give decay_factor",
        ),
        (
            "latency_s = -0.1",
            "gnss.latency_s: must be a finite number ≥ 0",
        ),
        ("lever_arm_m = [0, nan, 0]", "gnss.lever_arm_m"),
        (
            "outages = [{ start_s = 1.0, duration_s = 0.0 }]",
            "gnss.outages[0]: needs a finite start_s and a duration_s > 0",
        ),
        ("rate = 1.0", "unknown field `rate`"),
        // No fix inside the run: the GNSS file would hold only its header.
        (
            "latency_s = 1e308",
            "gnss: no fix falls within the run (it ends at",
        ),
        (
            "outages = [{ start_s = -1.0, duration_s = 1e9 }]",
            "outages included",
        ),
    ];
    for (keys, want) in cases {
        let e = run(&format!("{FIGURE8}[gnss]\n{keys}\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{keys}: {e}");
    }
    // A GNSS file without a receiver.
    let sc = ScenarioSpec::from_toml(FIGURE8, "g.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap();
    let dir = std::env::temp_dir();
    let e = sc
        .stream_to_files(
            None,
            imukit::run::pipeline::RunThreads::Auto,
            &imukit::run::simulate::StreamOutputs {
                imu: Some(&dir.join(format!("imukit-nognss-{}.csv", std::process::id()))),
                gnss: Some(&dir.join(format!("imukit-nognss-g-{}.csv", std::process::id()))),
                ..Default::default()
            },
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("the scenario has no [gnss] receiver"), "{e}");
}

#[test]
fn a_barometer_reads_the_height_and_an_odometer_the_forward_speed_with_their_errors() {
    // Flying north-east at 10 m/s, 50 m up, for 200 s: 2001 readings at 10 Hz of each.
    for (frame, z) in [("NED", "-50"), ("ENU", "50")] {
        let text = format!(
            "rate_hz = 100.0\nduration_s = 200.0\nnav_frame = \"{frame}\"\n[trajectory]\ntype = \"expression\"\n\
             position_m = [\"7.0710678118654755*t\", \"7.0710678118654755*t\", \"{z}\"]\nattitude = \"tangent\"\n\
             [baro]\nbias_m = 2.0\nnoise_m = 0.5\n[odometer]\nscale_factor_error = 0.01\nnoise_m_s = 0.05\n"
        );
        let sim = run(&text).unwrap();
        let (baro, odo) = (sim.baro.unwrap(), sim.odometer.unwrap());
        assert_eq!((baro.rows(), odo.rows()), (2001, 2001));
        let stats = |v: Vec<f64>| {
            let n = v.len() as f64;
            let m = v.iter().sum::<f64>() / n;
            (
                m,
                (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt(),
            )
        };
        let n = 2001f64;
        // Means within 4 standard errors σ/√n, deviations within 4 of σ/√(2n).
        let (m, s) = stats(baro.column("baro_height_m").unwrap());
        assert!((m - 52.0).abs() < 4.0 * 0.5 / n.sqrt(), "{frame}: {m}");
        assert!(
            (s / 0.5 - 1.0).abs() < 4.0 / (2.0 * n).sqrt(),
            "{frame}: {s}"
        );
        let (m, s) = stats(odo.column("speed_m_s").unwrap());
        assert!((m - 10.1).abs() < 4.0 * 0.05 / n.sqrt(), "{frame}: {m}");
        assert!(
            (s / 0.05 - 1.0).abs() < 4.0 / (2.0 * n).sqrt(),
            "{frame}: {s}"
        );
    }
    // On the Earth the barometer reads the WGS-84 height.
    let earth = run(
        "rate_hz = 10.0\nduration_s = 10.0\nnav_frame = \"NED\"\nearth = \"wgs84\"\n\
         origin = { latitude_deg = 47.0, longitude_deg = 8.0, height_m = 1200.0 }\n\
         [trajectory]\ntype = \"builtin\"\nname = \"static\"\n[baro]\nrate_hz = 1.0\nnoise_m = 0.0\n",
    )
    .unwrap();
    let h = earth.baro.unwrap().column("baro_height_m").unwrap();
    assert!(h.iter().all(|x| (x - 1200.0).abs() < 1e-6), "{h:?}");
    // Keys are checked by name.
    for (keys, want) in [
        (
            "[baro]\nrate_hz = 3.0",
            "baro.rate_hz: must be > 0 and divide",
        ),
        (
            "[baro]\nnoise_m = -1.0",
            "baro.noise_m: must be a finite number ≥ 0",
        ),
        (
            "[odometer]\nscale_factor_error = nan",
            "odometer.scale_factor_error: must be a finite number",
        ),
        ("[odometer]\nrate = 1.0", "unknown field `rate`"),
    ] {
        let e = run(&format!("{FIGURE8}{keys}\n")).unwrap_err().to_string();
        assert!(e.contains(want), "{keys}: {e}");
    }
}

#[test]
fn a_filter_told_its_fixes_are_exact_is_refused_by_the_accuracy_named() {
    use imukit::error::RequestOption;
    use imukit::run::fuse::PartModel;
    use imukit::run::navigate::NavSetup;
    use imukit::scenario::gnss::GnssSpec;
    let part = |gnss: GnssSpec| PartModel {
        imu: imukit::run::fuse::Part::Preset("stim300".into()),
        part: None,
        gnss,
    };
    for (gnss, field) in [
        (
            GnssSpec {
                velocity_accuracy_m_s: Some(0.0),
                ..GnssSpec::default()
            },
            RequestOption::GnssVelocityAccuracy,
        ),
        (
            GnssSpec {
                horizontal_accuracy_m: Some(-1.0),
                ..GnssSpec::default()
            },
            RequestOption::GnssHorizontalAccuracy,
        ),
        (
            GnssSpec {
                vertical_accuracy_m: Some(f64::NAN),
                ..GnssSpec::default()
            },
            RequestOption::GnssVerticalAccuracy,
        ),
        (
            GnssSpec {
                decay_factor: Some(1.5),
                ..GnssSpec::default()
            },
            RequestOption::GnssDecayFactor,
        ),
        (
            GnssSpec {
                latency_s: Some(-0.1),
                ..GnssSpec::default()
            },
            RequestOption::GnssLatency,
        ),
        (
            GnssSpec {
                lever_arm_m: Some([0.0, f64::INFINITY, 0.0]),
                ..GnssSpec::default()
            },
            RequestOption::GnssLeverArm,
        ),
    ] {
        match part(gnss).setup(&NavSetup::default(), None, 100.0) {
            Err(Error::Request { option, message }) => {
                assert_eq!(option, field);
                let accuracy = matches!(
                    option,
                    RequestOption::GnssVelocityAccuracy
                        | RequestOption::GnssHorizontalAccuracy
                        | RequestOption::GnssVerticalAccuracy
                );
                assert!(!accuracy || message.contains("above 0"), "{message}");
            }
            other => panic!("{field:?}: {other:?}"),
        }
    }
    let given = GnssSpec {
        velocity_accuracy_m_s: Some(0.05),
        ..GnssSpec::default()
    };
    assert!(part(given).setup(&NavSetup::default(), None, 100.0).is_ok());
}
