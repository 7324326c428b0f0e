//! Length expressions: the one parser of the arithmetic written in descriptions.
//!
//! Every length a description may write as text — a serial robot's `xyz` and twist `v`
//! ([`Linear`]), a closed mechanism's lengths and angles, the
//! generator's symbolic polynomials — is read here into an [`Expr`] that keeps its symbols.
//! Callers then evaluate it ([`Expr::eval`]), require it to be linear in the parameters
//! ([`Expr::linear`], a [`Linear`]: `constant + Σ coefficient · parameter`), or walk the
//! tree themselves (the generator turns it into an exact polynomial).
//!
//! The grammar (whitespace separates tokens and is otherwise ignored):
//!
//! ```text
//! sum     = ["+" | "-"] product { ("+" | "-") product }
//! product = unary { ("*" | "/") unary }
//! unary   = ("-" | "+") unary | power
//! power   = primary [ "^" ["-"] digits ]
//! primary = number | name | "pi" | "(" sum ")"
//! number  = digits-and-dots [ ("e" | "E") ["+" | "-"] digits ]      (2, 0.33, .5, 2e-3)
//! name    = (letter | "_") { letter | digit | "_" }
//! ```
//!
//! Exponents are integers of magnitude at most [`MAX_EXPONENT`] (64).
//!
//! `pi` is the constant π; every other name is a symbol. Errors carry the byte offset of the
//! offending token ([`ExprError::at`]).
//!
//! ```
//! use trocar_model::expr::Expr;
//!
//! let e = Expr::parse("-0.5*l_8 + 0.1").unwrap();
//! assert_eq!(e.symbols(), vec!["l_8"]);
//! assert_eq!(e.eval(|_| Some(2.0)).unwrap(), -0.9);
//! let lin = e.linear().unwrap();
//! assert_eq!(lin.terms, vec![(-0.5, "l_8".to_string())]);
//! let err = Expr::parse("l_a * l_b").unwrap().linear().unwrap_err();
//! assert_eq!(err.at, 4); // the `*`
//! assert_eq!(Expr::parse("l_a + $").unwrap_err().at, 6);
//! ```

use std::fmt;

/// A binary operator of [`Expr::Binary`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
}

impl BinOp {
    fn symbol(self) -> char {
        match self {
            BinOp::Add => '+',
            BinOp::Sub => '-',
            BinOp::Mul => '*',
            BinOp::Div => '/',
        }
    }
}

/// A parsed length expression. Offsets (`at`) are byte offsets into the parsed text.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A decimal literal, as `f64` (`str::parse`).
    Number {
        /// The value.
        value: f64,
        /// Offset of the literal.
        at: usize,
    },
    /// The constant `pi` (π).
    Pi {
        /// Offset of `pi`.
        at: usize,
    },
    /// A named parameter (any identifier other than `pi`).
    Symbol {
        /// The name.
        name: String,
        /// Offset of the name.
        at: usize,
    },
    /// Unary minus.
    Neg {
        /// The negated expression.
        operand: Box<Expr>,
        /// Offset of the `-`.
        at: usize,
    },
    /// `lhs op rhs`.
    Binary {
        /// The operator.
        op: BinOp,
        /// Left operand.
        lhs: Box<Expr>,
        /// Right operand.
        rhs: Box<Expr>,
        /// Offset of the operator.
        at: usize,
    },
    /// `base ^ exponent`, an integer exponent (possibly negative).
    Pow {
        /// The base.
        base: Box<Expr>,
        /// The exponent.
        exponent: i32,
        /// Offset of the `^`.
        at: usize,
    },
}

/// A parse or evaluation error: a message and the byte offset it refers to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExprError {
    /// Byte offset into the expression's text.
    pub at: usize,
    /// What is wrong.
    pub message: String,
}

impl ExprError {
    fn new(at: usize, message: impl Into<String>) -> Self {
        ExprError {
            at,
            message: message.into(),
        }
    }
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (at byte {})", self.message, self.at)
    }
}

