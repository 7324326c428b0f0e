//! [`NumericRobot`]: a robot description evaluated numerically with parameter values, the
//! dynamic-size numeric reference for the CLI (`trocar eval --numeric`, `trocar jacobian`),
//! the simulations and the tests of generated code.
//!
//! [`NumericRobot`] evaluates a [`RobotDescription`] with its nominal `[parameters]` (or
//! overrides) and answers with [`faer::Mat`] outputs; every error on user input is a
//! [`RobotError`], never a panic. Its methods carry the names of the generated functions
//! ([`trocar_model::catalogue`]): `constrained_jacobian`, `constraint_jacobian_c`,
//! `partial_body_jacobian`, `constrained_task_jacobian`, ... Its values are those of the one
//! numeric reference, [`trocar_model::reference`] (the kernels of the allocation-free typed API
//! on the [`NumericModel`] of `trocar-model`, which `trocar-check` compares generated code
//! with), copied into faer matrices; [`NumericRobot::to_chain`] and
//! [`NumericRobot::to_constraint`] hand the description to that API for control loops.
//! Pseudo-inverses and determinants of dynamic matrices are faer's dense decompositions
//! ([`crate::linalg`]).

pub use crate::linalg::RobotScalar;
use faer::{Col, Mat};
use nalgebra::{Const, DMatrix};
use trocar::constraint::Constraint;
use trocar::kinematics::{Chain, Joint};
use trocar::linalg::SquareDim;
use trocar::se3::{Se3, Twist};
use trocar_model::description::RobotDescription;
pub use trocar_model::numeric::{AnyConstraint, NumericModel, RobotError};
use trocar_model::reference;

/// A numeric robot: a [`RobotDescription`] evaluated with parameter values, answering with
/// dynamic-size [`faer::Mat`] matrices. Joint values `q` are all `n` joints, base first.
#[derive(Clone, Debug, PartialEq)]
pub struct NumericRobot<T: RobotScalar = f64> {
    model: NumericModel<T>,
}

impl<T: RobotScalar> NumericRobot<T> {
    /// Builds the robot from a description: `[parameters]` at their nominal values, except those
    /// in `overrides` (`(name, value)`; an unknown name is an error).
    pub fn from_description(
        description: &RobotDescription,
        overrides: &[(String, f64)],
    ) -> Result<Self, RobotError> {
        Ok(NumericRobot {
            model: NumericModel::from_description(description, overrides)?,
        })
    }

    /// The robot of an evaluated description.
    pub fn from_model(model: NumericModel<T>) -> Self {
        NumericRobot { model }
    }

    /// The evaluated description (joints, tool, constraint) the robot computes with.
    pub fn model(&self) -> &NumericModel<T> {
        &self.model
    }

