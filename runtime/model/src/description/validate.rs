//! Validation of descriptions: every rule with the field it names.
//!
//! [`RobotDescription::from_toml_str`] runs these checks before it returns and gives every error the
//! line and column of its field; [`RobotDescription::validate`] runs them on any description (built
//! in code, imported from URDF), with lines known for joints read from a file.
//!
//! | rule | field |
//! |---|---|
//! | the robot has a name | `robot.name` |
//! | parameter names are identifiers (not Rust keywords), unique, with finite values | `parameters.NAME` |
//! | at least one joint | `joints` |
//! | joint names are non-empty and unique | `joints[k].name` |
//! | revolute/prismatic axis finite, non-zero, unit (±1e-9) | `joints[k].axis` |
//! | joint limits under the number rule ([`crate::validity`]) with lower < upper | `joints[k].limits` |
//! | joint speed, acceleration, jerk and effort limits finite and positive | `joints[k].speed_limit`, `….acceleration_limit`, `….jerk_limit`, `….effort_limit` |
//! | joint damping and friction finite and ≥ 0 | `joints[k].damping`, `joints[k].friction` |
//! | a link's mass positive, its inertia positive definite | `joints[k].mass`, `joints[k].inertia` |
//! | the instrument's mass and radius finite and positive | `instrument.mass`, `instrument.radius` |
//! | twist: `‖ω‖ = 1`, or `ω = 0` and `‖v‖ = 1` (checked when `v` is numeric; a parametric `v` must not be zero) | `joints[k].w`, `joints[k].v` |
//! | numbers finite (xyz, rpy, rotation, axis, v, w, H, parameter values) | the number's field |
//! | every parameter named in a length is declared in `[parameters]` | `….xyz[c]`, `joints[k].v[c]` |
//! | rotation matrices orthonormal with determinant 1 (±1e-9) | `….rotation` |
//! | constrained link `1 ≤ i ≤ n` (link `i` is carried by joint `i`) | `constraint.link` |
//! | H has 1 to 5 rows, none zero, linearly independent | `constraint.h`, `constraint.h[k]` |
//! | the method needs `n − r ≥ t` (`t` task rows, 6 without `[task]`) | `constraint.h` (`task.select` with a task) |
//! | `J^r` needs `m = (6 − r) + (n − i) ≥ t` columns (3.15) | `constraint.link` (`task.select` with a task) |
//! | `i ≥ 6` joints before the constrained link (`J^B_0i` of rank 6) | `constraint.link` |
//! | on the last link, a constraint point sliding along the instrument (`o + l_a d`) not beyond the end effector along `d` at the nominal value | `parameters.NAME` (`constraint.xyz` when `d` does not point toward the end effector) |
//! | `S J^r_0e` (`J^r_0e` without a task) of rank `t` at some configuration ([`admission_rank_problem`]) | `task.select` (`constraint.h` without a task) |
//! | task rows: 1 to 6, none zero, linearly independent | `task.select`, `task.select[k]` |
//! | wrist `unidirectional` needs `H = x_r`; `zy`/`zx` need `H = (x_r, z_r)` | `constraint.wrist` |
//! | wrist `zy`: joint `i+1` revolute about z, joint `i+2` about y (`zx`: about x) | `joints[i].axis`, `joints[i+1].axis` |
//! | a wrist needs `g_ir = (I, (0, l_a, 0))` with `l_a` a parameter of non-zero nominal value | `constraint.xyz[c]`, `constraint.rpy`/`constraint.rotation` |
//!
//! Reading TOML checks the format before these rules, with the same field paths: TOML syntax
//! (`(document)`, with the position), unknown keys (the key and its table) and missing keys, types,
//! expressions (`"l_a + l_b"`, linear in the parameters), joint types, `rpy` and `rotation` not both,
//! rows of `H` of 6 entries and known axis letters (`constraint.h[k]`), known wrist names.
//!
//! Joint indices in field paths are 0-based (`joints[0]` is joint 1), as in the TOML array.
//!
//! The admission rules of the method — which constrained link, how many rows of `H`, how many
//! joints — are written once, in [`admission_problems`]; the generator's derivation and the numeric
//! robot call it too.

use super::{
    DescriptionError, JointKind, Linear, Location, NullSpaceBasis, Origin, RobotDescription,
    Rotation, Wrist,
};
use crate::expr::is_name as is_identifier;

