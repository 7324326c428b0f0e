//! The symbolic model of a closed planar mechanism: chains, joints and lengths as written, with
//! the admission rules of the structural equations (2), (9)–(10), (23)–(24), (32)–(33).

use crate::description::DescriptionError;
use crate::expr::Expr;
use std::path::PathBuf;

/// Parameter values by name (`None`: not a parameter): what the model's expressions are
/// evaluated with ([`MechanismModel::lookup`] gives one for values in declaration order).
pub type Lookup<'a> = dyn Fn(&str) -> Option<f64> + 'a;

/// The number `value` as an expression (a TOML literal, an absent field).
pub const fn number(value: f64) -> Expr {
    Expr::Number { value, at: 0 }
}

const ZERO: Expr = number(0.0);

/// One component of the task vector `x` (1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Position x of the common frame.
    X,
    /// Position y of the common frame.
    Y,
    /// Orientation `φ` of the common frame.
    Phi,
}

impl Output {
    /// Index in `(x, y, φ)`.
    pub fn index(self) -> usize {
        match self {
            Output::X => 0,
            Output::Y => 1,
            Output::Phi => 2,
        }
    }

    /// Name as written in descriptions: `x`, `y` or `phi`.
    pub fn name(self) -> &'static str {
        match self {
            Output::X => "x",
            Output::Y => "y",
            Output::Phi => "phi",
        }
    }
}

/// A named parameter with its nominal value.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismParameter {
    /// Name (an identifier, not `pi`).
    pub name: String,
    /// The value as written (an expression of the parameters declared before it).
    pub expr: Expr,
    /// Its value with the nominal values of the parameters before it.
    pub nominal: f64,
}

/// A planar pose `Trans(x, y) · Rot_z(angle)` as written (absent coordinates are zero).
#[derive(Clone, Debug, PartialEq)]
pub struct PoseExpr {
    /// x coordinate.
    pub x: Expr,
    /// y coordinate.
    pub y: Expr,
    /// Rotation about z (rad).
    pub angle: Expr,
}

impl PoseExpr {
    /// The identity pose.
    pub const IDENTITY: PoseExpr = PoseExpr {
        x: ZERO,
        y: ZERO,
        angle: ZERO,
    };

    /// `(x, y, angle)` with the parameter values `values`; errors name `field` and are raised
    /// for non-finite results.
    pub fn eval(&self, values: &Lookup, field: &str) -> Result<[f64; 3], DescriptionError> {
        Ok([
            eval(&self.x, values, &format!("{field}.x"))?,
            eval(&self.y, values, &format!("{field}.y"))?,
            eval(&self.angle, values, &format!("{field}.angle"))?,
        ])
    }
}

/// What a planar joint does.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanarJointKind {
    /// Rotation about z through the joint frame's origin.
    Revolute,
    /// Translation along `axis` (normalised when evaluated, [`PlanarJointKind::unit_axis`]).
    Prismatic {
        /// Direction in the joint frame, as written.
        axis: [Expr; 2],
    },
}

impl PlanarJointKind {
    /// The prismatic joint's unit axis with the parameter values `values` (`None` for a
    /// revolute joint). Errors (field `field`) for a zero or non-finite axis.
    pub fn unit_axis(
        &self,
        values: &Lookup,
        field: &str,
    ) -> Result<Option<[f64; 2]>, DescriptionError> {
        let PlanarJointKind::Prismatic { axis } = self else {
            return Ok(None);
        };
        let a = [
            eval(&axis[0], values, &format!("{field}[0]"))?,
            eval(&axis[1], values, &format!("{field}[1]"))?,
        ];
        let n = (a[0] * a[0] + a[1] * a[1]).sqrt();
        if !(n.is_finite() && n > 1e-12) {
            return Err(invalid(
                field,
                "prismatic axis must be a non-zero finite vector",
            ));
        }
        Ok(Some([a[0] / n, a[1] / n]))
    }
}

/// One joint: the joint frame is `origin` from the previous frame; the joint then moves the
/// next link by `Rot_z(θ)` or `Trans(θ · axis)`.
#[derive(Clone, Debug, PartialEq)]
pub struct JointModel {
    /// Unique name in the mechanism.
    pub name: String,
    /// Revolute or prismatic.
    pub kind: PlanarJointKind,
    /// Transform from the previous frame (chain base or previous joint) to the joint frame.
    pub origin: PoseExpr,
    /// Active (actuated, `θ_a`) or passive (`θ_p`).
    pub active: bool,
    /// Optional limits `[θ_min, θ_max]` (used by the joint-limit objective of (46)).
    pub limits: Option<[Expr; 2]>,
    /// Optional value near an assembly.
    pub initial: Option<Expr>,
}

/// A contact of an arm's end effector with a held object (35)–(42).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSpec {
    /// Rows of `H`: the free directions `(v_x, v_y, ω)` in the contact frame (empty: gripped).
    pub h: Vec<[Expr; 3]>,
    /// Transform from the contact frame to the object frame `E_c`.
    pub object: PoseExpr,
}

