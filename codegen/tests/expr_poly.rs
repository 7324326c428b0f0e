//! `Poly::from_expr` (the generator's reading of [`trocar_model::expr`]) gives, on every string of
//! every shipped mechanism, exactly the polynomial the closed-chain length parser it replaces gave
//! (kept here verbatim as the reference; so does the mechanism derivation's `length_poly`), and
//! `Poly::parse` reads the grammar's forms.

use std::path::Path;
use trocar_codegen::closed_chain::length_poly;
use trocar_codegen::symbolic::{Poly, Rational, SymbolicError};
use trocar_model::expr::Expr;

const MECHANISMS: &[&str] = &["four-bar", "planar-stewart", "cooperative-arms"];

fn strings(v: &toml::Value, out: &mut Vec<String>) {
    match v {
        toml::Value::String(s) => out.push(s.clone()),
        toml::Value::Array(a) => a.iter().for_each(|x| strings(x, out)),
        toml::Value::Table(t) => t.values().for_each(|x| strings(x, out)),
        _ => {}
    }
}

#[test]
fn mechanism_lengths_agree_with_the_old_parser() {
    let mut checked = 0;
    for name in MECHANISMS {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("../runtime/model/robots/mechanisms/{name}.toml"));
        let table: toml::Table = toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let params: Vec<(String, f64)> = table
            .get("parameters")
            .and_then(|p| p.as_table())
            .map(|t| {
                t.iter()
                    .filter_map(|(k, v)| {
                        v.as_float()
                            .or(v.as_integer().map(|i| i as f64))
                            .map(|x| (k.clone(), x))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut all = Vec::new();
        strings(&toml::Value::Table(table), &mut all);
        for s in all {
            let Ok(old) = old_parse_length(&s, &params) else {
                continue;
            };
            let expr = Expr::parse(&s).unwrap();
            let new = Poly::from_expr(&expr, &|n| {
                params.iter().position(|(p, _)| p == n).map(Poly::param)
            })
            .unwrap_or_else(|e| panic!("{name}: `{s}`: {e}"));
            assert_eq!(new, old, "{name}: `{s}`");
            // What the mechanism derivation reads its lengths with.
            let names: Vec<&str> = params.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(length_poly(&expr, &names), Ok(old), "{name}: `{s}`");
            checked += 1;
        }
    }
    assert!(checked > 10, "{checked}");
}

#[test]
fn poly_parse_reads_the_grammar() {
    let names = ["la", "lb"];
    let p = |t: &str| Poly::parse(t, &names).unwrap();
    assert_eq!(p("-la*lb"), p("(-la)*lb"));
    assert_eq!(p("2e-1*la"), p("la/5"));
    assert_eq!(p("la^-2*la^2"), Poly::one());
    assert_eq!(
        p("pi"),
        Poly::constant(Rational::from_f64_decimal(std::f64::consts::PI).unwrap())
    );
    assert_eq!(p("s1 * c2 * q3"), p("q3*c2*s1"));
    assert_eq!(
        Poly::parse("la + zz", &names),
        Err(SymbolicError::Parse(5, "unknown identifier `zz`".into()))
    );
    assert!(matches!(
        Poly::parse("la + $", &names),
        Err(SymbolicError::Parse(5, _))
    ));
    assert_eq!(
        Poly::parse("1/(la - la)", &names),
        Err(SymbolicError::DivisionByZero)
    );
}

/// The closed-chain length parser before `trocar_model::expr`, verbatim.
fn old_parse_length(src: &str, params: &[(String, f64)]) -> Result<Poly, String> {
    #[derive(Clone, Debug, PartialEq)]
    enum Tok {
        Num(f64),
        Id(String),
        Op(char),
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
    struct P<'a> {
        toks: &'a [Tok],
        pos: usize,
        params: &'a [(String, f64)],
    }
    impl P<'_> {
        fn peek(&self) -> Option<&Tok> {
            self.toks.get(self.pos)
        }
        fn expr(&mut self) -> Result<Poly, String> {
            let mut v = self.term()?;
            while let Some(Tok::Op(c @ ('+' | '-'))) = self.peek().cloned() {
                self.pos += 1;
                let r = self.term()?;
                v = if c == '+' { v.add(&r) } else { v.sub(&r) };
            }
            Ok(v)
        }
        fn term(&mut self) -> Result<Poly, String> {
            let mut v = self.unary()?;
            while let Some(Tok::Op(c @ ('*' | '/'))) = self.peek().cloned() {
                self.pos += 1;
                let r = self.unary()?;
                v = if c == '*' {
                    v.mul(&r)
                } else {
                    v.div(&r).map_err(|e: SymbolicError| e.to_string())?
                };
            }
            Ok(v)
        }
        fn unary(&mut self) -> Result<Poly, String> {
            match self.peek().cloned() {
                Some(Tok::Op('-')) => {
                    self.pos += 1;
                    Ok(self.unary()?.neg())
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
                    Rational::from_f64_decimal(x)
                        .map(Poly::constant)
                        .map_err(|e| e.to_string())
                }
                Some(Tok::Id(name)) => {
                    self.pos += 1;
                    if name == "pi" {
                        return Rational::from_f64_decimal(std::f64::consts::PI)
                            .map(Poly::constant)
                            .map_err(|e| e.to_string());
                    }
                    self.params
                        .iter()
                        .position(|(n, _)| *n == name)
                        .map(Poly::param)
                        .ok_or_else(|| format!("unknown parameter `{name}`"))
                }
                Some(t) => Err(format!("unexpected `{t:?}`")),
                None => Err("expression ends too early".into()),
            }
        }
    }
    let toks = tokenize(src)?;
    let mut p = P {
        toks: &toks,
        pos: 0,
        params,
    };
    let v = p.expr()?;
    if p.pos != toks.len() {
        return Err(format!("unexpected token in `{src}`"));
    }
    Ok(v)
}