/// Rust's strict and reserved keywords (2021 and 2024 editions) and `_`: not parameter names.
const RUST_KEYWORDS: &[&str] = &[
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

/// A constraint the method (thesis chapter 3) does not admit: the rules on the constrained link
/// `i`, the rows `r` of `H`, the joints `n` and the `t` task rows (six without a `[task]`), in the
/// order [`admission_problems`] checks them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdmissionError {
    /// The constrained link is not `1 ≤ i ≤ n` (link `i` is carried by joint `i`).
    LinkOutOfRange {
        /// The link `i` given.
        link: usize,
        /// Joints `n`.
        n: usize,
    },
    /// `H` has no row.
    NoRows,
    /// `H` has more than 5 rows.
    TooManyRows {
        /// Rows `r`.
        r: usize,
    },
    /// The robot keeps `n − r` degrees of freedom under the constraint, fewer than the `t` task
    /// rows (the thesis's `n − r ≥ 6` when the task is the whole twist).
    TooFewJoints {
        /// Joints `n`.
        n: usize,
        /// Rows `r`.
        r: usize,
        /// Task rows `t`.
        t: usize,
    },
    /// Fewer than 6 joints before the constrained link: `J^B_0i` (6 × i) cannot give the link
    /// every twist `Λ# v0i + Λ† dv_0r` (3.33) that the controller resolves through it (3.18).
    TooFewJointsBefore {
        /// The link `i`.
        link: usize,
    },
    /// `J^r` (3.15) has `m = (6 − r) + (n − i)` columns, fewer than the `t` task rows.
    TooFewColumns {
        /// Columns `m`.
        m: usize,
        /// Joints `n − i` after the constrained link.
        after: usize,
        /// Rows `r`.
        r: usize,
        /// Task rows `t`.
        t: usize,
    },
    /// What the task commands, `S J^r_0e` (`J^r_0e` without a `[task]`), has rank below its `t`
    /// rows at every configuration tried (see [`admission_rank_problem`]): the task asks for a
    /// motion the constraint forbids or the joints cannot give, and the manipulability is 0
    /// everywhere.
    SingularEverywhere {
        /// The largest rank met.
        rank: usize,
        /// Task rows `t`.
        t: usize,
        /// Configurations tried.
        tried: usize,
    },
}

impl AdmissionError {
    /// The description field the rule is about (`task.select` when a `[task]` selects fewer than
    /// six rows and the count is what fails). A description with a `[task]` of six rows has its
    /// field from [`AdmissionError::field_for`].
    pub fn field(&self) -> &'static str {
        let task = match self {
            Self::TooFewJoints { t, .. }
            | Self::TooFewColumns { t, .. }
            | Self::SingularEverywhere { t, .. } => *t < 6,
            _ => false,
        };
        self.field_for(task)
    }

    /// The description field the rule is about, for a description with (`task = true`) or without
    /// a `[task]`: the counts and the rank are about the task's rows when there is one
    /// (`task.select`), otherwise about `H` (`constraint.h`) or the constrained link.
    pub fn field_for(&self, task: bool) -> &'static str {
        match self {
            Self::TooFewJoints { .. }
            | Self::TooFewColumns { .. }
            | Self::SingularEverywhere { .. }
                if task =>
            {
                "task.select"
            }
            Self::LinkOutOfRange { .. }
            | Self::TooFewColumns { .. }
            | Self::TooFewJointsBefore { .. } => "constraint.link",
            Self::NoRows
            | Self::TooManyRows { .. }
            | Self::TooFewJoints { .. }
            | Self::SingularEverywhere { .. } => "constraint.h",
        }
    }
}

impl std::fmt::Display for AdmissionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::LinkOutOfRange { link, n } => write!(
                f,
                "constrained link {link} is not a link of the robot: link i is carried by joint i, so 1 ≤ i ≤ n = {n}"
            ),
            Self::NoRows => write!(
                f,
                "H needs at least one row (remove [constraint] for an unconstrained robot)"
            ),
            Self::TooManyRows { r } => write!(
                f,
                "H has {r} rows; at most 5 (r = 6 would leave the constrained link no motion)"
            ),
            Self::TooFewJoints { n, r, t } => {
                write!(
                    f,
                    "the method requires n − r ≥ t (n joints, r rows of H, t task rows); here n = {n}, r = {r}, t = {t}: n − r = {}",
                    n as i64 - r as i64
                )?;
                if t == 6 {
                    write!(f, "; a smaller task can be selected with [task] select = [...]")?;
                }
                Ok(())
            }
            Self::TooFewJointsBefore { link } => write!(
                f,
                "the joints before the constrained link must give it any twist (J^B_0i of rank 6, resolving V^B_0i = Λ# v0i + Λ† dv_0r), which needs i ≥ 6 joints; here i = {link}"
            ),
            Self::TooFewColumns { m, after, r, t } => {
                write!(
                    f,
                    "J^r has m = (6 − r) + (n − i) = {m} columns (r = {r}, n − i = {after} joints after the constraint), fewer than the t = {t} task rows"
                )?;
                if t == 6 {
                    write!(
                        f,
                        "; move the constraint to an earlier link or select fewer task rows with [task] select = [...]"
                    )?;
                }
                Ok(())
            }
            Self::SingularEverywhere { rank, t, tried } => {
                let what = if t == 6 { "J^r_0e" } else { "S J^r_0e" };
                write!(
                    f,
                    "the task is singular at every configuration: {what} has rank {rank} < t = {t} at each of {tried} random configurations (nominal parameters), so the manipulability is 0 everywhere; "
                )?;
                if t == 6 {
                    write!(f, "the constraint H (or a joint parallel to a constrained direction) leaves fewer than 6 independent end-effector motions: select the rows the robot can follow with [task] select = [...]")
                } else {
                    write!(f, "the selected rows ask for motions the constraint H forbids or the joints cannot give (e.g. a rotation about an axis the trocar fixes, or a row that H also constrains): select rows the robot can follow")
                }
            }
        }
    }
}

