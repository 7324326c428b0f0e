//! The length-expression parser ([`trocar_model::expr`]) gives, on every string of every shipped
//! description (serial robots, mechanisms, examples and test fixtures), exactly the values the
//! parsers it replaced gave: the serial `Linear` reader and the closed-chain evaluator, kept here
//! verbatim as references.

use std::path::{Path, PathBuf};
use trocar_model::description::Linear;
use trocar_model::expr::Expr;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const SERIAL: &[&str] = &[
    "runtime/model/robots/unidirectional.toml",
    "runtime/model/robots/bidirectional-zy.toml",
    "runtime/model/robots/bidirectional-zx.toml",
    "runtime/model/robots/dia10_like_zy.toml",
    "runtime/model/robots/dia10_like_zx.toml",
    "runtime/model/tests/data/arm7.toml",
    "examples/robots/dia10_like_zy.toml",
    "examples/firmware/robots/dia10_like_zy.toml",
    "tests/generated/robots/chain9_prismatic.toml",
    "tests/generated/robots/rotated_rcm.toml",
    "derive/tests/ui/robots/arm.toml",
    "derive/tests/ui/robots/bad_axis.toml",
];

const MECHANISMS: &[&str] = &[
    "runtime/model/robots/mechanisms/four-bar.toml",
    "runtime/model/robots/mechanisms/planar-stewart.toml",
    "runtime/model/robots/mechanisms/cooperative-arms.toml",
];

fn strings(v: &toml::Value, out: &mut Vec<String>) {
    match v {
        toml::Value::String(s) => out.push(s.clone()),
        toml::Value::Array(a) => a.iter().for_each(|x| strings(x, out)),
        toml::Value::Table(t) => t.values().for_each(|x| strings(x, out)),
        _ => {}
    }
}

fn read(path: &str) -> toml::Table {
    let text = std::fs::read_to_string(root().join(path)).unwrap();
    toml::from_str(&text).unwrap()
}

#[test]
fn serial_scalars_agree_with_the_old_reader() {
    let mut checked = 0;
    for path in SERIAL {
        let mut all = Vec::new();
        strings(&toml::Value::Table(read(path)), &mut all);
        for s in all {
            let Ok(old) = old_scalar_parse(&s) else {
                continue;
            };
            let new = Linear::parse(&s).unwrap_or_else(|e| panic!("{path}: `{s}`: {e}"));
            assert_eq!(
                new.constant.to_bits(),
                old.constant.to_bits(),
                "{path}: `{s}`"
            );
            assert_eq!(new.terms.len(), old.terms.len(), "{path}: `{s}`");
            for ((a, n), (b, m)) in new.terms.iter().zip(&old.terms) {
                assert_eq!((a.to_bits(), n), (b.to_bits(), m), "{path}: `{s}`");
            }
            checked += 1;
        }
    }
    assert!(checked > 30, "{checked}");
}

#[test]
fn mechanism_lengths_agree_with_the_old_evaluator() {
    let mut checked = 0;
    for path in MECHANISMS {
        let table = read(path);
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
            let Ok(old) = old_eval_expr(&s, &params) else {
                continue;
            };
            let new = Expr::parse(&s)
                .and_then(|e| e.eval(|n| params.iter().find(|(p, _)| p == n).map(|(_, v)| *v)))
                .unwrap_or_else(|e| panic!("{path}: `{s}`: {e}"));
            assert_eq!(new.to_bits(), old.to_bits(), "{path}: `{s}`");
            checked += 1;
        }
    }
    assert!(checked > 10, "{checked}");
}

#[test]
fn old_forms_still_read_the_same() {
    for s in [
        "l_a + l_b",
        "-0.5*l_8 + 0.1 - 2e-1",
        "2 * l_a",
        "l_e-0.1",
        "1e-3*l_a - 2.5E+2",
        "0.33",
        "-l_a",
        "l_a - l_a + 3",
        "2*3*l_a + l_b*4 - l_a",
    ] {
        let old = old_scalar_parse(s).unwrap();
        let new = Linear::parse(s).unwrap();
        assert_eq!(new, old, "{s}");
    }
    for s in [
        "-l0/2",
        "l3 + 2*(l0 - 0.5)",
        "2/3*pi",
        "1e-3",
        "-(l0 + -l3)*2/l3",
    ] {
        let p = vec![("l0".to_string(), 1.0), ("l3".to_string(), 0.6)];
        let old = old_eval_expr(s, &p).unwrap();
        let new = Expr::parse(s)
            .unwrap()
            .eval(|n| p.iter().find(|(q, _)| q == n).map(|(_, v)| *v))
            .unwrap();
        assert_eq!(new.to_bits(), old.to_bits(), "{s}");
    }
}