    /// Changes one parameter's value and rebuilds the robot (e.g. `l_a` as the link slides
    /// through the trocar). On error the robot is unchanged.
    pub fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), RobotError> {
        self.model.set_parameter(name, value)
    }

    /// The description the robot was built from.
    pub fn description(&self) -> &RobotDescription {
        self.model.description()
    }

    /// Parameter values in use, in declaration order.
    pub fn parameters(&self) -> &[(String, f64)] {
        self.model.parameters()
    }

    /// Number of joints `n`.
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// The joints (numeric), base first.
    pub fn joints(&self) -> &[Joint<T>] {
        self.model.joints()
    }

    /// The end-effector transform `g_ne`.
    pub fn tool(&self) -> &Se3<T> {
        self.model.tool()
    }

    /// The constrained link `i` (1-based), if there is a constraint.
    pub fn constrained_link(&self) -> Option<usize> {
        self.model.constrained_link()
    }

    /// The number of constraint rows `r`, if there is a constraint.
    pub fn constraint_rows(&self) -> Option<usize> {
        self.model.constraint_rows()
    }

    fn constraint(&self) -> Result<&AnyConstraint<T>, RobotError> {
        self.model.constraint().ok_or(RobotError::NoConstraint)
    }

    /// Forward kinematics `g_0e(θ)` (2.35).
    pub fn forward_kinematics(&self, q: &[T]) -> Result<Se3<T>, RobotError> {
        reference::forward_kinematics(&self.model, q)
    }

    /// Forward kinematics as the homogeneous 4×4 matrix `[[R, p], [0, 1]]`.
    pub fn forward_kinematics_matrix(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        Ok(to_mat(&reference::homogeneous(
            &self.forward_kinematics(q)?,
        )))
    }

    /// The frame `g_0k` of link `k` (`0` is the base, `n` the last joint's frame).
    pub fn link_frame(&self, k: usize, q: &[T]) -> Result<Se3<T>, RobotError> {
        reference::link_frame(&self.model, k, q)
    }

    /// The body Jacobian `J^B_0e(θ)`, 6×n (2.54)–(2.55).
    pub fn body_jacobian(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::body_jacobian(&self.model, q).map(|m| to_mat(&m))
    }

    /// The spatial Jacobian `J^S_0e(θ)`, 6×n (2.53).
    pub fn spatial_jacobian(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::spatial_jacobian(&self.model, q).map(|m| to_mat(&m))
    }

    /// The partial body Jacobian `J^B_0k(θ_1..θ_k)`, 6×k (3.13), of the chain cut at `F_k`.
    pub fn partial_body_jacobian_at(&self, k: usize, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::partial_body_jacobian_at(&self.model, k, q).map(|m| to_mat(&m))
    }

    /// `J^B_0i` (3.13) at the constrained link `i`, 6×i.
    pub fn partial_body_jacobian(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::partial_body_jacobian(&self.model, q).map(|m| to_mat(&m))
    }

    /// The split (3.12) at the constrained link: `(J^B_0e1, J^B_0e2)`, 6×i and 6×(n−i).
    pub fn body_jacobian_split(&self, q: &[T]) -> Result<(Mat<T>, Mat<T>), RobotError> {
        let i = self.constraint()?.link();
        let j = self.body_jacobian(q)?;
        let n = self.dof();
        Ok((
            j.as_ref().subcols(0, i).to_owned(),
            j.as_ref().subcols(i, n - i).to_owned(),
        ))
    }

    /// `Λ = H Ad_{g_ri}`, r×6 (3.3).
    pub fn lambda(&self) -> Result<Mat<T>, RobotError> {
        reference::lambda(&self.model).map(|m| to_mat(&m))
    }

    /// `Λ#`, 6×(6−r): the thesis basis (3.23)/(3.27) when the description names a wrist preset,
    /// the computed basis otherwise (see [`trocar::constraint::NullSpaceBasis`]).
    pub fn lambda_null_space(&self) -> Result<Mat<T>, RobotError> {
        reference::lambda_null_space(&self.model).map(|m| to_mat(&m))
    }

    /// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`, 6×r.
    pub fn lambda_pinv(&self) -> Result<Mat<T>, RobotError> {
        reference::lambda_pinv(&self.model).map(|m| to_mat(&m))
    }

    /// The constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, 6×m, `m = 6 − r + n − i` (3.15).
    pub fn constrained_jacobian(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::constrained_jacobian(&self.model, q).map(|m| to_mat(&m))
    }

    /// `J_c = Ad_{g_ei} Λ†`, 6×r (3.33).
    pub fn constraint_jacobian_c(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        reference::constraint_jacobian_c(&self.model, q).map(|m| to_mat(&m))
    }

    /// The task selection `S`, t×6 (rows of the end-effector body twist, components in `F_e`), or
    /// `None` without a `[task]`.
    pub fn task_selection(&self) -> Option<Mat<T>> {
        reference::task_selection(&self.model)
            .ok()
            .map(|m| to_mat(&m))
    }

    /// The task Jacobian `S J^r_0e`, t×m (the product in faer). Errors without a `[task]`.
    pub fn constrained_task_jacobian(&self, q: &[T]) -> Result<Mat<T>, RobotError> {
        let s = self.task_selection().ok_or(RobotError::NoTask)?;
        Ok(s * self.constrained_jacobian(q)?)
    }

    /// Manipulability (3.36) of what the task commands: `w = sqrt(|det(J Jᵀ)|)` of `S J^r_0e` with
    /// a `[task]`, of `J^r_0e` without ([`manipulability_dynamic`], faer's LU).
    pub fn manipulability(&self, q: &[T]) -> Result<T, RobotError> {
        let jr = self.constrained_jacobian(q)?;
        Ok(match self.task_selection() {
            Some(s) => manipulability_dynamic(&(s * jr)),
            None => manipulability_dynamic(&jr),
        })
    }

    /// (3.10)/(3.31): `θ̇_{1..i} = (J^B_0i)† (Λ# v0i + Λ† dv_0r)` (`dv_0r` empty or zero for a
    /// fixed RCM), with the SVD pseudo-inverse (faer's SVD; singular values below `1e-12` are
    /// dropped).
    pub fn joint_rates_before_constraint(
        &self,
        q: &[T],
        v0i: &[T],
        dv_0r: &[T],
    ) -> Result<Col<T>, RobotError> {
        let c = self.constraint()?;
        let sharp = c.lambda_null_space_columns();
        if v0i.len() != sharp.len() {
            return Err(RobotError::WrongSize {
                what: "v0i",
                expected: sharp.len(),
                got: v0i.len(),
            });
        }
        let mut v = Twist::zeros();
        for (s, &x) in sharp.iter().zip(v0i) {
            v += s * x;
        }
        if !dv_0r.is_empty() {
            if dv_0r.len() != c.rows() {
                return Err(RobotError::WrongSize {
                    what: "dv_0r",
                    expected: c.rows(),
                    got: dv_0r.len(),
                });
            }
            let pinv = c.lambda_pinv_column_major();
            for (k, &x) in dv_0r.iter().enumerate() {
                for r in 0..6 {
                    v[r] += pinv[k * 6 + r] * x;
                }
            }
        }
        let j = self.partial_body_jacobian(q)?;
        let pinv = crate::linalg::pseudo_inverse(j.as_ref())
            .ok_or_else(|| RobotError::BadParameterValue("(pseudo-inverse)".into()))?;
        let v = Col::from_fn(6, |r| v[r]);
        Ok(&pinv * &v)
    }

    /// The finite-difference body Jacobian (central differences through the SE(3) log), step `h`.
    pub fn finite_difference_body_jacobian(&self, q: &[T], h: T) -> Result<Mat<T>, RobotError> {
        reference::finite_difference_body_jacobian(&self.model, q, h).map(|m| to_mat(&m))
    }

    /// The typed chain for the allocation-free API. Errors if `N ≠ n`.
    pub fn to_chain<const N: usize>(&self) -> Result<Chain<T, N>, RobotError> {
        self.model.to_chain()
    }

    /// The typed constraint for the allocation-free API. Errors if there is none or `R ≠ r`.
    pub fn to_constraint<const R: usize>(&self) -> Result<Constraint<T, R>, RobotError>
    where
        Const<R>: SquareDim,
    {
        self.model.to_constraint()
    }
}

