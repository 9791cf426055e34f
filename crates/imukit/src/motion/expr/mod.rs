//! Formula strings of time, parsed once and evaluated over dual numbers for exact derivatives.
//!
//! The language: numbers (`1`, `2.5`, `1e-3`), the variable `t` (s), named constants (given by the
//! caller), `pi` and `e`; `+ - * /`, powers `^` or `**` (right-associative, binding tighter than a
//! leading minus: `-t^2 = -(t^2)`); functions `sin cos tan asin acos atan atan2(y, x) sinh cosh
//! tanh exp ln log log10 log2 sqrt cbrt abs hypot(x, y) pow(x, y) min(a, b) max(a, b)`; and
//! piecewise definitions `if(cond, a, b)` and `piecewise(c1, v1, c2, v2, …, otherwise)` with
//! conditions `< <= > >= == !=` joined by `&&`, `||`. Conditions are decided on the value (not the
//! derivatives), so each piece is differentiated exactly.
//!
//! A dedicated parser, rather than a general evaluator crate: the expressions must evaluate over
//! [`num_dual`] scalars (exact first to third derivatives) and errors must point at a column of
//! the string; the evaluator crates we looked at (`evalexpr`, `meval`) evaluate `f64` only.
use std::collections::BTreeMap;
use std::fmt;

use crate::motion::analytic::Scalar;

mod parse;
#[cfg(test)]
mod tests;
mod tokens;

use parse::{Parser, describe};
use tokens::{Tok, tokenize};

/// The deepest nesting of parentheses, signs, powers and calls a formula may have. The parser
/// and the evaluator recurse once per level, so the limit keeps them far from the end of any
/// thread's stack (Python's, rayon's); no hand-written motion comes near it.
pub const MAX_NESTING: usize = 64;

/// The deepest tree a formula may become: a sum of `n` terms is `n` deep (it is evaluated left
/// to right, term by term). Longer formulas: split them into named parts, or use samples.
pub const MAX_DEPTH: usize = 1000;

/// The longest formula, in characters.
pub const MAX_LENGTH: usize = 100_000;

/// A parse error, with the 1-based character column where it was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExprError {
    /// What is wrong.
    pub message: String,
    /// 1-based character column in `source`.
    pub column: usize,
    /// The expression as given.
    pub source: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} at column {} of \"{}\"",
            self.message, self.column, self.source
        )
    }
}

impl std::error::Error for ExprError {}

/// A function of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Func1 {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Log10,
    Log2,
    Sqrt,
    Cbrt,
    Abs,
}

/// A function of two arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Func2 {
    Atan2,
    Hypot,
    Pow,
    Min,
    Max,
}

fn func1(name: &str) -> Option<Func1> {
    Some(match name {
        "sin" => Func1::Sin,
        "cos" => Func1::Cos,
        "tan" => Func1::Tan,
        "asin" | "arcsin" => Func1::Asin,
        "acos" | "arccos" => Func1::Acos,
        "atan" | "arctan" => Func1::Atan,
        "sinh" => Func1::Sinh,
        "cosh" => Func1::Cosh,
        "tanh" => Func1::Tanh,
        "exp" => Func1::Exp,
        "ln" | "log" => Func1::Ln,
        "log10" => Func1::Log10,
        "log2" => Func1::Log2,
        "sqrt" => Func1::Sqrt,
        "cbrt" => Func1::Cbrt,
        "abs" | "Abs" => Func1::Abs,
        _ => return None,
    })
}

fn func2(name: &str) -> Option<Func2> {
    Some(match name {
        "atan2" => Func2::Atan2,
        "hypot" => Func2::Hypot,
        "pow" => Func2::Pow,
        "min" | "Min" => Func2::Min,
        "max" | "Max" => Func2::Max,
        _ => return None,
    })
}

const FUNCTION_NAMES: &str = "sin, cos, tan, asin, acos, atan, atan2, sinh, cosh, tanh, exp, ln, \
     log, log10, log2, sqrt, cbrt, abs, hypot, pow, min, max, if, piecewise";

/// A parsed formula's tree.
#[derive(Clone, Debug)]
pub(crate) enum Node {
    Num(f64),
    T,
    Neg(Box<Node>),
    Add(Box<Node>, Box<Node>),
    Sub(Box<Node>, Box<Node>),
    Mul(Box<Node>, Box<Node>),
    Div(Box<Node>, Box<Node>),
    PowI(Box<Node>, i32),
    PowF(Box<Node>, f64),
    Pow(Box<Node>, Box<Node>),
    F1(Func1, Box<Node>),
    F2(Func2, Box<Node>, Box<Node>),
    /// `(condition, value)` pairs tried in order, then the fallback.
    Piecewise(Vec<(Cond, Node)>, Box<Node>),
}

/// A comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum CmpOp {
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
}

