//! Closed planar mechanisms (second source, SPEC §4): the reduced Jacobian in closed form.
//!
//! Equation numbers refer to G. M. Freitas, A. C. Leite, F. Lizarralde, *Controle de sistemas
//! robóticos com restrições cinemáticas*, CBA 2010. A mechanism is described as in
//! [`trocar_model::closed_chain::description`] (`runtime/model/robots/mechanisms/*.toml`): open planar chains
//! that all reach one common frame, joints split into active `θ_a` and passive `θ_p`.
//!
//! [`derive_mechanism`] carries the runtime's numeric construction
//! ([`trocar_model::closed_chain::Mechanism::differential`]) out on symbols:
//!
//! 1. Each chain's pose: angles add, so the frame's rotation is `(cos Σθ, sin Σθ)` expanded into
//!    products of `s_k, c_k`; positions are sums of lengths times those (`l cos(Σθ)`,
//!    `l sin(Σθ)`); a prismatic joint adds `θ_k` times its direction.
//! 2. Chain Jacobians `S J_k` (15)–(16), (26)–(28): a revolute column is
//!    `(−(y_e − y_k), x_e − x_k, 1)`, a prismatic one `(R_k a, 0)`.
//! 3. `J_C = Ã J` (rows `J_1 − J_k`, `k = 2..m`) and `J_A = S_x A† J = S_x (1/m) Σ_k J_k`
//!    (17)–(19), (29)–(31), split into active/passive columns (5)–(6).
//! 4. With `J_Cp` square: `det J_Cp` and its adjugate (cofactors, exact), so that
//!    `J = (det(J_Cp) J_Aa − J_Ap adj(J_Cp) J_Ca) / det(J_Cp)` (8) and
//!    `θ̇_p = −adj(J_Cp) J_Ca θ̇_a / det(J_Cp)` (7): numerators and the denominator are
//!    polynomials, and the only division is by `det J_Cp`, which vanishes exactly at the
//!    parallel (actuator) singularities.
//!
//! Every function is a function of **all** joint values, active and passive: the caller solves the
//! passive joints (for the four-bar linkage with the runtime's closed form
//! [`trocar_model::closed_chain::four_bar::FourBar::passive`], which needs `acos`, or with Newton's
//! method [`trocar_model::closed_chain::Mechanism::solve_passive`]). Off the constraint manifold the
//! results are those of the same formulas, as in the runtime.
//!
//! Lengths (`x`, `y` of `base`, `tip` and `origin`) may be expressions of the parameters (`+ − * /`,
//! parentheses, `pi`); they stay symbolic and become fields of the generated `Params`. Fixed
//! angles must be constants (numbers and `pi`): their sines and cosines are exact for multiples
//! of `π/2`, and the `f64` values otherwise. Mechanisms whose `J_Cp` is not square (more
//! structural equations than passive joints, such as cooperating arms with point contacts) are
//! rejected with an error, as are contact models.
//!
//! [`emit`] turns a [`MechanismDerivation`] into a module (see [`emit::module_tokens`]).

pub mod emit;

use crate::symbolic::{Matrix, Poly, Rational, SymbolicError};
use std::fmt;
use std::path::{Path, PathBuf};
use trocar_model::closed_chain::{description, ClosedChainError, JointType, Mechanism, Output};
use trocar_model::description::DescriptionError;

/// A mechanism derivation's results: everything the emitter needs.
///
/// Joint indices of expressions are positions in `θ` (chain 1's joints, then chain 2's, …);
/// parameter indices are positions in [`MechanismDerivation::params`].
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismDerivation {
    /// Mechanism name.
    pub name: String,
    /// Parameter names, in declaration order.
    pub params: Vec<String>,
    /// Nominal parameter values, same order.
    pub param_values: Vec<f64>,
    /// Joint names in `θ` order.
    pub joint_names: Vec<String>,
    /// Which joints are prismatic (their value appears itself, not through `s_k, c_k`).
    pub joint_is_linear: Vec<bool>,
    /// Indices in `θ` of the active joints.
    pub active: Vec<usize>,
    /// Indices in `θ` of the passive joints.
    pub passive: Vec<usize>,
    /// The task outputs (`x`, `y`, `φ`), in order.
    pub outputs: Vec<Output>,
    /// Constraint Jacobian `J_C = Ã J` (`r × n`) (19), (31).
    pub j_c: Matrix,
    /// Analytic Jacobian `J_A = S_x A† J` (`m_x × n`) (19), (31).
    pub j_a: Matrix,
    /// `det J_Cp`.
    pub det_j_cp: Poly,
    /// `adj(J_Cp)`, so that `J_Cp⁻¹ = adj(J_Cp) / det(J_Cp)`.
    pub adj_j_cp: Matrix,
    /// `det(J_Cp) · J = det(J_Cp) J_Aa − J_Ap adj(J_Cp) J_Ca` (`m_x × n_a`), numerator of (8).
    pub reduced_numerator: Matrix,
    /// `−adj(J_Cp) J_Ca` (`n_p × n_a`), numerator of (7).
    pub passive_numerator: Matrix,
}

