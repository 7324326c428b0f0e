//! The numeric reference of every serial function of the catalogue: the kernels of the
//! allocation-free typed API ([`trocar::kinematics`], [`trocar::constraint`]) on the
//! [`NumericModel`] of a description, answered as dynamic [`nalgebra::DMatrix`] values in the
//! layout [`crate::verify`] compares (a transform as its 4 × 4 homogeneous matrix, a scalar as
//! 1 × 1).

use nalgebra::DMatrix;
use trocar::kinematics;
use trocar::se3::{Se3, Twist};
use trocar_model::catalogue::Function;
use trocar_model::numeric::{NumericModel, RobotError};

/// A 6 × k matrix from twist columns.
fn columns(cols: &[Twist<f64>]) -> DMatrix<f64> {
    DMatrix::from_fn(6, cols.len(), |r, c| cols[c][r])
}

/// The 4 × 4 homogeneous matrix of a transform.
pub fn homogeneous(g: &Se3<f64>) -> DMatrix<f64> {
    let m = g.to_homogeneous();
    DMatrix::from_fn(4, 4, |r, c| m[(r, c)])
}

/// `sqrt(|det(J Jᵀ)|)` of a dynamic matrix (3.36), `|det J|` directly when `J` is square
/// (squaring first would double the condition number).
pub fn manipulability(j: &DMatrix<f64>) -> f64 {
    if j.nrows() == j.ncols() {
        return j.clone().determinant().abs();
    }
    (j * j.transpose()).determinant().abs().sqrt()
}

/// The body Jacobian `J^B_0e(θ)`, 6 × n (2.53)–(2.55).
pub fn body_jacobian(model: &NumericModel<f64>, q: &[f64]) -> DMatrix<f64> {
    let mut cols = vec![Twist::zeros(); model.dof()];
    kinematics::body_jacobian_columns(model.joints(), q, model.tool(), &mut cols);
    columns(&cols)
}

/// The constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, 6 × m (3.15).
pub fn constrained_jacobian(
    model: &NumericModel<f64>,
    q: &[f64],
) -> Result<DMatrix<f64>, RobotError> {
    let c = model.constraint().ok_or(RobotError::NoConstraint)?;
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

/// The task selection `S`, t × 6, of a description with a `[task]`.
pub fn task_selection(model: &NumericModel<f64>) -> Result<DMatrix<f64>, RobotError> {
    let task = model
        .description()
        .task
        .as_ref()
        .ok_or(RobotError::NoTask)?;
    Ok(DMatrix::from_fn(task.select.len(), 6, |r, c| {
        task.select[r][c]
    }))
}

/// What manipulability (3.36) is taken of: `S J^r_0e` with a `[task]`, `J^r_0e` without.
pub fn manipulated_jacobian(
    model: &NumericModel<f64>,
    q: &[f64],
) -> Result<DMatrix<f64>, RobotError> {
    let jr = constrained_jacobian(model, q)?;
    Ok(match model.description().task {
        Some(_) => task_selection(model)? * jr,
        None => jr,
    })
}

/// The numeric value of the serial function `function` at joints `q` (all `n`, base first), or
/// `None` for a function of closed mechanisms; errors where the model cannot answer (a
/// constrained quantity without a constraint, `S` without a `[task]`, a wrong joint count).
pub fn evaluate(
    model: &NumericModel<f64>,
    function: Function,
    q: &[f64],
) -> Result<Option<DMatrix<f64>>, RobotError> {
    if q.len() != model.dof() {
        return Err(RobotError::WrongJointCount {
            expected: model.dof(),
            got: q.len(),
        });
    }
    let constraint = || model.constraint().ok_or(RobotError::NoConstraint);
    let joints = model.joints();
    Ok(Some(match function {
        Function::ForwardKinematics => {
            homogeneous(&kinematics::forward_kinematics(joints, q, model.tool()))
        }
        Function::BodyJacobian => body_jacobian(model, q),
        Function::ConstrainedJacobian => constrained_jacobian(model, q)?,
        Function::ConstraintJacobianC => {
            let c = constraint()?;
            let i = c.link();
            let g_ie = kinematics::forward_kinematics(&joints[i..], &q[i..], model.tool());
            let values = c.constraint_jacobian_c_column_major(&g_ie);
            DMatrix::from_column_slice(6, c.rows(), &values)
        }
        Function::PartialBodyJacobian => {
            let i = constraint()?.link();
            let mut cols = vec![Twist::zeros(); i];
            kinematics::body_jacobian_columns(&joints[..i], &q[..i], &Se3::identity(), &mut cols);
            columns(&cols)
        }
        Function::ConstrainedLinkKinematics => {
            let i = constraint()?.link();
            homogeneous(&kinematics::forward_kinematics(
                &joints[..i],
                &q[..i],
                &Se3::identity(),
            ))
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
            constraint()?;
            let h = &model
                .description()
                .constraint
                .as_ref()
                .ok_or(RobotError::NoConstraint)?
                .h;
            DMatrix::from_fn(h.len(), 6, |r, c| h[r][c])
        }
        Function::LambdaNullSpace => columns(constraint()?.lambda_null_space_columns()),
        Function::LambdaPinv => {
            let c = constraint()?;
            DMatrix::from_column_slice(6, c.rows(), &c.lambda_pinv_column_major())
        }
        Function::ConstraintFrame => homogeneous(&constraint()?.frame()),
        Function::TaskSelection => task_selection(model)?,
        Function::ConstrainedTaskJacobian => {
            task_selection(model)? * constrained_jacobian(model, q)?
        }
        _ => return Ok(None),
    }))
}
