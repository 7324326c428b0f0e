//! A description evaluated with parameter values: the joints, tool and constraint of the
//! allocation-free typed API ([`trocar::kinematics`], [`trocar::constraint`]).
//!
//! [`NumericModel`] evaluates a [`RobotDescription`] with its nominal `[parameters]` (or
//! overrides); every error on user input is a [`RobotError`], never a panic.
//! [`NumericModel::to_chain`] and [`NumericModel::to_constraint`] hand the description to the typed
//! API for control loops; the dynamic-size numeric reference (`trocar_sim::robot::NumericRobot`)
//! is built on it.

use crate::description::{
    admit, AdmissionError, JointKind, Linear, Origin, RobotDescription, Rotation,
};
use nalgebra::{convert, Const, Matrix3, RealField, SMatrix, Vector3};
use std::fmt;
use trocar::constraint::{Constraint, ConstraintError, NullSpaceBasis};
use trocar::control::{ChainKinematics, Shaft};
use trocar::kinematics::{Chain, Joint};
use trocar::linalg::SquareDim;
use trocar::se3::{self, Se3, Twist};

/// Why a robot cannot be built or evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum RobotError {
    /// A length names a parameter that has no value.
    UnknownParameter {
        /// The parameter.
        name: String,
        /// Where it is used, e.g. `joints[6].xyz[1]`.
        field: String,
    },
    /// An override names a parameter the description does not declare.
    UnknownOverride(String),
    /// A parameter value (nominal or override) is not finite.
    BadParameterValue(String),
    /// Wrong number of joint values.
    WrongJointCount {
        /// Joints of the robot.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// The operation needs a constraint and the description has none.
    NoConstraint,
    /// The operation needs a task selection and the description has no `[task]`.
    NoTask,
    /// The constrained link is not one of the robot's links `1..=n`.
    LinkOutOfRange {
        /// The link given.
        link: usize,
        /// Joints of the robot.
        joints: usize,
    },
    /// A joint axis or twist is zero, not unit, or not finite.
    BadAxis {
        /// The field, e.g. `joints[2].axis`.
        field: String,
    },
    /// A rotation matrix is not a rotation.
    BadRotation {
        /// The field, e.g. `joints[2].rotation`.
        field: String,
    },
    /// The constraint is invalid (dependent rows, thesis basis with another frame, `l_a = 0`, ...).
    Constraint(ConstraintError),
    /// Another admission rule of the method is broken (see
    /// [`admission_problems`](crate::description::admission_problems)).
    NotAdmitted(AdmissionError),
    /// The controller needs the constraint frame to slide along the link with a parameter `l_a`
    /// (`g_ir = (R_ir, o + l_a d)`), and it does not.
    NoShaft,
    /// The typed conversion was asked for the wrong size.
    WrongSize {
        /// What was asked for.
        what: &'static str,
        /// The robot's size.
        expected: usize,
        /// The size asked for.
        got: usize,
    },
}

impl fmt::Display for RobotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownParameter { name, field } => {
                write!(f, "field `{field}`: unknown parameter `{name}`")
            }
            Self::UnknownOverride(n) => write!(f, "unknown parameter `{n}` (not in [parameters])"),
            Self::BadParameterValue(n) => write!(f, "parameter `{n}` is not a finite number"),
            Self::WrongJointCount { expected, got } => {
                write!(
                    f,
                    "{got} joint values given, the robot has {expected} joints"
                )
            }
            Self::NoConstraint => write!(f, "the robot has no [constraint]"),
            Self::NoTask => write!(f, "the robot has no [task]"),
            Self::NoShaft => write!(
                f,
                "field `constraint.xyz`: the trocar must slide along the link with a parameter \
                 `l_a` (g_ir = (R_ir, o + l_a d)) for the controller to follow it"
            ),
            Self::LinkOutOfRange { link, joints } => write!(
                f,
                "field `constraint.link`: link {link} is not one of 1..={joints}"
            ),
            Self::BadAxis { field } => {
                write!(f, "field `{field}`: the axis must be a finite unit vector")
            }
            Self::BadRotation { field } => {
                write!(f, "field `{field}`: not a rotation matrix")
            }
            Self::Constraint(e) => write!(f, "field `constraint`: {e}"),
            Self::NotAdmitted(e) => write!(f, "field `{}`: {e}", e.field()),
            Self::WrongSize {
                what,
                expected,
                got,
            } => write!(f, "{what}: the robot has {expected}, {got} asked for"),
        }
    }
}

