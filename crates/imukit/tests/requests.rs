//! The request types front ends fill in: one place that checks names and numbers, errors that
//! name the field (and, for files, the row and column), and scheme names that parse.
use std::path::Path;

use imu_core::strapdown::planar::PlanarScheme;
use imukit::choice::Choice;
use imukit::io::conventions::{AccelSignName, EarthGravityName, EarthName, NavFrameName};
use imukit::io::table::ImuKind;
use imukit::run::navigate::{
    DEFAULT_RK4_SUBSTEPS, NavRequest, NavScheme, SchemeName, VerticalName,
};
use imukit::run::planar::{EXERCISE_POSITION0_M, PlanarRequest};
use imukit::scenario::sensors::TemperatureSpec;
use imukit::scenario::spec::{Formula, TrajectorySpec};
use imukit::{Error, ScenarioSpec};

#[test]
fn scheme_names_parse_and_unknown_ones_are_listed() {
    assert_eq!(
        SchemeName::parse("scheme", "coning").unwrap(),
        SchemeName::Coning
    );
    assert_eq!(SchemeName::parse("scheme", "RK4").unwrap(), SchemeName::Rk4);
    let e = SchemeName::parse("scheme", "euler").unwrap_err();
    assert_eq!(
        e.to_string(),
        "scheme: unknown scheme \"euler\" (auto, coning, rk4)"
    );
    assert_eq!(e.location().field.as_deref(), Some("scheme"));
    assert_eq!(
        PlanarScheme::parse("scheme", "exercise").unwrap(),
        PlanarScheme::Exercise
    );
    assert_eq!(
        PlanarScheme::parse("scheme", "euler")
            .unwrap_err()
            .to_string(),
        "scheme: unknown scheme \"euler\" (trapezoid, exercise)"
    );
    assert!(PlanarScheme::parse("scheme", "rk4").is_err());
}

#[test]
fn choice_names_round_trip_and_agree_with_the_scenario_parser() {
    // A scenario file spells a choice as serde reads it.
    fn parse_name<T: serde::de::DeserializeOwned>(name: &str) -> T {
        serde_json::from_value(serde_json::Value::String(name.into())).unwrap()
    }
    for kind in [ImuKind::AccelGyro, ImuKind::AccelMag, ImuKind::AccelGyroMag] {
        assert_eq!(parse_name::<ImuKind>(kind.name()), kind);
        assert_eq!(ImuKind::parse("kind", kind.name()).unwrap(), kind);
    }
    for (name, frame) in NavFrameName::NAMES {
        assert_eq!(parse_name::<NavFrameName>(name), *frame);
    }
    for (name, sign) in AccelSignName::NAMES {
        assert_eq!(parse_name::<AccelSignName>(name), *sign);
    }
    for (name, earth) in EarthName::NAMES {
        assert_eq!(parse_name::<EarthName>(name), *earth);
    }
}

