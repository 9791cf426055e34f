//! Formulas compiled into one flat program and evaluated over chunks of samples.
//!
//! [`Program::compile`] turns the parsed trees of several formulas (a motion's three positions
//! and its angles) into one list of operations in evaluation order: every subexpression that
//! occurs more than once — within a formula or across them — is computed once, subexpressions
//! of constants are folded, a sum, difference, product or quotient with a constant holds the
//! constant in the operation (not in a register refilled every chunk), and values are kept in as
//! few registers as their lifetimes allow.
//! [`Program::eval`] runs the list over up to [`CHUNK`] samples at a time, each register
//! holding a [`Jet`] per sample: the value and its first three time derivatives.
//!
//! A jet's arithmetic is num-dual's, operation for operation in the same order: of its
//! third-order dual numbers (`Dual3`, [`Order::Third`]: products by Leibniz's rule, quotients
//! through the reciprocal's chain rule, each function's derivatives `f, f′, f″, f‴` through the
//! chain rule) for positions, or of its second-order ones (`Dual2`, [`Order::Second`], whose
//! products and quotients group their terms differently) for angles. So a compiled formula gives
//! the numbers the formula's tree gives over those dual numbers — bit for bit, up to the sign of
//! a zero (a constant's folded derivatives are `+0`) — except through sines and cosines: the
//! program takes a chunk's `sin_cos` at once from the vector kernels of [`imu_core::trig`]
//! (within [`imu_core::trig::MAX_ULP`] of the correctly rounded values, where the C library
//! num-dual calls is within one), so a formula with `sin` or `cos` is within
//! [`DUAL_NUMBERS_BOUND`] of the dual numbers instead. No tree walk and no dispatch per sample
//! and node.
use std::collections::HashMap;

use crate::motion::expr::{CmpOp, Cond, Expr, Func1, Func2, Node};

mod interpret;
mod jets;
#[cfg(test)]
mod tests;

use interpret::{apply, run, split};
use jets::{Second, Third};

/// Value and first three derivatives with respect to time.
pub type Jet = [f64; 4];

/// Samples evaluated together.
pub const CHUNK: usize = 64;

/// How far a compiled formula's jets may be from the formula's evaluation over num-dual's dual
/// numbers: in units of ε (2⁻⁵²) times the largest magnitude that component takes over the
/// samples compared. The two differ only through their sines and cosines (the program's from
/// [`imu_core::trig`], within [`imu_core::trig::MAX_ULP`] of the correctly rounded values;
/// num-dual's from the C library, within one); on every example and built-in the largest
/// difference is 2.6 ε, in the truth built from them too.
pub const DUAL_NUMBERS_BOUND: f64 = 8.0;

/// The most registers a program may use (each holds [`CHUNK`] jets, 2 KiB); a formula that
/// would need more is evaluated over dual numbers instead.
pub const MAX_REGISTERS: usize = 4096;

/// Which dual numbers' arithmetic a program (or a group of its formulas) follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Order {
    /// Second derivatives, as num-dual's `Dual2` (the jets' fourth entry is 0).
    Second,
    /// Third derivatives, as num-dual's `Dual3`.
    Third,
}

/// An operation on earlier values (indices into the program's values).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(f64),
    T,
    Neg(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    PowI(u32, i32),
    PowF(u32, f64),
    F1(Func1, u32),
    F2(Func2, u32, u32),
    /// 1 where the comparison holds, else 0 (on values).
    Cmp(CmpOp, u32, u32),
    And(u32, u32),
    Or(u32, u32),
    Not(u32),
    /// Per sample: the second where the first is non-zero, else the third.
    Select(u32, u32, u32),
    /// `sin` or `cos` of a value: its `sin_cos` (the chunk's at once), the pair kept in the slot
    /// for [`Op::FromPair`] of the other one.
    SinCos(Func1, u32, u32),
    /// `sin` or `cos` from the pair an earlier [`Op::SinCos`] of the same value kept.
    FromPair(Func1, u32, u32),
    /// `+`, `−`, `×` or `÷` of a value and a constant (on the side given): the same arithmetic
    /// as the operation on the constant's jet `[c, 0, 0, 0]`, the constant held in the step
    /// instead of a register filled with it every chunk.
    WithConst(Arith, u32, f64, Side),
}

/// The four arithmetic operations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Arith {
    Add,
    Sub,
    Mul,
    Div,
}

