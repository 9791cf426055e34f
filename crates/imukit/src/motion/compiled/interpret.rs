//! The compiled program run over a chunk of samples: each operation over its registers' jets.

use imu_core::trig;

use super::jets::{Arithmetic, add, func1, func2, neg, powf, powi, sub};
use super::{Arith, CHUNK, Jet, Op, Side};
use crate::motion::expr::{CmpOp, Func1};

/// `op` on the jets `args` (constant folding).
pub(super) fn apply<A: Arithmetic>(op: Op, args: &[Jet]) -> Jet {
    let arg = |k: usize| args[k];
    match op {
        Op::Const(c) => [c, 0.0, 0.0, 0.0],
        Op::T => unreachable!("not a function of operands"),
        Op::Neg(_) => neg(arg(0)),
        Op::Add(..) => add(arg(0), arg(1)),
        Op::Sub(..) => sub(arg(0), arg(1)),
        Op::Mul(..) => A::mul(arg(0), arg(1)),
        Op::Div(..) => A::div(arg(0), arg(1)),
        Op::PowI(_, k) => powi::<A>(arg(0), k),
        Op::PowF(_, k) => powf::<A>(arg(0), k),
        Op::F1(f, _) => func1::<A>(f, arg(0)),
        Op::F2(f, ..) => func2::<A>(f, arg(0), arg(1)),
        Op::Cmp(c, ..) => truth(compare(c, arg(0)[0], arg(1)[0])),
        Op::And(..) => truth(arg(0)[0] != 0.0 && arg(1)[0] != 0.0),
        Op::Or(..) => truth(arg(0)[0] != 0.0 || arg(1)[0] != 0.0),
        Op::Not(_) => truth(arg(0)[0] == 0.0),
        Op::Select(..) => {
            if arg(0)[0] != 0.0 {
                arg(1)
            } else {
                arg(2)
            }
        }
        Op::SinCos(f, ..) | Op::FromPair(f, ..) => func1::<A>(f, arg(0)),
        Op::WithConst(arith, _, c, side) => {
            let k = [c, 0.0, 0.0, 0.0];
            let (x, y) = match side {
                Side::Right => (arg(0), k),
                Side::Left => (k, arg(0)),
            };
            match arith {
                Arith::Add => add(x, y),
                Arith::Sub => sub(x, y),
                Arith::Mul => A::mul(x, y),
                Arith::Div => A::div(x, y),
            }
        }
    }
}

/// The registers but one, to read while that one is written.
pub(super) struct Others<'a> {
    below: &'a [[Jet; CHUNK]],
    above: &'a [[Jet; CHUNK]],
    r: usize,
}

impl Others<'_> {
    pub(super) fn get(&self, v: u32) -> &[Jet; CHUNK] {
        let v = v as usize;
        if v < self.r {
            &self.below[v]
        } else {
            &self.above[v - self.r - 1]
        }
    }
}

/// Register `r` to write and the others to read (an operation never reads the register it
/// writes: registers are handed out again only after their value's last reader).
pub(super) fn split(regs: &mut [[Jet; CHUNK]], r: usize) -> (&mut [Jet; CHUNK], Others<'_>) {
    let (below, rest) = regs.split_at_mut(r);
    let (out, above) = rest.split_first_mut().expect("the program's registers");
    (out, Others { below, above, r })
}

fn map1(out: &mut [Jet], x: &[Jet; CHUNK], f: impl Fn(Jet) -> Jet) {
    for (o, x) in out.iter_mut().zip(x) {
        *o = f(*x);
    }
}

fn map2(out: &mut [Jet], x: &[Jet; CHUNK], y: &[Jet; CHUNK], f: impl Fn(Jet, Jet) -> Jet) {
    for ((o, x), y) in out.iter_mut().zip(x).zip(y) {
        *o = f(*x, *y);
    }
}

/// `sin` or `cos` of `x` from `(sin x₀, cos x₀)`.
fn from_pair<A: Arithmetic>(f: Func1, x: Jet, (s, c): (f64, f64)) -> Jet {
    if f == Func1::Sin {
        A::chain(x, s, c, -s, -c)
    } else {
        A::chain(x, c, -s, -c, s)
    }
}