#[test]
fn a_nav_request_is_checked_field_by_field() {
    let ok = NavRequest::default().setup().unwrap();
    assert_eq!(ok.gravity_m_s2, imu_core::DEFAULT_GRAVITY_M_S2);
    assert_eq!(ok.nav_frame, NavFrameName::ENU);
    assert_eq!(
        ok.scheme,
        NavScheme::Auto {
            substeps: DEFAULT_RK4_SUBSTEPS
        }
    );
    assert!(ok.earth.is_none());
    let field = |r: NavRequest| r.setup().unwrap_err().location().field;
    let d = NavRequest::default();
    let zero_substeps = NavRequest {
        scheme: SchemeName::Rk4,
        substeps: 0,
        ..d
    };
    assert_eq!(field(zero_substeps).as_deref(), Some("substeps"));
    for g in [f64::NAN, f64::INFINITY, -1.0, 1e308 * 10.0] {
        let r = NavRequest {
            gravity_m_s2: g,
            ..d
        };
        assert_eq!(field(r).as_deref(), Some("gravity_m_s2"), "{g}");
    }
    // The coning scheme ignores sub-steps; RK4 takes them.
    let rk4 = NavRequest {
        scheme: SchemeName::Rk4,
        substeps: 7,
        ..d
    };
    assert_eq!(rk4.setup().unwrap().scheme, NavScheme::Rk4 { substeps: 7 });
    let coning = NavRequest {
        scheme: SchemeName::Coning,
        substeps: 0,
        ..d
    };
    assert_eq!(coning.setup().unwrap().scheme, NavScheme::ConingSculling);
    // The vertical channel and the Earth's gravity model belong to the WGS-84 Earth.
    let flat_hold = NavRequest {
        vertical: VerticalName::Hold,
        ..d
    };
    assert_eq!(field(flat_hold).as_deref(), Some("vertical"));
    let flat_constant = NavRequest {
        earth_gravity: EarthGravityName::Constant,
        ..d
    };
    assert_eq!(field(flat_constant).as_deref(), Some("earth_gravity"));
    let bad_tau = NavRequest {
        earth: EarthName::Wgs84,
        vertical: VerticalName::Baro,
        baro_time_constant_s: 0.0,
        ..d
    };
    assert_eq!(field(bad_tau).as_deref(), Some("baro_time_constant_s"));
    // Barometer readings feed the baro vertical channel only: with another they are refused,
    // one rule for the command line and Python.
    for vertical in [VerticalName::Free, VerticalName::Hold] {
        let r = NavRequest {
            earth: EarthName::Wgs84,
            vertical,
            barometer: true,
            ..d
        };
        assert_eq!(field(r).as_deref(), Some("baro"), "{vertical}");
    }
    let baro = NavRequest {
        earth: EarthName::Wgs84,
        vertical: VerticalName::Baro,
        barometer: true,
        ..d
    };
    assert!(baro.setup().is_ok());
}

#[test]
fn a_planar_request_turns_the_start_velocity_into_the_body_frame() {
    let r = PlanarRequest {
        heading0_rad: std::f64::consts::FRAC_PI_2,
        velocity0_m_s: [0.0, 2.0],
        ..PlanarRequest::default()
    };
    let s = r.initial_state(5.0).unwrap();
    assert_eq!(s.position_m, EXERCISE_POSITION0_M);
    assert_eq!(s.t_s, 5.0);
    // Heading north (+90°) and moving north: straight ahead in the body frame.
    assert!((s.velocity_body_m_s[0] - 2.0).abs() < 1e-15);
    assert!(s.velocity_body_m_s[1].abs() < 1e-15);
    let bad = PlanarRequest {
        heading0_rad: f64::INFINITY,
        ..PlanarRequest::default()
    };
    let e = bad.initial_state(0.0).unwrap_err();
    assert_eq!(e.location().field.as_deref(), Some("heading0_rad"));
}

#[test]
fn an_infinite_measurement_range_in_a_scenario_file_means_no_saturation() {
    // TOML writes infinity as `inf`; it used to reach the parameter parser as NaN.
    let spec = ScenarioSpec::from_toml(
        "rate_hz = 10.0\nduration_s = 0.1\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu.accelerometer]\nMeasurementRange = inf\n",
        "inf.toml",
    )
    .unwrap();
    let sim = spec.resolve(Path::new(".")).unwrap().simulate().unwrap();
    assert_eq!(sim.imu.column("accel_z_m_s2").unwrap()[0], 9.81);
    let nan = ScenarioSpec::from_toml(
        "[trajectory]\ntype = \"builtin\"\nname = \"static\"\n[imu.accelerometer]\nMeasurementRange = nan\n",
        "nan.toml",
    )
    .unwrap();
    let e = nan.resolve(Path::new(".")).unwrap_err();
    assert_eq!(
        e.location().field.as_deref(),
        Some("imu.accelerometer.MeasurementRange")
    );
}

#[test]
fn a_refused_parameter_carries_the_cores_error_as_its_source() {
    let spec = ScenarioSpec::from_toml(
        "[trajectory]\ntype = \"builtin\"\nname = \"static\"\n[imu.gyroscope]\nNoiseDensity = -1\n",
        "neg.toml",
    )
    .unwrap();
    let e = spec.resolve(Path::new(".")).unwrap_err();
    let Error::Param { context, source } = &e else {
        panic!("expected a parameter error, got {e:?}");
    };
    assert_eq!(context, "imu.gyroscope");
    assert_eq!(source.field(), "noise_density");
    assert!(std::error::Error::source(&e).is_some());
    assert_eq!(
        e.location().field.as_deref(),
        Some("imu.gyroscope.noise_density")
    );
}

