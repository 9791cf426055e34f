//! Property tests with hostile input at the library's doors: formulas, scenario files, CSV
//! tables, parameter files and Allan inputs. Each property asserts what the user is promised:
//! an error or a result, never a panic, and a result never holds a value that is not finite.
//!
//! The Python script `tests/fuzz/hostile.py` drives the command line and the Python API the same
//! way. Run longer with `PROPTEST_CASES=20000 cargo test --release -p imukit --test integration hostile::`.
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use imukit::io::params::Profile;
use imukit::io::part_file::read_param_file;
use imukit::io::read::read_table;
use imukit::motion::expr::Expr;
use imukit::run::allan::allan;
use imukit::run::navigate::{InitialState, NavSetup, integrate};
use imukit::{ScenarioSpec, Table};
use proptest::prelude::*;

/// Scenarios simulated in full only up to this many samples (a bound on each case's time; the
/// sample-count limits themselves are tested by name elsewhere).
const MAX_SIMULATED_SAMPLES: usize = 20_000;

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// A fresh folder under the system's temporary folder, removed with its files when dropped.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("imukit-hostile-{name}-"))
        .tempdir()
        .unwrap()
}

/// Pieces formulas are made of, hostile numbers and broken syntax among them.
const FORMULA_TOKENS: &[&str] = &[
    "t", "(", ")", "+", "-", "*", "/", "^", ",", "sin(", "cos(", "exp(", "log(", "sqrt(", "abs(",
    "atan2(", "min(", "max(", "if(", "<", ">", "pi", "e", "1e308", "1e-308", "0", "2.5", "-1",
    "nan", "inf", "x", "tan(", "sinh(", "1e9", " ", "((", "))", "t^t", "t/0",
];

fn formula() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::collection::vec(prop::sample::select(FORMULA_TOKENS), 0..40).prop_map(|v| v.concat()),
        "\\PC{0,40}",
        (
            1usize..20_000,
            prop::sample::select(&["(", "-", "sin("][..])
        )
            .prop_map(|(n, open)| format!("{}t{}", open.repeat(n), ")".repeat(n))),
        (1usize..60_000).prop_map(|n| vec!["t"; n].join("+")),
    ]
}

/// Numbers a hostile file puts where a number belongs.
const HOSTILE_NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e-320",
    "0",
    "-0.0",
    "-1",
    "1e9",
    "1e18",
    "99999999999999999999",
    "0.5",
    "\"x\"",
    "[]",
    "[1, 2]",
    "true",
    "{}",
];

/// One edit of a text file: a number swapped for a hostile one, a line dropped or doubled, a
/// cut, or a byte changed.
#[derive(Clone, Debug)]
enum Edit {
    Number { which: usize, by: &'static str },
    DropLine(usize),
    DoubleLine(usize),
    Cut(usize),
    Byte { at: usize, to: u8 },
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => (any::<usize>(), prop::sample::select(HOSTILE_NUMBERS))
            .prop_map(|(which, by)| Edit::Number { which, by }),
        1 => any::<usize>().prop_map(Edit::DropLine),
        1 => any::<usize>().prop_map(Edit::DoubleLine),
        1 => any::<usize>().prop_map(Edit::Cut),
        2 => (any::<usize>(), any::<u8>()).prop_map(|(at, to)| Edit::Byte { at, to }),
    ]
}

/// Byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric());
        if starts {
            let j = (i..b.len())
                .find(|&j| !(b[j].is_ascii_digit() || b".eE+-".contains(&b[j])))
                .unwrap_or(b.len());
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(text: &str, edits: &[Edit]) -> Vec<u8> {
    let mut s = text.to_string();
    for e in edits {
        match e {
            Edit::Number { which, by } => {
                let spans = numbers(&s);
                if let Some(&(a, b)) = spans.get(which % spans.len().max(1)) {
                    s.replace_range(a..b, by);
                }
            }
            Edit::DropLine(k) | Edit::DoubleLine(k) => {
                let mut lines: Vec<&str> = s.lines().collect();
                if !lines.is_empty() {
                    let k = k % lines.len();
                    if matches!(e, Edit::DropLine(_)) {
                        lines.remove(k);
                    } else {
                        lines.insert(k, lines[k]);
                    }
                }
                s = lines.join("\n") + "\n";
            }
            Edit::Cut(at) => {
                let mut at = at % (s.len() + 1);
                while !s.is_char_boundary(at) {
                    at -= 1;
                }
                s.truncate(at);
            }
            Edit::Byte { at, to } => {
                let mut bytes = s.into_bytes();
                if !bytes.is_empty() {
                    let at = at % bytes.len();
                    bytes[at] = *to;
                }
                // Invalid UTF-8 goes straight to the reader as bytes.
                match String::from_utf8(bytes) {
                    Ok(text) => s = text,
                    Err(e) => return e.into_bytes(),
                }
            }
        }
    }
    s.into_bytes()
}

fn assert_finite(table: &Table, what: &str) {
    assert!(
        table.data.iter().all(|v| v.is_finite()),
        "{what} holds a value that is not finite"
    );
}

const SCENARIOS: &[&str] = &[
    "expression.toml",
    "piecewise.toml",
    "builtin.toml",
    "track.toml",
    "waypoints.toml",
    "body_rates.toml",
    "samples.toml",
    "matlab_stationary.toml",
    "matlab_platform_realistic.toml",
    "earth_flight.toml",
    "schuler.toml",
];

proptest! {
    #[test]
    fn formulas_parse_or_are_refused_and_never_panic(source in formula()) {
        if let Ok(expr) = Expr::parse(&source, &BTreeMap::new()) {
            // Evaluation is total: any number, the boundary checks judge finiteness.
            for t in [0.0, 0.5, -3.0, 1e3] {
                let _ = expr.eval(t);
            }
        }
    }

    #[test]
    fn edited_scenarios_simulate_finite_numbers_or_say_what_is_wrong(
        which in 0..SCENARIOS.len(),
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let name = SCENARIOS[which];
        let text = std::fs::read_to_string(examples_dir().join(name)).unwrap();
        let Ok(mutant) = String::from_utf8(apply(&text, &edits)) else {
            return Ok(());
        };
        let scenario = ScenarioSpec::from_toml(&mutant, name)
            .and_then(|spec| spec.resolve(&examples_dir()));
        match scenario {
            Err(e) => prop_assert!(!e.to_string().is_empty()),
            Ok(s) if s.t_s.len() <= MAX_SIMULATED_SAMPLES => {
                if let Ok(sim) = s.simulate() {
                    assert_finite(&sim.truth, "truth");
                    assert_finite(&sim.imu, "imu");
                }
            }
            Ok(_) => {}
        }
    }

    #[test]
    fn edited_imu_tables_integrate_to_finite_numbers_or_name_the_problem(
        edits in prop::collection::vec(edit(), 1..4),
        case in any::<u32>(),
    ) {
        let mut text = String::from(
            "t_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n",
        );
        for k in 0..40 {
            let t = f64::from(k) * 0.01;
            text += &format!("{t},0.1,-0.2,9.81,0.01,0.02,{}\n", 0.3 * t.sin());
        }
        let dir = scratch("imu");
        let path = dir.path().join(format!("{case}.csv"));
        std::fs::write(&path, apply(&text, &edits)).unwrap();
        if let Ok(table) = read_table(&path) {
            assert_finite(&table, "the table read");
            if let Ok(nav) = integrate(&table, &InitialState::default(), &NavSetup::default()) {
                assert_finite(&nav, "navigation");
            }
        }
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn edited_parameter_files_are_read_or_refused(
        edits in prop::collection::vec(edit(), 1..4),
        json in any::<bool>(),
        case in any::<u32>(),
    ) {
        let (text, ext) = if json {
            (r#"{"Part": {"Accelerometer": {"MeasurementRange": 19.6, "NoiseDensity": [0.001, 0.002, 0.003],
                 "BiasInstabilityCoefficients": {"Numerator": [1], "Denominator": [1, -0.5]}},
                 "Gyroscope": {"ConstantBias": 0.01, "AxesMisalignment": [[100, 1, 2], [3, 100, 4], [5, 6, 100]]}}}"#,
             "json")
        } else {
            ("[accelerometer]\nnoise_density_m_s2_per_rt_hz = 0.001\nbias_instability_m_s2 = 1e-4\n\
              bias_instability_flicker_tau_s = [1, 1000]\n[gyroscope]\nrandom_walk_rad_s_per_rt_s = 1e-5\n\
              measurement_range_rad_s = 8.7\n", "toml")
        };
        let dir = scratch("params");
        let path = dir.path().join(format!("{case}.{ext}"));
        std::fs::write(&path, apply(text, &edits)).unwrap();
        if let Err(e) = read_param_file(&path, None, Profile::Default) {
            // The message names the file or the key it is about.
            let message = e.to_string();
            prop_assert!(
                message.contains(&format!("{case}.{ext}")) || e.location().field.is_some(),
                "{message}"
            );
        }
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn allan_deviations_are_finite_or_refused(
        values in prop::collection::vec(
            prop_oneof![-1e3f64..1e3, Just(1e200), Just(-1e300), Just(1e-300), Just(0.0)],
            0..300,
        ),
        rate in prop_oneof![0.1f64..1e4, Just(0.0), Just(-1.0), Just(f64::NAN), Just(1e308)],
    ) {
        if let Ok(result) = allan(&[("gyro_x_rad_s".to_string(), values)], rate) {
            assert_finite(&result.table, "the Allan table");
            let tau = result.table.column("tau_s").unwrap();
            prop_assert!(tau.iter().all(|v| *v > 0.0));
        }
    }

    #[test]
    fn damaged_binary_tables_read_finite_or_are_refused_naming_the_file(
        format in 0..3usize,
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        cut in prop::option::of(any::<prop::sample::Index>()),
        case in any::<u32>(),
    ) {
        // A valid table of each binary format, then bytes changed (most in the part a reader
        // trusts most: Parquet's footer, the .npy header, the archive's directory) and
        // perhaps cut short. The reader gives finite values or an error naming the file.
        let ext = ["parquet", "npy", "npz"][format];
        let dir = scratch("binary");
        let good = dir.path().join(format!("good.{ext}"));
        let mut t = Table::new(&["t_s", "accel_x_m_s2", "gyro_z_rad_s"]);
        for k in 0..300 {
            let x = f64::from(k);
            t.push_row(&[x / 100.0, (x * 0.3).sin(), 1e-3 * x]);
        }
        t.write(&good).unwrap();
        let mut bytes = std::fs::read(&good).unwrap();
        let tail = bytes.len().min(400);
        let n = bytes.len();
        for (i, value) in &flips {
            // Half the changes fall in the first or last 400 bytes.
            let at = match value % 3 {
                0 => i.index(tail),
                1 => n - tail + i.index(tail),
                _ => i.index(n),
            };
            bytes[at] = *value;
        }
        if let Some(c) = cut {
            bytes.truncate(c.index(n));
        }
        let bad = dir.path().join(format!("{case}.{ext}"));
        std::fs::write(&bad, &bytes).unwrap();
        match read_table(&bad) {
            Ok(table) => assert_finite(&table, "a damaged table read back"),
            Err(e) => prop_assert!(e.to_string().contains(&format!("{case}.{ext}")), "{e}"),
        }
    }
}
