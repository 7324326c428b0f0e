//! TOML descriptions of closed mechanisms (the serial-robot TOML family, extended with chains).
//!
//! ```toml
//! name = "four-bar"
//! outputs = ["phi"]                 # task components: any of "x", "y", "phi"
//!
//! [parameters]                      # named lengths, usable in any number field
//! l0 = 1.0
//! l1 = 1.2
//!
//! [[chains]]
//! name = "chain1"
//! base = { x = "-l0/2" }            # pose of the chain's base: x, y, angle (default 0)
//! tip = { x = "l3 + l4" }           # last joint frame → common frame
//!
//! [[chains.joints]]
//! name = "theta1"
//! type = "revolute"                 # or "prismatic" (with axis = [ax, ay], default [1, 0])
//! origin = { x = 0.0 }              # previous frame → joint frame
//! active = true                     # default false (passive)
//! limits = [0.72, 2.27]             # optional
//! initial = 1.2                     # optional: a configuration near an assembly
//!
//! # cooperating arms: the chain's tip is the contact frame, then the contact's free directions
//! # (rows of H, (v_x, v_y, ω) in the contact frame) become passive joints (36)–(42),
//! # then `object` leads to the object frame E_c. `h = []` is a gripped contact (H = 0).
//! contact = { h = [[0, 0, 1]], object = { x = 0.3 } }
//! ```
//!
//! Numbers may be written as expressions of the parameters: `+ - * /`, parentheses, `pi`.
//! Every error is a [`DescriptionError`] naming the field (`chains[1].joints[0].type`); syntax
//! errors also give line and column.

use super::cooperative::{attach_contact, Contact};
use super::mechanism::{Chain, JointType, Mechanism, Output, PlanarJoint, Pose2};
use super::ClosedChainError;
use crate::description::DescriptionError;
use std::path::Path;
use toml::{Table, Value};

/// The shipped description of the four-bar linkage (`robots/mechanisms/four-bar.toml`).
pub const FOUR_BAR_TOML: &str = include_str!("../../robots/mechanisms/four-bar.toml");
/// The shipped planar Gough–Stewart platform (`robots/mechanisms/planar-stewart.toml`).
pub const STEWART_TOML: &str = include_str!("../../robots/mechanisms/planar-stewart.toml");
/// Two cooperating planar arms holding an object with frictional point contacts
/// (`robots/mechanisms/cooperative-arms.toml`).
pub const COOPERATIVE_TOML: &str = include_str!("../../robots/mechanisms/cooperative-arms.toml");

/// Names accepted by [`shipped`].
pub const SHIPPED: [&str; 3] = ["four-bar", "planar-stewart", "cooperative-arms"];

/// A shipped mechanism by name (`four-bar`, `planar-stewart`, `cooperative-arms`).
pub fn shipped(name: &str) -> Result<Mechanism, ClosedChainError> {
    let src = match name {
        "four-bar" => FOUR_BAR_TOML,
        "planar-stewart" | "stewart" => STEWART_TOML,
        "cooperative-arms" | "cooperative" => COOPERATIVE_TOML,
        _ => {
            return Err(ClosedChainError::UnknownScenario {
                name: name.into(),
                known: SHIPPED.to_vec(),
            })
        }
    };
    from_toml_str(src)
}

/// Reads a mechanism description from a file; errors name the file and the field.
pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Mechanism, ClosedChainError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| DescriptionError {
        file: Some(path.to_path_buf()),
        line: None,
        column: None,
        field: String::new(),
        message: format!("cannot read: {e}"),
    })?;
    from_toml_str(&text).map_err(|e| match e {
        ClosedChainError::Description(mut d) => {
            d.file = Some(path.to_path_buf());
            ClosedChainError::Description(d)
        }
        other => other,
    })
}

fn err(field: impl Into<String>, message: impl Into<String>) -> ClosedChainError {
    ClosedChainError::invalid(field, message)
}