impl MechanismDerivation {
    /// Number of joints `n`.
    pub fn n(&self) -> usize {
        self.joint_names.len()
    }
}

/// Why a mechanism could not be derived; names the field at fault.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismError {
    /// The field, as a path such as `chains[1].joints[0].origin.x`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl MechanismError {
    fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        MechanismError {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The same error as a [`DescriptionError`] in `file` (when known).
    pub fn into_description_error(self, file: Option<&Path>) -> DescriptionError {
        DescriptionError {
            file: file.map(Path::to_path_buf),
            line: None,
            column: None,
            field: self.field,
            message: self.message,
        }
    }
}

impl fmt::Display for MechanismError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "field `{}`: {}", self.field, self.message)
    }
}

impl std::error::Error for MechanismError {}

/// A mechanism description read for the generator: the runtime's validated [`Mechanism`] and the
/// raw TOML (for the symbolic length expressions).
#[derive(Clone, Debug)]
pub struct MechanismSource {
    /// The validated mechanism.
    pub mechanism: Mechanism,
    /// The TOML text.
    pub text: String,
    /// The file it came from, if any.
    pub file: Option<PathBuf>,
}

fn closed_chain_error(e: ClosedChainError, file: Option<&Path>) -> DescriptionError {
    match e {
        ClosedChainError::Description(mut d) => {
            if d.file.is_none() {
                d.file = file.map(Path::to_path_buf);
            }
            d
        }
        other => DescriptionError {
            file: file.map(Path::to_path_buf),
            line: None,
            column: None,
            field: String::new(),
            message: other.to_string(),
        },
    }
}

impl MechanismSource {
    /// Reads and validates a mechanism description file (errors name file, line and field).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| DescriptionError {
            file: Some(path.to_path_buf()),
            line: None,
            column: None,
            field: String::new(),
            message: format!("cannot read: {e}"),
        })?;
        let mut s = Self::from_toml_str(&text).map_err(|mut e| {
            e.file = Some(path.to_path_buf());
            e
        })?;
        s.file = Some(path.to_path_buf());
        Ok(s)
    }

    /// Reads and validates a mechanism description from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, DescriptionError> {
        let mechanism =
            description::from_toml_str(text).map_err(|e| closed_chain_error(e, None))?;
        Ok(MechanismSource {
            mechanism,
            text: text.to_string(),
            file: None,
        })
    }

    /// A shipped mechanism by name (`four-bar`, `planar-stewart`, `cooperative-arms`).
    pub fn shipped(name: &str) -> Result<Self, DescriptionError> {
        let text = match name {
            "four-bar" => description::FOUR_BAR_TOML,
            "planar-stewart" | "stewart" => description::STEWART_TOML,
            "cooperative-arms" | "cooperative" => description::COOPERATIVE_TOML,
            _ => {
                return Err(DescriptionError {
                    file: None,
                    line: None,
                    column: None,
                    field: String::new(),
                    message: format!(
                        "unknown mechanism `{name}`; shipped: {}",
                        description::SHIPPED.join(", ")
                    ),
                })
            }
        };
        Self::from_toml_str(text)
    }

    /// Derives the closed-form reduced kinematics ([`derive_mechanism`]); errors name the file.
    pub fn derive(&self) -> Result<MechanismDerivation, DescriptionError> {
        derive_mechanism(&self.mechanism, &self.text)
            .map_err(|e| e.into_description_error(self.file.as_deref()))
    }
}