/// The passive joint a row of `H` becomes (see [`ContactSpec::joints`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactJoint {
    /// A free rotation `(0, 0, 1)`.
    Revolute,
    /// A free translation along this unit direction of the contact frame.
    Prismatic([f64; 2]),
}

impl ContactSpec {
    /// The passive joint of each row of `H` with the parameter values `values`: `(0, 0, 1)` a
    /// revolute joint,
    /// `(v_x, v_y, 0)` a prismatic joint along that direction (36)–(42). Errors name
    /// `{field}.h[i]` for a row that mixes rotation and translation or is zero.
    pub fn joints(
        &self,
        values: &Lookup,
        field: &str,
    ) -> Result<Vec<ContactJoint>, DescriptionError> {
        self.h
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let f = format!("{field}.h[{i}]");
                let r = [
                    eval(&row[0], values, &format!("{f}[0]"))?,
                    eval(&row[1], values, &format!("{f}[1]"))?,
                    eval(&row[2], values, &format!("{f}[2]"))?,
                ];
                contact_joint(r).ok_or_else(|| {
                    invalid(
                        f,
                        "a free direction must be a rotation (0, 0, 1) or a translation \
                         (v_x, v_y, 0)",
                    )
                })
            })
            .collect()
    }
}

/// The joint a numeric row of `H` becomes, or `None` when it mixes rotation and translation.
pub fn contact_joint(row: [f64; 3]) -> Option<ContactJoint> {
    let lin = (row[0] * row[0] + row[1] * row[1]).sqrt();
    if lin < 1e-12 && (row[2] - 1.0).abs() < 1e-12 {
        Some(ContactJoint::Revolute)
    } else if row[2].abs() < 1e-12 && lin > 1e-12 && lin.is_finite() {
        Some(ContactJoint::Prismatic([row[0] / lin, row[1] / lin]))
    } else {
        None
    }
}

/// An open planar chain from the ground to the common frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainModel {
    /// Name (for messages; contact joints are named `<chain>_contact<i>`).
    pub name: String,
    /// Pose of the chain's base in the world frame `E_0`.
    pub base: PoseExpr,
    /// Joints, base first.
    pub joints: Vec<JointModel>,
    /// Transform from the last joint's moving frame to the common frame (the contact frame when
    /// there is a contact).
    pub tip: PoseExpr,
    /// Contact with a held object (cooperating arms), if any.
    pub contact: Option<ContactSpec>,
}

impl ChainModel {
    /// Number of joints including the passive contact joints (one per row of `H`).
    pub fn n_joints(&self) -> usize {
        self.joints.len() + self.contact.as_ref().map_or(0, |c| c.h.len())
    }

    /// Joint names in `θ` order, contact joints last.
    pub fn joint_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.joints.iter().map(|j| j.name.clone()).collect();
        if let Some(c) = &self.contact {
            v.extend((0..c.h.len()).map(|i| format!("{}_contact{}", self.name, i + 1)));
        }
        v
    }
}

/// A closed planar mechanism as described: open chains joined at a common frame, with its
/// parameters kept symbolic.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismModel {
    /// Name.
    pub name: String,
    /// Named parameters in declaration order.
    pub parameters: Vec<MechanismParameter>,
    /// The task components `x ⊂ (x, y, φ)`, in order.
    pub outputs: Vec<Output>,
    /// The open chains; all end at the common frame.
    pub chains: Vec<ChainModel>,
    /// The file it was read from, if any.
    pub file: Option<PathBuf>,
}

