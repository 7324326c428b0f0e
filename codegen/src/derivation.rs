//! The thesis's derivation (chapter 3) carried out on symbols, from any valid
//! [`RobotDescription`].
//!
//! Steps, with the thesis's equation numbers (see [`derive()`]):
//!
//! 1. Each joint `k` gives `T_k = origin_k · exp(ξ̂_k q_k)` (parent frame → `F_k`), with `ξ_k` the
//!    joint twist in `F_k` (2.25)–(2.27), linear part first. A revolute joint about an oblique
//!    axis (not a coordinate axis of `F_k`) is written in its link frame turned by a constant
//!    rotation `A_k` whose `z` axis is the joint's axis, `F'_k = F_k A_k`: Rodrigues' formula
//!    (2.14) is then `R_z(q_k)` and the twist `(0, ẑ)`, and the chain is
//!    `T'_k = A_{k−1}⁻¹ · origin_k · A_k · R_z(q_k)` ([`Derivation::frame_turns`]). A product that
//!    ends at a link frame (`g_0i`, `J^B_0i`, the end effector's `g_ne`) turns back by `A⁻¹` there,
//!    one that starts at one (`g_ie`) by `A`, so every result is in the description's frames.
//!    Prismatic joints and joints given as a twist keep their frames.
//! 2. Forward kinematics `g_0e = T_1 ⋯ T_n · g_ne` and `g_0i = T_1 ⋯ T_i` (2.21).
//! 3. Body Jacobians (2.53)–(2.55), (3.13): column `k` is `Ad_{g_ke}⁻¹ ξ_k`; `J^B_0i` is the same
//!    for the chain cut at `F_i`, `J^B_0e2` the columns `j..n` of `J^B_0e`.
//! 4. The constraint: `Λ = H Ad_{g_ri}` (3.4), (3.22), (3.26); the null-space basis `Λ#`
//!    ((3.23), (3.27) for the wrist presets, see [`NullSpaceBasis`] and
//!    [`ConstraintDesc::basis`](trocar_model::description::ConstraintDesc::basis)); `Λ† = Λᵀ(ΛΛᵀ)⁻¹`.
//! 5. `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]` (3.15), `J_c = Ad_{g_ei} Λ†` (3.33).
//!    With the constraint on the last link (`i = n`) `J^B_0e2` has no column and
//!    `J^r_0e = Ad_{g_ei} Λ#`.
//! 6. The task (a `[task]` section): `S J^r_0e`, the rows of the end-effector twist the task
//!    commands.
//! 7. Manipulability (3.36)–(3.39) in closed form, of `S J^r` with a task and of `J^r` without:
//!    `|det|` when square, otherwise `sqrt(Σ maximal minors²)` (Cauchy–Binet); the squared value
//!    is a polynomial.
//!
//! Every matrix is a [`Matrix`] of [`Poly`]s: sums of monomials in `s_k, c_k, q_k`, parameters
//! (also negative powers), `Inv` atoms and `Node` atoms, with rational coefficients. Products
//! along the chain are expanded into canonical form while their entries stay short
//! ([`SHARE_TERMS`]); a longer entry becomes a shared subexpression (a `Node`, see
//! [`Poly::shared`]), so a long or generic chain is derived as an expression graph whose size
//! grows linearly with the joints. Coefficients are exact while short and floating beyond
//! (rule "float stays float" of [`crate::symbolic::number`]): the thesis's robots are derived
//! exactly and canonically, a calibrated robot's float geometry in `f64` precision. The
//! per-joint transforms are kept as well ([`Derivation::joint_transforms`], in the turned frames
//! of step 1) so an emitter may evaluate forward kinematics as a product instead of the expanded
//! form.
//!
//! # For an emitter
//! Walk [`Matrix::entries`] (row-major) and [`Poly::terms`]: each term is a [`Rational`]
//! coefficient ([`Rational::to_f64`], or [`Rational::to_parts`] for exact literals) times a
//! [`crate::symbolic::Monomial`] whose [`factors`](crate::symbolic::Monomial::factors) are
//! `(Atom, exponent)`: `Sin(k)`/`Cos(k)` → one `sin_cos(q[k])` per joint, `Joint(k)` → `q[k]`,
//! `Param(p)` with a possibly negative exponent → `params.<name>` (hoist `1/param`),
//! `Inv(id)` → `1 / P` with `P` = [`crate::symbolic::inverse_denominator`]`(id)` (hoist it;
//! it never depends on an `Inv` itself), `Node(id)` → one value for the polynomial
//! [`crate::symbolic::node_definition`]`(id)` (hoist it; it refers only to earlier nodes). Which joints/parameters a result needs:
//! [`Poly::joints`], [`Matrix::joints`], [`Derivation::dependencies`].
//!
//! # Size budgets
//! Generic chains grow like `3^n` terms when fully expanded; with shared subexpressions
//! ([`SHARE_TERMS`]) no product is expanded beyond a few terms per entry. The full-chain `g_0e`,
//! `J^B_0e` are formed only within [`EXPANSION_BUDGET`] (else `None`: use the factorisation
//! `g_0e = g_0i g_ie`, `J^B_0e = [Ad_{g_ei} J^B_0i | J^B_0e2]`), and the closed-form
//! manipulability only from a canonical expansion within [`MANIPULABILITY_BUDGET`] terms.

use crate::symbolic::{rational_null_space, Matrix, Poly, Rational, SymbolicError, Transform};
use std::collections::BTreeSet;
use std::fmt;
pub use trocar::constraint::NullSpaceBasis;
use trocar_model::description::{
    admit, AdmissionError, DescriptionError, JointKind, Linear, Origin, RobotDescription, Rotation,
};

/// What kind of problem a [`DerivationError`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DerivationErrorKind {
    /// A malformed field (non-finite number, non-unit axis, unknown parameter, bad `H`, ...).
    Invalid,
    /// The method's requirement `n − r ≥ 6` (and `m = 6 − r + n − i ≥ 6`) does not hold.
    TooFewJoints,
    /// The wrist preset's basis (3.23)/(3.27) is not a null basis of `Λ` for this geometry.
    WristMismatch,
    /// A symbolic operation failed (division by an expression that is identically zero).
    Symbolic,
}