/// A condition of `if` and `piecewise`, decided on values.
#[derive(Clone, Debug)]
pub(crate) enum Cond {
    Cmp(CmpOp, Node, Node),
    And(Box<Cond>, Box<Cond>),
    Or(Box<Cond>, Box<Cond>),
    Not(Box<Cond>),
}

/// A parsed formula of time `t`.
#[derive(Clone, Debug)]
pub struct Expr {
    root: Node,
    source: String,
}

impl Expr {
    /// Parses `source`, a formula of time `t`, with named `constants`.
    ///
    /// # Errors
    /// [`ExprError`] naming the problem (unknown function or variable, syntax) and its column.
    pub fn parse(source: &str, constants: &BTreeMap<String, f64>) -> Result<Self, ExprError> {
        if source.chars().count() > MAX_LENGTH {
            return Err(ExprError {
                message: format!("longer than {MAX_LENGTH} characters"),
                column: MAX_LENGTH + 1,
                source: source.chars().take(80).collect::<String>() + "…",
            });
        }
        let tokens = tokenize(source)?;
        let mut p = Parser {
            tokens,
            pos: 0,
            source,
            constants,
            nesting: 0,
            depth: 0,
            args_depth: 0,
        };
        if p.peek().tok == Tok::End {
            return Err(p.error("empty expression".into(), 1));
        }
        let root = p.sum()?;
        let t = p.next();
        if t.tok != Tok::End {
            return Err(p.error(
                format!("unexpected {} after a complete expression", describe(&t)),
                t.column,
            ));
        }
        Ok(Self {
            root,
            source: source.into(),
        })
    }

    /// The expression as written.
    #[must_use]
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The parsed tree (for [`crate::motion::compiled`]).
    pub(crate) fn root(&self) -> &Node {
        &self.root
    }

    /// The value at time `t` over any scalar (`f64` or a dual number for exact derivatives).
    #[must_use]
    pub fn eval<D: Scalar>(&self, t: D) -> D {
        eval(&self.root, t)
    }
}

fn eval<D: Scalar>(n: &Node, t: D) -> D {
    match n {
        Node::Num(v) => D::from(*v),
        Node::T => t,
        Node::Neg(a) => -eval(a, t),
        Node::Add(a, b) => eval(a, t) + eval(b, t),
        Node::Sub(a, b) => eval(a, t) - eval(b, t),
        Node::Mul(a, b) => eval(a, t) * eval(b, t),
        Node::Div(a, b) => eval(a, t) / eval(b, t),
        Node::PowI(a, k) => eval(a, t).powi(*k),
        Node::PowF(a, k) => eval(a, t).powf(*k),
        Node::Pow(a, b) => eval(a, t).powd(eval(b, t)),
        Node::F1(f, a) => {
            let x = eval(a, t);
            match f {
                Func1::Sin => x.sin(),
                Func1::Cos => x.cos(),
                Func1::Tan => x.tan(),
                Func1::Asin => x.asin(),
                Func1::Acos => x.acos(),
                Func1::Atan => x.atan(),
                Func1::Sinh => x.sinh(),
                Func1::Cosh => x.cosh(),
                Func1::Tanh => x.tanh(),
                Func1::Exp => x.exp(),
                Func1::Ln => x.ln(),
                Func1::Log10 => x.log10(),
                Func1::Log2 => x.log2(),
                Func1::Sqrt => x.sqrt(),
                Func1::Cbrt => x.cbrt(),
                Func1::Abs => {
                    if x.re() < 0.0 {
                        -x
                    } else {
                        x
                    }
                }
            }
        }
        Node::F2(f, a, b) => {
            let (x, y) = (eval(a, t), eval(b, t));
            match f {
                Func2::Atan2 => crate::motion::analytic::atan2(x, y),
                Func2::Hypot => (x * x + y * y).sqrt(),
                Func2::Pow => x.powd(y),
                Func2::Min => {
                    if y.re() < x.re() {
                        y
                    } else {
                        x
                    }
                }
                Func2::Max => {
                    if y.re() > x.re() {
                        y
                    } else {
                        x
                    }
                }
            }
        }
        Node::Piecewise(pieces, fallback) => {
            for (c, v) in pieces {
                if holds(c, t) {
                    return eval(v, t);
                }
            }
            eval(fallback, t)
        }
    }
}

fn holds<D: Scalar>(c: &Cond, t: D) -> bool {
    match c {
        Cond::Cmp(op, a, b) => {
            let (x, y) = (eval(a, t).re(), eval(b, t).re());
            match op {
                CmpOp::Lt => x < y,
                CmpOp::Le => x <= y,
                CmpOp::Gt => x > y,
                CmpOp::Ge => x >= y,
                CmpOp::Eq => x == y,
                CmpOp::Ne => x != y,
            }
        }
        Cond::And(a, b) => holds(a, t) && holds(b, t),
        Cond::Or(a, b) => holds(a, t) || holds(b, t),
        Cond::Not(a) => !holds(a, t),
    }
}
