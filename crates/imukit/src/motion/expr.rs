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

#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident,
    Op(&'static str),
    LParen,
    RParen,
    Comma,
    End,
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    text: String,
    column: usize,
}

const OPERATORS: [&str; 15] = [
    "**", "<=", ">=", "==", "!=", "&&", "||", "+", "-", "*", "/", "^", "<", ">", "!",
];

fn tokenize(src: &str) -> Result<Vec<Token>, ExprError> {
    let chars: Vec<char> = src.chars().collect();
    let err = |message: String, i: usize| ExprError {
        message,
        column: i + 1,
        source: src.into(),
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit)) {
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text: String = chars[start..i].iter().collect();
            let value = text
                .parse::<f64>()
                .map_err(|_| err(format!("bad number \"{text}\""), start))?;
            out.push(Token {
                tok: Tok::Num(value),
                text,
                column: start + 1,
            });
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let text: String = chars[start..i].iter().collect();
            out.push(Token {
                tok: Tok::Ident,
                text,
                column: start + 1,
            });
            continue;
        }
        let tok = match c {
            '(' => Some(Tok::LParen),
            ')' => Some(Tok::RParen),
            ',' => Some(Tok::Comma),
            _ => None,
        };
        if let Some(tok) = tok {
            out.push(Token {
                tok,
                text: c.to_string(),
                column: start + 1,
            });
            i += 1;
            continue;
        }
        let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
        match OPERATORS.iter().find(|op| rest.starts_with(**op)) {
            Some(op) => {
                out.push(Token {
                    tok: Tok::Op(op),
                    text: (*op).into(),
                    column: start + 1,
                });
                i += op.chars().count();
            }
            None => return Err(err(format!("unexpected character '{c}'"), start)),
        }
    }
    out.push(Token {
        tok: Tok::End,
        text: String::new(),
        column: chars.len() + 1,
    });
    Ok(out)
}

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

struct Parser<'a> {
    tokens: Vec<Token>,
    pos: usize,
    source: &'a str,
    constants: &'a BTreeMap<String, f64>,
    /// Nesting levels entered now (parentheses, signs, powers, calls, conditions).
    nesting: usize,
    /// Depth of the node (or condition) most recently returned.
    depth: usize,
    /// Depth of the deepest argument of the call most recently parsed.
    args_depth: usize,
}