/// Why a description could not be derived, and which field is at fault.
#[derive(Clone, Debug, PartialEq)]
pub struct DerivationError {
    /// The kind of problem.
    pub kind: DerivationErrorKind,
    /// The field, as a path such as `joints[3].axis` or `constraint.h`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl DerivationError {
    fn new(
        kind: DerivationErrorKind,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        DerivationError {
            kind,
            field: field.into(),
            message: message.into(),
        }
    }

    fn symbolic(field: &str, e: SymbolicError) -> Self {
        Self::new(DerivationErrorKind::Symbolic, field, e.to_string())
    }

    /// The same error as a [`DescriptionError`] located in `desc`'s source file (and at the
    /// joint's line when the field names a joint that has a location).
    pub fn into_description_error(self, desc: &RobotDescription) -> DescriptionError {
        let loc = self
            .field
            .strip_prefix("joints[")
            .and_then(|s| s.split(']').next())
            .and_then(|k| k.parse::<usize>().ok())
            .and_then(|k| desc.joints.get(k))
            .and_then(|j| j.location);
        DescriptionError {
            file: desc.source.clone(),
            line: loc.map(|l| l.line),
            column: loc.map(|l| l.column),
            field: self.field,
            message: self.message,
        }
    }
}

impl fmt::Display for DerivationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "field `{}`: {}", self.field, self.message)
    }
}

impl std::error::Error for DerivationError {}

/// The closed form of the manipulability of `J^r_0e` (3.36)–(3.39).
#[derive(Clone, Debug, PartialEq)]
pub enum ManipulabilityForm {
    /// `J^r` is square: `w = |det J^r|`, the polynomial `det J^r` given.
    AbsDet(Poly),
    /// `J^r` is wide: `w = sqrt(Σ minors²)` (Cauchy–Binet: `det(J Jᵀ) = Σ minors²`), with each
    /// maximal minor and the columns it keeps (0-based, increasing).
    SqrtSumOfSquares(Vec<(Vec<usize>, Poly)>),
}

/// Manipulability of `J^r_0e` in closed form.
#[derive(Clone, Debug, PartialEq)]
pub struct Manipulability {
    /// `w² = det(J^r J^rᵀ)`: a polynomial, cheap for thresholds (3.44).
    pub squared: Poly,
    /// How `w` itself is computed.
    pub form: ManipulabilityForm,
}

/// Everything derived for the constraint (present when the description has one).
#[derive(Clone, Debug, PartialEq)]
pub struct ConstrainedDerivation {
    /// The constrained link `i` (1-based); `j = i + 1`.
    pub link: usize,
    /// Number of constrained directions `r` (rows of `H`).
    pub r: usize,
    /// Number of columns of `J^r`: `m = 6 − r + n − i`.
    pub m: usize,
    /// `H ∈ R^{r×6}` (3.1), exact.
    pub h: Matrix,
    /// `g_ir`, the constraint frame `F_r` relative to `F_i`.
    pub g_ir: Transform,
    /// `Λ = H Ad_{g_ri}` (3.4), `r × 6`.
    pub lambda: Matrix,
    /// Which basis `Λ#` is: the thesis's (3.23) or (3.27) for a wrist preset, otherwise
    /// [`NullSpaceBasis::Computed`], here built exactly: `Λ# = Ad_{g_ir} N`, with `N` the exact
    /// null basis of `H` from its reduced row echelon form (one column per free coordinate of
    /// `H`, in increasing order, see [`rational_null_space`]). Since `Λ = H Ad_{g_ri}` and
    /// `Ad_{g_ri} Ad_{g_ir} = I`, `Λ Λ# = H N = 0`; no division is needed. `v0i` is then the free
    /// coordinates of the twist of `F_r` (body frame of `F_r`), and the manipulability of `J^r`
    /// refers to this basis.
    pub basis: NullSpaceBasis,
    /// `Λ#`, `6 × (6 − r)`, with `Λ Λ# = 0` (checked symbolically for the thesis bases; for the
    /// derived basis it holds by construction, exactly when `R_ir` is exact, otherwise to rounding).
    pub lambda_sharp: Matrix,
    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`, `6 × r` (3.31)–(3.33).
    pub lambda_pinv: Matrix,
    /// `g_0i(q_1..q_i)`, forward kinematics to the constrained link.
    pub fk_i: Transform,
    /// `g_ie(q_j..q_n)`.
    pub g_ie: Transform,
    /// `Ad_{g_ei} = Ad_{g_ie}⁻¹`, `6 × 6`.
    pub ad_g_ei: Matrix,
    /// `J^B_0i(q_1..q_i)`, `6 × i` (3.13).
    pub body_jacobian_i: Matrix,
    /// `J^B_0e2(q_j..q_n)`, `6 × (n − i)` (3.14).
    pub body_jacobian_e2: Matrix,
    /// `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, `6 × m` (3.15).
    pub jr: Matrix,
    /// `J_c = Ad_{g_ei} Λ†`, `6 × r` (3.33).
    pub jc: Matrix,
    /// The task selection and task Jacobian `S J^r`, when the description has a `[task]`.
    pub task: Option<TaskDerivation>,
    /// Manipulability (3.36)–(3.42) in closed form of what the task commands — `S J^r` with a
    /// task, `J^r` without; `None` when that matrix has more than
    /// [`MANIPULABILITY_BUDGET`] terms (generic chains: the minors would swell); then compute
    /// `det(J^r J^rᵀ)` numerically from the evaluated `J^r` (a 6×6 determinant).
    pub manipulability: Option<Manipulability>,
}