impl std::error::Error for AdmissionError {}

/// Configurations at which [`admission_rank_problem`] evaluates the task's Jacobian.
pub const RANK_CONFIGURATIONS: usize = 4;

/// The rank rule of admission: what the task commands, `S J^r_0e` (t × m; `J^r_0e` without a
/// `[task]`), must have rank `t` somewhere, or the task is singular at every configuration and its
/// manipulability identically 0 (`select = ["x", "ry"]` through a trocar that fixes `x`, `h = ["z"]`
/// with a `z` task, a prismatic joint parallel to a constrained translation). Checked at
/// [`RANK_CONFIGURATIONS`] pseudo-random configurations (each joint uniform in its limits, or in
/// `[−π, π]`; a fixed seed, so the answer is reproducible) with the nominal parameters; the rank
/// counts singular values above `1e-9 σ_max` once the rows, then the columns, are scaled to unit
/// norm. `None` when the rule holds, or when the robot
/// cannot be evaluated (the other rules report why).
pub fn admission_rank_problem(d: &RobotDescription) -> Option<AdmissionError> {
    let model = crate::numeric::NumericModel::<f64>::from_description(d, &[]).ok()?;
    let c = model.constraint()?;
    let i = c.link();
    let n = model.dof();
    let sharp = c.lambda_null_space_columns();
    let select: Vec<[f64; 6]> = match &d.task {
        Some(t) => t.select.clone(),
        None => (0..6)
            .map(|k| {
                let mut row = [0.0; 6];
                row[k] = 1.0;
                row
            })
            .collect(),
    };
    let t = select.len();
    let m = sharp.len() + n - i;
    // xorshift64*, fixed seed.
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut uniform = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut best = 0;
    for _ in 0..RANK_CONFIGURATIONS {
        let q: Vec<f64> = d
            .joints
            .iter()
            .map(|j| {
                let u = uniform();
                match j.limits {
                    Some([lo, hi]) if lo.is_finite() && hi.is_finite() => lo + u * (hi - lo),
                    _ => (2.0 * u - 1.0) * std::f64::consts::PI,
                }
            })
            .collect();
        let mut cols = vec![trocar::se3::Twist::<f64>::zeros(); m];
        trocar::kinematics::constrained_jacobian_columns(
            &model.joints()[i..],
            &q[i..],
            model.tool(),
            sharp,
            &mut cols,
        );
        let mut st = nalgebra::DMatrix::from_fn(t, m, |r, k| {
            (0..6).map(|e| select[r][e] * cols[k][e]).sum::<f64>()
        });
        if !st.iter().all(|x| x.is_finite()) {
            return None;
        }
        // Rows, then columns, scaled to unit norm (the rank is unchanged): linear rows in metres
        // and angular ones in radians, or lengths of 1e6 beside 1e-3, do not read as a rank
        // deficiency.
        for mut row in st.row_iter_mut() {
            let norm = row.norm();
            if norm > 0.0 {
                row /= norm;
            }
        }
        for mut col in st.column_iter_mut() {
            let norm = col.norm();
            if norm > 0.0 {
                col /= norm;
            }
        }
        let sv = st.singular_values();
        let top = sv.iter().copied().fold(0.0, f64::max);
        let rank = sv.iter().filter(|&&x| x > 1e-9 * top).count();
        if rank >= t {
            return None;
        }
        best = best.max(rank);
    }
    Some(AdmissionError::SingularEverywhere {
        rank: best,
        t,
        tried: RANK_CONFIGURATIONS,
    })
}

/// Every admission rule a constraint at link `link` with `r` rows of `H` on `n` joints and a task
/// of `t` rows (`6` without a `[task]`) breaks, in a fixed order: the link (`1 ≤ i ≤ n`), the rows
/// (`1 ≤ r ≤ 5`), `n − r ≥ t`, `i ≥ 6` (rank 6 of `J^B_0i`), and `m = (6 − r) + (n − i) ≥ t`
/// (the last two checked only when the others hold).
/// Empty when admitted. With `t = 6` these are the thesis's `n − r ≥ 6` and `m ≥ 6` (3.15).
pub fn admission_problems(n: usize, link: usize, r: usize, t: usize) -> Vec<AdmissionError> {
    let mut out = Vec::new();
    if !(1..=n).contains(&link) {
        out.push(AdmissionError::LinkOutOfRange { link, n });
    }
    if r == 0 {
        out.push(AdmissionError::NoRows);
    } else if r > 5 {
        out.push(AdmissionError::TooManyRows { r });
    }
    if r >= 1 && n < t + r {
        out.push(AdmissionError::TooFewJoints { n, r, t });
    }
    if out.is_empty() {
        if link < 6 {
            out.push(AdmissionError::TooFewJointsBefore { link });
        }
        let m = 6 - r + n - link;
        if m < t {
            out.push(AdmissionError::TooFewColumns {
                m,
                after: n - link,
                r,
                t,
            });
        }
    }
    out
}

