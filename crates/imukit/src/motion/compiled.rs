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

use imu_core::trig;

use crate::motion::expr::{CmpOp, Cond, Expr, Func1, Func2, Node};

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

/// `op` on the jets `args` (constant folding).
fn apply<A: Arithmetic>(op: Op, args: &[Jet]) -> Jet {
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
struct Others<'a> {
    below: &'a [[Jet; CHUNK]],
    above: &'a [[Jet; CHUNK]],
    r: usize,
}

impl Others<'_> {
    fn get(&self, v: u32) -> &[Jet; CHUNK] {
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
fn split(regs: &mut [[Jet; CHUNK]], r: usize) -> (&mut [Jet; CHUNK], Others<'_>) {
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
fn run<A: Arithmetic>(
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

fn neg(x: Jet) -> Jet {
    x.map(|v| -v)
}

fn add(x: Jet, y: Jet) -> Jet {
    [x[0] + y[0], x[1] + y[1], x[2] + y[2], x[3] + y[3]]
}

fn sub(x: Jet, y: Jet) -> Jet {
    [x[0] - y[0], x[1] - y[1], x[2] - y[2], x[3] - y[3]]
}

/// Products, quotients and the chain rule of one kind of dual number.
trait Arithmetic {
    fn mul(x: Jet, y: Jet) -> Jet;
    fn div(x: Jet, y: Jet) -> Jet;
    /// The chain rule with `f(x₀)` and its derivatives `f′, f″, f‴` there.
    fn chain(x: Jet, f0: f64, f1: f64, f2: f64, f3: f64) -> Jet;
}

/// num-dual's `Dual3`.
struct Third;

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
struct Second;

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

fn powi<A: Arithmetic>(x: Jet, k: i32) -> Jet {
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

fn powf<A: Arithmetic>(x: Jet, n: f64) -> Jet {
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

fn func1<A: Arithmetic>(f: Func1, x: Jet) -> Jet {
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

fn func2<A: Arithmetic>(f: Func2, x: Jet, y: Jet) -> Jet {
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

#[cfg(test)]
mod tests {
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
}