/// Which operand of [`Op::WithConst`] the constant is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Side {
    /// `value ∘ constant`.
    Right,
    /// `constant ∘ value`.
    Left,
}

/// [`Op`] as a hash key (constants by their bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    T,
    Neg(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    PowI(u32, i32),
    PowF(u32, u64),
    F1(Func1, u32),
    F2(Func2, u32, u32),
    Cmp(CmpOp, u32, u32),
    And(u32, u32),
    Or(u32, u32),
    Not(u32),
    Select(u32, u32, u32),
    SinCos(Func1, u32, u32),
    FromPair(Func1, u32, u32),
    WithConst(Arith, u32, u64, Side),
}

impl Op {
    fn key(self) -> Key {
        match self {
            Self::Const(c) => Key::Const(c.to_bits()),
            Self::T => Key::T,
            Self::Neg(a) => Key::Neg(a),
            Self::Add(a, b) => Key::Add(a, b),
            Self::Sub(a, b) => Key::Sub(a, b),
            Self::Mul(a, b) => Key::Mul(a, b),
            Self::Div(a, b) => Key::Div(a, b),
            Self::PowI(a, k) => Key::PowI(a, k),
            Self::PowF(a, k) => Key::PowF(a, k.to_bits()),
            Self::F1(f, a) => Key::F1(f, a),
            Self::F2(f, a, b) => Key::F2(f, a, b),
            Self::Cmp(c, a, b) => Key::Cmp(c, a, b),
            Self::And(a, b) => Key::And(a, b),
            Self::Or(a, b) => Key::Or(a, b),
            Self::Not(a) => Key::Not(a),
            Self::Select(c, a, b) => Key::Select(c, a, b),
            Self::SinCos(f, a, k) => Key::SinCos(f, a, k),
            Self::FromPair(f, a, k) => Key::FromPair(f, a, k),
            Self::WithConst(o, a, c, side) => Key::WithConst(o, a, c.to_bits(), side),
        }
    }

    /// The values it reads.
    fn operands(self) -> impl Iterator<Item = u32> {
        let (a, b, c) = match self {
            Self::Const(_) | Self::T => (None, None, None),
            Self::Neg(a)
            | Self::PowI(a, _)
            | Self::PowF(a, _)
            | Self::F1(_, a)
            | Self::Not(a)
            | Self::SinCos(_, a, _)
            | Self::FromPair(_, a, _)
            | Self::WithConst(_, a, ..) => (Some(a), None, None),
            Self::Add(a, b)
            | Self::Sub(a, b)
            | Self::Mul(a, b)
            | Self::Div(a, b)
            | Self::F2(_, a, b)
            | Self::Cmp(_, a, b)
            | Self::And(a, b)
            | Self::Or(a, b) => (Some(a), Some(b), None),
            Self::Select(c, a, b) => (Some(c), Some(a), Some(b)),
        };
        [a, b, c].into_iter().flatten()
    }

    /// The same operation on other values.
    fn map(self, f: impl Fn(u32) -> u32) -> Self {
        match self {
            Self::Const(_) | Self::T => self,
            Self::Neg(a) => Self::Neg(f(a)),
            Self::Add(a, b) => Self::Add(f(a), f(b)),
            Self::Sub(a, b) => Self::Sub(f(a), f(b)),
            Self::Mul(a, b) => Self::Mul(f(a), f(b)),
            Self::Div(a, b) => Self::Div(f(a), f(b)),
            Self::PowI(a, k) => Self::PowI(f(a), k),
            Self::PowF(a, k) => Self::PowF(f(a), k),
            Self::F1(g, a) => Self::F1(g, f(a)),
            Self::F2(g, a, b) => Self::F2(g, f(a), f(b)),
            Self::Cmp(c, a, b) => Self::Cmp(c, f(a), f(b)),
            Self::And(a, b) => Self::And(f(a), f(b)),
            Self::Or(a, b) => Self::Or(f(a), f(b)),
            Self::Not(a) => Self::Not(f(a)),
            Self::Select(c, a, b) => Self::Select(f(c), f(a), f(b)),
            Self::SinCos(g, a, k) => Self::SinCos(g, f(a), k),
            Self::FromPair(g, a, k) => Self::FromPair(g, f(a), k),
            Self::WithConst(o, a, c, side) => Self::WithConst(o, f(a), c, side),
        }
    }
}

