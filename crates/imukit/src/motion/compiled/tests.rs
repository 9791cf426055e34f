use std::collections::BTreeMap;

use num_dual::{Dual2, Dual3};

use super::*;

fn parse(s: &str) -> Expr {
    let mut c = BTreeMap::new();
    c.insert("r".to_string(), 60.0);
    Expr::parse(s, &c).unwrap()
}

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

/// Every function and operator, piecewise and CSE: the program's jets equal the tree's
/// `Dual3` and `Dual2` components bit for bit (zeros' signs aside), but where a formula takes
/// a sine or cosine (the first two): there within [`DUAL_NUMBERS_BOUND`] of each component's
/// largest magnitude, and not bit for bit everywhere (the kernels are not the C library).
#[test]
fn the_program_gives_the_trees_dual_numbers() {
    let formulas = [
        "r*sin(0.16*t + 0.02*sin(0.5*t))",
        "r*(1 - cos(0.16*t + 0.02*sin(0.5*t))) + t^3 - 2*t^-2 + t^2.5 + t^0.5",
        "tan(0.3*t) + asin(0.1*t) + acos(0.05*t) + atan(t) + sinh(0.2*t) + cosh(0.1*t) + tanh(t)",
        "exp(0.1*t) + ln(t + 1) + log10(t + 2) + log2(t + 3) + sqrt(t + 1) + cbrt(t + 1) + abs(t - 2)",
        "atan2(t - 1, 2 - t) + atan2(1, t) + hypot(t, 2) + pow(t + 1, 0.5*t) + (t + 1)^(t/3)",
        "min(t, 2) + max(t^2, 3) + if(t < 1 && t >= 0.2 || t > 4, t^2, -t) + piecewise(t < 2, t, t > 3, 2*t, 5 - t)",
        "2*pi*3 + t/(1 + t^2) - (t - 2)^4 + 3/(t + 1) + (t + 2)*0.5 - 1.5/t",
    ];
    let exprs: Vec<Expr> = formulas.iter().map(|f| parse(f)).collect();
    let refs: Vec<&Expr> = exprs.iter().collect();
    let times: Vec<f64> = (0..300).map(|i| 0.013 * f64::from(i)).collect();
    let (mut third, mut second) = (Vec::new(), Vec::new());
    Program::compile(&refs, Order::Third)
        .unwrap()
        .eval(&times, &mut third);
    Program::compile(&refs, Order::Second)
        .unwrap()
        .eval(&times, &mut second);
    // (formula, kind, derivative) → (largest |dual number|, largest difference).
    let mut sines = [[[0.0_f64; 2]; 4]; 4];
    for (i, &t) in times.iter().enumerate() {
        for (k, e) in exprs.iter().enumerate() {
            let d = e.eval(Dual3::new(t, 1.0, 0.0, 0.0));
            let d2 = e.eval(Dual2::new(t, 1.0, 0.0));
            let cases = [
                ([d.re, d.v1, d.v2, d.v3], third[i * exprs.len() + k]),
                ([d2.re, d2.v1, d2.v2, 0.0], second[i * exprs.len() + k]),
            ];
            for (kind, (want, got)) in cases.into_iter().enumerate() {
                for j in 0..4 {
                    if k < 2 {
                        let m = &mut sines[2 * k + kind][j];
                        m[0] = m[0].max(want[j].abs());
                        m[1] = m[1].max((got[j] - want[j]).abs());
                        continue;
                    }
                    assert!(
                        same(got[j], want[j]),
                        "{}: {} at t = {t}: derivative {j}: {} vs {}",
                        ["Dual3", "Dual2"][kind],
                        formulas[k],
                        got[j],
                        want[j]
                    );
                }
            }
        }
    }
    for (case, components) in sines.iter().enumerate() {
        for (j, [scale, worst]) in components.iter().enumerate() {
            assert!(
                *worst <= DUAL_NUMBERS_BOUND * f64::EPSILON * scale,
                "{} over {}: derivative {j} off by {worst} of {scale}",
                formulas[case / 2],
                ["Dual3", "Dual2"][case % 2]
            );
        }
    }
    let differ = sines
        .iter()
        .flatten()
        .filter(|[_, worst]| *worst > 0.0)
        .count();
    assert!(
        differ > 0,
        "the kernels gave the C library's numbers everywhere"
    );
}

#[test]
fn shared_subexpressions_are_computed_once_and_constants_folded() {
    let a = parse("r*sin(0.16*t + 0.02*sin(0.5*t))");
    let b = parse("r*(1 - cos(0.16*t + 0.02*sin(0.5*t)))");
    let both = Program::compile(&[&a, &b], Order::Third).unwrap();
    let alone = Program::compile(&[&a], Order::Third).unwrap().len()
        + Program::compile(&[&b], Order::Third).unwrap().len();
    // The phase `0.16*t + 0.02*sin(0.5*t)` (t and 5 operations) is shared.
    assert!(both.len() + 5 <= alone, "{} vs {alone}", both.len());
    // Constants are folded, and an operation holds its constant operand: t, then 6π·t.
    let folded = Program::compile(&[&parse("2*pi*3*t")], Order::Third).unwrap();
    assert_eq!(folded.len(), 2, "{folded:?}");
    assert!(matches!(
        folded.steps[1].1,
        Op::WithConst(Arith::Mul, _, c, Side::Left) if c == 2.0 * std::f64::consts::PI * 3.0
    ));
    let constant_out = Program::compile(&[&parse("2*pi")], Order::Third).unwrap();
    assert!(matches!(constant_out.steps[..], [(_, Op::Const(_), _)]));
}

#[test]
fn registers_are_reused_as_values_die() {
    let long = (0..500)
        .map(|k| format!("sin({k}*t)"))
        .collect::<Vec<_>>()
        .join(" + ");
    let p = Program::compile(&[&parse(&long)], Order::Second).unwrap();
    assert!(p.registers < 8, "{} registers", p.registers);
}