/// Does this TOML text describe a closed mechanism (a top-level `[[chains]]` array) rather than a
/// serial robot?
pub fn is_mechanism_toml(text: &str) -> bool {
    text.parse::<toml::Table>()
        .map(|t| t.contains_key("chains"))
        .unwrap_or(false)
}

/// A frame along a chain: position and rotation `(cos, sin)` of its accumulated angle.
#[derive(Clone, Debug)]
struct Frame {
    x: Poly,
    y: Poly,
    c: Poly,
    s: Poly,
}

impl Frame {
    /// `self · Trans(dx, dy) · Rot(c, s)`.
    fn compose(&self, dx: &Poly, dy: &Poly, c: &Poly, s: &Poly) -> Frame {
        Frame {
            x: self.x.add(&self.c.mul(dx)).sub(&self.s.mul(dy)),
            y: self.y.add(&self.s.mul(dx)).add(&self.c.mul(dy)),
            c: self.c.mul(c).sub(&self.s.mul(s)),
            s: self.s.mul(c).add(&self.c.mul(s)),
        }
    }
}

struct Reader<'a> {
    table: toml::Table,
    params: &'a [(String, f64)],
}

impl Reader<'_> {
    fn chain(&self, ci: usize) -> Option<&toml::Table> {
        self.table.get("chains")?.as_array()?.get(ci)?.as_table()
    }

    fn pose_table<'t>(t: Option<&'t toml::Table>, key: &str) -> Option<&'t toml::Table> {
        t?.get(key)?.as_table()
    }

    /// The symbolic `x`, `y` and the constant angle's `(cos, sin)` of a pose table.
    fn pose(
        &self,
        t: Option<&toml::Table>,
        path: &str,
        angle: f64,
    ) -> Result<(Poly, Poly, Poly, Poly), MechanismError> {
        let len = |k: &str| -> Result<Poly, MechanismError> {
            let field = format!("{path}.{k}");
            match t.and_then(|t| t.get(k)) {
                None => Ok(Poly::zero()),
                Some(toml::Value::Float(f)) => constant(*f, &field),
                Some(toml::Value::Integer(i)) => constant(*i as f64, &field),
                Some(toml::Value::String(s)) => {
                    parse_length(s, self.params).map_err(|m| MechanismError::new(field, m))
                }
                Some(_) => Err(MechanismError::new(
                    field,
                    "expected a number or expression",
                )),
            }
        };
        if let Some(toml::Value::String(s)) = t.and_then(|t| t.get("angle")) {
            if let Some(p) = self.params.iter().find(|(n, _)| mentions(s, n)) {
                return Err(MechanismError::new(
                    format!("{path}.angle"),
                    format!(
                        "fixed angles must be constants (numbers and `pi`) for the generator; \
                         `{s}` uses the parameter `{}`",
                        p.0
                    ),
                ));
            }
        }
        let (c, s) = angle_cos_sin(angle, &format!("{path}.angle"))?;
        Ok((len("x")?, len("y")?, c, s))
    }
}

fn mentions(expr: &str, name: &str) -> bool {
    expr.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .any(|w| w == name)
}

fn constant(x: f64, field: &str) -> Result<Poly, MechanismError> {
    Rational::from_f64_decimal(x)
        .map(Poly::constant)
        .map_err(|e| MechanismError::new(field, e.to_string()))
}

/// A prismatic joint's unit axis (normalised by the runtime), read with the "snap unit" rule.
fn unit_axis(axis: [f64; 2], field: &str) -> Result<(Poly, Poly), MechanismError> {
    let r = |x: f64| {
        Rational::from_f64_snapped(x)
            .map(Poly::constant)
            .map_err(|e| MechanismError::new(field, e.to_string()))
    };
    Ok((r(axis[0])?, r(axis[1])?))
}

/// `(cos α, sin α)` of a fixed angle: exact at multiples of `π/2`, otherwise the `f64` values
/// read exactly.
fn angle_cos_sin(a: f64, field: &str) -> Result<(Poly, Poly), MechanismError> {
    let quarter = a / std::f64::consts::FRAC_PI_2;
    if (quarter - quarter.round()).abs() < 1e-12 {
        let k = (quarter.round() as i64).rem_euclid(4);
        let (c, s) = [(1, 0), (0, 1), (-1, 0), (0, -1)][k as usize];
        return Ok((Poly::integer(c), Poly::integer(s)));
    }
    let (s, c) = a.sin_cos();
    Ok((constant(c, field)?, constant(s, field)?))
}

