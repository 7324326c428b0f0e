//! Length expressions of named parameters: `+ − * /`, parentheses, numbers and `pi`.
//!
//! The one tokenizer and parser of mechanism lengths: descriptions are parsed once into a
//! [`LengthExpr`] that keeps the parameters by index, which the numeric simulation evaluates
//! ([`LengthExpr::eval`]) and the generator folds into polynomials ([`LengthExpr::fold`]).

use std::fmt;

/// A parsed length expression (parameters by their index in the mechanism's parameter list).
#[derive(Clone, Debug, PartialEq)]
pub enum LengthExpr {
    /// A number as written (TOML literal or decimal in a string).
    Number(f64),
    /// `pi`.
    Pi,
    /// The parameter with this index.
    Param(usize),
    /// `−a`.
    Neg(Box<LengthExpr>),
    /// `a + b`.
    Add(Box<LengthExpr>, Box<LengthExpr>),
    /// `a − b`.
    Sub(Box<LengthExpr>, Box<LengthExpr>),
    /// `a · b`.
    Mul(Box<LengthExpr>, Box<LengthExpr>),
    /// `a / b`.
    Div(Box<LengthExpr>, Box<LengthExpr>),
}

/// The operations [`LengthExpr::fold`] maps an expression onto (numbers, polynomials, …).
pub trait LengthAlgebra: Sized {
    /// The error of a failed operation (a division the target cannot represent).
    type Error;
    /// A number as written.
    fn number(x: f64) -> Result<Self, Self::Error>;
    /// Parameter `index`.
    fn param(index: usize) -> Result<Self, Self::Error>;
    /// `−self`.
    fn neg(self) -> Self;
    /// `self + rhs`.
    fn add(self, rhs: Self) -> Self;
    /// `self − rhs`.
    fn sub(self, rhs: Self) -> Self;
    /// `self · rhs`.
    fn mul(self, rhs: Self) -> Self;
    /// `self / rhs`.
    fn div(self, rhs: Self) -> Result<Self, Self::Error>;
}

impl LengthExpr {
    /// Parses `src`; `params` are the names in scope (index = position).
    pub fn parse(src: &str, params: &[&str]) -> Result<LengthExpr, String> {
        let toks = tokenize(src)?;
        let mut p = Parser {
            toks: &toks,
            pos: 0,
            params,
        };
        let v = p.expr()?;
        if p.pos != toks.len() {
            return Err(format!("unexpected `{}` in `{src}`", toks[p.pos]));
        }
        Ok(v)
    }

    /// Maps the expression onto an algebra, left to right as written (`pi` is the number
    /// [`std::f64::consts::PI`]).
    pub fn fold<A: LengthAlgebra>(&self) -> Result<A, A::Error> {
        Ok(match self {
            LengthExpr::Number(x) => A::number(*x)?,
            LengthExpr::Pi => A::number(std::f64::consts::PI)?,
            LengthExpr::Param(i) => A::param(*i)?,
            LengthExpr::Neg(a) => a.fold::<A>()?.neg(),
            LengthExpr::Add(a, b) => a.fold::<A>()?.add(b.fold()?),
            LengthExpr::Sub(a, b) => a.fold::<A>()?.sub(b.fold()?),
            LengthExpr::Mul(a, b) => a.fold::<A>()?.mul(b.fold()?),
            LengthExpr::Div(a, b) => a.fold::<A>()?.div(b.fold()?)?,
        })
    }

    /// The value at parameter values `values` (errors on a division by zero).
    pub fn eval(&self, values: &[f64]) -> Result<f64, String> {
        Ok(match self {
            LengthExpr::Number(x) => *x,
            LengthExpr::Pi => std::f64::consts::PI,
            LengthExpr::Param(i) => *values
                .get(*i)
                .ok_or_else(|| format!("parameter {i} has no value"))?,
            LengthExpr::Neg(a) => -a.eval(values)?,
            LengthExpr::Add(a, b) => a.eval(values)? + b.eval(values)?,
            LengthExpr::Sub(a, b) => a.eval(values)? - b.eval(values)?,
            LengthExpr::Mul(a, b) => a.eval(values)? * b.eval(values)?,
            LengthExpr::Div(a, b) => {
                let (a, b) = (a.eval(values)?, b.eval(values)?);
                if b == 0.0 {
                    return Err("division by zero".into());
                }
                a / b
            }
        })
    }

    /// The parameters the expression uses (indices, ascending, without repeats).
    pub fn parameters(&self) -> Vec<usize> {
        fn walk(e: &LengthExpr, out: &mut Vec<usize>) {
            match e {
                LengthExpr::Number(_) | LengthExpr::Pi => {}
                LengthExpr::Param(i) => out.push(*i),
                LengthExpr::Neg(a) => walk(a, out),
                LengthExpr::Add(a, b)
                | LengthExpr::Sub(a, b)
                | LengthExpr::Mul(a, b)
                | LengthExpr::Div(a, b) => {
                    walk(a, out);
                    walk(b, out);
                }
            }
        }
        let mut out = Vec::new();
        walk(self, &mut out);
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Zero (an absent field).
    pub const ZERO: LengthExpr = LengthExpr::Number(0.0);
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Id(String),
    Op(char),
}

impl fmt::Display for Tok {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tok::Num(x) => write!(f, "{x}"),
            Tok::Id(s) => write!(f, "{s}"),
            Tok::Op(c) => write!(f, "{c}"),
        }
    }
}