/// The admission rule broken (see [`admission_problems`]), if any: `n − r ≥ t` first (it is about
/// the robot as a whole), then the others in the order of [`admission_problems`].
pub fn admit(n: usize, link: usize, r: usize, t: usize) -> Result<(), AdmissionError> {
    let problems = admission_problems(n, link, r, t);
    let first = problems
        .iter()
        .find(|e| matches!(e, AdmissionError::TooFewJoints { .. }))
        .or(problems.first());
    match first {
        Some(e) => Err(*e),
        None => Ok(()),
    }
}

/// On the last link (`i = n`) with a constraint point that slides along the instrument with
/// one parameter (`g_ir = (R, o + l_a d)`), the point must not lie beyond the instrument's tip
/// (the end effector, fixed in the same link) along `d` at the parameters' values: the trocar
/// would be outside the instrument. `Some((parameter, message))` when it does.
pub fn trocar_beyond_tip(d: &RobotDescription) -> Option<(String, String)> {
    let s = sliding_point(d)?;
    let (name, value, dd, at_tip) = (&s.name, s.value, s.dd, s.at_tip);
    let beyond = (value - at_tip) * dd.sqrt();
    (beyond > 1e-12 * (1.0 + at_tip.abs()) && beyond.is_finite()).then(|| {
        (
            name.clone(),
            format!(
                "the trocar is outside the instrument: at {name} = {value} the constraint point lies {beyond:.6} beyond the tip `{}` along the shaft (constraint.xyz); {name} must stay below {at_tip:.6}",
                d.end_effector.name
            ),
        )
    })
}

/// When [`trocar_beyond_tip`] finds the trocar beyond the tip because the direction the
/// constraint point slides along (its parameter's coefficients in `constraint.xyz`) does not
/// point toward the tip at all — the tip's projection on that line is at or behind the point at
/// parameter 0, as with `xyz = [0, "l_a", 0]` on a shaft along `z` — the axis is what is wrong,
/// not the parameter's value: the message for `constraint.xyz`.
pub fn shaft_not_toward_tip(d: &RobotDescription) -> Option<String> {
    let s = sliding_point(d)?;
    if s.at_tip > 0.0 || trocar_beyond_tip(d).is_none() {
        return None;
    }
    // `+ 0.0` writes -0 as 0.
    let f = |v: [f64; 3]| format!("({}, {}, {})", v[0] + 0.0, v[1] + 0.0, v[2] + 0.0);
    Some(format!(
        "the constraint point slides along {} with {} (from {}), which does not point toward the tip `{}` at {} (end_effector.xyz): the trocar's offset runs along the instrument's shaft, from the link toward the tip",
        f(s.dir),
        s.name,
        f(s.origin),
        d.end_effector.name,
        f(s.tip)
    ))
}

/// A constraint point on the last link that slides along a line with one parameter, and the
/// instrument's tip: what [`trocar_beyond_tip`] and [`shaft_not_toward_tip`] judge.
struct SlidingPoint {
    name: String,
    value: f64,
    dir: [f64; 3],
    origin: [f64; 3],
    tip: [f64; 3],
    /// `|dir|²`.
    dd: f64,
    /// The parameter's value that puts the point at the tip's projection on the line.
    at_tip: f64,
}

fn sliding_point(d: &RobotDescription) -> Option<SlidingPoint> {
    let c = d.constraint.as_ref()?;
    if c.link != d.joints.len() {
        return None;
    }
    let mut names = c
        .origin
        .xyz
        .iter()
        .flat_map(|s| s.terms.iter().map(|(_, n)| n));
    let name = names.next()?;
    if names.any(|n| n != name) {
        return None;
    }
    let value = d.parameter(name)?;
    let lookup = |n: &str| d.parameter(n);
    let coefficient = |s: &Linear| -> f64 {
        s.terms
            .iter()
            .filter(|(_, n)| n == name)
            .map(|(k, _)| k)
            .sum()
    };
    let dir = [0, 1, 2].map(|k| coefficient(&c.origin.xyz[k]));
    let origin = [0, 1, 2].map(|k| c.origin.xyz[k].constant);
    let mut tip = [0.0; 3];
    for (t, s) in tip.iter_mut().zip(&d.end_effector.origin.xyz) {
        let Ok(v) = s.eval(lookup) else {
            return None;
        };
        *t = v;
    }
    let dd: f64 = dir.iter().map(|x| x * x).sum();
    if dd <= 0.0 || !dd.is_finite() {
        return None;
    }
    // The value of the parameter that puts the point at the tip's projection on the shaft.
    let at_tip = (0..3).map(|k| dir[k] * (tip[k] - origin[k])).sum::<f64>() / dd;
    Some(SlidingPoint {
        name: name.clone(),
        value,
        dir,
        origin,
        tip,
        dd,
        at_tip,
    })
}

