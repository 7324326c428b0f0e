//! The TOML reader of mechanism descriptions (format: see the parent module).

use super::model::{
    invalid, number, ChainModel, ContactSpec, JointModel, MechanismModel, MechanismParameter,
    Output, PlanarJointKind, PoseExpr,
};
use crate::description::DescriptionError;
use crate::expr::{is_name, Expr};
use std::path::Path;
use toml::{Table, Value};

/// The shipped description of the four-bar linkage (`robots/mechanisms/four-bar.toml`).
pub const FOUR_BAR_TOML: &str = include_str!("../../robots/mechanisms/four-bar.toml");
/// The shipped planar Gough–Stewart platform (`robots/mechanisms/planar-stewart.toml`).
pub const STEWART_TOML: &str = include_str!("../../robots/mechanisms/planar-stewart.toml");
/// Two cooperating planar arms holding an object with frictional point contacts
/// (`robots/mechanisms/cooperative-arms.toml`).
pub const COOPERATIVE_TOML: &str = include_str!("../../robots/mechanisms/cooperative-arms.toml");

/// Names accepted by [`MechanismModel::shipped`].
pub const SHIPPED: [&str; 3] = ["four-bar", "planar-stewart", "cooperative-arms"];

/// The text of a shipped mechanism by name (`four-bar`, `planar-stewart`/`stewart`,
/// `cooperative-arms`/`cooperative`).
pub fn shipped_text(name: &str) -> Option<&'static str> {
    match name {
        "four-bar" => Some(FOUR_BAR_TOML),
        "planar-stewart" | "stewart" => Some(STEWART_TOML),
        "cooperative-arms" | "cooperative" => Some(COOPERATIVE_TOML),
        _ => None,
    }
}

impl MechanismModel {
    /// A shipped mechanism by name (see [`SHIPPED`]).
    pub fn shipped(name: &str) -> Result<Self, DescriptionError> {
        let text = shipped_text(name).ok_or_else(|| {
            invalid(
                "",
                format!(
                    "unknown mechanism `{name}`; shipped: {}",
                    SHIPPED.join(", ")
                ),
            )
        })?;
        Self::from_toml_str(text)
    }

    /// Reads a mechanism description from a file; errors name the file, the line and the field.
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = DescriptionError::read_file(path)?;
        let table = parse_table(&text).map_err(|mut e| {
            e.file = Some(path.to_path_buf());
            e
        })?;
        Self::from_table(&table, &text, Some(path))
    }

    /// Reads a mechanism description from TOML text.
    pub fn from_toml_str(src: &str) -> Result<Self, DescriptionError> {
        Self::from_table(&parse_table(src)?, src, None)
    }

    /// Reads a mechanism from TOML already parsed into `table` (`src` is its text, for the lines
    /// of errors; `file` is named in errors and kept in the model).
    pub fn from_table(
        table: &Table,
        src: &str,
        file: Option<&Path>,
    ) -> Result<Self, DescriptionError> {
        let spanned = |mut d: DescriptionError| {
            if d.line.is_none() {
                d.line = locate(src, &d.field);
            }
            d.file = file.map(Path::to_path_buf);
            d
        };
        let mut r = Reader { params: Vec::new() };
        let mut m = r.mechanism(table).map_err(spanned)?;
        m.validate().map_err(spanned)?;
        m.check_values(&m.nominal_values()).map_err(spanned)?;
        m.file = file.map(Path::to_path_buf);
        Ok(m)
    }
}

/// Parses TOML text into a table; syntax errors carry line and column.
pub(crate) fn parse_table(src: &str) -> Result<Table, DescriptionError> {
    src.parse::<Table>().map_err(|e| {
        let (line, column) = e
            .span()
            .map(|s| line_col(src, s.start))
            .map_or((None, None), |(l, c)| (Some(l), Some(c)));
        DescriptionError {
            file: None,
            line,
            column,
            field: String::new(),
            message: format!("TOML syntax: {}", e.message()),
        }
    })
}