/// The registers a [`Program`] works in, kept between calls of [`Program::eval_rows`] (and
/// [`Program::eval_in`]).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    registers: Vec<[Jet; CHUNK]>,
    pairs: Vec<[(f64, f64); CHUNK]>,
}

/// Several formulas compiled together (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// `(arithmetic, operation on registers, register it writes)`, in order.
    steps: Vec<(Order, Op, u32)>,
    /// The register holding each formula's value at the end.
    outputs: Vec<u32>,
    registers: usize,
    /// Slots of `(sin, cos)` pairs shared by [`Op::SinCos`] and [`Op::FromPair`].
    pairs: usize,
}

/// Builds the value list: one entry per distinct operation in each arithmetic.
struct Builder {
    /// The arithmetic of the formulas being added.
    order: Order,
    ops: Vec<(Order, Op)>,
    known: HashMap<(Order, Key), u32>,
}

impl Builder {
    /// The value of `op`: an earlier equal one, a folded constant, or a new entry.
    fn push(&mut self, op: Op) -> u32 {
        let op = self.fold(op);
        let key = (self.order, op.key());
        if let Some(&v) = self.known.get(&key) {
            return v;
        }
        let v = self.ops.len() as u32;
        self.ops.push((self.order, op));
        self.known.insert(key, v);
        v
    }

    /// `op` on constants evaluated now, when its jet is a finite constant (a value whose
    /// derivatives are zero): the same arithmetic the program would run.
    fn fold(&self, op: Op) -> Op {
        let mut constants = Vec::with_capacity(3);
        for v in op.operands() {
            match self.ops[v as usize].1 {
                Op::Const(c) => constants.push([c, 0.0, 0.0, 0.0]),
                _ => return op,
            }
        }
        if matches!(op, Op::Const(_) | Op::T) {
            return op;
        }
        let jet = match self.order {
            Order::Second => apply::<Second>(op, &constants),
            Order::Third => apply::<Third>(op, &constants),
        };
        if jet.iter().all(|x| x.is_finite()) && jet[1..].iter().all(|d| *d == 0.0) {
            Op::Const(jet[0])
        } else {
            op
        }
    }

    fn node(&mut self, n: &Node) -> u32 {
        match n {
            Node::Num(v) => self.push(Op::Const(*v)),
            Node::T => self.push(Op::T),
            Node::Neg(a) => {
                let a = self.node(a);
                self.push(Op::Neg(a))
            }
            Node::Add(a, b) => self.binary(a, b, Op::Add),
            Node::Sub(a, b) => self.binary(a, b, Op::Sub),
            Node::Mul(a, b) => self.binary(a, b, Op::Mul),
            Node::Div(a, b) => self.binary(a, b, Op::Div),
            Node::PowI(a, k) => {
                let a = self.node(a);
                self.push(Op::PowI(a, *k))
            }
            Node::PowF(a, k) => {
                let a = self.node(a);
                self.push(Op::PowF(a, *k))
            }
            // `x^y` over duals is `exp(ln(x)·y)`.
            Node::Pow(a, b) => self.pow(a, b),
            Node::F1(f, a) => {
                let a = self.node(a);
                self.push(Op::F1(*f, a))
            }
            Node::F2(Func2::Pow, a, b) => self.pow(a, b),
            Node::F2(f, a, b) => self.binary(a, b, |x, y| Op::F2(*f, x, y)),
            Node::Piecewise(pieces, fallback) => {
                let mut value = self.node(fallback);
                for (c, v) in pieces.iter().rev() {
                    let (c, v) = (self.cond(c), self.node(v));
                    value = self.push(Op::Select(c, v, value));
                }
                value
            }
        }
    }

    fn binary(&mut self, a: &Node, b: &Node, op: impl Fn(u32, u32) -> Op) -> u32 {
        let a = self.node(a);
        let b = self.node(b);
        self.push(op(a, b))
    }

    fn pow(&mut self, a: &Node, b: &Node) -> u32 {
        let a = self.node(a);
        let b = self.node(b);
        let ln = self.push(Op::F1(Func1::Ln, a));
        let product = self.push(Op::Mul(ln, b));
        self.push(Op::F1(Func1::Exp, product))
    }

    fn cond(&mut self, c: &Cond) -> u32 {
        match c {
            Cond::Cmp(op, a, b) => self.binary(a, b, |x, y| Op::Cmp(*op, x, y)),
            Cond::And(a, b) => {
                let (a, b) = (self.cond(a), self.cond(b));
                self.push(Op::And(a, b))
            }
            Cond::Or(a, b) => {
                let (a, b) = (self.cond(a), self.cond(b));
                self.push(Op::Or(a, b))
            }
            Cond::Not(a) => {
                let a = self.cond(a);
                self.push(Op::Not(a))
            }
        }
    }
}