impl Parser<'_> {
    fn peek(&self) -> &Token {
        &self.tokens[self.pos]
    }
    fn next(&mut self) -> Token {
        let t = self.tokens[self.pos].clone();
        if self.pos + 1 < self.tokens.len() {
            self.pos += 1;
        }
        t
    }
    fn error(&self, message: String, column: usize) -> ExprError {
        ExprError {
            message,
            column,
            source: self.source.into(),
        }
    }
    /// Enters one nesting level at the token in `column`.
    fn enter(&mut self, column: usize) -> Result<(), ExprError> {
        self.nesting += 1;
        if self.nesting > MAX_NESTING {
            return Err(self.error(
                format!(
                    "nested deeper than {MAX_NESTING} levels (parentheses, signs, powers, calls)"
                ),
                column,
            ));
        }
        Ok(())
    }
    fn leave(&mut self) {
        self.nesting -= 1;
    }
    /// Records the depth of a node built on children of depth `child` and checks the limit.
    fn built(&mut self, child: usize, column: usize) -> Result<(), ExprError> {
        self.depth = child + 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(
                format!(
                    "more than {MAX_DEPTH} operations deep (a sum or product of that many terms): \
                     split the formula into named parts"
                ),
                column,
            ));
        }
        Ok(())
    }
    fn is_op(&self, op: &str) -> bool {
        matches!(self.peek().tok, Tok::Op(o) if o == op)
    }
    fn expect(&mut self, tok: Tok, what: &str) -> Result<(), ExprError> {
        let t = self.next();
        if t.tok == tok {
            Ok(())
        } else {
            Err(self.error(format!("expected {what}, found {}", describe(&t)), t.column))
        }
    }

    fn cond(&mut self) -> Result<Cond, ExprError> {
        let mut lhs = self.cond_and()?;
        let mut depth = self.depth;
        while self.is_op("||") {
            let column = self.peek().column;
            self.next();
            let rhs = self.cond_and()?;
            self.built(depth.max(self.depth), column)?;
            depth = self.depth;
            lhs = Cond::Or(Box::new(lhs), Box::new(rhs));
        }
        self.depth = depth;
        Ok(lhs)
    }
    fn cond_and(&mut self) -> Result<Cond, ExprError> {
        let mut lhs = self.cond_atom()?;
        let mut depth = self.depth;
        while self.is_op("&&") {
            let column = self.peek().column;
            self.next();
            let rhs = self.cond_atom()?;
            self.built(depth.max(self.depth), column)?;
            depth = self.depth;
            lhs = Cond::And(Box::new(lhs), Box::new(rhs));
        }
        self.depth = depth;
        Ok(lhs)
    }
    fn cond_atom(&mut self) -> Result<Cond, ExprError> {
        if self.is_op("!") {
            let column = self.peek().column;
            self.next();
            self.enter(column)?;
            let inner = self.cond_atom()?;
            self.leave();
            self.built(self.depth, self.peek().column)?;
            return Ok(Cond::Not(Box::new(inner)));
        }
        if self.peek().tok == Tok::LParen {
            // A parenthesised condition, or a parenthesised value that a comparison follows.
            let start = self.pos;
            let column = self.peek().column;
            self.next();
            self.enter(column)?;
            let inner = self.cond();
            self.leave();
            if let Ok(c) = inner
                && self.peek().tok == Tok::RParen
            {
                self.next();
                return Ok(c);
            }
            self.pos = start;
        }
        let lhs = self.sum()?;
        let lhs_depth = self.depth;
        let t = self.next();
        let op = match t.tok {
            Tok::Op("<") => CmpOp::Lt,
            Tok::Op("<=") => CmpOp::Le,
            Tok::Op(">") => CmpOp::Gt,
            Tok::Op(">=") => CmpOp::Ge,
            Tok::Op("==") => CmpOp::Eq,
            Tok::Op("!=") => CmpOp::Ne,
            _ => {
                return Err(self.error(
                    format!(
                        "expected a comparison (<, <=, >, >=, ==, !=), found {}",
                        describe(&t)
                    ),
                    t.column,
                ));
            }
        };
        let rhs = self.sum()?;
        self.built(lhs_depth.max(self.depth), t.column)?;
        Ok(Cond::Cmp(op, lhs, rhs))
    }

    fn sum(&mut self) -> Result<Node, ExprError> {
        let mut lhs = self.product()?;
        let mut depth = self.depth;
        loop {
            let column = self.peek().column;
            if self.is_op("+") {
                self.next();
                let rhs = self.product()?;
                self.built(depth.max(self.depth), column)?;
                lhs = Node::Add(Box::new(lhs), Box::new(rhs));
            } else if self.is_op("-") {
                self.next();
                let rhs = self.product()?;
                self.built(depth.max(self.depth), column)?;
                lhs = Node::Sub(Box::new(lhs), Box::new(rhs));
            } else {
                self.depth = depth;
                return Ok(lhs);
            }
            depth = self.depth;
        }
    }
    fn product(&mut self) -> Result<Node, ExprError> {
        let mut lhs = self.unary()?;
        let mut depth = self.depth;
        loop {
            let column = self.peek().column;
            if self.is_op("*") {
                self.next();
                let rhs = self.unary()?;
                self.built(depth.max(self.depth), column)?;
                lhs = Node::Mul(Box::new(lhs), Box::new(rhs));
            } else if self.is_op("/") {
                self.next();
                let rhs = self.unary()?;
                self.built(depth.max(self.depth), column)?;
                lhs = Node::Div(Box::new(lhs), Box::new(rhs));
            } else {
                self.depth = depth;
                return Ok(lhs);
            }
            depth = self.depth;
        }
    }
    fn unary(&mut self) -> Result<Node, ExprError> {
        let column = self.peek().column;
        if self.is_op("-") {
            self.next();
            self.enter(column)?;
            let inner = self.unary()?;
            self.leave();
            self.built(self.depth, column)?;
            return Ok(Node::Neg(Box::new(inner)));
        }
        if self.is_op("+") {
            self.next();
            self.enter(column)?;
            let inner = self.unary();
            self.leave();
            return inner;
        }
        self.power()
    }
    fn power(&mut self) -> Result<Node, ExprError> {
        let base = self.atom()?;
        let base_depth = self.depth;
        if self.is_op("^") || self.is_op("**") {
            let column = self.peek().column;
            self.next();
            self.enter(column)?;
            let exponent = self.unary()?;
            self.leave();
            self.built(base_depth.max(self.depth), column)?;
            return Ok(match exponent {
                Node::Num(k) if k.fract() == 0.0 && k.abs() < 1e6 => {
                    Node::PowI(Box::new(base), k as i32)
                }
                Node::Num(k) => Node::PowF(Box::new(base), k),
                Node::Neg(ref inner) if matches!(**inner, Node::Num(k) if k.fract() == 0.0 && k.abs() < 1e6) =>
                {
                    let Node::Num(k) = **inner else {
                        unreachable!()
                    };
                    Node::PowI(Box::new(base), -(k as i32))
                }
                other => Node::Pow(Box::new(base), Box::new(other)),
            });
        }
        self.depth = base_depth;
        Ok(base)
    }
    fn atom(&mut self) -> Result<Node, ExprError> {
        let t = self.next();
        self.depth = 1;
        match t.tok {
            Tok::Num(v) => Ok(Node::Num(v)),
            Tok::LParen => {
                self.enter(t.column)?;
                let inner = self.sum()?;
                self.leave();
                self.expect(Tok::RParen, "')'")?;
                Ok(inner)
            }
            Tok::Ident if self.peek().tok == Tok::LParen => self.call(&t),
            Tok::Ident => self.name(&t),
            _ => Err(self.error(
                format!("expected a number, name or '(', found {}", describe(&t)),
                t.column,
            )),
        }
    }
    fn name(&self, t: &Token) -> Result<Node, ExprError> {
        if t.text == "t" {
            return Ok(Node::T);
        }
        if let Some(v) = self.constants.get(&t.text) {
            return Ok(Node::Num(*v));
        }
        match t.text.as_str() {
            "pi" | "PI" | "Pi" => Ok(Node::Num(std::f64::consts::PI)),
            "e" | "E" => Ok(Node::Num(std::f64::consts::E)),
            _ => {
                let known: Vec<&str> = self.constants.keys().map(String::as_str).collect();
                let hint = if known.is_empty() {
                    "the variable is t; constants: pi, e (add more under `constants`)".to_string()
                } else {
                    format!("the variable is t; constants: pi, e, {}", known.join(", "))
                };
                Err(self.error(format!("unknown variable '{}' ({hint})", t.text), t.column))
            }
        }
    }
    fn args(&mut self) -> Result<Vec<(Token, ArgKind)>, ExprError> {
        self.expect(Tok::LParen, "'('")?;
        let mut out = Vec::new();
        self.args_depth = 0;
        if self.peek().tok == Tok::RParen {
            self.next();
            return Ok(out);
        }
        let mut deepest = 0;
        loop {
            let start = self.pos;
            let column = self.peek().column;
            // An argument is a condition if a comparison follows its first sum.
            let kind = match self.sum() {
                Ok(node) if !self.at_comparison() => ArgKind::Value(node),
                _ => {
                    self.pos = start;
                    ArgKind::Cond(self.cond()?)
                }
            };
            deepest = deepest.max(self.depth);
            out.push((
                Token {
                    tok: Tok::End,
                    text: String::new(),
                    column,
                },
                kind,
            ));
            let t = self.next();
            match t.tok {
                Tok::Comma => continue,
                Tok::RParen => {
                    self.args_depth = deepest;
                    return Ok(out);
                }
                _ => {
                    return Err(self.error(
                        format!("expected ',' or ')', found {}", describe(&t)),
                        t.column,
                    ));
                }
            }
        }
    }
    fn at_comparison(&self) -> bool {
        ["<", "<=", ">", ">=", "==", "!=", "&&", "||"]
            .iter()
            .any(|op| self.is_op(op))
    }
    fn call(&mut self, f: &Token) -> Result<Node, ExprError> {
        let name = f.text.as_str();
        self.enter(f.column)?;
        let args = self.args();
        self.leave();
        let args = args?;
        let deepest = self.args_depth;
        self.built(deepest, f.column)?;
        let value = |p: &Self, (tok, kind): (Token, ArgKind)| match kind {
            ArgKind::Value(n) => Ok(n),
            ArgKind::Cond(_) => Err(p.error("a condition is not a value here".into(), tok.column)),
        };
        let cond = |p: &Self, (tok, kind): (Token, ArgKind)| match kind {
            ArgKind::Cond(c) => Ok(c),
            ArgKind::Value(_) => {
                Err(p.error("expected a condition such as t < 1".into(), tok.column))
            }
        };
        let arity = |p: &Self, n: usize| {
            if args.len() == n {
                Ok(())
            } else {
                Err(p.error(
                    format!("{name}() takes {n} argument(s), got {}", args.len()),
                    f.column,
                ))
            }
        };
        if let Some(func) = func1(name) {
            arity(self, 1)?;
            let a = args
                .into_iter()
                .next()
                .map(|a| value(self, a))
                .transpose()?;
            return Ok(Node::F1(func, Box::new(a.unwrap_or(Node::Num(0.0)))));
        }
        if let Some(func) = func2(name) {
            arity(self, 2)?;
            let mut it = args.into_iter();
            let (a, b) = (it.next(), it.next());
            let a = a
                .map(|a| value(self, a))
                .transpose()?
                .unwrap_or(Node::Num(0.0));
            let b = b
                .map(|b| value(self, b))
                .transpose()?
                .unwrap_or(Node::Num(0.0));
            return Ok(Node::F2(func, Box::new(a), Box::new(b)));
        }
        match name {
            "if" | "piecewise" | "Piecewise" => {
                if args.len() < 3 || args.len() % 2 == 0 {
                    return Err(self.error(
                        format!(
                            "{name}() takes a condition and a value, repeated, then a fallback value \
                             (an odd number ≥ 3 of arguments), got {}",
                            args.len()
                        ),
                        f.column,
                    ));
                }
                let mut it = args.into_iter();
                let mut pieces = Vec::new();
                while it.len() > 1 {
                    let c = cond(self, it.next().unwrap_or_else(|| unreachable!()))?;
                    let v = value(self, it.next().unwrap_or_else(|| unreachable!()))?;
                    pieces.push((c, v));
                }
                let fallback = value(self, it.next().unwrap_or_else(|| unreachable!()))?;
                Ok(Node::Piecewise(pieces, Box::new(fallback)))
            }
            _ => Err(self.error(
                format!("unknown function '{name}' (known: {FUNCTION_NAMES})"),
                f.column,
            )),
        }
    }
}

enum ArgKind {
    Value(Node),
    Cond(Cond),
}

fn describe(t: &Token) -> String {
    match t.tok {
        Tok::End => "the end of the expression".into(),
        _ => format!("'{}'", t.text),
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::Dual3;

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
}