impl std::error::Error for ExprError {}

/// An expression linear in its parameters: `constant + Σ coefficient · parameter`, e.g. a length
/// of a serial description (`xyz`, a twist's `v`; [`crate::description::Origin`]).
///
/// Written in TOML as a number (`0.33`), a parameter name (`"l_a"`) or a linear combination
/// (`"l_a + l_b"`, `"-0.5*l_8 + 0.1"`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Linear {
    /// The constant part.
    pub constant: f64,
    /// `(coefficient, parameter)` pairs, each name once, in order of first appearance, none zero.
    pub terms: Vec<(f64, String)>,
}

impl Linear {
    /// A constant.
    pub fn constant(value: f64) -> Self {
        Linear {
            constant: value,
            terms: Vec::new(),
        }
    }

    fn scale(mut self, k: f64) -> Self {
        if self.constant != 0.0 {
            // (a zero constant stays zero, also for an infinite factor)
            self.constant *= k;
        }
        for (c, _) in &mut self.terms {
            *c *= k;
        }
        self
    }

    fn add(mut self, other: Linear, sign: f64) -> Self {
        self.constant += sign * other.constant;
        for (c, n) in other.terms {
            match self.terms.iter_mut().find(|(_, m)| *m == n) {
                Some((d, _)) => *d += sign * c,
                None => self.terms.push((sign * c, n)),
            }
        }
        self
    }

    fn as_constant(&self) -> Option<f64> {
        self.terms.is_empty().then_some(self.constant)
    }
}

/// `true` for a name the grammar reads as one symbol: a Rust-style identifier (`l_a`, `L8`,
/// `_x`) — letters, digits and `_`, not starting with a digit.
pub fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Parses a length expression (see the [module](self) grammar).
pub fn parse(text: &str) -> Result<Expr, ExprError> {
    Expr::parse(text)
}

/// `text` for an error message: whole when short, else its first 40 characters, `…` and the
/// length (an expression thousands of characters long is not repeated in full).
pub fn quoted(text: &str) -> String {
    const SHOWN: usize = 40;
    let n = text.chars().count();
    if n <= 2 * SHOWN {
        text.to_string()
    } else {
        let head: String = text.chars().take(SHOWN).collect();
        format!("{head}… ({n} characters)")
    }
}

impl Expr {
    /// Parses a length expression (see the [module](self) grammar).
    pub fn parse(text: &str) -> Result<Expr, ExprError> {
        let mut p = Parser {
            s: text.as_bytes(),
            i: 0,
            parens: 0,
        };
        if p.peek().is_none() {
            return Err(ExprError::new(p.i, "empty expression"));
        }
        let (e, _) = p.sum()?;
        if p.peek().is_some() {
            return Err(p.unexpected());
        }
        Ok(e)
    }

    /// The byte offset this node was written at (its operator for operations).
    pub fn at(&self) -> usize {
        match self {
            Expr::Number { at, .. }
            | Expr::Pi { at }
            | Expr::Symbol { at, .. }
            | Expr::Neg { at, .. }
            | Expr::Binary { at, .. }
            | Expr::Pow { at, .. } => *at,
        }
    }

    /// The numbers written in the expression, in order, with the byte offset of each.
    pub fn numbers(&self) -> Vec<(f64, usize)> {
        fn walk(e: &Expr, out: &mut Vec<(f64, usize)>) {
            match e {
                Expr::Number { value, at } => out.push((*value, *at)),
                Expr::Pi { .. } | Expr::Symbol { .. } => {}
                Expr::Neg { operand, .. } => walk(operand, out),
                Expr::Binary { lhs, rhs, .. } => {
                    walk(lhs, out);
                    walk(rhs, out);
                }
                Expr::Pow { base, .. } => walk(base, out),
            }
        }
        let mut out = Vec::new();
        walk(self, &mut out);
        out
    }