impl Program {
    /// `formulas` compiled together for jets of `order`; `None` when they would need more than
    /// [`MAX_REGISTERS`] registers at once.
    #[must_use]
    pub fn compile(formulas: &[&Expr], order: Order) -> Option<Self> {
        Self::compile_groups(&[(formulas, order)])
    }

    /// Groups of formulas, each in its own arithmetic, compiled into one program whose outputs
    /// are the groups' formulas in turn (a motion's positions in [`Order::Third`], its angles in
    /// [`Order::Second`]). Subexpressions are shared within an arithmetic; across them, a `sin`
    /// or `cos` of the same value takes the one `sin_cos` — a value (a jet's first entry) is the
    /// same number in either arithmetic, so this changes no result. `None` as [`Self::compile`].
    #[must_use]
    pub fn compile_groups(groups: &[(&[&Expr], Order)]) -> Option<Self> {
        let mut b = Builder {
            order: Order::Third,
            ops: Vec::new(),
            known: HashMap::new(),
        };
        let mut values: Vec<u32> = Vec::new();
        for (formulas, order) in groups {
            b.order = *order;
            values.extend(formulas.iter().map(|f| b.node(f.root())));
        }
        // An operation of a value and a constant holds the constant itself (the same numbers;
        // a constant read by nothing else is then dropped below).
        for i in 0..b.ops.len() {
            let (arith, x, y) = match b.ops[i].1 {
                Op::Add(x, y) => (Arith::Add, x, y),
                Op::Sub(x, y) => (Arith::Sub, x, y),
                Op::Mul(x, y) => (Arith::Mul, x, y),
                Op::Div(x, y) => (Arith::Div, x, y),
                _ => continue,
            };
            let constant = |v: u32| match b.ops[v as usize].1 {
                Op::Const(c) => Some(c),
                _ => None,
            };
            b.ops[i].1 = match (constant(x), constant(y)) {
                (None, Some(c)) => Op::WithConst(arith, x, c, Side::Right),
                (Some(c), None) => Op::WithConst(arith, y, c, Side::Left),
                _ => continue,
            };
        }
        // Keep only what the outputs need.
        let mut needed = vec![false; b.ops.len()];
        for &v in &values {
            needed[v as usize] = true;
        }
        for i in (0..b.ops.len()).rev() {
            if needed[i] {
                for v in b.ops[i].1.operands() {
                    needed[v as usize] = true;
                }
            }
        }
        // Which values are the same number whatever the arithmetic: the same operation on the
        // same numbers (a value lane never reads a derivative lane).
        let mut class = vec![0u32; b.ops.len()];
        let mut classes: HashMap<Key, u32> = HashMap::new();
        for (i, (_, op)) in b.ops.iter().enumerate() {
            let key = op.map(|v| class[v as usize]).key();
            let next = classes.len() as u32;
            class[i] = *classes.entry(key).or_insert(next);
        }
        // Every `sin` and `cos` is a `sin_cos` of its chunk's numbers at once (the vector
        // kernels of `imu_core::trig`), and `sin` and `cos` of the same number share one: the
        // first one's.
        let mut pairs = 0u32;
        let mut pair_of: HashMap<u32, u32> = HashMap::new();
        for (i, &need) in needed.iter().enumerate() {
            let (_, Op::F1(f @ (Func1::Sin | Func1::Cos), a)) = b.ops[i] else {
                continue;
            };
            if !need {
                continue;
            }
            b.ops[i].1 = match pair_of.get(&class[a as usize]) {
                Some(&k) => Op::FromPair(f, a, k),
                None => {
                    pair_of.insert(class[a as usize], pairs);
                    pairs += 1;
                    Op::SinCos(f, a, pairs - 1)
                }
            };
        }
        // Each value's last reader (outputs live to the end).
        let mut last_use = vec![0usize; b.ops.len()];
        for (i, (_, op)) in b.ops.iter().enumerate() {
            for v in op.operands() {
                last_use[v as usize] = i;
            }
        }
        for &v in &values {
            last_use[v as usize] = usize::MAX;
        }
        // Registers by lifetime: a value's register is free again after its last reader.
        let mut register = vec![u32::MAX; b.ops.len()];
        let mut free: Vec<u32> = Vec::new();
        let mut releases: Vec<Vec<u32>> = vec![Vec::new(); b.ops.len()];
        let mut registers = 0usize;
        let mut steps = Vec::new();
        for (i, &(order, op)) in b.ops.iter().enumerate() {
            if !needed[i] {
                continue;
            }
            let r = free.pop().unwrap_or_else(|| {
                registers += 1;
                (registers - 1) as u32
            });
            if registers > MAX_REGISTERS {
                return None;
            }
            steps.push((order, op.map(|v| register[v as usize]), r));
            register[i] = r;
            // Operands whose last reader this is give their registers back (after the write:
            // an operation never writes the register it reads).
            for v in op.operands() {
                if last_use[v as usize] == i && !releases[i].contains(&register[v as usize]) {
                    releases[i].push(register[v as usize]);
                }
            }
            free.append(&mut releases[i]);
        }
        Some(Self {
            steps,
            outputs: values.iter().map(|&v| register[v as usize]).collect(),
            registers,
            pairs: pairs as usize,
        })
    }