/// Parses a length expression of the parameters into a polynomial: numbers (read exactly),
/// parameter names, `pi` (its `f64` value), `+ − * /` and parentheses.
pub fn parse_length(src: &str, params: &[(String, f64)]) -> Result<Poly, String> {
    let toks = tokenize(src)?;
    let mut p = ExprParser {
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

struct ExprParser<'a> {
    toks: &'a [Tok],
    pos: usize,
    params: &'a [(String, f64)],
}

impl ExprParser<'_> {
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

/// The columns `cols` of `m`.
fn select_columns(m: &Matrix, cols: &[usize]) -> Matrix {
    Matrix::from_fn(m.rows(), cols.len(), |r, c| m.get(r, cols[c]).clone())
}

/// The adjugate `adj(A)` (transposed cofactors) of a square matrix, so `A adj(A) = det(A) I`.
pub fn adjugate(a: &Matrix) -> Result<Matrix, SymbolicError> {
    let n = a.rows();
    if n != a.cols() {
        return Err(SymbolicError::Overflow);
    }
    if n == 0 {
        return Ok(Matrix::zeros(0, 0));
    }
    if n == 1 {
        return Ok(Matrix::identity(1));
    }
    let mut out = Matrix::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            // Entry (i, j) of adj(A) is the cofactor of A at (j, i).
            let minor = Matrix::from_fn(n - 1, n - 1, |r, c| {
                let rr = if r < j { r } else { r + 1 };
                let cc = if c < i { c } else { c + 1 };
                a.get(rr, cc).clone()
            });
            let mut cof = minor.det()?;
            if (i + j) % 2 == 1 {
                cof = cof.neg();
            }
            out.set(i, j, cof);
        }
    }
    Ok(out)
}