impl std::error::Error for RobotError {}

impl From<AdmissionError> for RobotError {
    fn from(e: AdmissionError) -> Self {
        match e {
            AdmissionError::LinkOutOfRange { link, n } => Self::LinkOutOfRange { link, joints: n },
            AdmissionError::NoRows => ConstraintError::BadRowCount(0).into(),
            AdmissionError::TooManyRows { r } => ConstraintError::BadRowCount(r).into(),
            e @ (AdmissionError::TooFewJoints { .. }
            | AdmissionError::TooFewColumns { .. }
            | AdmissionError::TooFewJointsBefore { .. }
            | AdmissionError::SingularEverywhere { .. }) => Self::NotAdmitted(e),
        }
    }
}

impl From<ConstraintError> for RobotError {
    fn from(e: ConstraintError) -> Self {
        Self::Constraint(e)
    }
}

/// A constraint (3.3) with a number of rows `r` (1 to 5) known at run time.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyConstraint<T: RealField + Copy> {
    /// `r = 1`.
    R1(Constraint<T, 1>),
    /// `r = 2`.
    R2(Constraint<T, 2>),
    /// `r = 3`.
    R3(Constraint<T, 3>),
    /// `r = 4`.
    R4(Constraint<T, 4>),
    /// `r = 5`.
    R5(Constraint<T, 5>),
}

macro_rules! dispatch {
    ($self:expr, $c:ident => $body:expr) => {
        match $self {
            AnyConstraint::R1($c) => $body,
            AnyConstraint::R2($c) => $body,
            AnyConstraint::R3($c) => $body,
            AnyConstraint::R4($c) => $body,
            AnyConstraint::R5($c) => $body,
        }
    };
}

impl<T: RealField + Copy> AnyConstraint<T> {
    fn new(
        link: usize,
        g_ir: Se3<T>,
        h: &[[f64; 6]],
        basis: NullSpaceBasis,
    ) -> Result<Self, ConstraintError> {
        fn typed<T: RealField + Copy, const R: usize>(
            link: usize,
            g_ir: Se3<T>,
            h: &[[f64; 6]],
            basis: NullSpaceBasis,
        ) -> Result<Constraint<T, R>, ConstraintError>
        where
            Const<R>: SquareDim,
        {
            let m = SMatrix::<T, R, 6>::from_fn(|r, c| convert(h[r][c]));
            Constraint::with_basis(link, g_ir, m, basis)
        }
        Ok(match h.len() {
            1 => Self::R1(typed(link, g_ir, h, basis)?),
            2 => Self::R2(typed(link, g_ir, h, basis)?),
            3 => Self::R3(typed(link, g_ir, h, basis)?),
            4 => Self::R4(typed(link, g_ir, h, basis)?),
            5 => Self::R5(typed(link, g_ir, h, basis)?),
            r => return Err(ConstraintError::BadRowCount(r)),
        })
    }

    /// The number of constraint rows `r`.
    pub fn rows(&self) -> usize {
        dispatch!(self, c => c.h().nrows())
    }

    /// The constrained link `i` (1-based).
    pub fn link(&self) -> usize {
        dispatch!(self, c => c.link())
    }

    /// The constraint frame `g_ir`.
    pub fn frame(&self) -> Se3<T> {
        dispatch!(self, c => *c.frame())
    }