impl MechanismModel {
    /// Nominal parameter values, in declaration order.
    pub fn nominal_values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.nominal).collect()
    }

    /// Parameter names, in declaration order.
    pub fn parameter_names(&self) -> Vec<&str> {
        self.parameters.iter().map(|p| p.name.as_str()).collect()
    }

    /// The parameter values `values` (one per parameter, in declaration order) looked up by
    /// name, what the model's expressions are evaluated with ([`eval`]).
    pub fn lookup<'a>(&'a self, values: &'a [f64]) -> impl Fn(&str) -> Option<f64> + 'a {
        move |name| {
            self.parameter_index(name)
                .and_then(|k| values.get(k).copied())
        }
    }

    /// Index of the parameter `name`.
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }

    /// Joint names in `θ` order (chain 1's joints, its contact joints, then chain 2's, …).
    pub fn joint_names(&self) -> Vec<String> {
        self.chains
            .iter()
            .flat_map(ChainModel::joint_names)
            .collect()
    }

    /// Number of structural equations `r = 3(m − 1)`.
    pub fn n_constraints(&self) -> usize {
        3 * self.chains.len().saturating_sub(1)
    }

    /// Indices in `θ` of the active and of the passive joints (contact joints are passive).
    pub fn partition(&self) -> (Vec<usize>, Vec<usize>) {
        let (mut active, mut passive) = (Vec::new(), Vec::new());
        let mut k = 0;
        for ch in &self.chains {
            for j in &ch.joints {
                if j.active {
                    active.push(k);
                } else {
                    passive.push(k);
                }
                k += 1;
            }
            for _ in 0..ch.n_joints() - ch.joints.len() {
                passive.push(k);
                k += 1;
            }
        }
        (active, passive)
    }

    /// The structural admission rules (field paths as in descriptions): at least two chains,
    /// every chain with a joint, outputs present and not repeated, unique joint names, at least
    /// one active joint, and no more passive joints than structural equations.
    pub fn validate(&self) -> Result<(), DescriptionError> {
        if self.chains.len() < 2 {
            return Err(invalid(
                "chains",
                format!(
                    "a closed mechanism needs at least two chains, found {}",
                    self.chains.len()
                ),
            ));
        }
        if self.outputs.is_empty() {
            return Err(invalid(
                "outputs",
                "at least one task output (x, y or phi) is required",
            ));
        }
        for (i, o) in self.outputs.iter().enumerate() {
            if self.outputs[..i].contains(o) {
                return Err(invalid(
                    format!("outputs[{i}]"),
                    format!("output `{}` repeated", o.name()),
                ));
            }
        }
        for (ci, ch) in self.chains.iter().enumerate() {
            if ch.joints.is_empty() {
                return Err(invalid(
                    format!("chains[{ci}].joints"),
                    "a chain needs at least one joint",
                ));
            }
        }
        let mut names: Vec<String> = Vec::new();
        for (ci, ch) in self.chains.iter().enumerate() {
            for (ji, name) in ch.joint_names().into_iter().enumerate() {
                if names.contains(&name) {
                    return Err(invalid(
                        format!("chains[{ci}].joints[{ji}].name"),
                        format!("duplicate joint name `{name}`"),
                    ));
                }
                names.push(name);
            }
        }
        let (active, passive) = self.partition();
        if active.is_empty() {
            return Err(invalid(
                "chains",
                "no active joint: mark at least one joint `active = true`",
            ));
        }
        let r = self.n_constraints();
        if passive.len() > r {
            return Err(invalid(
                "chains",
                format!(
                    "{} passive joints but only {r} structural equations: passive joints are not determined",
                    passive.len()
                ),
            ));
        }
        Ok(())
    }

    /// The value admission rules at parameter values `values`: every number finite, prismatic
    /// axes non-zero, limits with `min < max`, contact rows a rotation or a translation.
    pub fn check_values(&self, values: &[f64]) -> Result<(), DescriptionError> {
        let values = &self.lookup(values);
        for (ci, ch) in self.chains.iter().enumerate() {
            let path = format!("chains[{ci}]");
            ch.base.eval(values, &format!("{path}.base"))?;
            ch.tip.eval(values, &format!("{path}.tip"))?;
            for (ji, j) in ch.joints.iter().enumerate() {
                let jp = format!("{path}.joints[{ji}]");
                j.origin.eval(values, &format!("{jp}.origin"))?;
                j.kind.unit_axis(values, &format!("{jp}.axis"))?;
                joint_limits(j, values, &jp)?;
                if let Some(e) = &j.initial {
                    eval(e, values, &format!("{jp}.initial"))?;
                }
            }
            if let Some(c) = &ch.contact {
                c.joints(values, &format!("{path}.contact"))?;
                c.object.eval(values, &format!("{path}.contact.object"))?;
            }
        }
        Ok(())
    }
}

/// A joint's limits with the parameter values `values` (field `{joint}.limits`): finite with
/// `min < max`.
pub fn joint_limits(
    j: &JointModel,
    values: &Lookup,
    joint: &str,
) -> Result<Option<[f64; 2]>, DescriptionError> {
    let Some([lo, hi]) = &j.limits else {
        return Ok(None);
    };
    let lo = eval(lo, values, &format!("{joint}.limits[0]"))?;
    let hi = eval(hi, values, &format!("{joint}.limits[1]"))?;
    if lo >= hi {
        return Err(invalid(format!("{joint}.limits"), "needs min < max"));
    }
    Ok(Some([lo, hi]))
}

/// Evaluates `e` with the parameter values `values` (looked up by name); errors (unknown
/// parameter, division by zero, non-finite) name `field`.
pub fn eval(e: &Expr, values: &Lookup, field: &str) -> Result<f64, DescriptionError> {
    let x = e.eval(values).map_err(|m| invalid(field, m.to_string()))?;
    if !x.is_finite() {
        return Err(invalid(field, "not finite"));
    }
    Ok(x)
}

pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> DescriptionError {
    DescriptionError {
        file: None,
        line: None,
        column: None,
        field: field.into(),
        message: message.into(),
    }
}
