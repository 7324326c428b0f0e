//! The numeric reference of the catalogue: every serial function of [`crate::catalogue`] (and the
//! few extra quantities the simulations ask for) computed by the kernels of the allocation-free
//! typed API ([`trocar::kinematics`], [`trocar::constraint`]) on the [`NumericModel`] of a
//! description, answered as dynamic [`nalgebra::DMatrix`] values.
//!
//! It is the one numeric reference: `trocar-check` compares generated code with [`evaluate`]
//! (a transform as its 4 × 4 homogeneous matrix, a scalar as 1 × 1), and `trocar-sim`'s
//! `NumericRobot` answers with these values as faer matrices. Joint values `q` are all `n`
//! joints, base first; a wrong count is [`RobotError::WrongJointCount`].

use crate::catalogue::Function;
use crate::numeric::{AnyConstraint, NumericModel, RobotError};
use nalgebra::{convert, DMatrix, RealField};
use trocar::kinematics;
use trocar::se3::{Se3, Twist};

/// A 6 × k matrix from twist columns.
fn columns<T: RealField + Copy>(cols: &[Twist<T>]) -> DMatrix<T> {
    DMatrix::from_fn(6, cols.len(), |r, c| cols[c][r])
}

/// The 4 × 4 homogeneous matrix of a transform.
pub fn homogeneous<T: RealField + Copy>(g: &Se3<T>) -> DMatrix<T> {
    let m = g.to_homogeneous();
    DMatrix::from_fn(4, 4, |r, c| m[(r, c)])
}

/// `sqrt(|det(J Jᵀ)|)` of a dynamic matrix (3.36), `|det J|` directly when `J` is square
/// (squaring first would double the condition number).
pub fn manipulability<T: RealField + Copy>(j: &DMatrix<T>) -> T {
    if j.nrows() == j.ncols() {
        return j.clone().determinant().abs();
    }
    (j * j.transpose()).determinant().abs().sqrt()
}

/// `Ok` when `q` has one value per joint.
fn check_q<T: RealField + Copy>(model: &NumericModel<T>, q: &[T]) -> Result<(), RobotError> {
    if q.len() != model.dof() {
        return Err(RobotError::WrongJointCount {
            expected: model.dof(),
            got: q.len(),
        });
    }
    Ok(())
}

/// `Ok` when `k` names a link of the chain (`0` the base, `n` the last joint's frame).
fn check_link<T: RealField + Copy>(model: &NumericModel<T>, k: usize) -> Result<(), RobotError> {
    if k > model.dof() {
        return Err(RobotError::LinkOutOfRange {
            link: k,
            joints: model.dof(),
        });
    }
    Ok(())
}

/// The constraint of the model, or [`RobotError::NoConstraint`].
fn constraint<T: RealField + Copy>(
    model: &NumericModel<T>,
) -> Result<&AnyConstraint<T>, RobotError> {
    model.constraint().ok_or(RobotError::NoConstraint)
}

/// Forward kinematics `g_0e(θ)` (2.35).
pub fn forward_kinematics<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<Se3<T>, RobotError> {
    check_q(model, q)?;
    Ok(kinematics::forward_kinematics(
        model.joints(),
        q,
        model.tool(),
    ))
}

/// The frame `g_0k` of link `k` (`0` is the base, `n` the last joint's frame).
pub fn link_frame<T: RealField + Copy>(
    model: &NumericModel<T>,
    k: usize,
    q: &[T],
) -> Result<Se3<T>, RobotError> {
    check_q(model, q)?;
    check_link(model, k)?;
    Ok(kinematics::forward_kinematics(
        &model.joints()[..k],
        &q[..k],
        &Se3::identity(),
    ))
}

/// The body Jacobian `J^B_0e(θ)`, 6 × n (2.53)–(2.55).
pub fn body_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    let mut cols = vec![Twist::zeros(); model.dof()];
    kinematics::body_jacobian_columns(model.joints(), q, model.tool(), &mut cols);
    Ok(columns(&cols))
}

/// The spatial Jacobian `J^S_0e(θ)`, 6 × n (2.53).
pub fn spatial_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    let mut cols = vec![Twist::zeros(); model.dof()];
    kinematics::spatial_jacobian_columns(model.joints(), q, &mut cols);
    Ok(columns(&cols))
}

/// The partial body Jacobian `J^B_0k(θ_1..θ_k)`, 6 × k (3.13), of the chain cut at `F_k`.
pub fn partial_body_jacobian_at<T: RealField + Copy>(
    model: &NumericModel<T>,
    k: usize,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    check_link(model, k)?;
    let mut cols = vec![Twist::zeros(); k];
    kinematics::body_jacobian_columns(&model.joints()[..k], &q[..k], &Se3::identity(), &mut cols);
    Ok(columns(&cols))
}

/// `J^B_0i` (3.13) at the constrained link `i`, 6 × i.
pub fn partial_body_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    let i = constraint(model)?.link();
    partial_body_jacobian_at(model, i, q)
}

/// `Λ = H Ad_{g_ri}`, r × 6 (3.3).
pub fn lambda<T: RealField + Copy>(model: &NumericModel<T>) -> Result<DMatrix<T>, RobotError> {
    let c = constraint(model)?;
    Ok(DMatrix::from_column_slice(
        c.rows(),
        6,
        &c.lambda_column_major(),
    ))
}