#[test]
fn a_bad_csv_cell_is_located_by_file_row_and_column() {
    let dir = tempfile::Builder::new()
        .prefix("imukit-requests-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let path = dir.join("bad.csv");
    std::fs::write(&path, "t_s,gyro_z_rad_s\n0,0.1\n0.01,oops\n").unwrap();
    let e = imukit::io::read::read_table(&path).unwrap_err();
    let at = e.location();
    assert_eq!(at.file.as_deref(), Some(path.as_path()));
    assert_eq!(at.row, Some(3));
    assert_eq!(at.column.as_deref(), Some("gyro_z_rad_s"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_column_named_twice_is_refused_with_both_places() {
    let dir = tempfile::Builder::new()
        .prefix("imukit-dup-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let path = dir.join("dup.csv");
    std::fs::write(
        &path,
        "t_s,gyro_x_rad_s,gyro_x_rad_s\n0,0.1,0.2\n0.01,0.1,0.2\n",
    )
    .unwrap();
    for e in [
        imukit::io::read::read_table(&path).unwrap_err(),
        imukit::io::read::read_columns(&path, &["t_s", "gyro_x_rad_s"], "")
            .map(|_| ())
            .unwrap_err(),
    ] {
        assert_eq!(
            e.to_string(),
            format!(
                "{}: column gyro_x_rad_s appears twice in the header (fields 2 and 3)",
                path.display()
            )
        );
        assert_eq!(e.location().file.as_deref(), Some(path.as_path()));
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn runs_too_long_for_memory_are_refused_before_anything_is_allocated() {
    // 10⁹ body-rate samples would be evaluated into memory whole.
    let body_rates = ScenarioSpec::from_toml(
        "rate_hz = 1e9\nduration_s = 1.0\n[trajectory]\ntype = \"body-rates\"\n\
         angular_velocity_body_rad_s = [\"0\", \"0\", \"0.1\"]\n",
        "fast.toml",
    )
    .unwrap();
    let e = body_rates.resolve(Path::new(".")).unwrap_err();
    assert_eq!(e.location().field.as_deref(), Some("duration_s"));
    assert!(e.to_string().contains("IMUKIT_MAX_MEMORY_GB"), "{e}");
    // Formulas resolve without holding samples; the in-memory simulation is what is refused
    // (the command line streams the same scenario).
    let long = ScenarioSpec::from_toml(
        "rate_hz = 1e8\nduration_s = 9.99\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n",
        "long.toml",
    )
    .unwrap()
    .resolve(Path::new("."))
    .unwrap();
    let e = long.simulate().unwrap_err();
    assert!(
        e.to_string().contains("999000001 samples would take about"),
        "{e}"
    );
}

#[test]
fn rk4_substeps_are_bounded() {
    let r = NavRequest {
        scheme: SchemeName::Rk4,
        substeps: 1_000_000_000,
        ..NavRequest::default()
    };
    let e = r.setup().unwrap_err();
    assert_eq!(e.location().field.as_deref(), Some("substeps"));
    assert!(e.to_string().contains("at most 1000"), "{e}");
}

#[test]
fn parameters_that_overflow_at_the_sample_rate_are_named() {
    let resolve = |imu: &str| {
        ScenarioSpec::from_toml(
            &format!(
                "rate_hz = 100.0\nduration_s = 1.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n{imu}"
            ),
            "overflow.toml",
        )
        .unwrap()
        .resolve(Path::new("."))
    };
    let e = resolve("[imu.gyroscope]\nNoiseDensity = 1e308\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "imu: gyroscope.noise_density[0] is too large: at this sample rate the model is not finite"
    );
    assert_eq!(
        e.location().field.as_deref(),
        Some("imu.gyroscope.noise_density")
    );
    let e = resolve(
        "[imu.gyroscope]\nbias_instability_rad_s = 0.01\nbias_instability_flicker_tau_s = [1, 1e300]\n",
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("bias_instability_flicker_tau_s[0] is too large"),
        "{e}"
    );
}

#[test]
fn a_result_that_is_not_finite_is_never_written() {
    // Each parameter is valid, but 1.7e308 scaled by 11 (100 %/°C at 35 °C) overflows.
    let scenario = ScenarioSpec::from_toml(
        "rate_hz = 100.0\nduration_s = 1.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
         [imu]\ntemperature_c = 35.0\n[imu.accelerometer]\nConstantBias = 1.7e308\n\
         TemperatureScaleFactor = 100\n",
        "inf.toml",
    )
    .unwrap()
    .resolve(Path::new("."))
    .unwrap();
    let dir = tempfile::Builder::new()
        .prefix("imukit-notfinite-")
        .tempdir()
        .unwrap();
    let dir = dir.path();
    let out = dir.join("imu.csv");
    let e = scenario
        .stream_to_files(
            None,
            imukit::run::pipeline::RunThreads::Auto,
            &imukit::run::simulate::StreamOutputs {
                imu: Some(&out),
                ..Default::default()
            },
        )
        .unwrap_err();
    assert!(matches!(e, Error::NotFinite { row: 2, .. }), "{e}");
    assert_eq!(e.location().column.as_deref(), Some("accel_x_m_s2"));
    assert!(!out.exists());
    assert!(
        std::fs::read_dir(dir).unwrap().next().is_none(),
        "no partial file"
    );
    let e = scenario.simulate().unwrap_err();
    assert!(
        e.to_string()
            .starts_with("IMU readings, row 2, column accel_x_m_s2: the result is inf"),
        "{e}"
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn typos_and_impossible_values_in_a_scenario_are_refused() {
    let resolve = |text: &str| {
        ScenarioSpec::from_toml(text, "s.toml").and_then(|s| s.resolve(Path::new(".")))
    };
    // A misspelt key beside a built-in's name is refused, as in every other table.
    let e =
        resolve("[trajectory]\ntype = \"builtin\"\nname = \"static\"\nnmae = \"x\"\n").unwrap_err();
    assert!(
        e.to_string()
            .contains("unknown field `nmae`, expected `name`"),
        "{e}"
    );
    let tangent = "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"expression\"\n\
                   position_m = [\"t\", \"0\", \"0\"]\nattitude = \"tangent\"\n";
    for speed in ["-1", "nan"] {
        let e = resolve(&format!("{tangent}min_speed_m_s = {speed}\n")).unwrap_err();
        assert_eq!(
            e.location().field.as_deref(),
            Some("trajectory.min_speed_m_s"),
            "{e}"
        );
    }
    let e = resolve(&format!("{tangent}[imu]\ntemperature_c = -300\n")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "imu.temperature_c: must be a finite temperature ≥ -273.15 °C, got -300"
    );
    assert!(resolve(&format!("{tangent}[imu]\ntemperature_c = -273.15\n")).is_ok());
}

#[test]
fn an_error_inside_the_trajectory_table_names_the_key() {
    let e = ScenarioSpec::from_toml(
        "rate_hz = 10.0\nduration_s = 1.0\n[trajectory]\ntype = \"expression\"\nposition_m = [\"t\", \"0\"]\n",
        "two.toml",
    )
    .unwrap_err()
    .to_string();
    // The key's own line is shown (line 5), not the table's header (line 3), and its full path.
    assert!(
        e.contains("invalid length 2, expected an array of length 3")
            && e.contains("in `trajectory.position_m`")
            && e.contains("TOML parse error at line 5, column 14")
            && e.contains("position_m = [\"t\", \"0\"]"),
        "{e}"
    );
    let e = ScenarioSpec::from_toml(
        "[trajectory]\ntype = \"builtin\"\nname = \"figure8\"\nspeed = 3\n",
        "builtin.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 4, column 1") && e.contains("in `trajectory.speed`"),
        "{e}"
    );
    let e = ScenarioSpec::from_toml("[trajectory]\ntype = \"expresion\"\n", "typo.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown variant `expresion`, expected one of `expression`"),
        "{e}"
    );
}

/// A scenario handed over as a tree of values (what a Python dict becomes) reads as the same
/// scenario its file does: every example, and the specs in `examples/study`.
#[test]
fn every_example_reads_the_same_from_its_file_and_as_a_tree() {
    use imukit::io::params::ParamValue;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut read = 0;
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.display().to_string();
        let from_file = ScenarioSpec::from_toml(&text, &name).unwrap();
        let tree: ParamValue = toml::from_str(&text).unwrap();
        assert_eq!(
            ScenarioSpec::from_tree(&tree, "scenario dict").unwrap(),
            from_file,
            "{name}"
        );
        read += 1;
    }
    assert!(read >= 10, "{read} examples read");
}

/// Any `u64` seed reads from a tree as from JSON text (a seed of 2⁶³ or more once failed: the
/// tree went through TOML, whose integers end at `i64`); a seed a `u64` cannot hold is refused,
/// naming the key.
#[test]
fn a_tree_keeps_every_u64_seed_and_names_the_key_of_a_bad_one() {
    use imukit::io::params::ParamValue;
    let json = |seed: &str| {
        format!(
            r#"{{"rate_hz": 10.0, "trajectory": {{"type": "builtin", "name": "static"}},
                 "imu": {{"seed": {seed}, "accelerometer": {{"MeasurementRange": "inf"}}}}}}"#
        )
    };
    for seed in [0, 1 << 63, u64::MAX] {
        let text = json(&seed.to_string());
        let tree: ParamValue = serde_json::from_str(&text).unwrap();
        let spec = ScenarioSpec::from_tree(&tree, "scenario dict").unwrap();
        assert_eq!(spec.imu.seed, Some(seed));
        assert_eq!(spec, ScenarioSpec::from_json(&text, "s.json").unwrap());
    }
    for (seed, why) in [
        ("18446744073709551616", "expected u64"),
        ("-1", "invalid value: integer `-1`, expected u64"),
        ("2.5", "invalid type: floating point `2.5`, expected u64"),
        ("\"7\"", "invalid type: string \"7\", expected u64"),
    ] {
        let tree: ParamValue = serde_json::from_str(&json(seed)).unwrap();
        let e = ScenarioSpec::from_tree(&tree, "scenario dict").unwrap_err();
        assert_eq!(e.location().field.as_deref(), Some("imu.seed"), "{seed}");
        let text = e.to_string();
        assert!(
            text.starts_with("scenario dict: imu.seed: ") && text.contains(why),
            "{seed}: {text}"
        );
    }
    // Inside the trajectory (read by its type first) and in a list, the path goes to the item.
    let tree: ParamValue =
        serde_json::from_str(r#"{"trajectory": {"type": "expression", "position_m": ["t", "0"]}}"#)
            .unwrap();
    let e = ScenarioSpec::from_tree(&tree, "scenario dict").unwrap_err();
    assert_eq!(
        e.location().field.as_deref(),
        Some("trajectory.position_m"),
        "{e}"
    );
    assert!(
        e.to_string()
            .ends_with("invalid length 2, expected an array of length 3"),
        "{e}"
    );
    // A tree offers the trajectory's `type` first whatever its keys' order, so the path goes on
    // into the trajectory's lists too.
    let tree: ParamValue = serde_json::from_str(
        r#"{"trajectory": {"position_m": ["t", "0", [1]], "type": "expression"}}"#,
    )
    .unwrap();
    let e = ScenarioSpec::from_tree(&tree, "scenario dict").unwrap_err();
    assert_eq!(
        e.location().field.as_deref(),
        Some("trajectory.position_m[2]"),
        "{e}"
    );
    let tree: ParamValue =
        serde_json::from_str(r#"{"imu": {"lever_arm_m": [0.1, "x", 0.3]}}"#).unwrap();
    let e = ScenarioSpec::from_tree(&tree, "scenario dict").unwrap_err();
    assert_eq!(
        e.location().field.as_deref(),
        Some("imu.lever_arm_m[1]"),
        "{e}"
    );
}

/// A JSON scenario's error names the key path whose value does not fit, and the line and column
/// where the parser stopped in the value (the end of a list too short); a trajectory whose `type`
/// comes after other keys is still read, its error naming the key in the message.
#[test]
fn a_json_scenario_error_names_the_key_path_and_the_values_place() {
    let at = |text: &str| {
        let e = ScenarioSpec::from_json(text, "s.json").unwrap_err();
        (e.location().field, e.to_string())
    };
    let (field, text) =
        at("{\"trajectory\": {\"type\": \"expression\",\n  \"position_m\": [\"t\", \"0\"]}}");
    assert_eq!(field.as_deref(), Some("trajectory.position_m"), "{text}");
    assert!(
        text.starts_with("s.json: trajectory.position_m: invalid length 2")
            && text.ends_with("at line 2 column 26"),
        "{text}"
    );
    let (field, text) = at(r#"{"imu": {"seed": -1}}"#);
    assert_eq!(field.as_deref(), Some("imu.seed"), "{text}");
    assert!(text.contains("expected u64 at line 1 column 19"), "{text}");
    let (field, text) = at(r#"{"trajectory": {"type": 3}}"#);
    assert_eq!(field.as_deref(), Some("trajectory.type"), "{text}");
    // `type` after another key: the keys are held until it comes, the table is named.
    let (field, text) = at(r#"{"trajectory": {"position_m": ["t"], "type": "expression"}}"#);
    assert_eq!(field.as_deref(), Some("trajectory"), "{text}");
    assert!(
        text.contains("invalid length 1, expected an array of length 3")
            && text.contains("position_m"),
        "{text}"
    );
    let late = r#"{"trajectory": {"name": "static", "type": "builtin"}}"#;
    let early = r#"{"trajectory": {"type": "builtin", "name": "static"}}"#;
    assert_eq!(
        ScenarioSpec::from_json(late, "late.json").unwrap(),
        ScenarioSpec::from_json(early, "early.json").unwrap()
    );
    // Text after the scenario, or no scenario at all, is the parser's message alone.
    let (field, text) = at(&format!("{early} x"));
    assert_eq!(field, None, "{text}");
    assert!(
        text.contains("trailing characters at line 1 column"),
        "{text}"
    );
    let (field, text) = at("{");
    assert_eq!(field, None, "{text}");
    assert!(text.contains("EOF while parsing"), "{text}");
}

/// A value that is neither of a key's two kinds is refused saying what the key takes; each kind
/// reads as itself (an integer temperature or formula is a number).
#[test]
fn a_formula_or_a_temperature_of_the_wrong_kind_says_what_it_takes() {
    let scenario = |trajectory: &str, imu: &str| {
        format!(
            r#"{{"trajectory": {{"type": "expression", "position_m": {trajectory}, "yaw_rad": "0", "pitch_rad": "0", "roll_rad": "0"}}, "imu": {imu}}}"#
        )
    };
    let e = ScenarioSpec::from_json(&scenario(r#"["t", 2, true]"#, "{}"), "s.json").unwrap_err();
    assert_eq!(
        e.location().field.as_deref(),
        Some("trajectory.position_m[2]")
    );
    assert!(
        e.to_string()
            .contains("invalid type: boolean `true`, expected a formula string of t, or a number"),
        "{e}"
    );
    let e = ScenarioSpec::from_json(
        &scenario(r#"["t", 2, 3]"#, r#"{"temperature_c": [1]}"#),
        "s.json",
    )
    .unwrap_err();
    assert_eq!(e.location().field.as_deref(), Some("imu.temperature_c"));
    assert!(
        e.to_string().contains(
            "invalid type: sequence, expected a temperature in °C, or the path of a CSV file"
        ),
        "{e}"
    );
    let spec = ScenarioSpec::from_json(
        &scenario(r#"["t", 2, -3.5]"#, r#"{"temperature_c": 25}"#),
        "s.json",
    )
    .unwrap();
    let TrajectorySpec::Expression(x) = &spec.trajectory else {
        panic!("an expression trajectory")
    };
    assert_eq!(
        x.position_m,
        Some([
            Formula::Text("t".into()),
            Formula::Number(2.0),
            Formula::Number(-3.5)
        ])
    );
    assert_eq!(
        spec.imu.temperature_c,
        Some(TemperatureSpec::Constant(25.0))
    );
    let spec = ScenarioSpec::from_json(
        &scenario(r#"["t", 2, 3]"#, r#"{"temperature_c": "profile.csv"}"#),
        "s.json",
    )
    .unwrap();
    assert_eq!(
        spec.imu.temperature_c,
        Some(TemperatureSpec::File("profile.csv".into()))
    );
}

#[test]
fn a_fuse_request_finishes_the_scenario_setup_and_names_its_fields() {
    use imukit::run::fuse::{AlignName, DEFAULT_COVARIANCE_INTERVAL_S, FuseRequest, Start};
    use imukit::run::navigate::InitialState;
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let scenario = ScenarioSpec::from_file(&examples.join("car_tunnel.toml"))
        .unwrap()
        .resolve(&examples)
        .unwrap();
    let initial = InitialState::default();
    let d = FuseRequest::default();
    let field = |r: FuseRequest<'_>| r.setup(&scenario).unwrap_err().location().field;
    // A start: the truth row or an alignment, exactly one.
    assert_eq!(field(d).as_deref(), Some("initial"));
    let both = Start::of(Some(&initial), Some(AlignName::Gnss)).unwrap_err();
    assert_eq!(both.location().field.as_deref(), Some("initial"));
    // The scenario decides the Earth.
    let wgs84 = FuseRequest {
        start: Some(Start::AlignGnss),
        earth: Some(EarthName::Wgs84),
        ..d
    };
    assert_eq!(field(wgs84).as_deref(), Some("earth"));
    let (setup, start) = FuseRequest {
        start: Some(AlignName::Static.into()),
        earth: Some(EarthName::Flat),
        ..d
    }
    .setup(&scenario)
    .unwrap();
    assert!(matches!(start, Start::AlignStatic { .. }));
    assert!(setup.gate.is_on());
    assert_eq!(setup.covariance_interval_s, DEFAULT_COVARIANCE_INTERVAL_S);
    // Not told: the sensor errors as the part warrants, the rest found in the readings.
    assert_eq!(setup.estimate_sensor_errors, setup.warrants_sensor_errors());
    assert!(setup.detect_rest);
    assert_eq!(setup.aiding.nhc_sigma_m_s, None);
    let (setup, start) = FuseRequest {
        start: Some(Start::State(&initial)),
        gate: false,
        nhc_sigma_m_s: Some(0.2),
        covariance_interval_s: Some(0.0),
        sensor_errors: Some(true),
        rest_s: Some(5.0),
        ..d
    }
    .setup(&scenario)
    .unwrap();
    assert_eq!(start, Start::State(&initial));
    assert_eq!(setup.gate, imukit::run::fuse::Gate::Off);
    assert_eq!(setup.aiding.nhc_sigma_m_s, Some(0.2));
    assert_eq!(setup.covariance_interval_s, 0.0);
    assert!(setup.estimate_sensor_errors);
    assert_eq!(setup.rest_s, 5.0);
    assert!(!setup.detect_rest);
}

/// Every setting an orientation filter takes has its default in one table
/// ([`FilterKind::setting_defaults`]), and a filter given those defaults by name is the filter
/// built without them.
#[test]
fn each_filter_setting_has_one_default_and_stating_it_changes_nothing() {
    use imukit::choice::Choice;
    use imukit::run::orient::{FilterKind, FilterSpec};
    for (name, kind) in FilterKind::NAMES {
        for magnetometer in [false, true] {
            if kind.magnetometer().is_some_and(|m| m != magnetometer) {
                continue;
            }
            let defaults = kind.setting_defaults(magnetometer);
            let mut named: Vec<&str> = defaults.iter().map(|(n, _)| *n).collect();
            let mut takes = kind.settings();
            named.sort_unstable();
            takes.sort_unstable();
            assert_eq!(
                named, takes,
                "{name}: a default for every setting, and no other"
            );
            let plain = FilterSpec {
                magnetometer,
                ..FilterSpec::new(*kind, imu_core::AccelSign::SpecificForce)
            };
            let stated = FilterSpec {
                settings: defaults
                    .iter()
                    .map(|(n, v)| ((*n).to_string(), *v))
                    .collect(),
                ..plain.clone()
            };
            let rate = kind.setting_defaults(magnetometer)[0].1;
            assert_eq!(
                format!("{:?}", plain.build::<imu_core::Enu>(rate).unwrap()),
                format!("{:?}", stated.build::<imu_core::Enu>(rate).unwrap()),
                "{name}, magnetometer {magnetometer}"
            );
        }
    }
}
