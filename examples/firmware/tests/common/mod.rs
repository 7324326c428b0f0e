//! The firmware's control law in `f64` on the numeric runtime (`trocar_sim::robot::NumericRobot`,
//! faer solves): `[v0i; θ̇_78] = J^rᵀ(J^r J^rᵀ + κ²I)⁻¹ u`, `θ̇_1..6 = J^B_0iᵀ(J^B_0i J^B_0iᵀ +
//! κ_b²I)⁻¹ Λ# v0i`, independent of the generated kinematics.

// Each test file that includes this module uses a part of it.
#![allow(dead_code)]

use faer::linalg::solvers::Solve;
use faer::{Col, Mat};
use trocar_firmware::Tuning;
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

/// `Jᵀ (J Jᵀ + κ² I)⁻¹ b`, the solve by faer's LU.
pub fn dls(j: &Mat<f64>, b: &Col<f64>, kappa: f64) -> Col<f64> {
    let damping = Mat::from_fn(6, 6, |r, c| if r == c { kappa * kappa } else { 0.0 });
    let a = j * j.transpose() + damping;
    j.transpose() * a.partial_piv_lu().solve(b)
}

/// The rates of the law at `q` with the trocar at `l_a` on link 6, and the manipulability `w`.
pub fn numeric_rates(q: &[f64; 8], l_a: f64, u: &[f64; 6], tuning: &Tuning) -> (Vec<f64>, f64) {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let robot = NumericRobot::<f64>::from_description(&d, &[("l_a".into(), l_a)]).unwrap();
    let jr = robot.constrained_jacobian(q).unwrap();
    let w = robot.manipulability(q).unwrap();
    let kappa = f64::from(trocar_firmware::damping(w as f32, tuning.w0, tuning.alpha0));
    let x = dls(&jr, &Col::from_fn(6, |k| u[k]), kappa);
    let sharp = robot.lambda_null_space().unwrap();
    let twist_i = &sharp * x.as_ref().subrows(0, 4);
    let jb = robot.partial_body_jacobian(q).unwrap();
    let before = dls(&jb, &twist_i, f64::from(tuning.kappa_b));
    let rates = before
        .iter()
        .chain(x.as_ref().subrows(4, 2).iter())
        .copied()
        .collect();
    (rates, w)
}

/// `l_a` of the trocar point on link 6 at `q`: `(p_trocar − p_06) · y_6`, from the numeric
/// model's link frame.
pub fn trocar_offset(q: &[f64; 8], trocar: &[f64; 3]) -> f64 {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    // The link frame does not depend on `l_a` (the constraint frame does; any offset is valid).
    let robot = NumericRobot::<f64>::from_description(&d, &[("l_a".into(), 0.15)]).unwrap();
    let g = robot.link_frame(6, q).unwrap();
    let y = g.rotation.column(1);
    (0..3).map(|k| (trocar[k] - g.translation[k]) * y[k]).sum()
}
