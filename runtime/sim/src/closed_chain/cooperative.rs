//! Cooperating arms holding an object: contact models by a selection `H` (35)–(42).
//!
//! The velocity `v_i` of the object at contact `i` is `v_i = A_i v_c` (35) and differs from the
//! end-effector velocity `v_i⁺ = J_i θ̇_i` (38) by the free contact motions:
//! `v_i = v_i⁺ + H_iᵀ w_i` (36). Stacking, `J θ̇ + Hᵀ w = A v_c` (39); with the contact motions as
//! passive joints `θ_p = w`, `J_C = Ã [J Hᵀ]` (40) and `J_A = A† [J Hᵀ]` (41).
//! A gripped contact allows no motion, `H = 0` (no rows); a frictional point contact allows only
//! the relative rotation, `H = [0 0 1]` (42). (In the plane, twists are `(v_x, v_y, ω)`.)
//!
//! Two equivalent routes are provided: [`contact_jacobians`] builds (39)–(41) literally from the
//! arms' Jacobians; [`Mechanism::from_model`] turns each row of `H` into a passive joint of the
//! arm's chain (a rotation row into a revolute joint at the contact, a translation row into a
//! prismatic joint), so that the generic [`Mechanism`] machinery applies.

use super::error::ClosedChainError;
use super::mechanism::Mechanism;
use crate::linalg;
use faer::Mat;
use trocar_model::closed_chain::{number, MechanismModel};

/// The contact models of §5.3.
#[derive(Clone, Debug, PartialEq)]
pub enum ContactModel {
    /// The object is gripped: no relative motion, `H = 0` (no rows).
    Gripped,
    /// Point contact with friction: only the relative rotation is free, `H = [0 0 1]` (42).
    PointWithFriction,
    /// Any other selection (rows `(v_x, v_y, ω)` in the contact frame).
    Custom(Vec<[f64; 3]>),
}

impl ContactModel {
    /// The rows of `H`.
    pub fn h(&self) -> Vec<[f64; 3]> {
        match self {
            ContactModel::Gripped => Vec::new(),
            ContactModel::PointWithFriction => vec![[0.0, 0.0, 1.0]],
            ContactModel::Custom(h) => h.clone(),
        }
    }
}

/// `A_i = [[I, −P̂_eic], [0, I]]` of (35) in the plane: maps the object velocity `v_c = (ṗ_c, ω)`
/// to the velocity of the object's point at the contact, `r = p_c − p_i` (world coordinates).
/// Row by row.
pub fn contact_map(r: [f64; 2]) -> [[f64; 3]; 3] {
    [[1.0, 0.0, r[1]], [0.0, 1.0, -r[0]], [0.0, 0.0, 1.0]]
}

/// The constraint and analytic Jacobians of cooperating arms (39)–(41).
#[derive(Clone, Debug, PartialEq)]
pub struct CooperativeJacobians {
    /// `J_C = Ã [J Hᵀ]` (40), columns: all arm joints, then all contact motions `w`.
    pub j_c: Mat<f64>,
    /// `J_A = A† [J Hᵀ]` (41).
    pub j_a: Mat<f64>,
    /// Indices of the active columns (the arm joints).
    pub active: Vec<usize>,
    /// Indices of the passive columns (the contact motions `w`).
    pub passive: Vec<usize>,
}

/// Builds (39)–(41) from each arm's `S J_i` (`3 × n_i`, world frame, at its contact point), the
/// contact frame orientations `ψ_i`, the selections `H_i` (rows in the contact frame) and the
/// vectors `r_i = p_c − p_i` from contact to object frame.
pub fn contact_jacobians(
    arm_jacobians: &[Mat<f64>],
    contact_angles: &[f64],
    h: &[Vec<[f64; 3]>],
    r: &[[f64; 2]],
) -> Result<CooperativeJacobians, ClosedChainError> {
    let m = arm_jacobians.len();
    for (what, len) in [
        ("contact angles", contact_angles.len()),
        ("selections H", h.len()),
        ("contact vectors r", r.len()),
    ] {
        if len != m {
            return Err(ClosedChainError::Dimension {
                what: what.into(),
                expected: m,
                got: len,
            });
        }
    }
    if let Some(i) = arm_jacobians.iter().position(|j| j.nrows() != 3) {
        return Err(ClosedChainError::Dimension {
            what: format!("rows of arm {i}'s Jacobian"),
            expected: 3,
            got: arm_jacobians[i].nrows(),
        });
    }
    let n_a: usize = arm_jacobians.iter().map(|j| j.ncols()).sum();
    let n_w: usize = h.iter().map(|x| x.len()).sum();
    let mut big = Mat::zeros(3 * m, n_a + n_w);
    let mut a = Mat::zeros(3 * m, 3);
    let (mut ca, mut cw) = (0, n_a);
    for i in 0..m {
        big.as_mut()
            .submatrix_mut(3 * i, ca, 3, arm_jacobians[i].ncols())
            .copy_from(&arm_jacobians[i]);
        ca += arm_jacobians[i].ncols();
        let (s, c) = contact_angles[i].sin_cos();
        for row in &h[i] {
            big[(3 * i, cw)] = c * row[0] - s * row[1];
            big[(3 * i + 1, cw)] = s * row[0] + c * row[1];
            big[(3 * i + 2, cw)] = row[2];
            cw += 1;
        }
        for (k, row) in contact_map(r[i]).iter().enumerate() {
            for (c, x) in row.iter().enumerate() {
                a[(3 * i + k, c)] = *x;
            }
        }
    }
    if !linalg::all_finite(big.as_ref()) || !linalg::all_finite(a.as_ref()) {
        return Err(ClosedChainError::NonFinite {
            what: "cooperative Jacobians".into(),
        });
    }
    let (j_c, j_a) = super::mechanism::constraint_and_analytic(&big, &a)?;
    Ok(CooperativeJacobians {
        j_c,
        j_a,
        active: (0..n_a).collect(),
        passive: (n_a..n_a + n_w).collect(),
    })
}

/// The shipped two-arm system (`cooperative-arms.toml`) with every contact replaced by `model`.
pub fn two_arms(model: &ContactModel) -> Result<Mechanism, ClosedChainError> {
    let mut m = MechanismModel::shipped("cooperative-arms")?;
    with_contacts(&mut m, &model.h());
    Mechanism::nominal(&m)
}

/// Replaces the selection `H` of every contact of `model` by the rows `h`.
pub fn with_contacts(model: &mut MechanismModel, h: &[[f64; 3]]) {
    for c in model.chains.iter_mut().filter_map(|c| c.contact.as_mut()) {
        c.h = h.iter().map(|r| r.map(number)).collect();
    }
}