/// The task of a `[task]` section: `S ∈ R^{t×6}` selects rows of the end-effector body twist
/// `V^B_0e` (components in `F_e`), and `S J^r_0e` maps the constrained coordinates
/// `(v0i, θ̇_j..θ̇_n)` to them.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskDerivation {
    /// `S`, `t × 6`, exact.
    pub s: Matrix,
    /// `S J^r_0e`, `t × m`.
    pub jacobian: Matrix,
}

/// The symbolic derivation for one robot: what an emitter turns into Rust.
///
/// Joint indices in expressions are 0-based positions in `q`; parameter indices are positions
/// in [`Derivation::params`].
#[derive(Clone, Debug, PartialEq)]
pub struct Derivation {
    /// Robot name.
    pub name: String,
    /// Parameter names, in declaration order (the index used by `Atom::Param`).
    pub params: Vec<String>,
    /// Nominal parameter values, same order.
    pub param_values: Vec<f64>,
    /// Number of joints `n`.
    pub n: usize,
    /// Which joints are prismatic-like (their value `q_k` appears itself, not through `s_k, c_k`).
    pub joint_is_linear: Vec<bool>,
    /// `ξ_k` in `F'_k` (`F_k` turned by [`Derivation::frame_turns`]), `6 × 1` each.
    pub twists: Vec<Matrix>,
    /// `T'_k = A_{k−1}⁻¹ · origin_k · A_k · exp(ξ̂'_k q_k)`, `F'_{k−1}` → `F'_k`, one per joint
    /// (`T_k = origin_k · exp(ξ̂_k q_k)` where no frame is turned).
    pub joint_transforms: Vec<Transform>,
    /// Entry `k` (0-based) is `A_{k+1}`, the constant rotation that turns link frame `k + 1`
    /// (1-based, after joint `k + 1`) so that its joint's oblique axis is its `z` axis
    /// (`F'_{k+1} = F_{k+1} A_{k+1}`), or `None` for a frame kept as the description gives it.
    /// A product of [`Derivation::joint_transforms`] from link `a` to link `b` is the
    /// description's `T_{a+1} ⋯ T_b` once `A_a` is put before it and `A_b⁻¹` after it
    /// ([`Derivation::frame_turn`], [`Derivation::turned_back`]).
    pub frame_turns: Vec<Option<Transform>>,
    /// `g_ne`, the end effector relative to the last joint frame `F_n` (constant; as the
    /// description gives it, not turned).
    pub end_effector: Transform,
    /// `g_0e(q)`, forward kinematics, fully expanded; `None` when the expansion would exceed
    /// [`EXPANSION_BUDGET`] (generic chains grow like `3^n` terms). Then evaluate it as a product:
    /// `fk_i · g_ie` for a constrained robot, or the [`Derivation::joint_transforms`] in order
    /// followed by [`Derivation::turned_back`]`(n, Some(&end_effector))`.
    pub fk_e: Option<Transform>,
    /// `J^B_0e(q)`, `6 × n` (2.53)–(2.55), fully expanded; `None` beyond [`EXPANSION_BUDGET`].
    /// For a constrained robot it is `[Ad_{g_ei} J^B_0i | J^B_0e2]` (3.12)–(3.14).
    pub body_jacobian_e: Option<Matrix>,
    /// The constrained part, when the description has a constraint.
    pub constraint: Option<ConstrainedDerivation>,
    /// Joint limits `[lower, upper]` (rad or m), when every joint has them (from the URDF or
    /// `limits = [lo, hi]`).
    pub joint_limits: Option<Vec<[f64; 2]>>,
    /// Each joint's limits `[lower, upper]`, base first; `None` for a joint without (a URDF
    /// `continuous` joint, or none written): it turns without bound.
    pub joint_ranges: Vec<Option<[f64; 2]>>,
    /// Each joint's speed limit `|q̇| ≤ v` (rad/s or m/s), base first, from the description (a
    /// URDF joint's `velocity`, `speed_limit = v`); `None` for a joint without.
    pub joint_speed_limits: Vec<Option<f64>>,
    /// Each joint's acceleration limit (rad/s² or m/s²), base first, from the description (a
    /// URDF 1.2 joint's `acceleration`, `acceleration_limit = a`); `None` for a joint without.
    pub joint_acceleration_limits: Vec<Option<f64>>,
    /// Each joint's jerk limit (rad/s³ or m/s³), base first (a URDF 1.2 joint's `jerk`,
    /// `jerk_limit = j`); `None` for a joint without.
    pub joint_jerk_limits: Vec<Option<f64>>,
}

/// Largest estimated number of terms of one entry of an expanded product (`len(a) · len(b) ·
/// inner dimension`) that [`derive()`] computes for the optional full-chain expansions
/// ([`Derivation::fk_e`], [`Derivation::body_jacobian_e`]). The matrices the thesis needs
/// (`g_0i`, `g_ie`, `J^B_0i`, `J^B_0e2`, `J^r`, `J_c`, manipulability) are always expanded.
pub const EXPANSION_BUDGET: usize = 20_000;

/// Largest total number of terms of `J^r` for which [`derive()`] forms the closed-form
/// manipulability (the presets and dia10_like have well under 100).
pub const MANIPULABILITY_BUDGET: usize = 400;

/// Most maximal minors of a wide `t × m` Jacobian (`C(m, t)`) for which the manipulability is
/// a sum of squared minors (in closed form, or from the Jacobian's values): `t + 1`, one spare
/// column. Beyond it the count grows combinatorially (`C(10, 6) = 210` minors for a 12-joint
/// chain, whose closed form took 2.9 s) and the manipulability comes from a factorisation of the
/// emitted Jacobian instead (`lower::manipulability_from_jr`).
pub fn minors_apply(rows: usize, cols: usize) -> bool {
    cols >= rows && cols - rows <= 1
}

/// Most terms an entry of a chain product keeps in expanded canonical form. A longer entry
/// becomes a shared subexpression ([`Poly::shared`]): the next product multiplies that one node
/// by the few terms of a joint transform instead of expanding a product of sums, so the size of
/// the derivation grows linearly with the chain rather than like `3^n`. The choice is made per
/// entry, by this bound: the thesis's robots (at most a few dozen terms per entry) stay fully
/// expanded and canonical, which is what proves their closed forms and errata symbolically;
/// generic and long chains become an expression graph.
pub const SHARE_TERMS: usize = 8;

