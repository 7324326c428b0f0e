//! The symbolic derivation of a mechanism's reduced kinematics (see the parent module).

use crate::symbolic::{Matrix, Poly, Rational, SymbolicError};
use std::fmt;
use std::path::Path;
use trocar_model::closed_chain::{MechanismModel, Output, PlanarJointKind, PoseExpr};
use trocar_model::description::DescriptionError;
use trocar_model::expr::Expr;

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
    pub(crate) fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
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

/// Derives the closed-form reduced kinematics of `model` ([`derive_mechanism`]); errors name the
/// model's file.
pub fn derive(model: &MechanismModel) -> Result<MechanismDerivation, DescriptionError> {
    derive_mechanism(model).map_err(|e| e.into_description_error(model.file.as_deref()))
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

/// A length expression as a polynomial of the parameters `names` (parameter `k` is
/// [`Poly::param`]`(k)`), through [`Poly::from_expr`] as for serial descriptions: numbers read
/// exactly as their decimals, `pi` as its `f64` value.
pub fn length_poly(e: &Expr, names: &[&str]) -> Result<Poly, SymbolicError> {
    Poly::from_expr(e, &|name| {
        names.iter().position(|n| *n == name).map(Poly::param)
    })
}

/// The symbolic `x`, `y` and the constant angle's `(cos, sin)` of a pose.
fn pose(
    m: &MechanismModel,
    p: &PoseExpr,
    path: &str,
) -> Result<(Poly, Poly, Poly, Poly), MechanismError> {
    let names = m.parameter_names();
    let len = |e: &Expr, k: &str| {
        let poly = length_poly(e, &names)
            .map_err(|err| MechanismError::new(format!("{path}.{k}"), err.to_string()))?;
        if poly.len() > MAX_LENGTH_TERMS {
            return Err(MechanismError::new(
                format!("{path}.{k}"),
                format!(
                    "`{e}` expands to {} terms; a length of the generator has at most \
                     {MAX_LENGTH_TERMS} (every product of the derivation multiplies them)",
                    poly.len()
                ),
            ));
        }
        Ok(poly)
    };
    // (the first parameter in declaration order, as named before)
    let first = p
        .angle
        .symbols()
        .into_iter()
        .filter_map(|s| m.parameter_index(s))
        .min();
    if let Some(k) = first {
        return Err(MechanismError::new(
            format!("{path}.angle"),
            format!(
                "fixed angles must be constants (numbers and `pi`) for the generator; \
                 the angle uses the parameter `{}`",
                m.parameters[k].name
            ),
        ));
    }
    let angle_field = format!("{path}.angle");
    let angle = p
        .angle
        .eval(|_| None)
        .map_err(|err| MechanismError::new(angle_field.clone(), err.to_string()))?;
    let (c, s) = angle_cos_sin(angle, &angle_field)?;
    Ok((len(&p.x, "x")?, len(&p.y, "y")?, c, s))
}

fn constant(x: f64, field: &str) -> Result<Poly, MechanismError> {
    Rational::from_f64_decimal(x)
        .map(Poly::constant)
        .map_err(|e| MechanismError::new(field, e.to_string()))
}

/// A prismatic joint's unit axis (normalised as in the numeric model), read with the "snap
/// unit" rule.
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

/// The columns `cols` of `m`.
fn select_columns(m: &Matrix, cols: &[usize]) -> Matrix {
    Matrix::from_fn(m.rows(), cols.len(), |r, c| m.get(r, cols[c]).clone())
}

/// The most passive joints (the size of the square `J_Cp`) whose closed forms are derived: the
/// determinant and adjugate grow steeply with it (a six-legged planar platform, 15, takes a few
/// seconds; seven legs ran for minutes and eight overflowed the polynomial exponents).
pub const MAX_PASSIVE: usize = 15;

/// The most terms a length of a mechanism may expand to (`(l1 + l2 + l3 + l4)^30` has 5456):
/// the derivation multiplies lengths together, so large ones made it run for minutes.
pub const MAX_LENGTH_TERMS: usize = 64;

/// Derives the closed-form reduced kinematics (7)–(8) of a mechanism (see the module docs).
///
/// Errors: `J_Cp` not square (`chains`), contact models (`chains[k].contact`), angles depending
/// on parameters, lengths the polynomials cannot hold or of more than
/// [`MAX_LENGTH_TERMS`] terms, more than [`MAX_PASSIVE`] passive joints.
pub fn derive_mechanism(m: &MechanismModel) -> Result<MechanismDerivation, MechanismError> {
    let (active, passive) = m.partition();
    let n = active.len() + passive.len();
    let r = m.n_constraints();
    let n_p = passive.len();
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
    if n_p > MAX_PASSIVE {
        return Err(MechanismError::new(
            "chains",
            format!(
                "J_Cp is {n_p} × {n_p}: the closed forms are derived for at most {MAX_PASSIVE} \
                 passive joints (their cost grows steeply with the size of J_Cp; a planar \
                 platform of six legs has 15); use the runtime's numeric `Mechanism::reduced`"
            ),
        ));
    }
    for (ci, ch) in m.chains.iter().enumerate() {
        if ch.contact.is_some() {
            return Err(MechanismError::new(
                format!("chains[{ci}].contact"),
                format!(
                    "chain `{}`: contact models are not supported by the generator",
                    ch.name
                ),
            ));
        }
    }
    let nominal = m.nominal_values();
    let at_nominal = m.lookup(&nominal);

    // Steps 1–2: chain poses and Jacobians S J_k, placed in their columns of θ.
    let mut chain_jacobians = Vec::with_capacity(m.chains.len());
    let mut start = 0;
    for (ci, ch) in m.chains.iter().enumerate() {
        let path = format!("chains[{ci}]");
        let (bx, by, bc, bs) = pose(m, &ch.base, &format!("{path}.base"))?;
        let mut g = Frame {
            x: bx,
            y: by,
            c: bc,
            s: bs,
        };
        let mut frames = Vec::with_capacity(ch.joints.len());
        let mut axes = Vec::with_capacity(ch.joints.len());
        for (ji, j) in ch.joints.iter().enumerate() {
            let k = start + ji;
            let (ox, oy, oc, os) = pose(m, &j.origin, &format!("{path}.joints[{ji}].origin"))?;
            g = g.compose(&ox, &oy, &oc, &os);
            frames.push(g.clone());
            let field = format!("{path}.joints[{ji}].axis");
            let axis = j
                .kind
                .unit_axis(&at_nominal, &field)
                .map_err(|e| MechanismError::new(e.field, e.message))?
                .map(|a| unit_axis(a, &field))
                .transpose()?;
            g = match &axis {
                None => g.compose(&Poly::zero(), &Poly::zero(), &Poly::cos(k), &Poly::sin(k)),
                Some((ax, ay)) => {
                    let q = Poly::joint(k);
                    g.compose(&q.mul(ax), &q.mul(ay), &Poly::one(), &Poly::zero())
                }
            };
            axes.push(axis);
        }
        let (tx, ty, tc, ts) = pose(m, &ch.tip, &format!("{path}.tip"))?;
        let end = g.compose(&tx, &ty, &tc, &ts);
        let mut jk = Matrix::zeros(3, n);
        for (ji, (axis, f)) in axes.iter().zip(&frames).enumerate() {
            let k = start + ji;
            match axis {
                None => {
                    jk.set(0, k, end.y.sub(&f.y).neg());
                    jk.set(1, k, end.x.sub(&f.x));
                    jk.set(2, k, Poly::one());
                }
                Some((ax, ay)) => {
                    jk.set(0, k, f.c.mul(ax).sub(&f.s.mul(ay)));
                    jk.set(1, k, f.s.mul(ax).add(&f.c.mul(ay)));
                }
            }
        }
        chain_jacobians.push(jk);
        start += ch.joints.len();
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
    let adj_j_cp = j_cp.adjugate().map_err(sym)?;
    let passive_numerator = adj_j_cp.mul(&j_ca).scale(&Poly::integer(-1));
    let reduced_numerator = j_aa.scale(&det_j_cp).add(&j_ap.mul(&passive_numerator));

    Ok(MechanismDerivation {
        name: m.name.clone(),
        params: m.parameters.iter().map(|p| p.name.clone()).collect(),
        param_values: nominal.clone(),
        joint_names: m.joint_names(),
        joint_is_linear: m
            .chains
            .iter()
            .flat_map(|c| &c.joints)
            .map(|j| matches!(j.kind, PlanarJointKind::Prismatic { .. }))
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
    use trocar_model::closed_chain::FOUR_BAR_TOML;

    #[test]
    fn lengths_are_symbolic() {
        let p = ["l0", "l3"];
        let parse_length = |s: &str, p: &[&str]| -> Result<Poly, String> {
            let e = Expr::parse(s).map_err(|e| e.to_string())?;
            length_poly(&e, p).map_err(|e| e.to_string())
        };
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
        let adj = m.adjugate().unwrap();
        let det = m.det().unwrap();
        assert_eq!(m.mul(&adj), Matrix::identity(3).scale(&det));
    }

    /// The numerators satisfy their defining identities exactly (symbolically):
    /// `J_Cp · (−adj(J_Cp) J_Ca) = −det(J_Cp) J_Ca` and
    /// `det(J_Cp) J_Aa + J_Ap · (−adj(J_Cp) J_Ca) = det(J_Cp) · J`.
    #[test]
    fn numerators_solve_the_constraint_exactly() {
        for name in ["four-bar", "planar-stewart"] {
            let d = derive(&MechanismModel::shipped(name).unwrap()).unwrap();
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
        let e =
            derive_mechanism(&MechanismModel::shipped("cooperative-arms").unwrap()).unwrap_err();
        assert_eq!(e.field, "chains");
        assert!(e.message.contains("square"), "{}", e.message);
    }

    #[test]
    fn parameter_angles_are_rejected() {
        let text = FOUR_BAR_TOML.replace(
            "base = { x = \"l0/2\" }",
            "base = { x = \"l0/2\", angle = \"l0 - 1\" }",
        );
        assert_ne!(text, FOUR_BAR_TOML);
        let e = derive_mechanism(&MechanismModel::from_toml_str(&text).unwrap()).unwrap_err();
        assert_eq!(e.field, "chains[1].base.angle");
    }
}
