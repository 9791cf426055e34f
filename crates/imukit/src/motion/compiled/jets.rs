//! The jets' arithmetic, num-dual's own operation for operation: `Dual3`'s and `Dual2`'s
//! products, quotients and chain rule, powers, and the functions a formula may call.

use super::Jet;
use crate::motion::expr::{Func1, Func2};

/// Products, quotients and the chain rule of one kind of dual number.
pub(super) trait Arithmetic {
    fn mul(x: Jet, y: Jet) -> Jet;
    fn div(x: Jet, y: Jet) -> Jet;
    /// The chain rule with `f(x₀)` and its derivatives `f′, f″, f‴` there.
    fn chain(x: Jet, f0: f64, f1: f64, f2: f64, f3: f64) -> Jet;
}

/// num-dual's `Dual3`.
pub(super) struct Third;

impl Arithmetic for Third {
    /// Leibniz's rule.
    fn mul(x: Jet, y: Jet) -> Jet {
        [
            x[0] * y[0],
            x[1] * y[0] + x[0] * y[1],
            x[2] * y[0] + 2.0 * x[1] * y[1] + x[0] * y[2],
            x[3] * y[0] + 3.0 * (x[2] * y[1] + x[1] * y[2]) + x[0] * y[3],
        ]
    }

    /// `1/y` by the chain rule, then the product.
    fn div(x: Jet, y: Jet) -> Jet {
        let rec = 1.0 / y[0];
        let f0 = rec;
        let f1 = -f0 * rec;
        let f2 = -f1 * rec * 2.0;
        let f3 = -f2 * rec * 3.0;
        Self::mul(x, Self::chain(y, f0, f1, f2, f3))
    }

    fn chain(x: Jet, f0: f64, f1: f64, f2: f64, f3: f64) -> Jet {
        [
            f0,
            f1 * x[1],
            f2 * x[1] * x[1] + f1 * x[2],
            f3 * x[1] * x[1] * x[1] + 3.0 * f2 * x[1] * x[2] + f1 * x[3],
        ]
    }
}

/// num-dual's `Dual2` (its terms grouped as it groups them; the fourth entry 0).
pub(super) struct Second;

impl Arithmetic for Second {
    fn mul(x: Jet, y: Jet) -> Jet {
        [
            x[0] * y[0],
            y[1] * x[0] + x[1] * y[0],
            y[2] * x[0] + x[1] * y[1] + y[1] * x[1] + x[2] * y[0],
            0.0,
        ]
    }

    fn div(x: Jet, y: Jet) -> Jet {
        let inv = y[0].recip();
        let inv2 = inv * inv;
        [
            x[0] * inv,
            (x[1] * y[0] - y[1] * x[0]) * inv2,
            x[2] * inv - (y[2] * x[0] + x[1] * y[1] + y[1] * x[1]) * inv2
                + y[1] * y[1] * ((1.0 + 1.0) * x[0] * inv2 * inv),
            0.0,
        ]
    }

    fn chain(x: Jet, f0: f64, f1: f64, f2: f64, _f3: f64) -> Jet {
        [f0, x[1] * f1, x[2] * f1 + x[1] * x[1] * f2, 0.0]
    }
}

pub(super) fn powi<A: Arithmetic>(x: Jet, k: i32) -> Jet {
    match k {
        0 => [1.0, 0.0, 0.0, 0.0],
        1 => x,
        2 => A::mul(x, x),
        _ => {
            let pow3 = x[0].powi(k - 3);
            let f0 = pow3 * x[0] * x[0] * x[0];
            let f1 = pow3 * x[0] * x[0] * f64::from(k);
            // num-dual multiplies the factors in i32 (which overflows beyond |k| ≈ 1290); in f64
            // they are the same numbers where it does not.
            let (k, k1, k2) = (f64::from(k), f64::from(k - 1), f64::from(k - 2));
            let f2 = pow3 * x[0] * (k * k1);
            let f3 = pow3 * (k * k1 * k2);
            A::chain(x, f0, f1, f2, f3)
        }
    }
}

pub(super) fn powf<A: Arithmetic>(x: Jet, n: f64) -> Jet {
    if n == 0.0 {
        [1.0, 0.0, 0.0, 0.0]
    } else if n == 1.0 {
        x
    } else if (n - 1.0 - 1.0).abs() < f64::EPSILON {
        A::mul(x, x)
    } else {
        let n1 = n - 1.0;
        let n2 = n1 - 1.0;
        let n3 = n2 - 1.0;
        let pow3 = x[0].powf(n3);
        let f0 = pow3 * x[0] * x[0] * x[0];
        let f1 = pow3 * x[0] * x[0] * n;
        let f2 = pow3 * x[0] * n * n1;
        let f3 = pow3 * n * n1 * n2;
        A::chain(x, f0, f1, f2, f3)
    }
}

fn sin_cos<A: Arithmetic>(x: Jet) -> (Jet, Jet) {
    let (s, c) = x[0].sin_cos();
    (A::chain(x, s, c, -s, -c), A::chain(x, c, -s, -c, s))
}