    /// `Λ = H Ad_{g_ri}` (3.3), r×6, column-major.
    pub fn lambda_column_major(&self) -> Vec<T> {
        dispatch!(self, c => c.lambda().as_slice().to_vec())
    }

    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`, 6×r, column-major.
    pub fn lambda_pinv_column_major(&self) -> Vec<T> {
        dispatch!(self, c => c.lambda_pinv().as_slice().to_vec())
    }

    /// `J_c = Ad_{g_ei} Λ†` (3.33), 6×r, column-major, from `g_ie`.
    pub fn constraint_jacobian_c_column_major(&self, g_ie: &Se3<T>) -> Vec<T> {
        dispatch!(self, c => {
            (trocar::se3::Adjoint(*g_ie).inverse_matrix() * c.lambda_pinv())
                .as_slice()
                .to_vec()
        })
    }

    /// The columns of `Λ#`, 6×(6−r): the thesis basis (3.23)/(3.27) or the computed one.
    pub fn lambda_null_space_columns(&self) -> &[Twist<T>] {
        dispatch!(self, c => c.lambda_null_space_columns())
    }

    /// The typed constraint. Errors if `R ≠ r`.
    pub fn to_constraint<const R: usize>(&self) -> Result<Constraint<T, R>, RobotError>
    where
        Const<R>: SquareDim,
    {
        let wrong = RobotError::WrongSize {
            what: "constraint rows",
            expected: self.rows(),
            got: R,
        };
        let (link, g, basis, h) = dispatch!(self, c => (
            c.link(),
            *c.frame(),
            c.basis(),
            c.h().as_slice().to_vec()
        ));
        if self.rows() != R {
            return Err(wrong);
        }
        let h = SMatrix::<T, R, 6>::from_column_slice(&h);
        Ok(Constraint::with_basis(link, g, h, basis)?)
    }
}

/// A [`RobotDescription`] evaluated with parameter values: numeric joints (base first), tool and
/// constraint.
#[derive(Clone, Debug, PartialEq)]
pub struct NumericModel<T: RealField + Copy = f64> {
    description: RobotDescription,
    parameters: Vec<(String, f64)>,
    joints: Vec<Joint<T>>,
    tool: Se3<T>,
    constraint: Option<AnyConstraint<T>>,
}

/// `field` names the value in an error; it is formatted only then.
fn eval_scalar(
    s: &Linear,
    params: &[(String, f64)],
    field: impl FnOnce() -> String,
) -> Result<f64, RobotError> {
    s.eval(|n| params.iter().find(|(p, _)| p == n).map(|(_, v)| *v))
        .map_err(|name| RobotError::UnknownParameter {
            name,
            field: field(),
        })
}

fn eval_origin<T: RealField + Copy>(
    o: &Origin,
    params: &[(String, f64)],
    field: &dyn Fn() -> String,
) -> Result<Se3<T>, RobotError> {
    let mut p = [0.0; 3];
    for (k, s) in o.xyz.iter().enumerate() {
        p[k] = eval_scalar(s, params, || format!("{}.xyz[{k}]", field()))?;
    }
    let r: Matrix3<f64> = match &o.rotation {
        Rotation::Rpy([r, p, y]) => {
            if ![r, p, y].iter().all(|x| x.is_finite()) {
                return Err(RobotError::BadRotation {
                    field: format!("{}.rpy", field()),
                });
            }
            se3::rotation_from_rpy(*r, *p, *y)
        }
        Rotation::Matrix(m) => {
            let m = Matrix3::from_fn(|r, c| m[r][c]);
            let ok = m.iter().all(|x| x.is_finite())
                && (m.transpose() * m - Matrix3::identity()).amax() < 1e-6
                && m.determinant() > 0.0;
            if !ok {
                return Err(RobotError::BadRotation {
                    field: format!("{}.rotation", field()),
                });
            }
            m
        }
    };
    Ok(Se3::new(
        r.map(convert),
        Vector3::new(convert(p[0]), convert(p[1]), convert(p[2])),
    ))
}

fn unit(axis: &[f64; 3], field: impl FnOnce() -> String) -> Result<Vector3<f64>, RobotError> {
    let a = Vector3::new(axis[0], axis[1], axis[2]);
    if !a.iter().all(|x| x.is_finite()) || (a.norm() - 1.0).abs() > 1e-9 {
        return Err(RobotError::BadAxis { field: field() });
    }
    Ok(a)
}