    /// The symbols (parameter names) used, each once, in order of first appearance.
    pub fn symbols(&self) -> Vec<&str> {
        fn walk<'a>(e: &'a Expr, out: &mut Vec<&'a str>) {
            match e {
                Expr::Number { .. } | Expr::Pi { .. } => {}
                Expr::Symbol { name, .. } => {
                    if !out.contains(&name.as_str()) {
                        out.push(name);
                    }
                }
                Expr::Neg { operand, .. } => walk(operand, out),
                Expr::Binary { lhs, rhs, .. } => {
                    walk(lhs, out);
                    walk(rhs, out);
                }
                Expr::Pow { base, .. } => walk(base, out),
            }
        }
        let mut out = Vec::new();
        walk(self, &mut out);
        out
    }

    /// Checks that every symbol is `known`; else the error `unknown parameter` at the first
    /// unknown one (as [`Expr::eval`] words it).
    pub fn check_symbols(&self, known: impl Fn(&str) -> bool) -> Result<(), ExprError> {
        fn walk(e: &Expr, known: &dyn Fn(&str) -> bool) -> Result<(), ExprError> {
            match e {
                Expr::Number { .. } | Expr::Pi { .. } => Ok(()),
                Expr::Symbol { name, at } => {
                    if known(name) {
                        Ok(())
                    } else {
                        Err(ExprError::new(*at, format!("unknown parameter `{name}`")))
                    }
                }
                Expr::Neg { operand, .. } => walk(operand, known),
                Expr::Binary { lhs, rhs, .. } => {
                    walk(lhs, known)?;
                    walk(rhs, known)
                }
                Expr::Pow { base, .. } => walk(base, known),
            }
        }
        walk(self, &known)
    }

    /// `true` when no symbol appears.
    pub fn is_constant(&self) -> bool {
        self.symbols().is_empty()
    }

    /// The value, with `lookup` giving each parameter's value. Errors: an unknown parameter (at
    /// its offset) and division by zero (at the `/`).
    pub fn eval(&self, lookup: impl Fn(&str) -> Option<f64>) -> Result<f64, ExprError> {
        self.eval_with(&lookup)
    }

    fn eval_with(&self, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, ExprError> {
        Ok(match self {
            Expr::Number { value, .. } => *value,
            Expr::Pi { .. } => std::f64::consts::PI,
            Expr::Symbol { name, at } => lookup(name)
                .ok_or_else(|| ExprError::new(*at, format!("unknown parameter `{name}`")))?,
            Expr::Neg { operand, .. } => -operand.eval_with(lookup)?,
            Expr::Binary { op, lhs, rhs, at } => {
                let a = lhs.eval_with(lookup)?;
                let b = rhs.eval_with(lookup)?;
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => {
                        if b == 0.0 {
                            return Err(ExprError::new(*at, "division by zero"));
                        }
                        a / b
                    }
                }
            }
            Expr::Pow { base, exponent, .. } => base.eval_with(lookup)?.powi(*exponent),
        })
    }

    /// The expression as `constant + Σ coefficient · parameter`, or an error (at the offending
    /// operator or symbol) when it is not linear in its parameters. Products and quotients
    /// need a constant factor or divisor; powers need a constant base (or exponent 1).
    pub fn linear(&self) -> Result<Linear, ExprError> {
        let mut out = self.linear_part()?;
        if out.constant == 0.0 {
            out.constant = 0.0; // not −0
        }
        Ok(out)
    }

    fn linear_part(&self) -> Result<Linear, ExprError> {
        Ok(match self {
            Expr::Number { value, .. } => Linear::constant(*value),
            Expr::Pi { .. } => Linear::constant(std::f64::consts::PI),
            Expr::Symbol { name, .. } => Linear {
                constant: 0.0,
                terms: vec![(1.0, name.clone())],
            },
            Expr::Neg { operand, .. } => operand.linear_part()?.scale(-1.0),
            Expr::Binary { op, lhs, rhs, at } => {
                let a = lhs.linear_part()?;
                let b = rhs.linear_part()?;
                let mut out = match op {
                    BinOp::Add => a.add(b, 1.0),
                    BinOp::Sub => a.add(b, -1.0),
                    BinOp::Mul => match (a.as_constant(), b.as_constant()) {
                        (Some(k), _) => b.scale(k),
                        (None, Some(k)) => a.scale(k),
                        (None, None) => {
                            return Err(ExprError::new(*at, "not linear in the parameters"))
                        }
                    },
                    BinOp::Div => match b.as_constant() {
                        Some(0.0) => return Err(ExprError::new(*at, "division by zero")),
                        Some(k) => {
                            let mut a = a;
                            a.constant /= k;
                            for (c, _) in &mut a.terms {
                                *c /= k;
                            }
                            a
                        }
                        None => {
                            return Err(ExprError::new(
                                *at,
                                "not linear in the parameters (division by a parameter)",
                            ))
                        }
                    },
                };
                out.terms.retain(|(c, _)| *c != 0.0);
                out
            }
            Expr::Pow { base, exponent, at } => {
                let b = base.linear_part()?;
                match (b.as_constant(), exponent) {
                    (Some(k), _) => Linear::constant(k.powi(*exponent)),
                    (None, 1) => b,
                    (None, _) => return Err(ExprError::new(*at, "not linear in the parameters")),
                }
            }
        })
    }
}