/// `sqrt(|det(J Jᵀ)|)` of a dynamic matrix (3.36), by faer's LU (`|det J|` directly when `J` is
/// square: squaring first would double the condition number). At an exactly singular matrix
/// (a zero pivot, where the LU's divisions give `NaN`) the answer is 0, as the closed form's;
/// a determinant that overflows stays infinite.
pub fn manipulability_dynamic<T: RobotScalar>(j: &Mat<T>) -> T {
    let (m, det) = if j.nrows() == j.ncols() {
        (j.to_owned(), j.determinant())
    } else {
        let jjt = j * j.transpose();
        let det = jjt.determinant();
        (jjt, det)
    };
    if !nalgebra::ComplexField::is_finite(&det) && has_zero_pivot(&m) {
        return T::zero();
    }
    let det = nalgebra::ComplexField::abs(det);
    if j.nrows() == j.ncols() {
        det
    } else {
        nalgebra::ComplexField::sqrt(det)
    }
}

/// Whether Gaussian elimination with partial pivoting on the square matrix `m` (finite entries)
/// meets a column whose candidates are all exactly 0: `m` is then exactly singular.
fn has_zero_pivot<T: RobotScalar>(m: &Mat<T>) -> bool {
    let n = m.nrows();
    let mut a: Vec<Vec<T>> = (0..n)
        .map(|r| (0..n).map(|c| m[(r, c)]).collect())
        .collect();
    if a.iter()
        .flatten()
        .any(|x| !nalgebra::ComplexField::is_finite(x))
    {
        return false;
    }
    for k in 0..n {
        let abs = |x: T| nalgebra::ComplexField::abs(x);
        let Some(p) = (k..n).max_by(|&x, &y| {
            abs(a[x][k])
                .partial_cmp(&abs(a[y][k]))
                .unwrap_or(std::cmp::Ordering::Equal)
        }) else {
            return false;
        };
        if a[p][k] == T::zero() {
            return true;
        }
        a.swap(k, p);
        let (top, below) = a.split_at_mut(k + 1);
        let pivot = &top[k];
        for row in below {
            let f = row[k] / pivot[k];
            for (x, &v) in row[k..].iter_mut().zip(&pivot[k..]) {
                *x -= f * v;
            }
        }
    }
    false
}

/// The faer matrix of a nalgebra one (the same entries).
fn to_mat<T: RobotScalar>(m: &DMatrix<T>) -> Mat<T> {
    Mat::from_fn(m.nrows(), m.ncols(), |r, c| m[(r, c)])
}