/// `m` with every entry longer than [`SHARE_TERMS`] made a shared subexpression.
fn shared(m: Matrix) -> Matrix {
    if m.entries().iter().all(|e| e.len() <= SHARE_TERMS) {
        return m;
    }
    Matrix::from_fn(m.rows(), m.cols(), |i, j| m.get(i, j).shared(SHARE_TERMS))
}

/// `g` with its entries shared as in [`shared`].
fn shared_transform(g: Transform) -> Transform {
    Transform {
        rot: shared(g.rot),
        pos: shared(g.pos),
    }
}

/// `m` with its shared subexpressions written out ([`Poly::expanded`]), or `None` when that
/// takes more than `budget` terms in all.
pub fn expanded_within(m: &Matrix, budget: usize) -> Option<Matrix> {
    let mut total = 0usize;
    let mut entries = Vec::with_capacity(m.rows() * m.cols());
    for e in m.entries() {
        let x = e.expanded(budget.checked_sub(total)?)?;
        total += x.len();
        entries.push(x);
    }
    let cols = m.cols();
    Some(Matrix::from_fn(m.rows(), cols, |i, j| {
        entries[i * cols + j].clone()
    }))
}

fn max_len(m: &Matrix) -> usize {
    m.entries().iter().map(Poly::len).max().unwrap_or(0)
}

/// `a · b` expanded, or `None` when the estimated entry size exceeds [`EXPANSION_BUDGET`].
fn compose_within_budget(a: &Transform, b: &Transform) -> Option<Transform> {
    let la = max_len(&a.rot).max(max_len(&a.pos)).max(1);
    let lb = max_len(&b.rot).max(max_len(&b.pos)).max(1);
    if la.saturating_mul(lb).saturating_mul(4) > EXPANSION_BUDGET {
        None
    } else {
        Some(shared_transform(a.compose(b)))
    }
}

struct Ctx<'a> {
    desc: &'a RobotDescription,
}