impl fmt::Display for Expr {
    /// Fully parenthesised where precedence needs it; reads back to an equal tree (offsets aside).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn prec(e: &Expr) -> u8 {
            match e {
                Expr::Binary {
                    op: BinOp::Add | BinOp::Sub,
                    ..
                } => 1,
                Expr::Binary { .. } => 2,
                Expr::Neg { .. } => 3,
                Expr::Pow { .. } => 4,
                _ => 5,
            }
        }
        fn child(f: &mut fmt::Formatter<'_>, e: &Expr, min: u8) -> fmt::Result {
            if prec(e) < min {
                write!(f, "({e})")
            } else {
                write!(f, "{e}")
            }
        }
        match self {
            Expr::Number { value, .. } => write!(f, "{value:?}"),
            Expr::Pi { .. } => write!(f, "pi"),
            Expr::Symbol { name, .. } => write!(f, "{name}"),
            Expr::Neg { operand, .. } => {
                write!(f, "-")?;
                child(f, operand, 4)
            }
            Expr::Binary { op, lhs, rhs, .. } => {
                let p = prec(self);
                child(f, lhs, p)?;
                write!(f, " {} ", op.symbol())?;
                child(f, rhs, p + 1)
            }
            Expr::Pow { base, exponent, .. } => {
                child(f, base, 5)?;
                write!(f, "^{exponent}")
            }
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    /// Open parentheses around the current position (the parser's own recursion).
    parens: usize,
}

/// The deepest expression tree the parser builds: parentheses, signs and chains of operators
/// each add a level. Every walk over the tree (evaluation, printing, dropping it) recurses once
/// per level, so an unbounded depth would exhaust the stack; a length in a description needs a
/// handful.
pub const MAX_DEPTH: usize = 200;

/// The largest exponent magnitude of `base ^ exponent`. Descriptions need small powers; a large
/// one (`l3^30000`, `pi^-2000`) is refused where it is written, instead of overflowing, or
/// expanding into an enormous polynomial in the generator.
pub const MAX_EXPONENT: i32 = 64;

/// A parsed subexpression and the depth of its tree.
type Parsed = (Expr, usize);