impl<T: RealField + Copy> NumericModel<T> {
    /// Builds the robot from a description: `[parameters]` at their nominal values, except those
    /// in `overrides` (`(name, value)`; an unknown name is an error).
    pub fn from_description(
        description: &RobotDescription,
        overrides: &[(String, f64)],
    ) -> Result<Self, RobotError> {
        let mut parameters: Vec<(String, f64)> = description
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect();
        for (name, value) in overrides {
            match parameters.iter_mut().find(|(n, _)| n == name) {
                Some(p) => p.1 = *value,
                None => return Err(RobotError::UnknownOverride(name.clone())),
            }
        }
        if let Some((n, _)) = parameters.iter().find(|(_, v)| !v.is_finite()) {
            return Err(RobotError::BadParameterValue(n.clone()));
        }
        let mut joints = Vec::with_capacity(description.joints.len());
        for (k, j) in description.joints.iter().enumerate() {
            let field = || format!("joints[{k}]");
            let origin = eval_origin(&j.origin, &parameters, &field)?;
            let xi: Twist<f64> = match &j.kind {
                JointKind::Revolute { axis } => {
                    let a = unit(axis, || format!("{}.axis", field()))?;
                    se3::twist(&Vector3::zeros(), &a)
                }
                JointKind::Prismatic { axis } => {
                    se3::prismatic_twist(&unit(axis, || format!("{}.axis", field()))?)
                }
                JointKind::Twist { v, w } => {
                    let mut vv = [0.0; 3];
                    for (c, s) in v.iter().enumerate() {
                        vv[c] = eval_scalar(s, &parameters, || format!("{}.v[{c}]", field()))?;
                    }
                    let v = Vector3::from(vv);
                    let w = Vector3::new(w[0], w[1], w[2]);
                    let ok = v.iter().chain(w.iter()).all(|x| x.is_finite())
                        && if w.norm() > 0.0 {
                            (w.norm() - 1.0).abs() < 1e-9
                        } else {
                            (v.norm() - 1.0).abs() < 1e-9
                        };
                    if !ok {
                        return Err(RobotError::BadAxis {
                            field: format!("{}.w", field()),
                        });
                    }
                    se3::twist(&v, &w)
                }
            };
            joints.push(Joint::from_twist(origin, xi.map(convert)));
        }
        let tool = eval_origin(&description.end_effector.origin, &parameters, &|| {
            "end_effector".to_string()
        })?;
        let n = joints.len();
        let constraint = match &description.constraint {
            None => None,
            Some(c) => {
                admit(n, c.link, c.h.len(), description.task_rows())?;
                let g_ir = eval_origin(&c.origin, &parameters, &|| "constraint".to_string())?;
                Some(AnyConstraint::new(c.link, g_ir, &c.h, c.basis())?)
            }
        };
        Ok(Self {
            description: description.clone(),
            parameters,
            joints,
            tool,
            constraint,
        })
    }

