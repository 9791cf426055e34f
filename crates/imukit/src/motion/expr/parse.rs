//! Tokens into a tree: precedence, functions and their arguments, `piecewise` and `if`, each
//! refusal naming its column.
use std::collections::BTreeMap;

use super::tokens::{Tok, Token};
use super::{CmpOp, Cond, ExprError, FUNCTION_NAMES, MAX_DEPTH, MAX_NESTING, Node, func1, func2};

pub(super) struct Parser<'a> {
    pub(super) tokens: Vec<Token>,
    pub(super) pos: usize,
    pub(super) source: &'a str,
    pub(super) constants: &'a BTreeMap<String, f64>,
    /// Nesting levels entered now (parentheses, signs, powers, calls, conditions).
    pub(super) nesting: usize,
    /// Depth of the node (or condition) most recently returned.
    pub(super) depth: usize,
    /// Depth of the deepest argument of the call most recently parsed.
    pub(super) args_depth: usize,
}

impl Parser<'_> {
    pub(super) fn peek(&self) -> &Token {
        &self.tokens[self.pos]
    }
    pub(super) fn next(&mut self) -> Token {
        let t = self.tokens[self.pos].clone();
        if self.pos + 1 < self.tokens.len() {
            self.pos += 1;
        }
        t
    }
    pub(super) fn error(&self, message: String, column: usize) -> ExprError {
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

    pub(super) fn sum(&mut self) -> Result<Node, ExprError> {
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

pub(super) fn describe(t: &Token) -> String {
    match t.tok {
        Tok::End => "the end of the expression".into(),
        _ => format!("'{}'", t.text),
    }
}