fn line_col(src: &str, offset: usize) -> (usize, usize) {
    let before = &src[..offset.min(src.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Reads a mechanism description from TOML text.
pub fn from_toml_str(src: &str) -> Result<Mechanism, ClosedChainError> {
    from_toml_str_with_contacts(src, None)
}

/// Reads a mechanism description, replacing the selection `H` of every `contact` by `h` when
/// given (see [`super::cooperative::two_arms`]).
pub fn from_toml_str_with_contacts(
    src: &str,
    h: Option<&[[f64; 3]]>,
) -> Result<Mechanism, ClosedChainError> {
    let table: Table = src.parse::<Table>().map_err(|e| {
        let (line, column) = e
            .span()
            .map(|s| line_col(src, s.start))
            .map_or((None, None), |(l, c)| (Some(l), Some(c)));
        ClosedChainError::Description(DescriptionError {
            file: None,
            line,
            column,
            field: String::new(),
            message: format!("TOML syntax: {}", e.message()),
        })
    })?;
    let mut r = Reader {
        params: Vec::new(),
        h_override: h.map(|h| h.to_vec()),
    };
    r.mechanism(&table).map_err(|e| match e {
        ClosedChainError::Description(mut d) if d.line.is_none() => {
            d.line = locate(src, &d.field);
            ClosedChainError::Description(d)
        }
        other => other,
    })
}

/// Best-effort line of a field path such as `chains[1].joints[0].origin.x` in the TOML text
/// (array-of-tables headers are counted; inline tables resolve to the line of their key).
fn locate(src: &str, field: &str) -> Option<usize> {
    let lines: Vec<&str> = src.lines().collect();
    let is_header = |l: &str| l.trim_start().starts_with('[');
    let mut header = String::new();
    let (mut start, mut end) = (0usize, lines.len());
    let mut key = None;
    for seg in field.split('.') {
        let (name, index) = match seg.find('[') {
            Some(b) => (
                &seg[..b],
                seg[b + 1..]
                    .trim_end_matches(']')
                    .split("][")
                    .next()?
                    .parse::<usize>()
                    .ok(),
            ),
            None => (seg, None),
        };
        let qualified = if header.is_empty() {
            name.to_string()
        } else {
            format!("{header}.{name}")
        };
        let aot = format!("[[{qualified}]]");
        let tbl = format!("[{qualified}]");
        let found: Vec<usize> = (start..end)
            .filter(|&i| {
                let t = lines[i].trim();
                t == aot || t == tbl
            })
            .collect();
        if !found.is_empty() {
            let i = found[index.unwrap_or(0).min(found.len() - 1)];
            // The section runs to the next header of the same or an outer level.
            let stop = (i + 1..end)
                .find(|&j| {
                    let t = lines[j].trim();
                    is_header(t)
                        && !t.starts_with(&format!("[[{qualified}."))
                        && !t.starts_with(&format!("[{qualified}."))
                })
                .unwrap_or(end);
            start = i;
            end = stop;
            header = qualified;
            key = None;
            continue;
        }
        // A key inside the current section (before any nested header).
        let sec_end = (start + 1..end)
            .find(|&j| is_header(lines[j]))
            .unwrap_or(end);
        let first = if header.is_empty() { 0 } else { start + 1 };
        if let Some(i) = (first..sec_end).find(|&i| {
            let t = lines[i].trim_start();
            t.strip_prefix(name)
                .is_some_and(|r| r.trim_start().starts_with('='))
        }) {
            key = Some(i);
        }
        break;
    }
    key.or(if header.is_empty() { None } else { Some(start) })
        .map(|i| i + 1)
}

struct Reader {
    params: Vec<(String, f64)>,
    h_override: Option<Vec<[f64; 3]>>,
}

fn check_keys(t: &Table, path: &str, allowed: &[&str]) -> Result<(), ClosedChainError> {
    for k in t.keys() {
        if !allowed.contains(&k.as_str()) {
            let field = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            return Err(err(
                field,
                format!("unknown field; expected one of: {}", allowed.join(", ")),
            ));
        }
    }
    Ok(())
}

impl Reader {
    fn mechanism(&mut self, t: &Table) -> Result<Mechanism, ClosedChainError> {
        check_keys(
            t,
            "",
            &["name", "description", "outputs", "parameters", "chains"],
        )?;
        let name = match t.get("name") {
            Some(Value::String(s)) if !s.trim().is_empty() => s.clone(),
            Some(_) => return Err(err("name", "must be a non-empty string")),
            None => return Err(err("name", "missing")),
        };
        if let Some(v) = t.get("description") {
            if !v.is_str() {
                return Err(err("description", "must be a string"));
            }
        }
        if let Some(p) = t.get("parameters") {
            let p = p
                .as_table()
                .ok_or_else(|| err("parameters", "must be a table of name = number"))?;
            for (k, v) in p {
                let field = format!("parameters.{k}");
                if !is_ident(k) || k == "pi" {
                    return Err(err(field, "parameter names must be identifiers (not `pi`)"));
                }
                let x = self.number(v, &field)?;
                self.params.push((k.clone(), x));
            }
        }
        let outputs = match t.get("outputs") {
            None => return Err(err("outputs", "missing (list of \"x\", \"y\", \"phi\")")),
            Some(Value::Array(a)) => a
                .iter()
                .enumerate()
                .map(|(i, v)| match v.as_str() {
                    Some("x") => Ok(Output::X),
                    Some("y") => Ok(Output::Y),
                    Some("phi") => Ok(Output::Phi),
                    _ => Err(err(
                        format!("outputs[{i}]"),
                        "expected \"x\", \"y\" or \"phi\"",
                    )),
                })
                .collect::<Result<Vec<_>, _>>()?,
            Some(_) => return Err(err("outputs", "must be an array of strings")),
        };
        let chains_v = match t.get("chains") {
            Some(Value::Array(a)) => a,
            Some(_) => return Err(err("chains", "must be an array of tables ([[chains]])")),
            None => return Err(err("chains", "missing ([[chains]] tables)")),
        };
        let mut chains = Vec::new();
        let mut initial = Vec::new();
        let mut any_initial = false;
        for (ci, cv) in chains_v.iter().enumerate() {
            let path = format!("chains[{ci}]");
            let ct = cv
                .as_table()
                .ok_or_else(|| err(path.clone(), "must be a table"))?;
            check_keys(ct, &path, &["name", "base", "tip", "joints", "contact"])?;
            let cname = match ct.get("name") {
                Some(Value::String(s)) => s.clone(),
                Some(_) => return Err(err(format!("{path}.name"), "must be a string")),
                None => format!("chain{}", ci + 1),
            };
            let base = self.pose(ct.get("base"), &format!("{path}.base"))?;
            let tip = self.pose(ct.get("tip"), &format!("{path}.tip"))?;
            let joints_v = match ct.get("joints") {
                Some(Value::Array(a)) => a,
                Some(_) => {
                    return Err(err(
                        format!("{path}.joints"),
                        "must be an array of tables ([[chains.joints]])",
                    ))
                }
                None => return Err(err(format!("{path}.joints"), "missing")),
            };
            let mut joints = Vec::new();
            for (ji, jv) in joints_v.iter().enumerate() {
                let jp = format!("{path}.joints[{ji}]");
                let jt = jv
                    .as_table()
                    .ok_or_else(|| err(jp.clone(), "must be a table"))?;
                check_keys(
                    jt,
                    &jp,
                    &[
                        "name", "type", "axis", "origin", "active", "limits", "initial",
                    ],
                )?;
                let name = match jt.get("name") {
                    Some(Value::String(s)) if is_ident(s) => s.clone(),
                    Some(_) => {
                        return Err(err(
                            format!("{jp}.name"),
                            "must be an identifier (letters, digits, _)",
                        ))
                    }
                    None => return Err(err(format!("{jp}.name"), "missing")),
                };
                let kind = match jt.get("type").and_then(Value::as_str) {
                    Some("revolute") => {
                        if jt.contains_key("axis") {
                            return Err(err(
                                format!("{jp}.axis"),
                                "a planar revolute joint turns about z: no axis",
                            ));
                        }
                        JointType::Revolute
                    }
                    Some("prismatic") => {
                        let axis = match jt.get("axis") {
                            None => [1.0, 0.0],
                            Some(Value::Array(a)) if a.len() == 2 => [
                                self.number(&a[0], &format!("{jp}.axis[0]"))?,
                                self.number(&a[1], &format!("{jp}.axis[1]"))?,
                            ],
                            Some(_) => return Err(err(format!("{jp}.axis"), "must be [ax, ay]")),
                        };
                        JointType::Prismatic { axis }
                    }
                    Some(other) => {
                        return Err(err(
                            format!("{jp}.type"),
                            format!(
                            "unknown joint type `{other}`; expected \"revolute\" or \"prismatic\""
                        ),
                        ))
                    }
                    None => {
                        return Err(err(
                            format!("{jp}.type"),
                            "missing or not a string (\"revolute\" or \"prismatic\")",
                        ))
                    }
                };
                let origin = self.pose(jt.get("origin"), &format!("{jp}.origin"))?;
                let active = match jt.get("active") {
                    None => false,
                    Some(Value::Boolean(b)) => *b,
                    Some(_) => return Err(err(format!("{jp}.active"), "must be true or false")),
                };
                let limits = match jt.get("limits") {
                    None => None,
                    Some(Value::Array(a)) if a.len() == 2 => {
                        let lo = self.number(&a[0], &format!("{jp}.limits[0]"))?;
                        let hi = self.number(&a[1], &format!("{jp}.limits[1]"))?;
                        if lo >= hi {
                            return Err(err(format!("{jp}.limits"), "needs min < max"));
                        }
                        Some([lo, hi])
                    }
                    Some(_) => return Err(err(format!("{jp}.limits"), "must be [min, max]")),
                };
                match jt.get("initial") {
                    None => initial.push(0.0),
                    Some(v) => {
                        any_initial = true;
                        initial.push(self.number(v, &format!("{jp}.initial"))?);
                    }
                }
                joints.push(PlanarJoint {
                    name,
                    kind,
                    origin,
                    active,
                    limits,
                });
            }
            let mut chain = Chain {
                name: cname,
                base,
                joints,
                tip,
            };
            if let Some(cv) = ct.get("contact") {
                let cp = format!("{path}.contact");
                let ctt = cv
                    .as_table()
                    .ok_or_else(|| err(cp.clone(), "must be a table { h, object }"))?;
                check_keys(ctt, &cp, &["h", "object"])?;
                let h = match ctt.get("h") {
                    Some(Value::Array(rows)) => rows
                        .iter()
                        .enumerate()
                        .map(|(ri, row)| match row {
                            Value::Array(r) if r.len() == 3 => Ok([
                                self.number(&r[0], &format!("{cp}.h[{ri}][0]"))?,
                                self.number(&r[1], &format!("{cp}.h[{ri}][1]"))?,
                                self.number(&r[2], &format!("{cp}.h[{ri}][2]"))?,
                            ]),
                            _ => Err(err(
                                format!("{cp}.h[{ri}]"),
                                "each row of H is [v_x, v_y, omega]",
                            )),
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                    Some(_) => return Err(err(format!("{cp}.h"), "must be an array of rows")),
                    None => {
                        return Err(err(
                            format!("{cp}.h"),
                            "missing (use h = [] for a gripped contact)",
                        ))
                    }
                };
                let object = self.pose(ctt.get("object"), &format!("{cp}.object"))?;
                let h = self.h_override.clone().unwrap_or(h);
                let contact = Contact { h, object };
                let n_before = chain.joints.len();
                chain = attach_contact(chain, &contact).map_err(|e| match e {
                    ClosedChainError::Description(mut d) => {
                        d.field = format!("{cp}.{}", d.field);
                        ClosedChainError::Description(d)
                    }
                    o => o,
                })?;
                initial.resize(initial.len() + chain.joints.len() - n_before, 0.0);
            }
            chains.push(chain);
        }
        let mut m = Mechanism::new(name, chains, outputs)?;
        m.parameters = std::mem::take(&mut self.params);
        if any_initial {
            m.initial = Some(initial);
        }
        Ok(m)
    }

    fn pose(&self, v: Option<&Value>, path: &str) -> Result<Pose2, ClosedChainError> {
        let Some(v) = v else {
            return Ok(Pose2::IDENTITY);
        };
        let t = v.as_table().ok_or_else(|| {
            err(
                path.to_string(),
                "must be a table { x = …, y = …, angle = … }",
            )
        })?;
        check_keys(t, path, &["x", "y", "angle"])?;
        let get = |k: &str| -> Result<f64, ClosedChainError> {
            t.get(k)
                .map_or(Ok(0.0), |v| self.number(v, &format!("{path}.{k}")))
        };
        Ok(Pose2::new(get("x")?, get("y")?, get("angle")?))
    }

    fn number(&self, v: &Value, field: &str) -> Result<f64, ClosedChainError> {
        let x = match v {
            Value::Float(f) => *f,
            Value::Integer(i) => *i as f64,
            Value::String(s) => eval_expr(s, &self.params).map_err(|m| err(field, m))?,
            _ => {
                return Err(err(
                    field,
                    "expected a number or an expression of parameters",
                ))
            }
        };
        if !x.is_finite() {
            return Err(err(field, "not finite"));
        }
        Ok(x)
    }
}

fn is_ident(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic() || ch == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

/// Evaluates an arithmetic expression of named parameters (`+ - * /`, parentheses, `pi`).
pub fn eval_expr(src: &str, params: &[(String, f64)]) -> Result<f64, String> {
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

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Id(String),
    Op(char),
}

impl std::fmt::Display for Tok {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
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
    params: &'a [(String, f64)],
}

impl Parser<'_> {
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
            Some(t) => Err(format!("unexpected `{t}`")),
            None => Err("expression ends too early".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions() {
        let p = vec![("l0".to_string(), 1.0), ("l3".to_string(), 0.6)];
        assert_eq!(eval_expr("-l0/2", &p).unwrap(), -0.5);
        assert!((eval_expr("l3 + 2*(l0 - 0.5)", &p).unwrap() - 1.6).abs() < 1e-15);
        assert!(
            (eval_expr("2/3*pi", &p).unwrap() - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-15
        );
        assert!(eval_expr("l9", &p).unwrap_err().contains("l9"));
        assert!(eval_expr("1e-3", &p).unwrap() == 1e-3);
        assert!(eval_expr("1 +", &p).is_err());
    }

    #[test]
    fn shipped_files_parse() {
        for n in SHIPPED {
            shipped(n).unwrap();
        }
    }
}
