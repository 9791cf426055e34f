//! Formula trajectories are evaluated by the compiled program (`motion::compiled`): on every
//! example and built-in scenario whose trajectory is formulas, its derivatives are the formulas'
//! evaluation over dual numbers to within `DUAL_NUMBERS_BOUND` (the program takes its sines and
//! cosines from `imu_core::trig`'s vector kernels, num-dual from the C library), and so is the
//! truth built from them.
use std::path::Path;

use imu_core::{Enu, Truth};
use imukit::motion::ExpressionMotion;
use imukit::motion::Trajectory;
use imukit::motion::analytic::{
    AnalyticOptions, Motion, MotionPoint, dual_derivatives, truth_from_motion,
};
use imukit::motion::compiled::DUAL_NUMBERS_BOUND;
use imukit::scenario::builtin;
use imukit::{Scenario, ScenarioSpec};

/// Every scenario with a formula trajectory: the examples and the built-ins, with its name.
fn formula_scenarios() -> Vec<(String, Scenario)> {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut out = Vec::new();
    let mut files: Vec<_> = std::fs::read_dir(&examples)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    for path in files {
        if let Ok(s) = Scenario::from_file(&path) {
            out.push((path.display().to_string(), s));
        }
    }
    for name in builtin::NAMES {
        let spec: ScenarioSpec = builtin::spec(name).unwrap();
        out.push((name.to_string(), spec.resolve(Path::new(".")).unwrap()));
    }
    out.push(("the formula job".to_string(), formula_job()));
    out.retain(|(_, s)| matches!(s.trajectory, Trajectory::Expression(..)));
    out
}

/// The benchmarks' formula job (`benches/formula_job.toml`), 30 s of it: positions and angles
/// that take the sines of the same numbers.
fn formula_job() -> Scenario {
    let text = include_str!("../../../benches/formula_job.toml")
        .replace("duration_s = 10.0", "duration_s = 30.0");
    ScenarioSpec::from_toml(&text, "formula_job.toml")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
}

#[test]
fn a_number_whose_sine_positions_and_angles_both_take_gets_one_sin_cos() {
    let job = formula_job();
    let Trajectory::Expression(motion, _) = &job.trajectory else {
        unreachable!()
    };
    // sin(w t), sin(2 w t), sin(3 w t) in the positions; sin(w t), sin(2 w t), sin(w t + 0.5) in
    // the angles: four distinct numbers, not six.
    assert_eq!(motion.compiled().unwrap().sin_cos_per_sample(), 4);
}

/// The largest `|a − b|` over pairs of series, in units of ε times the largest `|b|`.
fn deviation(pairs: impl Iterator<Item = (f64, f64)> + Clone) -> f64 {
    let scale = pairs.clone().map(|(_, b)| b.abs()).fold(0.0, f64::max);
    let worst = pairs.map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    if worst == 0.0 {
        0.0
    } else {
        worst / (f64::EPSILON * scale)
    }
}

/// Every derivative of `a` within the bound of `b`'s, component by component over the run.
fn assert_close_points(name: &str, a: &[MotionPoint], b: &[MotionPoint]) {
    let pairs =
        |f: &dyn Fn(&MotionPoint) -> f64| a.iter().map(f).zip(b.iter().map(f)).collect::<Vec<_>>();
    for axis in 0..3 {
        for k in 0..4 {
            let d = deviation(pairs(&|p: &MotionPoint| p.position[axis][k]).into_iter());
            assert!(
                d <= DUAL_NUMBERS_BOUND,
                "{name}: position axis {axis} derivative {k}: {d} ε"
            );
        }
    }
    assert_eq!(a[0].euler.is_some(), b[0].euler.is_some(), "{name}");
    if a[0].euler.is_some() {
        for angle in 0..3 {
            for k in 0..3 {
                let d = deviation(
                    pairs(&|p: &MotionPoint| p.euler.expect("angles")[angle][k]).into_iter(),
                );
                assert!(
                    d <= DUAL_NUMBERS_BOUND,
                    "{name}: angle {angle} derivative {k}: {d} ε"
                );
            }
        }
    }
}

#[test]
fn compiled_formulas_give_the_dual_numbers_within_the_bound_on_every_example_and_builtin() {
    let scenarios = formula_scenarios();
    assert!(
        scenarios.len() >= 5,
        "{:?}",
        scenarios.iter().map(|s| &s.0).collect::<Vec<_>>()
    );
    for (name, s) in &scenarios {
        let Trajectory::Expression(motion, _) = &s.trajectory else {
            unreachable!()
        };
        let t = s.t_s.to_vec();
        let (mut compiled, mut duals) = (Vec::new(), Vec::new());
        motion.derivatives(&t, &mut compiled);
        dual_derivatives(motion, &t, &mut duals);
        assert_eq!(compiled.len(), t.len());
        assert_close_points(name, &compiled, &duals);
    }
}

