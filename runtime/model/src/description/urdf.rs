//! Importing numeric chains from URDF files (with the `urdf-rs` crate).
//!
//! [`RobotDescription::from_urdf_file`] walks the kinematic tree from the root link (the one link
//! that is no joint's child) to the requested tip link:
//!
//! - `revolute` and `continuous` joints become revolute joints, `prismatic` joints prismatic ones;
//!   the axis is normalised (a zero or non-finite axis is an error);
//! - a joint's origin (`xyz`, `rpy`) is kept as written; `fixed` joints are folded into the origin
//!   of the next moving joint (which then carries a rotation matrix, with entries below 1e-15 set
//!   to 0), or into the end effector;
//! - `floating`, `planar` and `spherical` joints on the path are errors;
//! - the end effector is the tip link's frame, named after it.
//!
//! Errors name the URDF joint (`joint[elbow].axis`, with the line of its `<joint>` element) or
//! `tip_link`; the imported joints keep the line of their `<joint>` element as their location.
//! Branches that do not lead to the tip are ignored. The result has no parameters and no constraint:
//! add one with [`RobotDescription::with_constraint`], or convert the chain to TOML with
//! [`RobotDescription::to_toml_string`] and add a `[constraint]` table there.

use super::locate::location_of;
use super::{
    ConstraintDesc, DescriptionError, EndEffector, JointDesc, JointKind, Location, Origin,
    RobotDescription, Rotation, Scalar,
};
use std::path::Path;
use urdf_rs::JointType;

type Mat3 = [[f64; 3]; 3];

/// `R = Rz(yaw) Ry(pitch) Rx(roll)` (URDF convention), [`trocar::se3::rotation_from_rpy_sin_cos`].
fn rpy_matrix(rpy: [f64; 3]) -> Mat3 {
    let m = trocar::se3::rotation_from_rpy_sin_cos(
        rpy[0].sin_cos(),
        rpy[1].sin_cos(),
        rpy[2].sin_cos(),
    );
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

fn mat_vec(a: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| a[r][k] * v[k]).sum())
}

/// A rigid transform `(R, p)`.
#[derive(Clone, Copy)]
struct Pose {
    r: Mat3,
    p: [f64; 3],
}

impl Pose {
    fn from_urdf(o: &urdf_rs::Pose) -> Self {
        Pose {
            r: rpy_matrix(o.rpy.0),
            p: o.xyz.0,
        }
    }

    fn then(&self, other: &Pose) -> Pose {
        let q = mat_vec(&self.r, &other.p);
        Pose {
            r: mat_mul(&self.r, &other.r),
            p: [0, 1, 2].map(|k| self.p[k] + q[k]),
        }
    }

    /// As an origin with a rotation matrix; entries below 1e-15 in magnitude (the rounding noise of
    /// `cos(π/2)` in composed rpy rotations) are written as 0.
    fn to_origin(self) -> Origin {
        let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
        Origin {
            xyz: self.p.map(|x| Scalar::constant(snap(x))),
            rotation: Rotation::Matrix(self.r.map(|row| row.map(snap))),
        }
    }
}

/// The line of `<joint name="NAME" ...>` in the URDF text.
fn joint_location(text: &str, name: &str) -> Option<Location> {
    let mut from = 0;
    while let Some(k) = text[from..].find("<joint") {
        let start = from + k;
        let end = text[start..].find('>').map_or(text.len(), |e| start + e);
        let tag = &text[start..end];
        if tag.contains(&format!("name=\"{name}\"")) || tag.contains(&format!("name='{name}'")) {
            return Some(location_of(text, start));
        }
        from = start + "<joint".len();
    }
    None
}

fn origin_of(o: &urdf_rs::Pose) -> Origin {
    Origin {
        xyz: o.xyz.0.map(Scalar::constant),
        rotation: Rotation::Rpy(o.rpy.0),
    }
}