/// `Λ#`, 6 × (6 − r): the thesis basis (3.23)/(3.27) when the description names a wrist preset,
/// the computed basis otherwise (see [`trocar::constraint::NullSpaceBasis`]).
pub fn lambda_null_space<T: RealField + Copy>(
    model: &NumericModel<T>,
) -> Result<DMatrix<T>, RobotError> {
    Ok(columns(constraint(model)?.lambda_null_space_columns()))
}

/// `Λ† = Λᵀ (Λ Λᵀ)⁻¹`, 6 × r.
pub fn lambda_pinv<T: RealField + Copy>(model: &NumericModel<T>) -> Result<DMatrix<T>, RobotError> {
    let c = constraint(model)?;
    Ok(DMatrix::from_column_slice(
        6,
        c.rows(),
        &c.lambda_pinv_column_major(),
    ))
}

/// The constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, 6 × m, `m = 6 − r + n − i`
/// (3.15).
pub fn constrained_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    let c = constraint(model)?;
    let i = c.link();
    let sharp = c.lambda_null_space_columns();
    let mut cols = vec![Twist::zeros(); sharp.len() + model.dof() - i];
    kinematics::constrained_jacobian_columns(
        &model.joints()[i..],
        &q[i..],
        model.tool(),
        sharp,
        &mut cols,
    );
    Ok(columns(&cols))
}

/// `J_c = Ad_{g_ei} Λ†`, 6 × r (3.33).
pub fn constraint_jacobian_c<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    let c = constraint(model)?;
    let i = c.link();
    let g_ie = kinematics::forward_kinematics(&model.joints()[i..], &q[i..], model.tool());
    Ok(DMatrix::from_column_slice(
        6,
        c.rows(),
        &c.constraint_jacobian_c_column_major(&g_ie),
    ))
}

/// The task selection `S`, t × 6 (rows of the end-effector body twist, components in `F_e`), of
/// a description with a `[task]`.
pub fn task_selection<T: RealField + Copy>(
    model: &NumericModel<T>,
) -> Result<DMatrix<T>, RobotError> {
    let task = model
        .description()
        .task
        .as_ref()
        .ok_or(RobotError::NoTask)?;
    Ok(DMatrix::from_fn(task.select.len(), 6, |r, c| {
        convert(task.select[r][c])
    }))
}

/// What manipulability (3.36) is taken of: `S J^r_0e` with a `[task]`, `J^r_0e` without.
pub fn manipulated_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
) -> Result<DMatrix<T>, RobotError> {
    let jr = constrained_jacobian(model, q)?;
    Ok(match model.description().task {
        Some(_) => task_selection(model)? * jr,
        None => jr,
    })
}

/// The finite-difference body Jacobian (central differences through the SE(3) log), step `h`.
pub fn finite_difference_body_jacobian<T: RealField + Copy>(
    model: &NumericModel<T>,
    q: &[T],
    h: T,
) -> Result<DMatrix<T>, RobotError> {
    check_q(model, q)?;
    let mut qq = q.to_vec();
    let mut cols = vec![Twist::zeros(); model.dof()];
    trocar::finite_diff::body_jacobian_columns(model.joints(), &mut qq, model.tool(), h, &mut cols);
    Ok(columns(&cols))
}

/// The numeric value of the serial function `function` at joints `q` (all `n`, base first), or
/// `None` for a function of closed mechanisms; errors where the model cannot answer (a
/// constrained quantity without a constraint, `S` without a `[task]`, a wrong joint count).
pub fn evaluate<T: RealField + Copy>(
    model: &NumericModel<T>,
    function: Function,
    q: &[T],
) -> Result<Option<DMatrix<T>>, RobotError> {
    check_q(model, q)?;
    Ok(Some(match function {
        Function::ForwardKinematics => homogeneous(&forward_kinematics(model, q)?),
        Function::BodyJacobian => body_jacobian(model, q)?,
        Function::ConstrainedJacobian => constrained_jacobian(model, q)?,
        Function::ConstraintJacobianC => constraint_jacobian_c(model, q)?,
        Function::PartialBodyJacobian => partial_body_jacobian(model, q)?,
        Function::ConstrainedLinkKinematics => {
            homogeneous(&link_frame(model, constraint(model)?.link(), q)?)
        }
        Function::Manipulability => {
            DMatrix::from_element(1, 1, manipulability(&manipulated_jacobian(model, q)?))
        }
        Function::ManipulabilitySquared => DMatrix::from_element(
            1,
            1,
            manipulability(&manipulated_jacobian(model, q)?).powi(2),
        ),
        Function::ConstraintSelection => {
            constraint(model)?;
            let h = &model
                .description()
                .constraint
                .as_ref()
                .ok_or(RobotError::NoConstraint)?
                .h;
            DMatrix::from_fn(h.len(), 6, |r, c| convert(h[r][c]))
        }
        Function::LambdaNullSpace => lambda_null_space(model)?,
        Function::LambdaPinv => lambda_pinv(model)?,
        Function::ConstraintFrame => homogeneous(&constraint(model)?.frame()),
        Function::TaskSelection => task_selection(model)?,
        Function::ConstrainedTaskJacobian => {
            task_selection(model)? * constrained_jacobian(model, q)?
        }
        _ => return Ok(None),
    }))
}