    /// Number of formulas.
    #[must_use]
    pub fn outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Operations per sample.
    #[must_use]
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// `sin_cos` evaluations per sample: one for each distinct number whose sine or cosine a
    /// formula takes, in whichever arithmetic, and one for each tangent.
    #[must_use]
    pub fn sin_cos_per_sample(&self) -> usize {
        self.steps
            .iter()
            .filter(|(_, op, _)| {
                matches!(
                    op,
                    Op::SinCos(..) | Op::F1(Func1::Sin | Func1::Cos | Func1::Tan, _)
                )
            })
            .count()
    }

    /// Whether the program has no operation.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// The formulas at each time of `t_s`: `out[i * outputs + k]` is formula `k` at `t_s[i]`
    /// (resized to fit).
    pub fn eval(&self, t_s: &[f64], out: &mut Vec<Jet>) {
        self.eval_in(t_s, out, &mut Scratch::default());
    }

    /// [`Self::eval`] in the registers of `scratch`, grown once and kept for the next call (a
    /// caller that evaluates chunk after chunk allocates nothing after the first).
    pub fn eval_in(&self, t_s: &[f64], out: &mut Vec<Jet>, scratch: &mut Scratch) {
        out.clear();
        out.reserve(t_s.len() * self.outputs.len());
        self.eval_rows(t_s, scratch, |row| {
            out.extend((0..self.outputs.len()).map(|k| row.jet(k)));
        });
    }

    /// The formulas at each time of `t_s` in order, handed to `each` sample by sample as a
    /// [`Row`], whose jets are read straight from the registers: a caller that builds its own
    /// rows from them copies nothing in between.
    #[inline]
    pub fn eval_rows(&self, t_s: &[f64], scratch: &mut Scratch, mut each: impl FnMut(&Row<'_>)) {
        // Every register and pair slot is written before it is read (the program is in
        // order), so what an earlier call left there is never seen.
        if scratch.registers.len() < self.registers {
            scratch.registers.resize(self.registers, [[0.0; 4]; CHUNK]);
        }
        if scratch.pairs.len() < self.pairs {
            scratch.pairs.resize(self.pairs, [(0.0, 0.0); CHUNK]);
        }
        let regs = &mut scratch.registers[..self.registers];
        let pairs = &mut scratch.pairs[..self.pairs];
        for times in t_s.chunks(CHUNK) {
            let n = times.len();
            for &(order, op, r) in &self.steps {
                let (out, regs) = split(regs, r as usize);
                let out = &mut out[..n];
                match order {
                    Order::Second => run::<Second>(op, out, &regs, pairs, times),
                    Order::Third => run::<Third>(op, out, &regs, pairs, times),
                }
            }
            for i in 0..n {
                each(&Row {
                    registers: regs,
                    outputs: &self.outputs,
                    sample: i,
                });
            }
        }
    }
}

/// One time's outputs of a [`Program`], as [`Program::eval_rows`] hands them out.
pub struct Row<'a> {
    registers: &'a [[Jet; CHUNK]],
    outputs: &'a [u32],
    sample: usize,
}

impl Row<'_> {
    /// The jet of output `k` (in the order the program's formulas were given).
    #[inline(always)]
    #[must_use]
    pub fn jet(&self, k: usize) -> Jet {
        self.registers[self.outputs[k] as usize][self.sample]
    }
}