impl RobotDescription {
    /// Imports the chain from the root link to `tip_link` of a URDF file (see the module
    /// documentation for the rules). No parameters, no constraint.
    pub fn from_urdf_file(
        path: impl AsRef<Path>,
        tip_link: &str,
    ) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = DescriptionError::read_file(path)?;
        Self::from_urdf_text(&text, tip_link, Some(path))
    }

    /// Imports the chain from the root link to `tip_link` of URDF text.
    pub fn from_urdf_str(text: &str, tip_link: &str) -> Result<Self, DescriptionError> {
        Self::from_urdf_text(text, tip_link, None)
    }

    /// This description with `constraint` added (replacing any), validated.
    pub fn with_constraint(mut self, constraint: ConstraintDesc) -> Result<Self, DescriptionError> {
        self.constraint = Some(constraint);
        self.validate()?;
        Ok(self)
    }

    fn from_urdf_text(
        text: &str,
        tip_link: &str,
        file: Option<&Path>,
    ) -> Result<Self, DescriptionError> {
        let err = |field: &str, line: Option<Location>, message: String| DescriptionError {
            file: file.map(Path::to_path_buf),
            line: line.map(|l| l.line),
            column: line.map(|l| l.column),
            field: field.to_string(),
            message,
        };
        let robot = urdf_rs::read_from_string(text)
            .map_err(|e| err("(document)", None, format!("not a valid URDF: {e}")))?;
        let known_link = |name: &str| {
            robot.links.iter().any(|l| l.name == name)
                || robot
                    .joints
                    .iter()
                    .any(|j| j.parent.link == name || j.child.link == name)
        };
        if !known_link(tip_link) {
            let names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
            return Err(err(
                "tip_link",
                None,
                format!(
                    "unknown tip link `{tip_link}` (links: {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        }
        // Walk up from the tip to the root.
        let mut chain = Vec::new();
        let mut current = tip_link.to_string();
        loop {
            let parents: Vec<&urdf_rs::Joint> = robot
                .joints
                .iter()
                .filter(|j| j.child.link == current)
                .collect();
            match parents.as_slice() {
                [] => break,
                [j] => {
                    if chain.len() > robot.joints.len() {
                        return Err(err(
                            &format!("joint[{}]", j.name),
                            joint_location(text, &j.name),
                            "the joints form a cycle: a URDF must be a tree".into(),
                        ));
                    }
                    chain.push(*j);
                    current = j.parent.link.clone();
                }
                [a, b, ..] => {
                    return Err(err(
                        &format!("joint[{}]", b.name),
                        joint_location(text, &b.name),
                        format!(
                            "link `{current}` is the child of two joints (`{}` and `{}`): a URDF must be a tree",
                            a.name, b.name
                        ),
                    ))
                }
            }
        }
        chain.reverse();
        let mut joints = Vec::new();
        let mut pending: Option<Pose> = None;
        for j in chain {
            let field = format!("joint[{}]", j.name);
            let line = joint_location(text, &j.name);
            let finite = j
                .origin
                .xyz
                .iter()
                .chain(j.origin.rpy.iter())
                .all(|x| x.is_finite());
            if !finite {
                return Err(err(
                    &format!("{field}.origin"),
                    line,
                    "origin numbers must be finite".into(),
                ));
            }
            let moving = match j.joint_type {
                JointType::Fixed => None,
                JointType::Revolute | JointType::Continuous => Some(true),
                JointType::Prismatic => Some(false),
                JointType::Floating | JointType::Planar | JointType::Spherical => {
                    return Err(err(
                        &format!("{field}.type"),
                        line,
                        format!(
                            "joint type `{:?}` is not supported on the path to `{tip_link}` (only revolute, continuous, prismatic and fixed)",
                            j.joint_type
                        )
                        .to_lowercase(),
                    ))
                }
            };
            let here = Pose::from_urdf(&j.origin);
            let Some(revolute) = moving else {
                pending = Some(match pending {
                    Some(p) => p.then(&here),
                    None => here,
                });
                continue;
            };
            let a = j.axis.xyz.0;
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if !n.is_finite() || n == 0.0 {
                return Err(err(
                    &format!("{field}.axis"),
                    line,
                    format!(
                        "the axis [{}, {}, {}] cannot be normalised",
                        a[0], a[1], a[2]
                    ),
                ));
            }
            let axis = a.map(|x| x / n);
            let origin = match pending.take() {
                Some(p) => p.then(&here).to_origin(),
                None => origin_of(&j.origin),
            };
            joints.push(JointDesc {
                name: j.name.clone(),
                origin,
                kind: if revolute {
                    JointKind::Revolute { axis }
                } else {
                    JointKind::Prismatic { axis }
                },
                location: line,
            });
        }
        let end_effector = EndEffector {
            name: tip_link.to_string(),
            origin: match pending {
                Some(p) => p.to_origin(),
                None => Origin {
                    xyz: Default::default(),
                    rotation: Rotation::Rpy([0.0; 3]),
                },
            },
        };
        let description = RobotDescription {
            name: robot.name.clone(),
            parameters: Vec::new(),
            joints,
            end_effector,
            constraint: None,
            source: file.map(Path::to_path_buf),
        };
        description.validate()?;
        Ok(description)
    }
}