/// Tolerance on unit norms and orthonormality.
pub const TOLERANCE: f64 = 1e-9;

struct Checker<'a> {
    d: &'a RobotDescription,
    locate: &'a dyn Fn(&str) -> Option<Location>,
    out: Vec<DescriptionError>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn fmt3(v: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

impl Checker<'_> {
    fn err(&mut self, field: &str, message: impl Into<String>) {
        let loc = (self.locate)(field);
        self.out.push(DescriptionError {
            file: self.d.source.clone(),
            line: loc.map(|l| l.line),
            column: loc.map(|l| l.column),
            field: field.to_string(),
            message: message.into(),
        });
    }

    /// Every number of `values` obeys [`crate::validity`]; otherwise an error at `field`.
    fn finite(&mut self, field: &str, values: &[f64]) -> bool {
        match crate::validity::check_all(values) {
            Ok(()) => true,
            Err((k, problem)) => {
                self.err(field, format!("{:e} {problem}", values[k]));
                false
            }
        }
    }

    fn scalar(&mut self, field: &str, s: &Linear) {
        let numbers: Vec<f64> = std::iter::once(s.constant)
            .chain(s.terms.iter().map(|(c, _)| *c))
            .collect();
        self.finite(field, &numbers);
        for (_, name) in &s.terms {
            if self.d.parameter(name).is_none() {
                let declared: Vec<_> = self.d.parameters.iter().map(|p| p.name.as_str()).collect();
                self.err(
                    field,
                    format!(
                        "unknown parameter `{name}`: declare it in [parameters] (declared: {})",
                        if declared.is_empty() {
                            "none".to_string()
                        } else {
                            declared.join(", ")
                        }
                    ),
                );
            }
        }
    }

    fn origin(&mut self, prefix: &str, o: &Origin) {
        for (c, s) in o.xyz.iter().enumerate() {
            self.scalar(&format!("{prefix}.xyz[{c}]"), s);
        }
        match &o.rotation {
            Rotation::Rpy(rpy) => {
                self.finite(&format!("{prefix}.rpy"), rpy);
            }
            Rotation::Matrix(m) => {
                let field = format!("{prefix}.rotation");
                if !self.finite(&field, m.as_flattened()) {
                    return;
                }
                let mut worst: f64 = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        // (R Rᵀ)_ab − δ_ab: rows orthonormal.
                        let dot: f64 = (0..3).map(|k| m[a][k] * m[b][k]).sum();
                        worst = worst.max((dot - f64::from(u8::from(a == b))).abs());
                    }
                }
                let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
                if worst > TOLERANCE {
                    self.err(
                        &field,
                        format!(
                            "not a rotation: the rows are not orthonormal (R Rᵀ differs from I by {worst:.3e})"
                        ),
                    );
                } else if (det - 1.0).abs() > TOLERANCE {
                    self.err(
                        &field,
                        format!("not a rotation: det R = {det} (a reflection); it must be 1"),
                    );
                }
            }
        }
    }

    /// A link's mass properties: positive mass, finite centre of mass, and a tensor that is
    /// physical (positive principal moments that obey the triangle inequality).
    fn inertia(&mut self, prefix: &str, i: &super::Inertia) {
        if self.finite(&format!("{prefix}.mass"), &[i.mass]) && i.mass <= 0.0 {
            self.err(
                &format!("{prefix}.mass"),
                format!("mass needs a finite positive number (kg), not {}", i.mass),
            );
        }
        self.finite(&format!("{prefix}.com"), &i.com);
        if !self.finite(&format!("{prefix}.inertia"), &i.inertia) {
            return;
        }
        let m = nalgebra::Matrix3::from_fn(|r, c| i.matrix()[r][c]);
        let e = m.symmetric_eigenvalues();
        let (a, b, c) = (e[0], e[1], e[2]);
        // Positive definite. The triangle inequality (each principal moment at most the sum of
        // the other two) holds for every real body but not for every published identification
        // (Franka's link 4 misses it by 9%); a plant that needs it says so where it is built.
        if a <= 0.0 || b <= 0.0 || c <= 0.0 {
            self.err(
                &format!("{prefix}.inertia"),
                format!(
                    "[ixx, iyy, izz, ixy, ixz, iyz] is not the inertia of a body: its principal moments {a:e}, {b:e}, {c:e} must be positive"
                ),
            );
        }
    }

    fn unit_axis(&mut self, field: &str, axis: &[f64; 3]) {
        if !self.finite(field, axis) {
            return;
        }
        let n = norm(axis);
        if n == 0.0 {
            self.err(field, "the axis is zero; it must be a unit vector");
        } else if (n - 1.0).abs() > TOLERANCE {
            let u = axis.map(|x| x / n);
            self.err(
                field,
                format!(
                    "the axis {} is not a unit vector (norm {n}); write {}",
                    fmt3(axis),
                    fmt3(&u)
                ),
            );
        }
    }

    /// Rows of a selection (`H` of the constraint, `S` of the task): finite, non-zero and linearly
    /// independent (Gram–Schmidt against the rows before each), each error on `{prefix}[k]`.
    fn independent_rows(&mut self, prefix: &str, what: &str, rows: &[[f64; 6]]) {
        let r = rows.len();
        let mut basis: Vec<[f64; 6]> = Vec::new();
        for (k, row) in rows.iter().enumerate() {
            let field = format!("{prefix}[{k}]");
            if !self.finite(&field, row) {
                continue;
            }
            let size = norm(row);
            if size == 0.0 {
                self.err(&field, format!("a row of {what} is zero"));
                continue;
            }
            let mut rest = *row;
            for b in &basis {
                let dot: f64 = (0..6).map(|t| rest[t] * b[t]).sum();
                for t in 0..6 {
                    rest[t] -= dot * b[t];
                }
            }
            let left = norm(&rest);
            if left <= 1e-9 * size {
                self.err(
                    &field,
                    format!("this row of {what} is a linear combination of the rows before it ({what} must have rank {r})"),
                );
                continue;
            }
            basis.push(rest.map(|x| x / left));
        }
    }

    fn task(&mut self, task: &super::TaskDesc) {
        let t = task.select.len();
        if t == 0 || t > 6 {
            self.err(
                "task.select",
                format!("a task selects 1 to 6 rows of the end-effector twist, not {t}"),
            );
        }
        self.independent_rows("task.select", "the task selection S", &task.select);
    }

    fn run(&mut self) {
        let d = self.d;
        if d.name.trim().is_empty() {
            self.err("robot.name", "the robot needs a name");
        }
        for (k, p) in d.parameters.iter().enumerate() {
            let field = format!("parameters.{}", p.name);
            if RUST_KEYWORDS.contains(&p.name.as_str()) || p.name == "_" {
                self.err(
                    &field,
                    format!(
                        "parameter name `{}` is a Rust keyword; parameters become arguments of generated code",
                        p.name
                    ),
                );
            } else if !is_identifier(&p.name) {
                self.err(
                    &field,
                    format!(
                        "parameter name `{}` is not an identifier (letters, digits, `_`, not starting with a digit)",
                        p.name
                    ),
                );
            }
            if d.parameters[..k].iter().any(|q| q.name == p.name) {
                self.err(&field, format!("parameter `{}` is declared twice", p.name));
            }
            self.finite(&field, &[p.value]);
        }
        if d.joints.is_empty() {
            self.err("joints", "the robot needs at least one joint ([[joints]])");
        }
        for (k, j) in d.joints.iter().enumerate() {
            let prefix = format!("joints[{k}]");
            if j.name.trim().is_empty() {
                self.err(&format!("{prefix}.name"), "a joint needs a name");
            } else if let Some(first) = d.joints[..k].iter().position(|o| o.name == j.name) {
                self.err(
                    &format!("{prefix}.name"),
                    format!(
                        "duplicate joint name `{}` (already used by joints[{first}])",
                        j.name
                    ),
                );
            }
            self.origin(&prefix, &j.origin);
            if let Some([lo, hi]) = j.limits {
                let field = format!("{prefix}.limits");
                if self.finite(&field, &[lo, hi]) && lo >= hi {
                    self.err(
                        &field,
                        format!("limits = [lower, upper] need lower < upper, not [{lo}, {hi}]"),
                    );
                }
            }
            for (name, value) in [
                ("speed_limit", j.speed_limit),
                ("acceleration_limit", j.acceleration_limit),
                ("jerk_limit", j.jerk_limit),
                ("effort_limit", j.dynamics.effort_limit),
            ] {
                if let Some(v) = value {
                    if self.finite(&format!("{prefix}.{name}"), &[v]) && v <= 0.0 {
                        self.err(
                            &format!("{prefix}.{name}"),
                            format!("{name} needs a finite positive number, not {v}"),
                        );
                    }
                }
            }
            for (name, value) in [
                ("damping", j.dynamics.damping),
                ("friction", j.dynamics.friction),
            ] {
                if let Some(v) = value {
                    if self.finite(&format!("{prefix}.{name}"), &[v]) && v < 0.0 {
                        self.err(
                            &format!("{prefix}.{name}"),
                            format!("{name} needs a finite number ≥ 0, not {v}"),
                        );
                    }
                }
            }
            if let Some(i) = &j.dynamics.inertia {
                self.inertia(&prefix, i);
            }
            match &j.kind {
                JointKind::Revolute { axis } | JointKind::Prismatic { axis } => {
                    self.unit_axis(&format!("{prefix}.axis"), axis);
                }
                JointKind::Twist { v, w } => {
                    for (c, s) in v.iter().enumerate() {
                        self.scalar(&format!("{prefix}.v[{c}]"), s);
                    }
                    let wf = format!("{prefix}.w");
                    if self.finite(&wf, w) {
                        let nw = norm(w);
                        if nw != 0.0 && (nw - 1.0).abs() > TOLERANCE {
                            self.err(
                                &wf,
                                format!("a twist needs ‖ω‖ = 1, or ω = 0 and ‖v‖ = 1; ‖ω‖ = {nw}"),
                            );
                        } else if nw == 0.0 {
                            let vf = format!("{prefix}.v");
                            if v.iter().all(Linear::is_constant) {
                                let vc = [v[0].constant, v[1].constant, v[2].constant];
                                let nv = norm(&vc);
                                if nv.is_finite() && (nv - 1.0).abs() > TOLERANCE {
                                    self.err(
                                        &vf,
                                        format!(
                                            "a twist with ω = 0 (prismatic) needs ‖v‖ = 1; ‖v‖ = {nv}"
                                        ),
                                    );
                                }
                            } else if v.iter().all(|s| s.is_constant() && s.constant == 0.0) {
                                self.err(&vf, "a twist with ω = 0 needs v ≠ 0");
                            }
                        }
                    }
                }
            }
        }
        self.origin("end_effector", &d.end_effector.origin);
        if let Some(i) = &d.instrument {
            for (name, v) in [("mass", i.mass), ("radius", i.radius)] {
                if self.finite(&format!("instrument.{name}"), &[v]) && v <= 0.0 {
                    self.err(
                        &format!("instrument.{name}"),
                        format!("the instrument's {name} needs a finite positive number, not {v}"),
                    );
                }
            }
        }
        if let Some(t) = &d.task {
            self.task(t);
            if d.constraint.is_none() {
                self.err(
                    "task",
                    "a [task] selects rows of the constrained Jacobian J^r; it needs a [constraint]",
                );
            }
        }
        if let Some(c) = &d.constraint {
            self.constraint(c);
        }
    }

    fn constraint(&mut self, c: &super::ConstraintDesc) {
        let n = self.d.joints.len();
        let r = c.h.len();
        let admission = admission_problems(n, c.link, r, self.d.task_rows());
        let link_ok = !admission
            .iter()
            .any(|e| matches!(e, AdmissionError::LinkOutOfRange { .. }));
        // Reported in the order of the fields (the link, the frame, then H), and `m ≥ 6` last.
        let task = self.d.task.is_some();
        let report = |this: &mut Self, which: &dyn Fn(&AdmissionError) -> bool| {
            for e in admission.iter().filter(|e| which(e)) {
                this.err(e.field_for(task), e.to_string());
            }
        };
        report(self, &|e| {
            matches!(e, AdmissionError::LinkOutOfRange { .. })
        });
        self.origin("constraint", &c.origin);
        report(self, &|e| {
            matches!(
                e,
                AdmissionError::NoRows | AdmissionError::TooManyRows { .. }
            )
        });
        self.independent_rows("constraint.h", "H", &c.h);
        report(self, &|e| matches!(e, AdmissionError::TooFewJoints { .. }));
        if let Some(w) = c.wrist {
            self.wrist(c, w, link_ok);
        }
        report(self, &|e| {
            matches!(
                e,
                AdmissionError::TooFewColumns { .. } | AdmissionError::TooFewJointsBefore { .. }
            )
        });
        if self.out.is_empty() {
            self.trocar_inside_the_instrument(c);
        }
        // The rank rule last: it evaluates the robot, which needs every other rule to hold.
        if self.out.is_empty() {
            if let Some(e) = admission_rank_problem(self.d) {
                self.err(e.field_for(self.d.task.is_some()), e.to_string());
            }
        }
    }

    /// [`trocar_beyond_tip`], on the parameter; on `constraint.xyz` when the point does not
    /// slide toward the tip at all ([`shaft_not_toward_tip`]).
    fn trocar_inside_the_instrument(&mut self, _c: &super::ConstraintDesc) {
        if let Some(message) = shaft_not_toward_tip(self.d) {
            self.err("constraint.xyz", message);
        } else if let Some((name, message)) = trocar_beyond_tip(self.d) {
            self.err(&format!("parameters.{name}"), message);
        }
    }

    fn wrist(&mut self, c: &super::ConstraintDesc, w: Wrist, link_ok: bool) {
        let name = match w {
            Wrist::Unidirectional => "unidirectional",
            Wrist::Zy => "zy",
            Wrist::Zx => "zx",
        };
        // The thesis bases are written for H = x_r (3.21) and H = (x_r, z_r) (3.25).
        const X_R: [f64; 6] = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        const Z_R: [f64; 6] = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let (rows, basis): (&[[f64; 6]], &str) = match c.basis() {
            NullSpaceBasis::Unidirectional => (&[X_R], "(3.23)"),
            NullSpaceBasis::Bidirectional => (&[X_R, Z_R], "(3.27)"),
            NullSpaceBasis::Computed => return,
        };
        if c.h.as_slice() != rows {
            let wanted = if rows.len() == 1 {
                "H = x_r (h = [\"x\"])"
            } else {
                "H = (x_r, z_r) (h = [\"x\", \"z\"])"
            };
            self.err(
                "constraint.wrist",
                format!("wrist `{name}` uses the thesis basis {basis}, which needs {wanted}"),
            );
        }
        // g_ir = (I, (0, l_a, 0)).
        let needs = format!(
            "wrist `{name}` uses the thesis basis {basis}, which needs g_ir = (I, (0, l_a, 0)) with l_a a parameter"
        );
        for c_ in [0, 2] {
            let s = &c.origin.xyz[c_];
            if !(s.is_constant() && s.constant == 0.0) {
                self.err(
                    &format!("constraint.xyz[{c_}]"),
                    format!("{needs}: this entry must be 0"),
                );
            }
        }
        let y = &c.origin.xyz[1];
        match y.terms.as_slice() {
            [(coefficient, p)] if *coefficient == 1.0 && y.constant == 0.0 => {
                if self.d.parameter(p) == Some(0.0) {
                    self.err(
                        "constraint.xyz[1]",
                        format!(
                            "{needs}: the nominal value of `{p}` is 0 and the basis divides by it"
                        ),
                    );
                }
            }
            _ => self.err(
                "constraint.xyz[1]",
                format!("{needs}: this entry must be a single parameter name such as \"l_a\""),
            ),
        }
        let identity = match &c.origin.rotation {
            Rotation::Rpy(rpy) => rpy.iter().all(|a| *a == 0.0),
            Rotation::Matrix(m) => {
                (0..3).all(|a| (0..3).all(|b| m[a][b] == f64::from(u8::from(a == b))))
            }
        };
        if !identity {
            let field = match c.origin.rotation {
                Rotation::Rpy(_) => "constraint.rpy",
                Rotation::Matrix(_) => "constraint.rotation",
            };
            self.err(field, format!("{needs}: the rotation must be the identity"));
        }
        // The two joints after the constraint.
        let second = match w {
            Wrist::Unidirectional => return,
            Wrist::Zy => ([0.0, 1.0, 0.0], "y"),
            Wrist::Zx => ([1.0, 0.0, 0.0], "x"),
        };
        if !link_ok {
            return;
        }
        let i = c.link;
        if self.d.joints.len() < i + 2 {
            self.err(
                "constraint.wrist",
                format!(
                    "wrist `{name}` needs two joints after the constrained link {i} (joints {} and {}); the robot has {}",
                    i + 1,
                    i + 2,
                    self.d.joints.len()
                ),
            );
            return;
        }
        for (offset, (axis, letter)) in [([0.0, 0.0, 1.0], "z"), second].into_iter().enumerate() {
            let k = i + offset; // 0-based index of joint i + 1 + offset
            let j = &self.d.joints[k];
            let ok = matches!(j.kind, JointKind::Revolute { axis: a } if a == axis);
            if !ok {
                self.err(
                    &format!("joints[{k}].axis"),
                    format!(
                        "wrist `{name}` needs joint {} (`{}`, the {} after the constrained link) revolute about {letter} (axis = {})",
                        k + 1,
                        j.name,
                        if offset == 0 { "first" } else { "second" },
                        fmt3(&axis)
                    ),
                );
            }
        }
    }
}