/// Derives the closed-form reduced kinematics (7)–(8) of a mechanism (see the module docs).
///
/// `text` is the mechanism's TOML description (the source of `mechanism`), read again for the
/// symbolic length expressions. Errors: `J_Cp` not square (`chains`), contact models
/// (`chains[k].contact`), angles depending on parameters, unknown parameters.
pub fn derive_mechanism(
    mechanism: &Mechanism,
    text: &str,
) -> Result<MechanismDerivation, MechanismError> {
    let m = mechanism;
    let n = m.n_joints();
    let r = m.n_constraints();
    let n_p = m.passive_indices().len();
    if n_p != r {
        return Err(MechanismError::new(
            "chains",
            format!(
                "J_Cp is {r} × {n_p} ({r} structural equations, {n_p} passive joints): the \
                 closed-form reduced Jacobian (8) needs a square J_Cp (as many passive joints as \
                 structural equations); use the runtime's numeric `Mechanism::reduced`, which \
                 handles r > n_p with a left inverse"
            ),
        ));
    }
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| MechanismError::new("", format!("TOML syntax: {e}")))?;
    let reader = Reader {
        table,
        params: &m.parameters,
    };
    for (ci, ch) in m.chains.iter().enumerate() {
        let t = reader.chain(ci);
        if t.is_none_or(|t| t.contains_key("contact")) {
            return Err(MechanismError::new(
                format!("chains[{ci}].contact"),
                format!(
                    "chain `{}`: contact models are not supported by the generator",
                    ch.name
                ),
            ));
        }
    }

    // Steps 1–2: chain poses and Jacobians S J_k, placed in their columns of θ.
    let mut chain_jacobians = Vec::with_capacity(m.chains.len());
    for (ci, ch) in m.chains.iter().enumerate() {
        let ct = reader.chain(ci);
        let path = format!("chains[{ci}]");
        let (bx, by, bc, bs) = reader.pose(
            Reader::pose_table(ct, "base"),
            &format!("{path}.base"),
            ch.base.angle,
        )?;
        let mut g = Frame {
            x: bx,
            y: by,
            c: bc,
            s: bs,
        };
        let range = m.chain_range(ci);
        let joints_t = ct
            .and_then(|t| t.get("joints"))
            .and_then(toml::Value::as_array);
        let mut frames = Vec::with_capacity(ch.joints.len());
        for (ji, j) in ch.joints.iter().enumerate() {
            let k = range.start + ji;
            let jt = joints_t
                .and_then(|a| a.get(ji))
                .and_then(toml::Value::as_table);
            let (ox, oy, oc, os) = reader.pose(
                Reader::pose_table(jt, "origin"),
                &format!("{path}.joints[{ji}].origin"),
                j.origin.angle,
            )?;
            g = g.compose(&ox, &oy, &oc, &os);
            frames.push(g.clone());
            g = match j.kind {
                JointType::Revolute => {
                    g.compose(&Poly::zero(), &Poly::zero(), &Poly::cos(k), &Poly::sin(k))
                }
                JointType::Prismatic { axis } => {
                    let (ax, ay) = unit_axis(axis, &format!("{path}.joints[{ji}].axis"))?;
                    let q = Poly::joint(k);
                    g.compose(&q.mul(&ax), &q.mul(&ay), &Poly::one(), &Poly::zero())
                }
            };
        }
        let (tx, ty, tc, ts) = reader.pose(
            Reader::pose_table(ct, "tip"),
            &format!("{path}.tip"),
            ch.tip.angle,
        )?;
        let end = g.compose(&tx, &ty, &tc, &ts);
        let mut jk = Matrix::zeros(3, n);
        for (ji, (j, f)) in ch.joints.iter().zip(&frames).enumerate() {
            let k = range.start + ji;
            match j.kind {
                JointType::Revolute => {
                    jk.set(0, k, end.y.sub(&f.y).neg());
                    jk.set(1, k, end.x.sub(&f.x));
                    jk.set(2, k, Poly::one());
                }
                JointType::Prismatic { axis } => {
                    let (ax, ay) = unit_axis(axis, &format!("{path}.joints[{ji}].axis"))?;
                    jk.set(0, k, f.c.mul(&ax).sub(&f.s.mul(&ay)));
                    jk.set(1, k, f.s.mul(&ax).add(&f.c.mul(&ay)));
                }
            }
        }
        chain_jacobians.push(jk);
    }

    // Step 3: J_C = Ã J (rows J_1 − J_k), J_A = S_x (1/m) Σ J_k.
    let nc = m.chains.len();
    let mut j_c = Matrix::zeros(r, n);
    for k in 1..nc {
        let d = chain_jacobians[0].sub(&chain_jacobians[k]);
        for row in 0..3 {
            for col in 0..n {
                j_c.set(3 * (k - 1) + row, col, d.get(row, col).clone());
            }
        }
    }
    let mut sum = Matrix::zeros(3, n);
    for jk in &chain_jacobians {
        sum = sum.add(jk);
    }
    let inv_m = Rational::new(1, nc as i64).unwrap_or_else(Rational::one);
    let j_a = Matrix::from_fn(m.outputs.len(), n, |o, col| {
        sum.get(m.outputs[o].index(), col).scale(&inv_m)
    });

    // Step 4: det, adjugate, numerators.
    let active = m.active_indices().to_vec();
    let passive = m.passive_indices().to_vec();
    let j_ca = select_columns(&j_c, &active);
    let j_cp = select_columns(&j_c, &passive);
    let j_aa = select_columns(&j_a, &active);
    let j_ap = select_columns(&j_a, &passive);
    let sym = |e: SymbolicError| MechanismError::new("chains", format!("J_Cp: {e}"));
    let det_j_cp = j_cp.det().map_err(sym)?;
    if det_j_cp.is_zero() {
        return Err(MechanismError::new(
            "chains",
            "det J_Cp is identically zero: the passive joints are never determined by the \
             active ones (structural singularity at every configuration)",
        ));
    }
    let adj_j_cp = adjugate(&j_cp).map_err(sym)?;
    let passive_numerator = adj_j_cp.mul(&j_ca).scale(&Poly::integer(-1));
    let reduced_numerator = j_aa.scale(&det_j_cp).add(&j_ap.mul(&passive_numerator));

    Ok(MechanismDerivation {
        name: m.name.clone(),
        params: m.parameters.iter().map(|(n, _)| n.clone()).collect(),
        param_values: m.parameters.iter().map(|(_, v)| *v).collect(),
        joint_names: m.joint_names().iter().map(|s| s.to_string()).collect(),
        joint_is_linear: m
            .joints()
            .map(|j| matches!(j.kind, JointType::Prismatic { .. }))
            .collect(),
        active,
        passive,
        outputs: m.outputs.clone(),
        j_c,
        j_a,
        det_j_cp,
        adj_j_cp,
        reduced_numerator,
        passive_numerator,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::symbolic::Env;
    use trocar::nalgebra::DVector;

    #[test]
    fn lengths_are_symbolic() {
        let p = vec![("l0".to_string(), 1.0), ("l3".to_string(), 0.6)];
        let e = parse_length("-l0/2 + 2*(l3 - 0.5)", &p).unwrap();
        assert_eq!(
            e,
            Poly::param(0)
                .scale(&Rational::new(-1, 2).unwrap())
                .add(&Poly::param(1).scale(&Rational::integer(2)))
                .sub(&Poly::one())
        );
        assert!(parse_length("l9", &p).unwrap_err().contains("l9"));
        assert!(parse_length("1/(l0 - l0)", &p).is_err());
    }

    #[test]
    fn adjugate_times_matrix_is_det_identity() {
        let names = ["a"];
        let m = Matrix::from_fn(3, 3, |i, j| {
            Poly::parse(
                &format!("c{} + {}*a + s{}", i + 1, i * 3 + j, j + 1),
                &names,
            )
            .unwrap()
        });
        let adj = adjugate(&m).unwrap();
        let det = m.det().unwrap();
        assert_eq!(m.mul(&adj), Matrix::identity(3).scale(&det));
    }

    /// The symbolic J_C and J_A of the four-bar linkage equal the runtime's numeric ones.
    #[test]
    fn four_bar_matches_runtime_differential() {
        let src = MechanismSource::shipped("four-bar").unwrap();
        let d = src.derive().unwrap();
        let q = [1.1, 5.3, 1.7, 4.9];
        let num = src
            .mechanism
            .differential(&DVector::from_row_slice(&q))
            .unwrap();
        let env = Env {
            q: &q,
            params: &d.param_values,
        };
        let jc = d.j_c.eval(&env);
        let ja = d.j_a.eval(&env);
        for (i, row) in jc.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                assert!((x - num.j_c[(i, j)]).abs() < 1e-13, "J_C[{i}][{j}]");
            }
        }
        for (j, x) in ja[0].iter().enumerate() {
            assert!((x - num.j_a[(0, j)]).abs() < 1e-13);
        }
        let det = d.det_j_cp.eval(&env);
        assert!((det - num.j_cp.determinant()).abs() < 1e-12);
    }

    /// The numerators satisfy their defining identities exactly (symbolically):
    /// `J_Cp · (−adj(J_Cp) J_Ca) = −det(J_Cp) J_Ca` and
    /// `det(J_Cp) J_Aa + J_Ap · (−adj(J_Cp) J_Ca) = det(J_Cp) · J`.
    #[test]
    fn numerators_solve_the_constraint_exactly() {
        for name in ["four-bar", "planar-stewart"] {
            let d = MechanismSource::shipped(name).unwrap().derive().unwrap();
            let j_cp = select_columns(&d.j_c, &d.passive);
            let j_ca = select_columns(&d.j_c, &d.active);
            assert_eq!(
                j_cp.mul(&d.passive_numerator),
                j_ca.scale(&d.det_j_cp.neg()),
                "{name}"
            );
            let j_aa = select_columns(&d.j_a, &d.active);
            let j_ap = select_columns(&d.j_a, &d.passive);
            assert_eq!(
                j_aa.scale(&d.det_j_cp).add(&j_ap.mul(&d.passive_numerator)),
                d.reduced_numerator,
                "{name}"
            );
        }
    }

    #[test]
    fn non_square_j_cp_is_an_error() {
        let e = MechanismSource::shipped("cooperative-arms")
            .unwrap()
            .derive()
            .unwrap_err();
        assert_eq!(e.field, "chains");
        assert!(e.message.contains("square"), "{}", e.message);
    }

    #[test]
    fn parameter_angles_are_rejected() {
        let text = description::FOUR_BAR_TOML.replace(
            "base = { x = \"l0/2\" }",
            "base = { x = \"l0/2\", angle = \"l0 - 1\" }",
        );
        assert_ne!(text, description::FOUR_BAR_TOML);
        let e = MechanismSource::from_toml_str(&text)
            .unwrap()
            .derive()
            .unwrap_err();
        assert_eq!(e.field, "chains[1].base.angle");
    }
}