fn err(field: impl Into<String>, message: impl Into<String>) -> DescriptionError {
    invalid(field, message)
}

fn line_col(src: &str, offset: usize) -> (usize, usize) {
    let before = &src[..offset.min(src.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
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
}

fn check_keys(t: &Table, path: &str, allowed: &[&str]) -> Result<(), DescriptionError> {
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
    fn mechanism(&mut self, t: &Table) -> Result<MechanismModel, DescriptionError> {
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
        let mut parameters = Vec::new();
        if let Some(p) = t.get("parameters") {
            let p = p
                .as_table()
                .ok_or_else(|| err("parameters", "must be a table of name = number"))?;
            for (k, v) in p {
                let field = format!("parameters.{k}");
                if !is_name(k) || k == "pi" {
                    return Err(err(field, "parameter names must be identifiers (not `pi`)"));
                }
                let expr = self.expr(v, &field)?;
                let nominal = super::model::eval(&expr, &|n| self.value(n), &field)?;
                self.params.push((k.clone(), nominal));
                parameters.push(MechanismParameter {
                    name: k.clone(),
                    expr,
                    nominal,
                });
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
                let before: usize = chains.iter().map(|c: &ChainModel| c.joints.len()).sum();
                if before + joints.len() >= crate::description::MAX_JOINTS {
                    return Err(err(
                        jp,
                        format!(
                            "too many joints: a mechanism has at most {} (all chains together)",
                            crate::description::MAX_JOINTS
                        ),
                    ));
                }
                joints.push(self.joint(jv, &jp)?);
            }
            let contact = match ct.get("contact") {
                None => None,
                Some(cv) => Some(self.contact(cv, &format!("{path}.contact"))?),
            };
            chains.push(ChainModel {
                name: cname,
                base,
                joints,
                tip,
                contact,
            });
        }
        Ok(MechanismModel {
            name,
            parameters,
            outputs,
            chains,
            file: None,
        })
    }

    fn joint(&self, jv: &Value, jp: &str) -> Result<JointModel, DescriptionError> {
        let jt = jv
            .as_table()
            .ok_or_else(|| err(jp.to_string(), "must be a table"))?;
        check_keys(
            jt,
            jp,
            &[
                "name", "type", "axis", "origin", "active", "limits", "initial",
            ],
        )?;
        let name = match jt.get("name") {
            Some(Value::String(s)) if is_name(s) => s.clone(),
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
                PlanarJointKind::Revolute
            }
            Some("prismatic") => {
                let axis = match jt.get("axis") {
                    None => [number(1.0), number(0.0)],
                    Some(Value::Array(a)) if a.len() == 2 => [
                        self.expr(&a[0], &format!("{jp}.axis[0]"))?,
                        self.expr(&a[1], &format!("{jp}.axis[1]"))?,
                    ],
                    Some(_) => return Err(err(format!("{jp}.axis"), "must be [ax, ay]")),
                };
                PlanarJointKind::Prismatic { axis }
            }
            Some(other) => {
                return Err(err(
                    format!("{jp}.type"),
                    format!("unknown joint type `{other}`; expected \"revolute\" or \"prismatic\""),
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
            Some(Value::Array(a)) if a.len() == 2 => Some([
                self.expr(&a[0], &format!("{jp}.limits[0]"))?,
                self.expr(&a[1], &format!("{jp}.limits[1]"))?,
            ]),
            Some(_) => return Err(err(format!("{jp}.limits"), "must be [min, max]")),
        };
        let initial = match jt.get("initial") {
            None => None,
            Some(v) => Some(self.expr(v, &format!("{jp}.initial"))?),
        };
        Ok(JointModel {
            name,
            kind,
            origin,
            active,
            limits,
            initial,
        })
    }

    fn contact(&self, cv: &Value, cp: &str) -> Result<ContactSpec, DescriptionError> {
        let ctt = cv
            .as_table()
            .ok_or_else(|| err(cp.to_string(), "must be a table { h, object }"))?;
        check_keys(ctt, cp, &["h", "object"])?;
        let h = match ctt.get("h") {
            Some(Value::Array(rows)) => rows
                .iter()
                .enumerate()
                .map(|(ri, row)| match row {
                    Value::Array(r) if r.len() == 3 => Ok([
                        self.expr(&r[0], &format!("{cp}.h[{ri}][0]"))?,
                        self.expr(&r[1], &format!("{cp}.h[{ri}][1]"))?,
                        self.expr(&r[2], &format!("{cp}.h[{ri}][2]"))?,
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
        Ok(ContactSpec { h, object })
    }

    fn pose(&self, v: Option<&Value>, path: &str) -> Result<PoseExpr, DescriptionError> {
        let Some(v) = v else {
            return Ok(PoseExpr::IDENTITY);
        };
        let t = v.as_table().ok_or_else(|| {
            err(
                path.to_string(),
                "must be a table { x = …, y = …, angle = … }",
            )
        })?;
        check_keys(t, path, &["x", "y", "angle"])?;
        let get = |k: &str| -> Result<Expr, DescriptionError> {
            t.get(k)
                .map_or(Ok(number(0.0)), |v| self.expr(v, &format!("{path}.{k}")))
        };
        Ok(PoseExpr {
            x: get("x")?,
            y: get("y")?,
            angle: get("angle")?,
        })
    }

    /// The nominal value of the parameter `name` declared so far.
    fn value(&self, name: &str) -> Option<f64> {
        self.params.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    /// A number field: a TOML number or a length expression ([`Expr`]) of the parameters
    /// declared so far.
    fn expr(&self, v: &Value, field: &str) -> Result<Expr, DescriptionError> {
        let e = match v {
            Value::Float(f) => number(*f),
            Value::Integer(i) => number(*i as f64),
            Value::String(s) => Expr::parse(s)
                .and_then(|e| e.check_symbols(|n| self.value(n).is_some()).map(|()| e))
                .map_err(|e| {
                    err(
                        field,
                        format!("cannot read `{}`: {e}", crate::expr::quoted(s)),
                    )
                })?,
            _ => {
                return Err(err(
                    field,
                    "expected a number or an expression of parameters",
                ))
            }
        };
        // The number rule (crate::validity) for every number written and for the value with
        // the parameters' nominal values: `l3*1e40` used to reach the generated code as an
        // `f32` literal that does not compile.
        for (value, at) in e.numbers() {
            if let Err(problem) = crate::validity::check(value) {
                return Err(err(
                    field,
                    format!("the number {value:e} (at byte {at}) {problem}"),
                ));
            }
        }
        let value = super::model::eval(&e, &|n| self.value(n), field)?;
        if let Err(problem) = crate::validity::check(value) {
            return Err(err(field, format!("its value {value:e} {problem}")));
        }
        Ok(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_files_parse() {
        for n in SHIPPED {
            MechanismModel::shipped(n).unwrap();
        }
    }

    /// A length field read as the reader reads it, evaluated with the parameters in scope.
    fn eval_expr(src: &str, p: &[(&str, f64)]) -> Result<f64, String> {
        let r = Reader {
            params: p.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
        };
        let e = r
            .expr(&Value::String(src.into()), "f")
            .map_err(|e| e.message)?;
        super::super::model::eval(&e, &|n| r.value(n), "f").map_err(|e| e.message)
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
        let e = Expr::parse("l3 * (l0 + l3)").unwrap();
        let mut used: Vec<usize> = e
            .symbols()
            .into_iter()
            .filter_map(|s| p.iter().position(|(n, _)| *n == s))
            .collect();
        used.sort_unstable();
        assert_eq!(used, [0, 1]);
    }
}