// The only test in this file that switches the AVX2 copy (`imu_core::cpu`): the others may run
// meanwhile and see either copy, which give the same numbers (that is what this checks).
#[test]
fn the_avx2_copy_of_compiled_formulas_gives_the_baselines_numbers_bit_for_bit() {
    let bits = |points: &[MotionPoint]| -> Vec<u64> {
        points
            .iter()
            .flat_map(|p| {
                let euler = p.euler.map_or_else(Vec::new, |e| e.concat());
                [p.position.concat(), euler].concat()
            })
            .map(f64::to_bits)
            .collect()
    };
    for (name, s) in formula_scenarios() {
        let Trajectory::Expression(motion, _) = &s.trajectory else {
            unreachable!()
        };
        let t = s.t_s.to_vec();
        let run = |avx2: bool| {
            imu_core::cpu::allow_avx2(avx2);
            let mut points = Vec::new();
            motion.derivatives(&t, &mut points);
            bits(&points)
        };
        let (baseline, avx2) = (run(false), run(true));
        assert!(baseline.len() >= 12 * t.len(), "{name}");
        assert!(avx2 == baseline, "{name}: the two copies' numbers differ");
    }
}

/// The motion's formulas evaluated only over dual numbers (the path before compilation).
struct OverDuals<'a>(&'a ExpressionMotion);

impl Motion for OverDuals<'_> {
    fn position<D: imukit::motion::analytic::Scalar>(&self, t: D) -> [D; 3] {
        self.0.position(t)
    }
    fn euler<D: imukit::motion::analytic::Scalar>(&self, t: D) -> Option<[D; 3]> {
        self.0.euler(t)
    }
}

/// A truth sample's numbers: position, velocity, acceleration, angles, quaternion, body rate
/// and angular acceleration.
fn numbers(s: &Truth<Enu>) -> Vec<f64> {
    let mut v = Vec::with_capacity(22);
    for x in [s.position_m, s.velocity_m_s, s.acceleration_m_s2] {
        v.extend(x.to_array());
    }
    v.extend(s.euler.to_array());
    v.extend(s.attitude.to_wxyz());
    v.extend(s.omega_b_rad_s.to_array());
    v.extend(s.alpha_b_rad_s2.to_array());
    v
}

/// How far the truth built from compiled formulas may be from the truth built from the same
/// formulas over dual numbers, in the units of [`DUAL_NUMBERS_BOUND`]: the derivatives' differences
/// pass through the tangent attitude's quotients (rates and angular accelerations divide by the
/// speed squared). The largest on the examples and built-ins is 15.9 ε: the angular acceleration
/// of the tilted circle's tangent attitude (`examples/expression.toml`).
const TRUTH_BOUND: f64 = 32.0;

#[test]
fn the_truth_of_compiled_formulas_is_the_truth_over_dual_numbers_within_the_bound() {
    for (name, s) in formula_scenarios() {
        let Trajectory::Expression(motion, _) = &s.trajectory else {
            unreachable!()
        };
        if motion.geodetic.is_some() {
            continue; // placed on the Earth: over dual numbers either way
        }
        let t = s.t_s.to_vec();
        let mut a = vec![Truth::<Enu>::default(); t.len()];
        let mut b = a.clone();
        let fast = truth_from_motion(motion, &t, AnalyticOptions::default(), &mut a);
        let slow = truth_from_motion(&OverDuals(motion), &t, AnalyticOptions::default(), &mut b);
        assert_eq!(fast.is_ok(), slow.is_ok(), "{name}");
        let (a, b): (Vec<_>, Vec<_>) = (
            a.iter().map(numbers).collect(),
            b.iter().map(numbers).collect(),
        );
        for column in 0..a[0].len() {
            let d = deviation(a.iter().map(|r| r[column]).zip(b.iter().map(|r| r[column])));
            assert!(d <= TRUTH_BOUND, "{name}: truth number {column}: {d} ε");
        }
    }
}

/// The stepper's blocks change no number: a whole run stepped a block at a time equals the same
/// run stepped sample by sample (each sample a block of one), bit for bit, with the tangent
/// attitude and with formula angles.
#[test]
fn stepping_in_blocks_or_sample_by_sample_gives_the_same_truth() {
    use imukit::motion::analytic::AnalyticStepper;
    let mut seen = [false; 2];
    for (name, s) in formula_scenarios() {
        let Trajectory::Expression(motion, _) = &s.trajectory else {
            unreachable!()
        };
        let t = s.t_s.to_vec();
        let mut points = Vec::new();
        motion.derivatives(&t, &mut points);
        seen[usize::from(points[0].euler.is_some())] = true;
        let mut whole = vec![Truth::<Enu>::default(); t.len()];
        let mut one_by_one = whole.clone();
        let mut a = AnalyticStepper::new(motion, AnalyticOptions::default());
        let mut b = AnalyticStepper::new(motion, AnalyticOptions::default());
        let first = a.step_block(&t, &points, &mut whole);
        let mut first_b = None;
        let mut failed = None;
        for (k, ((&tk, p), slot)) in t.iter().zip(&points).zip(&mut one_by_one).enumerate() {
            match b.step_into(tk, p, slot) {
                Ok(valid) => {
                    if valid {
                        first_b.get_or_insert(k);
                    }
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        match (first, failed) {
            (Ok(first), None) => {
                assert_eq!(first, first_b, "{name}: first valid sample");
                if let Some(i) = (0..t.len()).find(|&i| whole[i] != one_by_one[i]) {
                    panic!("{name}: sample {i}: {:?} vs {:?}", whole[i], one_by_one[i]);
                }
            }
            (Err(e), Some(f)) => assert_eq!(e.to_string(), f.to_string(), "{name}"),
            (a, b) => panic!("{name}: {a:?} vs {b:?}"),
        }
    }
    assert_eq!(
        seen,
        [true, true],
        "tangent and formula angles both covered"
    );
}
