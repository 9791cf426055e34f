//! Formula trajectories are evaluated by the compiled program (`motion::compiled`): on every
//! example and built-in scenario whose trajectory is formulas, its derivatives equal the
//! formulas' evaluation over dual numbers bit for bit (a zero's sign aside), and so does the
//! truth built from them.
use std::path::Path;

use imu_core::{Enu, Truth};
use imukit::motion::ExpressionMotion;
use imukit::motion::Trajectory;
use imukit::motion::analytic::{
    AnalyticOptions, Motion, MotionPoint, dual_derivatives, truth_from_motion,
};
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

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

fn assert_same_points(name: &str, t: &[f64], a: &[MotionPoint], b: &[MotionPoint]) {
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        for axis in 0..3 {
            for k in 0..4 {
                assert!(
                    same(p.position[axis][k], q.position[axis][k]),
                    "{name}, t = {}: position axis {axis} derivative {k}: {} vs {}",
                    t[i],
                    p.position[axis][k],
                    q.position[axis][k]
                );
            }
        }
        match (p.euler, q.euler) {
            (None, None) => {}
            (Some(e), Some(f)) => {
                for angle in 0..3 {
                    for k in 0..3 {
                        assert!(
                            same(e[angle][k], f[angle][k]),
                            "{name}, t = {}: angle {angle} derivative {k}",
                            t[i]
                        );
                    }
                }
            }
            _ => panic!("{name}: one has angles, the other not"),
        }
    }
}

#[test]
fn compiled_formulas_give_the_dual_numbers_on_every_example_and_builtin() {
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
        assert_same_points(name, &t, &compiled, &duals);
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

#[test]
fn the_truth_of_compiled_formulas_is_the_truth_over_dual_numbers() {
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
        if let Some(i) = (0..t.len()).find(|&i| a[i] != b[i]) {
            panic!("{name}: sample {i}: {:?} vs {:?}", a[i], b[i]);
        }
    }
}