    /// Changes one parameter's value and rebuilds the robot (e.g. `l_a` as the link slides
    /// through the trocar). On error the robot is unchanged.
    pub fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), RobotError> {
        let mut overrides = self.parameters.clone();
        match overrides.iter_mut().find(|(n, _)| n == name) {
            Some(p) => p.1 = value,
            None => return Err(RobotError::UnknownOverride(name.to_string())),
        }
        *self = Self::from_description(&self.description, &overrides)?;
        Ok(())
    }

    /// The description the robot was built from.
    pub fn description(&self) -> &RobotDescription {
        &self.description
    }

    /// Parameter values in use, in declaration order.
    pub fn parameters(&self) -> &[(String, f64)] {
        &self.parameters
    }

    /// Number of joints `n`.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The joints (numeric), base first.
    pub fn joints(&self) -> &[Joint<T>] {
        &self.joints
    }

    /// The end-effector transform `g_ne`.
    pub fn tool(&self) -> &Se3<T> {
        &self.tool
    }

    /// The constrained link `i` (1-based), if there is a constraint.
    pub fn constrained_link(&self) -> Option<usize> {
        self.constraint.as_ref().map(|c| c.link())
    }

    /// The number of constraint rows `r`, if there is a constraint.
    pub fn constraint_rows(&self) -> Option<usize> {
        self.constraint.as_ref().map(|c| c.rows())
    }

    /// The constraint, if the description has one.
    pub fn constraint(&self) -> Option<&AnyConstraint<T>> {
        self.constraint.as_ref()
    }

    /// The typed chain for the allocation-free API. Errors if `N ≠ n`.
    pub fn to_chain<const N: usize>(&self) -> Result<Chain<T, N>, RobotError> {
        let joints: [Joint<T>; N] =
            self.joints
                .as_slice()
                .try_into()
                .map_err(|_| RobotError::WrongSize {
                    what: "joints",
                    expected: self.joints.len(),
                    got: N,
                })?;
        Ok(Chain::new(joints, self.tool))
    }

    /// The typed constraint for the allocation-free API. Errors if there is none or `R ≠ r`.
    pub fn to_constraint<const R: usize>(&self) -> Result<Constraint<T, R>, RobotError>
    where
        Const<R>: SquareDim,
    {
        self.constraint
            .as_ref()
            .ok_or(RobotError::NoConstraint)?
            .to_constraint()
    }

    /// The line along which the trocar offset, the parameter `l_a`, slides the constraint frame:
    /// `g_ir(l_a) = (R_ir, o + l_a d)`, read off `g_ir` at `l_a = 1, 2, 3` (so that a basis that
    /// divides by `l_a` is never evaluated at 0). Errors without a constraint, without a
    /// parameter `l_a`, or if `g_ir` is not of that form.
    pub fn shaft(&self) -> Result<Shaft<T>, RobotError> {
        let frame = |v: f64| -> Result<Se3<T>, RobotError> {
            let mut m = self.clone();
            m.set_parameter("l_a", v)?;
            Ok(m.constraint
                .as_ref()
                .ok_or(RobotError::NoConstraint)?
                .frame())
        };
        let (f1, f2, f3) = (frame(1.0)?, frame(2.0)?, frame(3.0)?);
        let d = f2.translation - f1.translation;
        let shaft = Shaft {
            rotation: f1.rotation,
            origin: f1.translation - d,
            direction: d,
        };
        let tol: T = convert(1e-9);
        let scale = T::one() + shaft.origin.norm() + d.norm();
        let predicted = shaft.frame(convert(3.0));
        if d.norm() <= tol
            || (predicted.translation - f3.translation).norm() > tol * scale
            || (f2.rotation - f1.rotation).amax() > tol
            || (f3.rotation - f1.rotation).amax() > tol
        {
            return Err(RobotError::NoShaft);
        }
        Ok(shaft)
    }

    /// The task selection `S` (P × 6), the identity without a `[task]` (then `P` must be 6).
    /// Errors if `P` is not the number of task rows.
    pub fn task_selection<const P: usize>(&self) -> Result<SMatrix<T, P, 6>, RobotError> {
        let rows = self.description.task_rows();
        if rows != P {
            return Err(RobotError::WrongSize {
                what: "task rows",
                expected: rows,
                got: P,
            });
        }
        Ok(match &self.description.task {
            Some(task) => SMatrix::from_fn(|r, c| convert(task.select[r][c])),
            None => SMatrix::identity(),
        })
    }

    /// The numeric runtime as the controller's kinematics: the typed chain, constraint, its
    /// [`shaft`](Self::shaft) and the task selection. Errors on any size mismatch.
    pub fn to_kinematics<const N: usize, const R: usize, const P: usize>(
        &self,
    ) -> Result<ChainKinematics<T, N, R, P>, RobotError>
    where
        Const<R>: SquareDim,
    {
        Ok(ChainKinematics {
            chain: self.to_chain()?,
            constraint: self.to_constraint()?,
            shaft: self.shaft()?,
            task: self.task_selection()?,
        })
    }
}
