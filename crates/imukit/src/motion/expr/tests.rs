use num_dual::Dual3;

use super::*;

fn parse(s: &str) -> Result<Expr, ExprError> {
    let mut c = BTreeMap::new();
    c.insert("f".to_string(), 2.0);
    Expr::parse(s, &c)
}

#[test]
fn precedence_and_powers_follow_the_usual_rules() {
    let cases = [
        ("1 + 2*3", 7.0),
        ("-2^2", -4.0),
        ("2^3^2", 512.0),
        ("2**-1", 0.5),
        ("(1+2)*3", 9.0),
        ("f*pi", 2.0 * std::f64::consts::PI),
        ("atan2(1, 1)", std::f64::consts::FRAC_PI_4),
        ("1e-3*1E3", 1.0),
        (".5 + 0.25", 0.75),
    ];
    for (s, v) in cases {
        assert!((parse(s).unwrap().eval(0.0) - v).abs() < 1e-15, "{s}");
    }
}

#[test]
fn derivatives_are_exact_over_dual_numbers() {
    // x = 0.8 cos(2π f t): x' = −0.8·2πf sin, x'' = −0.8(2πf)² cos, x''' = 0.8(2πf)³ sin.
    let e = parse("0.8*cos(2*pi*f*t)").unwrap();
    let t = 0.123;
    let d = e.eval(Dual3::new(t, 1.0, 0.0, 0.0));
    let w = 2.0 * std::f64::consts::PI * 2.0;
    assert!((d.v1 + 0.8 * w * (w * t).sin()).abs() < 1e-13);
    assert!((d.v2 + 0.8 * w * w * (w * t).cos()).abs() < 1e-12);
    assert!((d.v3 - 0.8 * w * w * w * (w * t).sin()).abs() < 1e-10);
    let p = parse("t^3 - 2*t**2 + sqrt(t)")
        .unwrap()
        .eval(Dual3::<f64>::new(4.0, 1.0, 0.0, 0.0));
    assert!((p.v1 - (3.0 * 16.0 - 16.0 + 0.25)).abs() < 1e-14);
    assert!((p.v2 - (6.0 * 4.0 - 4.0 - 0.25 / 8.0)).abs() < 1e-14);
}

#[test]
fn atan2_differentiates_where_its_second_argument_is_zero() {
    // atan2(t, 1 − t) at t = 1: the angle π/2, d/dt = ((1 − t)·1 − t·(−1))/((1−t)² + t²) = 1,
    // second derivative −2(2t − 1)… = −2 at t = 1 ((x² + y²)' = 2(2t − 1)).
    let e = parse("atan2(t, 1 - t)").unwrap();
    let d = e.eval(Dual3::new(1.0, 1.0, 0.0, 0.0));
    assert_eq!(d.re, std::f64::consts::FRAC_PI_2);
    assert!((d.v1 - 1.0).abs() < 1e-15, "{}", d.v1);
    assert!((d.v2 + 2.0).abs() < 1e-14, "{}", d.v2);
    // The value is f64::atan2's, bit for bit, on either branch.
    for (y, x) in [(1.0, 3.0), (3.0, 1.0), (-2.0, -0.5), (0.1, -4.0)] {
        let v: f64 = parse(&format!("atan2({y}, {x})")).unwrap().eval(0.0);
        assert_eq!(v.to_bits(), f64::atan2(y, x).to_bits());
    }
}

#[test]
fn piecewise_picks_the_first_true_piece_and_differentiates_it() {
    let e = parse("piecewise(t < 4, pi/2*t, t >= 4 && t < 6, 2*pi + pi*(t-4), 4*pi)").unwrap();
    let d = e.eval(Dual3::new(5.0, 1.0, 0.0, 0.0));
    assert!((d.re - 3.0 * std::f64::consts::PI).abs() < 1e-14);
    assert!((d.v1 - std::f64::consts::PI).abs() < 1e-14);
    assert!((e.eval(1.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((e.eval(7.0) - 4.0 * std::f64::consts::PI).abs() < 1e-15);
    let i = parse("if(t > 1 || !(t > 0), 1, 2)").unwrap();
    assert_eq!((i.eval(2.0), i.eval(0.5), i.eval(-1.0)), (1.0, 2.0, 1.0));
}

#[test]
fn errors_name_the_problem_and_its_column() {
    let e = parse("0.8*cos(2*pi*g*t)").unwrap_err();
    assert_eq!(e.column, 14);
    assert!(e.message.contains("unknown variable 'g'"), "{e}");
    let e = parse("2*sine(t)").unwrap_err();
    assert_eq!(e.column, 3);
    assert!(e.message.contains("unknown function 'sine'"), "{e}");
    let e = parse("1 + ").unwrap_err();
    assert_eq!(e.column, 5);
    let e = parse("(1 + t").unwrap_err();
    assert!(e.message.contains("expected ')'"), "{e}");
    let e = parse("atan2(t)").unwrap_err();
    assert!(e.message.contains("takes 2 argument"), "{e}");
    let e = parse("t # 2").unwrap_err();
    assert_eq!(e.column, 3);
    assert!(parse("").is_err());
    let e = parse("if(t, 1, 2)").unwrap_err();
    assert!(e.message.contains("condition"), "{e}");
}

#[test]
fn nesting_depth_and_length_are_limited_before_the_stack_is() {
    let nested = |n: usize| format!("{}t{}", "(".repeat(n), ")".repeat(n));
    assert!(parse(&nested(MAX_NESTING)).is_ok());
    let e = parse(&nested(5000)).unwrap_err();
    assert!(e.message.contains("nested deeper than 64 levels"), "{e}");
    assert_eq!(e.column, MAX_NESTING + 1);
    let signs = format!("{}t", "-".repeat(5000));
    assert!(parse(&signs).unwrap_err().message.contains("nested deeper"));
    let calls = format!("{}t{}", "sin(".repeat(5000), ")".repeat(5000));
    assert!(parse(&calls).unwrap_err().message.contains("nested deeper"));
    let powers = format!("t{}", "^t".repeat(5000));
    assert!(
        parse(&powers)
            .unwrap_err()
            .message
            .contains("nested deeper")
    );
    // A long sum is deep although not nested: refused at the term that passes the limit.
    let sum = |n: usize| vec!["t"; n].join("+");
    let ok = parse(&sum(MAX_DEPTH)).unwrap();
    assert_eq!(ok.eval(2.0), 2.0 * MAX_DEPTH as f64);
    let e = parse(&sum(40_000)).unwrap_err();
    assert!(e.message.contains("more than 1000 operations deep"), "{e}");
    assert_eq!(e.column, 2 * MAX_DEPTH); // the '+' before term 1001
    let conds = format!("if({}, 1, 0)", vec!["t < 1"; 5000].join(" && "));
    assert!(
        parse(&conds)
            .unwrap_err()
            .message
            .contains("operations deep")
    );
    let e = parse(&"t".repeat(MAX_LENGTH + 1)).unwrap_err();
    assert!(e.message.contains("longer than 100000 characters"), "{e}");
}

#[test]
fn nested_conditions_parse_in_bounded_time() {
    // Parenthesised conditions are tried as conditions first, then as values: the work grows
    // with the square of the nesting, not exponentially (this would not finish otherwise).
    let n = MAX_NESTING - 2;
    let f = format!("if({}t{} < 1, 1, 0)", "(".repeat(n), ")".repeat(n));
    assert_eq!(parse(&f).unwrap().eval(0.5), 1.0);
    assert_eq!(parse(&f).unwrap().eval(1.5), 0.0);
}