/// Every problem of `d`, in a fixed order (description, parameters, joints, end effector,
/// constraint); `locate` gives the position of a field path.
pub(crate) fn problems(
    d: &RobotDescription,
    locate: &dyn Fn(&str) -> Option<Location>,
) -> Vec<DescriptionError> {
    let mut checker = Checker {
        d,
        locate,
        out: Vec::new(),
    };
    checker.run();
    checker.out
}

/// Position of `joints[k]…` from the joint's recorded location.
fn joint_location(d: &RobotDescription, field: &str) -> Option<Location> {
    let rest = field.strip_prefix("joints[")?;
    let k: usize = rest[..rest.find(']')?].parse().ok()?;
    d.joints.get(k)?.location
}

impl RobotDescription {
    /// Checks every rule of this module; the first problem found, if any.
    ///
    /// Descriptions read by [`RobotDescription::from_toml_str`] are already valid. On a description
    /// built in code or imported, errors carry the source file and, for joints with a recorded
    /// location, the line.
    pub fn validate(&self) -> Result<(), DescriptionError> {
        match self.problems().into_iter().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Every problem of this description (empty when valid), in a fixed order.
    pub fn problems(&self) -> Vec<DescriptionError> {
        problems(self, &|field| joint_location(self, field))
    }
}