fn sinh_cosh<A: Arithmetic>(x: Jet) -> (Jet, Jet) {
    let (s, c) = (x[0].sinh(), x[0].cosh());
    (A::chain(x, s, c, s, c), A::chain(x, c, s, c, s))
}

/// The logarithms' chain rule from `f(x₀)` and `f′(x₀)`.
fn log_like<A: Arithmetic>(x: Jet, f0: f64, f1: f64) -> Jet {
    let rec = x[0].recip();
    let f2 = -f1 * rec;
    let f3 = -f2 * rec * 2.0;
    A::chain(x, f0, f1, f2, f3)
}

pub(super) fn func1<A: Arithmetic>(f: Func1, x: Jet) -> Jet {
    let x0 = x[0];
    match f {
        Func1::Sin => sin_cos::<A>(x).0,
        Func1::Cos => sin_cos::<A>(x).1,
        Func1::Tan => {
            let (s, c) = sin_cos::<A>(x);
            A::div(s, c)
        }
        Func1::Asin | Func1::Acos => {
            let rec = (1.0 - x0 * x0).recip();
            let (f0, f1) = if f == Func1::Asin {
                (x0.asin(), rec.sqrt())
            } else {
                (x0.acos(), -rec.sqrt())
            };
            let f2 = x0 * f1 * rec;
            let f3 = (x0 * x0 * 2.0 + 1.0) * f1 * rec * rec;
            A::chain(x, f0, f1, f2, f3)
        }
        Func1::Atan => {
            let rec = (1.0 + x0 * x0).recip();
            let f1 = rec;
            let f2 = -x0 * f1 * rec * 2.0;
            let f3 = (x0 * x0 * 6.0 - 2.0) * f1 * rec * rec;
            A::chain(x, x0.atan(), f1, f2, f3)
        }
        Func1::Sinh => sinh_cosh::<A>(x).0,
        Func1::Cosh => sinh_cosh::<A>(x).1,
        Func1::Tanh => {
            let (s, c) = sinh_cosh::<A>(x);
            A::div(s, c)
        }
        Func1::Exp => {
            let e = x0.exp();
            A::chain(x, e, e, e, e)
        }
        Func1::Ln => log_like::<A>(x, x0.ln(), x0.recip()),
        Func1::Log10 => log_like::<A>(x, x0.log10(), x0.recip() / std::f64::consts::LN_10),
        Func1::Log2 => log_like::<A>(x, x0.log2(), x0.recip() / 2.0_f64.ln()),
        Func1::Sqrt => {
            let rec = x0.recip();
            let f0 = x0.sqrt();
            let f1 = f0 * rec * 0.5;
            let f2 = -f1 * rec * 0.5;
            let f3 = f2 * rec * (-1.0 - 0.5);
            A::chain(x, f0, f1, f2, f3)
        }
        Func1::Cbrt => {
            let rec = x0.recip();
            let third = 1.0 / 3.0;
            let f0 = x0.cbrt();
            let f1 = f0 * rec * third;
            let f2 = f1 * rec * (third - 1.0);
            let f3 = f2 * rec * (third - 1.0 - 1.0);
            A::chain(x, f0, f1, f2, f3)
        }
        Func1::Abs => {
            if x0 < 0.0 {
                neg(x)
            } else {
                x
            }
        }
    }
}

pub(super) fn func2<A: Arithmetic>(f: Func2, x: Jet, y: Jet) -> Jet {
    match f {
        // imukit's `atan2` (motion::analytic): the branch that divides by the larger, its
        // value replaced by `f64::atan2`'s.
        Func2::Atan2 => {
            let branch = if y[0].abs() >= x[0].abs() {
                func1::<A>(Func1::Atan, A::div(x, y))
            } else {
                neg(func1::<A>(Func1::Atan, A::div(y, x)))
            };
            let value = x[0].atan2(y[0]);
            // `value + (b₀ − b₀)`, as the helper adds the branch less its own value (NaN stays NaN).
            #[allow(clippy::eq_op)]
            [
                value + (branch[0] - branch[0]),
                0.0 + (branch[1] - 0.0),
                0.0 + (branch[2] - 0.0),
                0.0 + (branch[3] - 0.0),
            ]
        }
        Func2::Hypot => func1::<A>(Func1::Sqrt, add(A::mul(x, x), A::mul(y, y))),
        Func2::Pow => func1::<A>(Func1::Exp, A::mul(func1::<A>(Func1::Ln, x), y)),
        Func2::Min => {
            if y[0] < x[0] {
                y
            } else {
                x
            }
        }
        Func2::Max => {
            if y[0] > x[0] {
                y
            } else {
                x
            }
        }
    }
}

/// The jets' sums and negation, component by component (the same for every kind of dual number).
pub(super) fn neg(x: Jet) -> Jet {
    x.map(|v| -v)
}

pub(super) fn add(x: Jet, y: Jet) -> Jet {
    [x[0] + y[0], x[1] + y[1], x[2] + y[2], x[3] + y[3]]
}

pub(super) fn sub(x: Jet, y: Jet) -> Jet {
    [x[0] - y[0], x[1] - y[1], x[2] - y[2], x[3] - y[3]]
}