impl Ctx<'_> {
    fn number(&self, x: f64, field: &str) -> Result<Rational, DerivationError> {
        Rational::from_f64_decimal(x)
            .map_err(|e| DerivationError::new(DerivationErrorKind::Invalid, field, e.to_string()))
    }

    fn scalar(&self, s: &Linear, field: &str) -> Result<Poly, DerivationError> {
        let mut p = Poly::constant(self.number(s.constant, field)?);
        for (c, name) in &s.terms {
            let idx = self
                .desc
                .parameters
                .iter()
                .position(|q| &q.name == name)
                .ok_or_else(|| {
                    DerivationError::new(
                        DerivationErrorKind::Invalid,
                        field,
                        format!("unknown parameter `{name}`"),
                    )
                })?;
            p = p.add(&Poly::param(idx).scale(&self.number(*c, field)?));
        }
        Ok(p)
    }

    fn rotation(&self, r: &Rotation, field: &str) -> Result<Matrix, DerivationError> {
        // The entries become exact rationals below.
        let m = rotation_f64(r);
        let mut out = Matrix::zeros(3, 3);
        for (i, row) in m.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                let r = Rational::from_f64_snapped(*x).map_err(|e| {
                    DerivationError::new(DerivationErrorKind::Invalid, field, e.to_string())
                })?;
                out.set(i, j, Poly::constant(r));
            }
        }
        Ok(out)
    }

    fn origin(&self, o: &Origin, field: &str) -> Result<Transform, DerivationError> {
        let pos = Matrix::column_vector(vec![
            self.scalar(&o.xyz[0], &format!("{field}.xyz[0]"))?,
            self.scalar(&o.xyz[1], &format!("{field}.xyz[1]"))?,
            self.scalar(&o.xyz[2], &format!("{field}.xyz[2]"))?,
        ]);
        Ok(Transform {
            rot: self.rotation(&o.rotation, &format!("{field}.rotation"))?,
            pos,
        })
    }

    fn unit_axis(&self, a: &[f64; 3], field: &str) -> Result<[Rational; 3], DerivationError> {
        let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if !norm.is_finite() || (norm - 1.0).abs() > 1e-9 {
            return Err(DerivationError::new(
                DerivationErrorKind::Invalid,
                field,
                format!("axis {a:?} is not a unit vector (norm {norm})"),
            ));
        }
        Ok([
            Rational::from_f64_snapped(a[0]).map_err(|e| inv(field, e))?,
            Rational::from_f64_snapped(a[1]).map_err(|e| inv(field, e))?,
            Rational::from_f64_snapped(a[2]).map_err(|e| inv(field, e))?,
        ])
    }

    /// `A_k` of joint `k` (0-based, [`Derivation::frame_turns`]): for a revolute joint whose
    /// axis `ω` is not a coordinate axis, the rotation with columns `x`, `ω × x`, `ω`, where `x`
    /// is the unit vector along the common normal `ω × ω_next` of this axis and the next
    /// revolute joint's (Denavit–Hartenberg's choice), or along `ω × e` for the coordinate axis
    /// `e` least aligned with `ω` where there is none (the last joint, a prismatic one, parallel
    /// axes); `None` otherwise.
    fn frame_turn(&self, k: usize) -> Result<Option<Transform>, DerivationError> {
        let JointKind::Revolute { axis } = &self.desc.joints[k].kind else {
            return Ok(None);
        };
        let field = format!("joints[{k}].axis");
        let w = self.unit_axis(axis, &field)?;
        if w.iter().filter(|x| !x.is_zero()).count() < 2 {
            return Ok(None);
        }
        // The unit axis: A is then orthonormal to rounding, so that Aᵀ is its inverse.
        let length = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let a = axis.map(|v| v / length);
        let least = (0..3)
            .min_by(|&p, &q| a[p].abs().total_cmp(&a[q].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[least] = 1.0;
        let cross = |u: [f64; 3], v: [f64; 3]| {
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        // DH's choice where it exists: x along the common normal of this axis and the next
        // joint's (in F_k), so that the next turn leaves one entry of the constant zero.
        let next_axis = self
            .desc
            .joints
            .get(k + 1)
            .and_then(|next| match &next.kind {
                JointKind::Revolute { axis: b } => {
                    let m = rotation_f64(&next.origin.rotation);
                    Some([0, 1, 2].map(|r| m[r][0] * b[0] + m[r][1] * b[1] + m[r][2] * b[2]))
                }
                _ => None,
            });
        let normal = next_axis
            .map(|b| cross(a, b))
            .filter(|c| (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() > 1e-6);
        let x = normal.unwrap_or_else(|| cross(a, e));
        // One Gram–Schmidt step: a cross product of nearly parallel axes leaves `x` off the
        // perpendicular by its rounding over its length.
        let along = x[0] * a[0] + x[1] * a[1] + x[2] * a[2];
        let x = [0, 1, 2].map(|r| x[r] - along * a[r]);
        let norm = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let x = x.map(|v| v / norm);
        let y = cross(a, x);
        let mut rot = Matrix::zeros(3, 3);
        for (col, v) in [x, y, a].iter().enumerate() {
            for (row, value) in v.iter().enumerate() {
                let r = Rational::from_f64_snapped(*value).map_err(|e| inv(&field, e))?;
                rot.set(row, col, Poly::constant(r));
            }
        }
        Ok(Some(Transform {
            rot,
            pos: Matrix::zeros(3, 1),
        }))
    }

    /// `(ξ_k, exp(ξ̂_k q_k), linear?)` for joint `k` (0-based) (2.25)–(2.27), (2.36).
    fn joint(&self, k: usize) -> Result<(Matrix, Transform, bool), DerivationError> {
        let j = &self.desc.joints[k];
        let field = format!("joints[{k}]");
        let c = |r: &Rational| Poly::constant(r.clone());
        let (v, w): ([Poly; 3], Option<[Rational; 3]>) = match &j.kind {
            JointKind::Revolute { axis } => {
                let w = self.unit_axis(axis, &format!("{field}.axis"))?;
                ([Poly::zero(), Poly::zero(), Poly::zero()], Some(w))
            }
            JointKind::Prismatic { axis } => {
                let v = self.unit_axis(axis, &format!("{field}.axis"))?;
                ([c(&v[0]), c(&v[1]), c(&v[2])], None)
            }
            JointKind::Twist { v, w } => {
                let vp = [
                    self.scalar(&v[0], &format!("{field}.v[0]"))?,
                    self.scalar(&v[1], &format!("{field}.v[1]"))?,
                    self.scalar(&v[2], &format!("{field}.v[2]"))?,
                ];
                if w.iter().all(|x| *x == 0.0) {
                    (vp, None)
                } else {
                    (vp, Some(self.unit_axis(w, &format!("{field}.w"))?))
                }
            }
        };
        let q = Poly::joint(k);
        match w {
            None => {
                let xi = Matrix::column_vector(vec![
                    v[0].clone(),
                    v[1].clone(),
                    v[2].clone(),
                    Poly::zero(),
                    Poly::zero(),
                    Poly::zero(),
                ]);
                let g = Transform {
                    rot: Matrix::identity(3),
                    pos: Matrix::column_vector(v.iter().map(|x| x.mul(&q)).collect()),
                };
                Ok((xi, g, true))
            }
            Some(w) => {
                let wp = [c(&w[0]), c(&w[1]), c(&w[2])];
                let what = Matrix::hat(&wp);
                let what2 = what.mul(&what);
                let (s, cs) = (Poly::sin(k), Poly::cos(k));
                // Rodrigues (2.14): R = I + ŵ s + ŵ² (1 − c)
                let rot = Matrix::identity(3)
                    .add(&what.scale(&s))
                    .add(&what2.scale(&Poly::one().sub(&cs)));
                // p = (I − R)(ω × v) + ω ωᵀ v q (2.36)
                let vcol = Matrix::column_vector(v.to_vec());
                let wxv = what.mul(&vcol);
                let mut pos = Matrix::identity(3).sub(&rot).mul(&wxv);
                let wv = wp[0]
                    .mul(&v[0])
                    .add(&wp[1].mul(&v[1]))
                    .add(&wp[2].mul(&v[2]));
                let linear = !wv.is_zero();
                if linear {
                    let wcol = Matrix::column_vector(wp.to_vec());
                    pos = pos.add(&wcol.scale(&wv.mul(&q)));
                }
                let mut xi = v.to_vec();
                xi.extend(wp.iter().cloned());
                Ok((Matrix::column_vector(xi), Transform { rot, pos }, linear))
            }
        }
    }
}

/// A description's rotation as `f64` entries, row-major: `R = Rz(yaw) Ry(pitch) Rx(roll)` with
/// `f64::sin_cos` for `rpy`.
fn rotation_f64(r: &Rotation) -> [[f64; 3]; 3] {
    match r {
        Rotation::Matrix(m) => *m,
        Rotation::Rpy([roll, pitch, yaw]) => {
            let m = trocar::se3::rotation_from_rpy_sin_cos(
                roll.sin_cos(),
                pitch.sin_cos(),
                yaw.sin_cos(),
            );
            [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
        }
    }
}

/// The twist `(0, ẑ)` of a revolute joint about the `z` axis of its frame and
/// `exp(ξ̂ q_k) = (R_z(q_k), 0)` ((2.14) with `ω = ẑ`).
fn about_z(k: usize) -> (Matrix, Transform) {
    let (s, c) = (Poly::sin(k), Poly::cos(k));
    let z = Poly::zero;
    let xi = Matrix::column_vector(vec![z(), z(), z(), z(), z(), Poly::one()]);
    let rot = Matrix::from_fn(3, 3, |r, col| match (r, col) {
        (0, 0) | (1, 1) => c.clone(),
        (0, 1) => s.neg(),
        (1, 0) => s.clone(),
        (2, 2) => Poly::one(),
        _ => z(),
    });
    (
        xi,
        Transform {
            rot,
            pos: Matrix::zeros(3, 1),
        },
    )
}

/// `A_link⁻¹ · tail` (the identity or `tail` where the frame `F_link` is not turned): what a
/// product of the turned transforms up to link `link` (1-based; 0 is the base) needs after it
/// to end in the description's frame, then at `tail` given in that frame.
fn turned_back(turns: &[Option<Transform>], link: usize, tail: Option<&Transform>) -> Transform {
    let turn = link.checked_sub(1).and_then(|k| turns[k].as_ref());
    match (turn, tail) {
        (Some(a), Some(t)) => a.inverse().compose(t),
        (Some(a), None) => a.inverse(),
        (None, Some(t)) => t.clone(),
        (None, None) => Transform::identity(),
    }
}

/// Rows of a selection matrix (`H`, `S`) as exact rationals; errors name `{prefix}[k]`.
fn rational_rows(rows: &[[f64; 6]], prefix: &str) -> Result<Vec<Vec<Rational>>, DerivationError> {
    rows.iter()
        .enumerate()
        .map(|(k, row)| {
            row.iter()
                .map(|x| {
                    Rational::from_f64_decimal(*x).map_err(|e| inv(&format!("{prefix}[{k}]"), e))
                })
                .collect()
        })
        .collect()
}

fn inv(field: &str, e: impl fmt::Display) -> DerivationError {
    DerivationError::new(DerivationErrorKind::Invalid, field, e.to_string())
}

/// Body Jacobian columns `Ad_{g_ke}⁻¹ ξ_k` for `k = 0..upto` with `g_ke = T_{k+1} ⋯ T_{upto−1} · tail`
/// (2.53)–(2.55); returns the `6 × upto` matrix.
/// `None` when an intermediate product exceeds [`EXPANSION_BUDGET`] and `budget` is set.
fn body_jacobian(
    twists: &[Matrix],
    transforms: &[Transform],
    from: usize,
    upto: usize,
    tail: &Transform,
    budget: bool,
) -> Option<Matrix> {
    let mut g = tail.clone();
    let mut cols: Vec<Matrix> = vec![Matrix::zeros(6, 1); upto - from];
    for k in (from..upto).rev() {
        cols[k - from] = shared(g.adjoint_inverse_apply(&twists[k]));
        if k > from {
            g = if budget {
                compose_within_budget(&transforms[k], &g)?
            } else {
                shared_transform(transforms[k].compose(&g))
            };
        }
    }
    Some(Matrix::from_fn(6, upto - from, |i, j| {
        cols[j].get(i, 0).clone()
    }))
}

/// Derives everything for `desc` (see the module documentation for the steps).
///
/// # Errors
/// A [`DerivationError`] naming the field for malformed numbers, axes, parameters or `H`;
/// [`DerivationErrorKind::TooFewJoints`] when `n − r < 6` or `m < 6`;
/// [`DerivationErrorKind::WristMismatch`] when a wrist preset's basis does not annihilate `Λ`.
pub fn derive(desc: &RobotDescription) -> Result<Derivation, DerivationError> {
    let ctx = Ctx { desc };
    let n = desc.joints.len();
    if n == 0 {
        return Err(DerivationError::new(
            DerivationErrorKind::Invalid,
            "joints",
            "the robot has no joint",
        ));
    }
    if n > u16::MAX as usize || desc.parameters.len() > u16::MAX as usize {
        return Err(DerivationError::new(
            DerivationErrorKind::Invalid,
            "joints",
            "too many joints or parameters",
        ));
    }
    let mut twists = Vec::with_capacity(n);
    let mut transforms = Vec::with_capacity(n);
    let mut linear = Vec::with_capacity(n);
    let mut turns: Vec<Option<Transform>> = Vec::with_capacity(n);
    for k in 0..n {
        let origin = ctx.origin(&desc.joints[k].origin, &format!("joints[{k}].origin"))?;
        let (mut xi, mut e, lin) = ctx.joint(k)?;
        let turn = ctx.frame_turn(k)?;
        if turn.is_some() {
            // The oblique axis is z of the turned frame: (2.14) with ω = ẑ.
            (xi, e) = about_z(k);
        }
        // T'_k = A_{k−1}⁻¹ · origin_k · A_k · exp(ξ̂'_k q_k); link k − 1 is joint k's parent
        // (`turned_back` counts links from 1, `k` joints from 0).
        let mut t = turned_back(&turns, k, Some(&origin));
        if let Some(a) = &turn {
            t = t.compose(a);
        }
        twists.push(xi);
        transforms.push(t.compose(&e));
        linear.push(lin);
        turns.push(turn);
    }
    let end_effector = ctx.origin(&desc.end_effector.origin, "end_effector")?;
    // g_ne from the last turned frame F'_n.
    let end_effector_turned = turned_back(&turns, n, Some(&end_effector));

    let constraint = match &desc.constraint {
        None => None,
        Some(c) => Some(derive_constraint(
            &ctx,
            c,
            desc.task.as_ref().map(|t| t.select.as_slice()),
            &twists,
            &transforms,
            &turns,
            &end_effector_turned,
        )?),
    };
    let (fk_e, body_jacobian_e) = match &constraint {
        // g_0e = g_0i g_ie; J^B_0e = [Ad_{g_ei} J^B_0i | J^B_0e2] (3.12)–(3.14).
        Some(c) => {
            let fk = compose_within_budget(&c.fk_i, &c.g_ie);
            let size = max_len(&c.ad_g_ei).saturating_mul(max_len(&c.body_jacobian_i));
            let jb = if size.saturating_mul(6) > EXPANSION_BUDGET {
                None
            } else {
                Some(shared(c.ad_g_ei.mul(&c.body_jacobian_i)).hstack(&c.body_jacobian_e2))
            };
            (fk, jb)
        }
        None => {
            // Forward kinematics g_0e = T_1 ⋯ T_n g_ne (2.21).
            let mut g = Some(Transform::identity());
            for t in &transforms {
                g = g.and_then(|g| compose_within_budget(&g, t));
            }
            let fk = g.and_then(|g| compose_within_budget(&g, &end_effector_turned));
            (
                fk,
                body_jacobian(&twists, &transforms, 0, n, &end_effector_turned, true),
            )
        }
    };

    Ok(Derivation {
        name: desc.name.clone(),
        params: desc.parameters.iter().map(|p| p.name.clone()).collect(),
        param_values: desc.parameters.iter().map(|p| p.value).collect(),
        n,
        joint_is_linear: linear,
        twists,
        joint_transforms: transforms,
        frame_turns: turns,
        end_effector,
        fk_e,
        body_jacobian_e,
        constraint,
        joint_limits: desc.joints.iter().map(|j| j.limits).collect(),
        joint_ranges: desc.joints.iter().map(|j| j.limits).collect(),
        joint_speed_limits: desc.joints.iter().map(|j| j.speed_limit).collect(),
        joint_acceleration_limits: desc.joints.iter().map(|j| j.acceleration_limit).collect(),
        joint_jerk_limits: desc.joints.iter().map(|j| j.jerk_limit).collect(),
    })
}

fn derive_constraint(
    ctx: &Ctx<'_>,
    c: &trocar_model::description::ConstraintDesc,
    task: Option<&[[f64; 6]]>,
    twists: &[Matrix],
    transforms: &[Transform],
    turns: &[Option<Transform>],
    end_effector: &Transform,
) -> Result<ConstrainedDerivation, DerivationError> {
    let n = transforms.len();
    let i = c.link;
    let r = c.h.len();
    // The admission rules of the method, written once in the model.
    admit(n, i, r, task.map_or(6, <[[f64; 6]]>::len)).map_err(|e| {
        let kind = match e {
            AdmissionError::TooFewJoints { .. } | AdmissionError::TooFewColumns { .. } => {
                DerivationErrorKind::TooFewJoints
            }
            _ => DerivationErrorKind::Invalid,
        };
        DerivationError::new(kind, e.field_for(task.is_some()), e.to_string())
    })?;
    let h_rat = rational_rows(&c.h, "constraint.h")?;
    let (rank, null_h) = rational_null_space(&h_rat, 6);
    if rank != r {
        return Err(DerivationError::new(
            DerivationErrorKind::Invalid,
            "constraint.h",
            format!("the rows of H are linearly dependent (rank {rank} < {r})"),
        ));
    }
    let m = 6 - r + n - i;
    let h = Matrix::from_rationals(&h_rat);
    let g_ir = ctx.origin(&c.origin, "constraint.origin")?;
    let lambda = h.mul(&g_ir.adjoint_inverse()); // Ad_{g_ri} = Ad_{g_ir}⁻¹

    // Which basis: the one rule of the model (`ConstraintDesc::basis`).
    let basis = c.basis();
    let lambda_sharp = match basis {
        NullSpaceBasis::Computed => {
            let nmat = Matrix::from_fn(6, 6 - r, |a, b| Poly::constant(null_h[b][a].clone()));
            g_ir.adjoint().mul(&nmat)
        }
        NullSpaceBasis::Unidirectional | NullSpaceBasis::Bidirectional => {
            let w = c.wrist.map_or_else(String::new, |w| format!("{w:?}"));
            if !basis.fits_rows(r) {
                return Err(DerivationError::new(
                    DerivationErrorKind::WristMismatch,
                    "constraint.wrist",
                    format!("wrist preset {w} does not fit an H with {r} row(s)"),
                ));
            }
            let la = g_ir.pos.get(1, 0).clone();
            let inv_la = la
                .inv()
                .map_err(|e| DerivationError::symbolic("constraint.origin.xyz[1]", e))?;
            let e = |k: usize| {
                Matrix::from_fn(6, 1, |a, _| if a == k { Poly::one() } else { Poly::zero() })
            };
            let cols: Vec<Matrix> = if basis == NullSpaceBasis::Unidirectional {
                // (3.23)
                vec![e(0).add(&e(5).scale(&inv_la)), e(1), e(2), e(3), e(4)]
            } else {
                // (3.27)
                vec![
                    e(0).add(&e(5).scale(&inv_la)),
                    e(1),
                    e(2).sub(&e(3).scale(&inv_la)),
                    e(4),
                ]
            };
            let mut ls = cols[0].clone();
            for col in &cols[1..] {
                ls = ls.hstack(col);
            }
            if !lambda.mul(&ls).is_zero() {
                return Err(DerivationError::new(
                    DerivationErrorKind::WristMismatch,
                    "constraint.wrist",
                    "the thesis basis (3.23)/(3.27) needs g_ir = (I, (0, l_a, 0)) and H = x_r (or x_r, z_r); Λ Λ# ≠ 0 here",
                ));
            }
            ls
        }
    };
    let llt = lambda.mul(&lambda.transpose());
    let lambda_pinv = lambda.transpose().mul(
        &llt.inverse()
            .map_err(|e| DerivationError::symbolic("constraint", e))?,
    );

    // g_0i = T_1 ⋯ T_i and g_ie = T_j ⋯ T_n g_ne (2.21), in F_i (a turned F'_i turned back).
    let mut fk_i = Transform::identity();
    for t in &transforms[..i] {
        fk_i = shared_transform(fk_i.compose(t));
    }
    let back_to_i = turned_back(turns, i, None);
    if turns[i - 1].is_some() {
        fk_i = shared_transform(fk_i.compose(&back_to_i));
    }
    let mut g_ie = end_effector.clone();
    for t in transforms[i..].iter().rev() {
        g_ie = shared_transform(t.compose(&g_ie));
    }
    if let Some(a) = &turns[i - 1] {
        g_ie = shared_transform(a.compose(&g_ie));
    }
    let ad_g_ei = shared(g_ie.adjoint_inverse());
    // Without a budget `body_jacobian` always returns `Some`.
    let body_jacobian_i = body_jacobian(twists, transforms, 0, i, &back_to_i, false)
        .unwrap_or_else(|| Matrix::zeros(6, i));
    let body_jacobian_e2 = body_jacobian(twists, transforms, i, n, end_effector, false)
        .unwrap_or_else(|| Matrix::zeros(6, n - i));
    // With i = n there is no joint after the constraint: J^B_0e2 has no column and
    // J^r_0e = Ad_{g_ei} Λ#.
    let jr = shared(ad_g_ei.mul(&lambda_sharp)).hstack(&body_jacobian_e2);
    let jc = shared(ad_g_ei.mul(&lambda_pinv));
    // The task: S selects rows of the end-effector twist, S J^r is the task Jacobian.
    let task = match task {
        None => None,
        Some(rows) => {
            let s = Matrix::from_rationals(&rational_rows(rows, "task.select")?);
            let sj = s.mul(&jr);
            Some(TaskDerivation { s, jacobian: sj })
        }
    };
    // Manipulability of what the task commands: S J^r with a task, J^r without. In closed form
    // only from the canonical (expanded) matrix, and only while that stays small; a Jacobian in
    // graph form whose expansion would swell gets a factorisation of its values instead.
    let commanded = task.as_ref().map_or(&jr, |t| &t.jacobian);
    let manipulability = match expanded_within(commanded, MANIPULABILITY_BUDGET) {
        Some(j) if minors_apply(j.rows(), j.cols()) => {
            Some(manipulability(&j).map_err(|e| DerivationError::symbolic("constraint", e))?)
        }
        _ => None,
    };
    Ok(ConstrainedDerivation {
        link: i,
        r,
        m,
        h,
        g_ir,
        lambda,
        basis,
        lambda_sharp,
        lambda_pinv,
        fk_i,
        g_ie,
        ad_g_ei,
        body_jacobian_i,
        body_jacobian_e2,
        jr,
        jc,
        task,
        manipulability,
    })
}

/// Manipulability of a `t × m` matrix (`m ≥ t`: `J^r`, `6 × m`, or a task Jacobian `S J^r`) in
/// closed form (3.36)–(3.39).
pub fn manipulability(j: &Matrix) -> Result<Manipulability, SymbolicError> {
    if j.rows() == j.cols() {
        let d = j.det()?;
        Ok(Manipulability {
            squared: d.mul(&d),
            form: ManipulabilityForm::AbsDet(d),
        })
    } else {
        let minors = j.maximal_minors()?;
        let squared = minors
            .iter()
            .fold(Poly::zero(), |s, (_, p)| s.add(&p.mul(p)));
        Ok(Manipulability {
            squared,
            form: ManipulabilityForm::SqrtSumOfSquares(minors),
        })
    }
}

impl Derivation {
    /// `A` of link frame `link` (1-based: the frame after joint `link`; 0 is the base, never
    /// turned), if it is turned ([`Derivation::frame_turns`]).
    pub fn frame_turn(&self, link: usize) -> Option<&Transform> {
        link.checked_sub(1)
            .and_then(|k| self.frame_turns.get(k))
            .and_then(Option::as_ref)
    }

    /// `A_link⁻¹ · tail`: what a product of [`Derivation::joint_transforms`] up to link `link`
    /// needs after it to end in the description's frame `F_link` and then at `tail` (given in
    /// `F_link`); `None` when that is the identity.
    pub fn turned_back(&self, link: usize, tail: Option<&Transform>) -> Option<Transform> {
        match (self.frame_turn(link), tail) {
            (None, None) => None,
            _ => Some(turned_back(&self.frame_turns, link, tail)),
        }
    }

    /// Size summary `(name, rows, cols, total terms)` of every derived matrix, for reports.
    pub fn sizes(&self) -> Vec<(&'static str, usize, usize, usize)> {
        let t = |name, m: &Matrix| (name, m.rows(), m.cols(), m.total_terms());
        let mut v = Vec::new();
        if let Some(fk) = &self.fk_e {
            v.push(t("fk_e.rot", &fk.rot));
            v.push(t("fk_e.pos", &fk.pos));
        }
        if let Some(jb) = &self.body_jacobian_e {
            v.push(t("body_jacobian_e", jb));
        }
        if let Some(c) = &self.constraint {
            v.push(t("fk_i.rot", &c.fk_i.rot));
            v.push(t("fk_i.pos", &c.fk_i.pos));
            v.push(t("body_jacobian_i", &c.body_jacobian_i));
            v.push(t("jr", &c.jr));
            v.push(t("jc", &c.jc));
            if let Some(task) = &c.task {
                v.push(t("task_jacobian", &task.jacobian));
            }
            if let Some(w) = &c.manipulability {
                v.push(("manipulability_squared", 1, 1, w.squared.len()));
            }
        }
        v
    }

    /// Joints (0-based) each named result depends on.
    pub fn dependencies(&self) -> Vec<(&'static str, BTreeSet<usize>)> {
        let all: BTreeSet<usize> = (0..self.n).collect();
        let mut v = vec![
            (
                "fk_e",
                self.fk_e.as_ref().map_or(all.clone(), Transform::joints),
            ),
            (
                "body_jacobian_e",
                self.body_jacobian_e.as_ref().map_or(all, Matrix::joints),
            ),
        ];
        if let Some(c) = &self.constraint {
            v.push(("fk_i", c.fk_i.joints()));
            v.push(("body_jacobian_i", c.body_jacobian_i.joints()));
            v.push(("jr", c.jr.joints()));
            v.push(("jc", c.jc.joints()));
            if let Some(task) = &c.task {
                v.push(("task_jacobian", task.jacobian.joints()));
            }
            if let Some(w) = &c.manipulability {
                v.push(("manipulability", w.squared.joints()));
            }
        }
        v
    }
}
