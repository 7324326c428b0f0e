//! The planar Gough–Stewart platform of the source's §4.4 (Figure 2): three RPR legs, active
//! prismatic joints `θ_a = (d2, d5, d8)`, passive revolute joints `θ_p = (θ1, θ3, θ4, θ6, θ7, θ9)`.
//!
//! Inverse kinematics is closed form (each leg from its base joint to its platform joint);
//! forward kinematics is solved numerically by Newton's method on the structural equations
//! (23)–(24) ([`forward_kinematics`]), where the source uses Ritt–Wu characteristic sets.
//! `J_Cp` is singular when the three leg lines meet at a point (or are parallel): the platform
//! can then turn about that point with the legs locked (a parallel singularity).

use super::error::ClosedChainError;
use super::mechanism::{JointType, Mechanism, Pose2};
use faer::Col;

fn check_layout(m: &Mechanism) -> Result<(), ClosedChainError> {
    for (ci, ch) in m.chains.iter().enumerate() {
        let ok = ch.joints.len() == 3
            && matches!(ch.joints[0].kind, JointType::Revolute)
            && matches!(ch.joints[1].kind, JointType::Prismatic { axis } if (axis[0] - 1.0).abs() < 1e-12)
            && matches!(ch.joints[2].kind, JointType::Revolute)
            && ch.joints[1].origin == Pose2::IDENTITY
            && ch.joints[2].origin == Pose2::IDENTITY;
        if !ok {
            return Err(ClosedChainError::invalid(
                format!("chains[{ci}].joints"),
                "planar Gough–Stewart inverse kinematics needs RPR legs: revolute, prismatic along x, revolute, with identity origins after the first joint",
            ));
        }
    }
    Ok(())
}

/// All joints `θ` for a platform pose `(x, y, φ)` (closed form, leg by leg).
///
/// Errors when a leg would have zero length (its base joint on the platform joint).
pub fn inverse_kinematics(m: &Mechanism, pose: Pose2) -> Result<Col<f64>, ClosedChainError> {
    check_layout(m)?;
    if !pose.is_finite() {
        return Err(ClosedChainError::NonFinite {
            what: "platform pose".into(),
        });
    }
    let mut theta = Col::zeros(m.n_joints());
    for (k, ch) in m.chains.iter().enumerate() {
        // Frame after the third joint, expressed in the first joint's frame.
        let root = ch.base.compose(&ch.joints[0].origin);
        let f = root.inverse().compose(&pose).compose(&ch.tip.inverse());
        let d = (f.x * f.x + f.y * f.y).sqrt();
        if d < 1e-12 {
            return Err(ClosedChainError::Singular {
                kind: super::error::SingularityKind::Structural,
                what: format!("leg `{}` has zero length", ch.name),
                sigma_min: 0.0,
            });
        }
        let t1 = f.y.atan2(f.x);
        let r = m.chain_range(k);
        theta[r.start] = t1;
        theta[r.start + 1] = d;
        theta[r.start + 2] = f.angle - t1;
    }
    Ok(theta)
}

/// Forward kinematics: the platform pose and all joints for leg lengths `(d2, d5, d8)`, by
/// Newton's method on the structural equations from the configuration of `guess` (a nearby pose).
pub fn forward_kinematics(
    m: &Mechanism,
    lengths: &Col<f64>,
    guess: Pose2,
) -> Result<(Pose2, Col<f64>), ClosedChainError> {
    let start = inverse_kinematics(m, guess)?;
    let (_, passive_guess) = m.split(&start);
    let passive = m.solve_passive(lengths, &passive_guess)?;
    let theta = m.join(lengths, &passive);
    Ok((m.common_pose(&theta), theta))
}