fn tokenize(s: &str) -> Result<Vec<Tok>, String> {
    let cs: Vec<char> = s.chars().collect();
    let mut i = 0;
    let mut out = Vec::new();
    while i < cs.len() {
        let c = cs[i];
        if c.is_whitespace() {
            i += 1;
        } else if "+-*/()".contains(c) {
            out.push(Tok::Op(c));
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let st = i;
            while i < cs.len()
                && (cs[i].is_ascii_digit()
                    || cs[i] == '.'
                    || cs[i] == 'e'
                    || cs[i] == 'E'
                    || ((cs[i] == '-' || cs[i] == '+') && matches!(cs[i - 1], 'e' | 'E')))
            {
                i += 1;
            }
            let t: String = cs[st..i].iter().collect();
            out.push(Tok::Num(
                t.parse().map_err(|_| format!("bad number `{t}`"))?,
            ));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let st = i;
            while i < cs.len() && (cs[i].is_ascii_alphanumeric() || cs[i] == '_') {
                i += 1;
            }
            out.push(Tok::Id(cs[st..i].iter().collect()));
        } else {
            return Err(format!("unexpected character `{c}` in `{s}`"));
        }
    }
    if out.is_empty() {
        return Err("empty expression".into());
    }
    Ok(out)
}

struct Parser<'a> {
    toks: &'a [Tok],
    pos: usize,
    params: &'a [&'a str],
}

fn bin(
    op: fn(Box<LengthExpr>, Box<LengthExpr>) -> LengthExpr,
    a: LengthExpr,
    b: LengthExpr,
) -> LengthExpr {
    op(Box::new(a), Box::new(b))
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }

    fn expr(&mut self) -> Result<LengthExpr, String> {
        let mut v = self.term()?;
        while let Some(Tok::Op(c @ ('+' | '-'))) = self.peek().cloned() {
            self.pos += 1;
            let r = self.term()?;
            v = if c == '+' {
                bin(LengthExpr::Add, v, r)
            } else {
                bin(LengthExpr::Sub, v, r)
            };
        }
        Ok(v)
    }

    fn term(&mut self) -> Result<LengthExpr, String> {
        let mut v = self.unary()?;
        while let Some(Tok::Op(c @ ('*' | '/'))) = self.peek().cloned() {
            self.pos += 1;
            let r = self.unary()?;
            v = if c == '*' {
                bin(LengthExpr::Mul, v, r)
            } else {
                bin(LengthExpr::Div, v, r)
            };
        }
        Ok(v)
    }

    fn unary(&mut self) -> Result<LengthExpr, String> {
        match self.peek().cloned() {
            Some(Tok::Op('-')) => {
                self.pos += 1;
                Ok(LengthExpr::Neg(Box::new(self.unary()?)))
            }
            Some(Tok::Op('+')) => {
                self.pos += 1;
                self.unary()
            }
            Some(Tok::Op('(')) => {
                self.pos += 1;
                let v = self.expr()?;
                if self.peek() != Some(&Tok::Op(')')) {
                    return Err("missing `)`".into());
                }
                self.pos += 1;
                Ok(v)
            }
            Some(Tok::Num(x)) => {
                self.pos += 1;
                Ok(LengthExpr::Number(x))
            }
            Some(Tok::Id(name)) => {
                self.pos += 1;
                if name == "pi" {
                    return Ok(LengthExpr::Pi);
                }
                self.params
                    .iter()
                    .position(|n| *n == name)
                    .map(LengthExpr::Param)
                    .ok_or_else(|| format!("unknown parameter `{name}`"))
            }
            Some(t) => Err(format!("unexpected `{t}`")),
            None => Err("expression ends too early".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval_expr(src: &str, p: &[(&str, f64)]) -> Result<f64, String> {
        let names: Vec<&str> = p.iter().map(|(n, _)| *n).collect();
        let values: Vec<f64> = p.iter().map(|(_, v)| *v).collect();
        LengthExpr::parse(src, &names)?.eval(&values)
    }

    #[test]
    fn expressions() {
        let p = [("l0", 1.0), ("l3", 0.6)];
        assert_eq!(eval_expr("-l0/2", &p).unwrap(), -0.5);
        assert!((eval_expr("l3 + 2*(l0 - 0.5)", &p).unwrap() - 1.6).abs() < 1e-15);
        assert!(
            (eval_expr("2/3*pi", &p).unwrap() - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-15
        );
        assert!(eval_expr("l9", &p).unwrap_err().contains("l9"));
        assert!(eval_expr("1e-3", &p).unwrap() == 1e-3);
        assert!(eval_expr("1 +", &p).is_err());
        assert!(eval_expr("1/(l0 - l0)", &p).is_err());
        let e = LengthExpr::parse("l3 * (l0 + l3)", &["l0", "l3"]).unwrap();
        assert_eq!(e.parameters(), [0, 1]);
    }
}