#[test]
fn scalar_errors_name_the_offset() {
    let e = Linear::parse("l_a * l_b").unwrap_err();
    assert!(e.contains("not linear") && e.contains("at byte 4"), "{e}");
    let e = Linear::parse("l_a + $").unwrap_err();
    assert!(e.contains("at byte 6"), "{e}");
    let e = Linear::parse("").unwrap_err();
    assert!(e.contains("empty"), "{e}");
    // Forms the old reader refused and the one grammar reads.
    assert_eq!(
        Linear::parse("(l_a + l_b)/2").unwrap(),
        Linear {
            constant: 0.0,
            terms: vec![(0.5, "l_a".into()), (0.5, "l_b".into())]
        }
    );
    assert_eq!(
        Linear::parse("pi/2").unwrap(),
        Linear::constant(std::f64::consts::FRAC_PI_2)
    );
}

// ---- The replaced parsers, verbatim (references only) ----

/// The serial reader before `trocar_model::expr`.
fn old_scalar_parse(text: &str) -> Result<Linear, String> {
    let mut out = Linear::default();
    let compact: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    if compact.is_empty() {
        return Err("empty expression".into());
    }
    let mut terms = Vec::new();
    let mut start = 0;
    let bytes = compact.as_bytes();
    for k in 1..bytes.len() {
        if bytes[k] != b'+' && bytes[k] != b'-' {
            continue;
        }
        let prev = bytes[k - 1];
        if prev == b'*' {
            continue;
        }
        if prev == b'e' || prev == b'E' {
            let factor_start = compact[start..k - 1]
                .rfind(['*', '+', '-'])
                .map_or(start, |p| start + p + 1);
            let mantissa = &compact[factor_start..k - 1];
            if !mantissa.is_empty()
                && mantissa.bytes().all(|b| b.is_ascii_digit() || b == b'.')
                && mantissa.bytes().any(|b| b.is_ascii_digit())
            {
                continue;
            }
        }
        terms.push(&compact[start..k]);
        start = k;
    }
    terms.push(&compact[start..]);
    for term in terms {
        let (sign, body) = match term.as_bytes().first() {
            Some(b'-') => (-1.0, &term[1..]),
            Some(b'+') => (1.0, &term[1..]),
            _ => (1.0, term),
        };
        let mut coefficient = sign;
        let mut name: Option<&str> = None;
        for factor in body.split('*') {
            let numeric = factor.starts_with(|c: char| c.is_ascii_digit() || c == '.');
            if let (true, Ok(v)) = (numeric, factor.parse::<f64>()) {
                coefficient *= v;
            } else if trocar_model::expr::is_name(factor) {
                if name.is_some() {
                    return Err(format!("`{text}` is not linear in the parameters"));
                }
                name = Some(factor);
            } else {
                return Err(format!("cannot read `{factor}` in `{text}`"));
            }
        }
        match name {
            None => out.constant += coefficient,
            Some(n) => match out.terms.iter_mut().find(|(_, m)| m == n) {
                Some((c, _)) => *c += coefficient,
                None => out.terms.push((coefficient, n.to_string())),
            },
        }
    }
    out.terms.retain(|(c, _)| *c != 0.0);
    Ok(out)
}

/// The closed-chain evaluator before `trocar_model::expr`.
fn old_eval_expr(src: &str, params: &[(String, f64)]) -> Result<f64, String> {
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
        fn expr(&mut self) -> Result<f64, String> {
            let mut v = self.term()?;
            while let Some(Tok::Op(c @ ('+' | '-'))) = self.peek().cloned() {
                self.pos += 1;
                let r = self.term()?;
                v = if c == '+' { v + r } else { v - r };
            }
            Ok(v)
        }
        fn term(&mut self) -> Result<f64, String> {
            let mut v = self.unary()?;
            while let Some(Tok::Op(c @ ('*' | '/'))) = self.peek().cloned() {
                self.pos += 1;
                let r = self.unary()?;
                if c == '/' && r == 0.0 {
                    return Err("division by zero".into());
                }
                v = if c == '*' { v * r } else { v / r };
            }
            Ok(v)
        }
        fn unary(&mut self) -> Result<f64, String> {
            match self.peek().cloned() {
                Some(Tok::Op('-')) => {
                    self.pos += 1;
                    Ok(-self.unary()?)
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
                    Ok(x)
                }
                Some(Tok::Id(name)) => {
                    self.pos += 1;
                    if name == "pi" {
                        return Ok(std::f64::consts::PI);
                    }
                    self.params
                        .iter()
                        .find(|(n, _)| *n == name)
                        .map(|(_, v)| *v)
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