/// One operation over a chunk (`out` as long as the chunk), reading the other registers.
pub(super) fn run<A: Arithmetic>(
    op: Op,
    out: &mut [Jet],
    regs: &Others<'_>,
    pairs: &mut [[(f64, f64); CHUNK]],
    times: &[f64],
) {
    match op {
        Op::Const(c) => out.fill([c, 0.0, 0.0, 0.0]),
        Op::T => {
            for (o, t) in out.iter_mut().zip(times) {
                *o = [*t, 1.0, 0.0, 0.0];
            }
        }
        Op::Neg(a) => map1(out, regs.get(a), neg),
        Op::Add(a, b) => map2(out, regs.get(a), regs.get(b), add),
        Op::Sub(a, b) => map2(out, regs.get(a), regs.get(b), sub),
        Op::Mul(a, b) => map2(out, regs.get(a), regs.get(b), A::mul),
        Op::Div(a, b) => map2(out, regs.get(a), regs.get(b), A::div),
        Op::PowI(a, k) => map1(out, regs.get(a), |x| powi::<A>(x, k)),
        Op::PowF(a, k) => map1(out, regs.get(a), |x| powf::<A>(x, k)),
        Op::F1(f, a) => map1(out, regs.get(a), |x| func1::<A>(f, x)),
        Op::F2(f, a, b) => map2(out, regs.get(a), regs.get(b), |x, y| func2::<A>(f, x, y)),
        Op::Cmp(c, a, b) => map2(out, regs.get(a), regs.get(b), |x, y| {
            truth(compare(c, x[0], y[0]))
        }),
        Op::And(a, b) => map2(out, regs.get(a), regs.get(b), |x, y| {
            truth(x[0] != 0.0 && y[0] != 0.0)
        }),
        Op::Or(a, b) => map2(out, regs.get(a), regs.get(b), |x, y| {
            truth(x[0] != 0.0 || y[0] != 0.0)
        }),
        Op::Not(a) => map1(out, regs.get(a), |x| truth(x[0] == 0.0)),
        Op::Select(c, a, b) => {
            let (c, x, y) = (regs.get(c), regs.get(a), regs.get(b));
            for (i, o) in out.iter_mut().enumerate() {
                *o = if c[i][0] != 0.0 { x[i] } else { y[i] };
            }
        }
        Op::SinCos(f, a, k) => {
            let (x, pair) = (regs.get(a), &mut pairs[k as usize]);
            let n = out.len();
            let (mut x0, mut sin, mut cos) = ([0.0; CHUNK], [0.0; CHUNK], [0.0; CHUNK]);
            for (v, x) in x0.iter_mut().zip(&x[..n]) {
                *v = x[0];
            }
            trig::sin_cos_into(&x0[..n], &mut sin[..n], &mut cos[..n]);
            for (((o, x), p), sc) in out
                .iter_mut()
                .zip(x)
                .zip(pair)
                .zip(sin.into_iter().zip(cos))
            {
                *p = sc;
                *o = from_pair::<A>(f, *x, sc);
            }
        }
        Op::FromPair(f, a, k) => {
            let (x, pair) = (regs.get(a), &pairs[k as usize]);
            for ((o, x), p) in out.iter_mut().zip(x).zip(pair) {
                *o = from_pair::<A>(f, *x, *p);
            }
        }
        Op::WithConst(arith, a, c, side) => {
            let (x, k) = (regs.get(a), [c, 0.0, 0.0, 0.0]);
            match (arith, side) {
                (Arith::Add, Side::Right) => map1(out, x, |x| add(x, k)),
                (Arith::Add, Side::Left) => map1(out, x, |x| add(k, x)),
                (Arith::Sub, Side::Right) => map1(out, x, |x| sub(x, k)),
                (Arith::Sub, Side::Left) => map1(out, x, |x| sub(k, x)),
                (Arith::Mul, Side::Right) => map1(out, x, |x| A::mul(x, k)),
                (Arith::Mul, Side::Left) => map1(out, x, |x| A::mul(k, x)),
                (Arith::Div, Side::Right) => map1(out, x, |x| A::div(x, k)),
                (Arith::Div, Side::Left) => map1(out, x, |x| A::div(k, x)),
            }
        }
    }
}

fn truth(holds: bool) -> Jet {
    [if holds { 1.0 } else { 0.0 }, 0.0, 0.0, 0.0]
}

fn compare(c: CmpOp, x: f64, y: f64) -> bool {
    match c {
        CmpOp::Lt => x < y,
        CmpOp::Le => x <= y,
        CmpOp::Gt => x > y,
        CmpOp::Ge => x >= y,
        CmpOp::Eq => x == y,
        CmpOp::Ne => x != y,
    }
}