impl Parser<'_> {
    fn peek(&mut self) -> Option<u8> {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
        self.s.get(self.i).copied()
    }

    fn unexpected(&mut self) -> ExprError {
        match self.peek() {
            None => ExprError::new(self.i, "the expression ends too early"),
            Some(_) => {
                let text = std::str::from_utf8(&self.s[self.i..]).unwrap_or("");
                let c = text.chars().next().unwrap_or('?');
                ExprError::new(
                    self.i,
                    format!("unexpected `{c}`: expected a number, a parameter name, `pi` or `(`"),
                )
            }
        }
    }

    /// `depth`, or the error of a tree deeper than [`MAX_DEPTH`] at byte `at`.
    fn within_depth(&self, depth: usize, at: usize) -> Result<usize, ExprError> {
        if depth > MAX_DEPTH {
            Err(ExprError::new(
                at,
                format!("the expression is nested more than {MAX_DEPTH} levels deep"),
            ))
        } else {
            Ok(depth)
        }
    }

    fn sum(&mut self) -> Result<Parsed, ExprError> {
        let (mut acc, mut depth) = self.product()?;
        loop {
            let op = match self.peek() {
                Some(b'+') => BinOp::Add,
                Some(b'-') => BinOp::Sub,
                _ => return Ok((acc, depth)),
            };
            let at = self.i;
            self.i += 1;
            let (rhs, d) = self.product()?;
            depth = self.within_depth(depth.max(d) + 1, at)?;
            acc = Expr::Binary {
                op,
                lhs: Box::new(acc),
                rhs: Box::new(rhs),
                at,
            };
        }
    }

    fn product(&mut self) -> Result<Parsed, ExprError> {
        let (mut acc, mut depth) = self.unary()?;
        loop {
            let op = match self.peek() {
                Some(b'*') => BinOp::Mul,
                Some(b'/') => BinOp::Div,
                _ => return Ok((acc, depth)),
            };
            let at = self.i;
            self.i += 1;
            let (rhs, d) = self.unary()?;
            depth = self.within_depth(depth.max(d) + 1, at)?;
            acc = Expr::Binary {
                op,
                lhs: Box::new(acc),
                rhs: Box::new(rhs),
                at,
            };
        }
    }

    fn unary(&mut self) -> Result<Parsed, ExprError> {
        // Leading signs are counted before recursing, so that a long run of them stops at the
        // depth limit instead of on the stack.
        let start = self.i;
        let mut signs = Vec::new();
        loop {
            match self.peek() {
                Some(b'-') => {
                    signs.push(Some(self.i));
                    self.i += 1;
                }
                Some(b'+') => {
                    signs.push(None);
                    self.i += 1;
                }
                _ => break,
            }
            self.within_depth(signs.len(), start)?;
        }
        let (mut e, mut depth) = self.power()?;
        for at in signs.into_iter().rev().flatten() {
            depth = self.within_depth(depth + 1, at)?;
            e = Expr::Neg {
                operand: Box::new(e),
                at,
            };
        }
        Ok((e, depth))
    }

    fn power(&mut self) -> Result<Parsed, ExprError> {
        let (base, depth) = self.primary()?;
        if self.peek() != Some(b'^') {
            return Ok((base, depth));
        }
        let at = self.i;
        self.i += 1;
        let neg = self.peek() == Some(b'-');
        if neg {
            self.i += 1;
        }
        self.peek();
        let start = self.i;
        while self.i < self.s.len() && self.s[self.i].is_ascii_digit() {
            self.i += 1;
        }
        let digits = std::str::from_utf8(&self.s[start..self.i]).unwrap_or_default();
        if digits.is_empty() {
            return Err(ExprError::new(start, "expected an integer exponent"));
        }
        // Digits only: a parse error is an overflow.
        let n = digits
            .parse::<u64>()
            .ok()
            .and_then(|n| i32::try_from(n).ok())
            .filter(|n| *n <= MAX_EXPONENT)
            .ok_or_else(|| {
                ExprError::new(
                    start,
                    format!(
                        "the exponent {digits} is too large (at most {MAX_EXPONENT} in magnitude)"
                    ),
                )
            })?;
        Ok((
            Expr::Pow {
                base: Box::new(base),
                exponent: if neg { -n } else { n },
                at,
            },
            self.within_depth(depth + 1, at)?,
        ))
    }

    fn primary(&mut self) -> Result<Parsed, ExprError> {
        match self.peek() {
            Some(b'(') => {
                let open = self.i;
                self.i += 1;
                self.parens += 1;
                if self.parens > MAX_DEPTH {
                    return Err(ExprError::new(
                        open,
                        format!("the expression is nested more than {MAX_DEPTH} levels deep"),
                    ));
                }
                let (e, depth) = self.sum()?;
                self.parens -= 1;
                if self.peek() != Some(b')') {
                    return Err(ExprError::new(
                        self.i,
                        format!("expected `)` to close the `(` at byte {open}"),
                    ));
                }
                self.i += 1;
                Ok((e, depth))
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_digit() || self.s[self.i] == b'.')
                {
                    self.i += 1;
                }
                // An exponent: `e`, an optional sign, then digits (else `e` starts a name).
                if let Some(b'e' | b'E') = self.s.get(self.i) {
                    let mut j = self.i + 1;
                    if let Some(b'+' | b'-') = self.s.get(j) {
                        j += 1;
                    }
                    if self.s.get(j).is_some_and(u8::is_ascii_digit) {
                        while self.s.get(j).is_some_and(u8::is_ascii_digit) {
                            j += 1;
                        }
                        self.i = j;
                    }
                }
                let t = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                let value: f64 = t
                    .parse()
                    .map_err(|_| ExprError::new(start, format!("cannot read the number `{t}`")))?;
                Ok((Expr::Number { value, at: start }, 1))
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_')
                {
                    self.i += 1;
                }
                let name = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                let e = if name == "pi" {
                    Expr::Pi { at: start }
                } else {
                    Expr::Symbol {
                        name: name.to_string(),
                        at: start,
                    }
                };
                Ok((e, 1))
            }
            _ => Err(self.unexpected()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(t: &str) -> f64 {
        Expr::parse(t)
            .unwrap()
            .eval(|n| match n {
                "a" => Some(2.0),
                "l_e" => Some(0.5),
                _ => None,
            })
            .unwrap()
    }

    #[test]
    fn grammar() {
        assert_eq!(value("1 + 2 * 3"), 7.0);
        assert_eq!(value("(1 + 2) * 3"), 9.0);
        assert_eq!(value("-a^2"), -4.0);
        assert_eq!(value("a^-1"), 0.5);
        assert_eq!(Expr::parse("2^3^1").unwrap_err().at, 3);
        assert_eq!(value("- -a"), 2.0);
        assert_eq!(value("+a"), 2.0);
        assert_eq!(value("a*-3"), -6.0);
        assert_eq!(value("8/a/2"), 2.0);
        assert_eq!(value("1 - 2 - 3"), -4.0);
        assert_eq!(value("2e-3"), 2e-3);
        assert_eq!(value("2E+3"), 2e3);
        assert_eq!(value(".5"), 0.5);
        assert_eq!(value("l_e-0.1"), 0.4);
        assert_eq!(value("2/3*pi"), 2.0 / 3.0 * std::f64::consts::PI);
        assert_eq!(Expr::parse("2e").unwrap_err().at, 1);
        assert_eq!(Expr::parse("2*pi_x + pi").unwrap().symbols(), vec!["pi_x"]);
    }

    fn err_at(at: usize, name: &str) -> ExprError {
        ExprError::new(at, format!("unknown parameter `{name}`"))
    }

    #[test]
    fn errors_carry_offsets() {
        let at = |t: &str| Expr::parse(t).unwrap_err().at;
        assert_eq!(at(""), 0);
        assert_eq!(at("   "), 3);
        assert_eq!(at("1 +"), 3);
        assert_eq!(at("l_a + $"), 6);
        assert_eq!(at("(1 + 2"), 6);
        assert_eq!(at("1.2.3"), 0);
        assert_eq!(at("a^b"), 2);
        assert_eq!(at("a b"), 2);
        let e = Expr::parse("1 / (a - a)").unwrap();
        assert_eq!(e.eval(|_| Some(1.0)).unwrap_err().at, 2);
        let e = Expr::parse("1 + l9").unwrap();
        let err = e.eval(|_| None).unwrap_err();
        assert_eq!(
            (err.at, err.message.as_str()),
            (4, "unknown parameter `l9`")
        );
        assert!(err.to_string().contains("at byte 4"));
        let e = Expr::parse("a * (2 - l9) + l8").unwrap();
        assert_eq!(e.check_symbols(|n| n.len() == 1), Err(err_at(9, "l9")));
        assert_eq!(e.check_symbols(|_| true), Ok(()));
    }

    /// Nesting deeper than [`MAX_DEPTH`] is an error at the byte where it goes too deep (12,000
    /// parentheses used to overflow the stack and abort), whether by parentheses, signs or a
    /// long chain of operators; nesting within the limit still parses and evaluates.
    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let nested = |k: usize| format!("{}l_8{}", "(".repeat(k), ")".repeat(k));
        let e = Expr::parse(&nested(12_000)).unwrap_err();
        assert!(e.message.contains("nested more than 200 levels"), "{e}");
        assert_eq!(e.at, MAX_DEPTH);
        let ok = Expr::parse(&nested(150)).unwrap();
        assert_eq!(ok.eval(|_| Some(0.21)).unwrap(), 0.21);
        let signs = format!("{}1", "-".repeat(100_000));
        assert!(Expr::parse(&signs).unwrap_err().message.contains("nested"));
        assert_eq!(
            Expr::parse(&format!("{}1", "-".repeat(10)))
                .unwrap()
                .eval(|_| None)
                .unwrap(),
            1.0
        );
        let chain = vec!["1"; 100_000].join("+");
        assert!(Expr::parse(&chain).unwrap_err().message.contains("nested"));
        let short = vec!["1"; 100].join("+");
        assert_eq!(Expr::parse(&short).unwrap().eval(|_| None).unwrap(), 100.0);
        let powers = format!("{}2{}", "(".repeat(300), ")^2".repeat(300));
        assert!(Expr::parse(&powers).is_err());
    }

    #[test]
    fn linearity() {
        let l = |t: &str| Expr::parse(t).unwrap().linear();
        let s = l("-0.5*l_8 + 0.1 - 2e-1").unwrap();
        assert_eq!(s.terms, vec![(-0.5, "l_8".to_string())]);
        assert_eq!(s.constant, 0.1 - 0.2);
        assert_eq!(l("a - a").unwrap(), Linear::default());
        assert_eq!(l("(a + 2*b)/2 - b").unwrap().terms, vec![(0.5, "a".into())]);
        assert_eq!(l("2^2*a").unwrap().terms, vec![(4.0, "a".into())]);
        assert_eq!(l("a*b").unwrap_err().at, 1);
        assert_eq!(l("1 + 1/a").unwrap_err().at, 5);
        assert_eq!(l("a^2").unwrap_err().at, 1);
        assert_eq!(l("a/0").unwrap_err().at, 1);
    }

    #[test]
    fn display_reads_back() {
        for t in [
            "-(a + b)*c",
            "a - (b - c)",
            "a/(b*c)",
            "(-a)^2",
            "-a^2",
            "2e-3*pi + l_e",
        ] {
            let e = Expr::parse(t).unwrap();
            let again = Expr::parse(&e.to_string()).unwrap();
            let v = |e: &Expr| e.eval(|_| Some(0.7)).unwrap();
            assert_eq!(v(&e), v(&again), "{t} → {e}");
        }
    }
}
