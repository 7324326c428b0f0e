//! The admission rules of a scene's stack (each arm's own are its description's, checked when
//! it was read):
//!
//! 1. every arm has a constraint (its port);
//! 2. the arms are of one kind: the same number of joints, port rows and task rows, the port on
//!    the same link (the scene's step drives them all alike);
//! 3. shared joints are one joint: at the start their spatial twists in the scene's frame are
//!    equal (within 1e-9) and so are their values in `q0`;
//! 4. no coupling starts inside its safety distance;
//! 5. the port rows of all arms, `Λ_k J^B_0i,k θ̇_k = 0` (3.3), (3.13), are independent over the
//!    scene's joints at the start: the smallest singular value of the stacked rows is at least
//!    [`STACK_RANK_TOLERANCE`] times the largest. Shared joints are one column, so two arms on
//!    one torso whose ports would both have to be held by the torso alone are refused.

use super::SceneDescription;
use crate::description::DescriptionError;
use crate::numeric::NumericModel;
use crate::reference;
use nalgebra::{DMatrix, Vector3};
use trocar::control::scene::Between;
use trocar::distance::segment_distance;
use trocar::se3::Twist;

/// The smallest singular value of the stacked port rows, relative to the largest, below which
/// the rows are dependent (rule 5).
pub const STACK_RANK_TOLERANCE: f64 = 1e-9;

/// The arm's port at `q0`, in its base frame: the origin of its constraint frame `g_0i g_ir`.
pub(super) fn port_at(model: &NumericModel<f64>, q0: &[f64]) -> Result<Vector3<f64>, String> {
    let c = model.constraint().ok_or_else(|| {
        "the arm's robot has no constraint (its port): add a [constraint] to its description"
            .to_string()
    })?;
    let g_0i = reference::link_frame(model, c.link(), q0).map_err(|e| e.to_string())?;
    Ok(g_0i.compose(&c.frame()).translation)
}

/// Checks the stack's rules; `err(field, message)` locates an error.
pub(super) fn admit(
    scene: &SceneDescription,
    err: &dyn Fn(&str, String) -> DescriptionError,
) -> Result<(), DescriptionError> {
    let mut models = Vec::with_capacity(scene.arms.len());
    for (k, arm) in scene.arms.iter().enumerate() {
        let field = format!("arms[{k}].robot");
        let model = NumericModel::<f64>::from_description(&arm.robot, &[])
            .map_err(|e| err(&field, e.to_string()))?;
        // Rule 1.
        if model.constraint().is_none() {
            return Err(err(
                &field,
                format!(
                    "`{}` has no constraint: every arm of a scene goes through its port \
                     (add a [constraint] to its description)",
                    arm.robot_source
                ),
            ));
        }
        models.push(model);
    }
    // Rule 2.
    let kind = |k: usize| {
        let d = &scene.arms[k].robot;
        (
            d.joints.len(),
            d.constraint.as_ref().map_or(0, |c| c.h.len()),
            d.task_rows(),
            d.constraint.as_ref().map_or(0, |c| c.link),
        )
    };
    for k in 1..scene.arms.len() {
        if kind(k) != kind(0) {
            let ((n, r, t, i), (n0, r0, t0, i0)) = (kind(k), kind(0));
            return Err(err(
                &format!("arms[{k}].robot"),
                format!(
                    "`{}` has {n} joints, {r} port rows, {t} task rows and its port on link {i}, \
                     `{}` {n0}, {r0}, {t0} and link {i0}: the scene's step drives arms of one kind",
                    scene.arms[k].name, scene.arms[0].name
                ),
            ));
        }
    }
    // Rule 3.
    let twists: Vec<Vec<Twist<f64>>> = scene
        .arms
        .iter()
        .zip(&models)
        .map(|(arm, m)| {
            let j = reference::spatial_jacobian(m, &arm.q0).map_err(|e| e.to_string())?;
            let ad = arm.base.adjoint();
            Ok((0..j.ncols())
                .map(|c| ad.apply(&Twist::from_fn(|r, _| j[(r, c)])))
                .collect())
        })
        .collect::<Result<_, String>>()
        .map_err(|e| err("arms", e))?;
    for (k, arm) in scene.arms.iter().enumerate() {
        let Some((other, count)) = arm.shares else {
            continue;
        };
        let n = arm.robot.joints.len();
        if count > n {
            return Err(err(
                &format!("arms[{k}].shares.joints"),
                format!("{count} shared joints, but the arm has {n}"),
            ));
        }
        #[allow(clippy::needless_range_loop)]
        for j in 0..count {
            let (a, b) = (&twists[other][j], &twists[k][j]);
            let gap = (a - b).amax();
            if gap > 1e-9 * (1.0 + a.amax()) {
                return Err(err(
                    &format!("arms[{k}].shares"),
                    format!(
                        "joint {} of `{}` is not joint {} of `{}` in the scene's frame: their \
                         twists at the start differ by {gap:.3e} (shared joints must be one joint: \
                         place the bases and the joints so that they coincide)",
                        j + 1,
                        arm.name,
                        j + 1,
                        scene.arms[other].name
                    ),
                ));
            }
            if arm.q0[j] != scene.arms[other].q0[j] {
                return Err(err(
                    &format!("arms[{k}].q0[{j}]"),
                    format!(
                        "{} differs from `{}`'s {} for the joint they share",
                        arm.q0[j], scene.arms[other].name, scene.arms[other].q0[j]
                    ),
                ));
            }
        }
    }
    // Rule 4.
    let ends: Vec<(Vector3<f64>, Vector3<f64>)> = scene
        .arms
        .iter()
        .zip(&models)
        .map(|(arm, m)| {
            let port = port_at(m, &arm.q0)?;
            let tip = reference::forward_kinematics(m, &arm.q0).map_err(|e| e.to_string())?;
            Ok((
                arm.base.transform_point(&port),
                arm.base.transform_point(&tip.translation),
            ))
        })
        .collect::<Result<_, String>>()
        .map_err(|e| err("arms", e))?;
    for (p, c) in scene.couplings.iter().enumerate() {
        let (a, b) = c.arms;
        let d = match c.between {
            Between::Shafts => {
                segment_distance(&ends[a].0, &ends[a].1, &ends[b].0, &ends[b].1).distance
            }
            Between::Tips => (ends[a].1 - ends[b].1).norm(),
        };
        if d < c.safety {
            return Err(err(
                &format!("couplings[{p}].safety"),
                format!(
                    "`{}` and `{}` start {:.4} m apart, inside the safety distance {} m",
                    scene.arms[a].name, scene.arms[b].name, d, c.safety
                ),
            ));
        }
    }
    // Rule 5.
    let map = scene.joint_map();
    let rows: usize = models
        .iter()
        .map(|m| m.constraint_rows().unwrap_or(0))
        .sum();
    let mut stack = DMatrix::<f64>::zeros(rows, scene.scene_joints());
    let mut row = 0;
    for (k, (arm, m)) in scene.arms.iter().zip(&models).enumerate() {
        let lambda = reference::lambda(m).map_err(|e| err("arms", e.to_string()))?;
        let jb =
            reference::partial_body_jacobian(m, &arm.q0).map_err(|e| err("arms", e.to_string()))?;
        let block = lambda * jb;
        for r in 0..block.nrows() {
            for c in 0..block.ncols() {
                stack[(row + r, map[k][c])] += block[(r, c)];
            }
        }
        row += block.nrows();
    }
    if rows > scene.scene_joints() {
        return Err(err(
            "arms",
            format!(
                "the arms' ports ask {rows} rows of the scene's {} joints: more than they can hold",
                scene.scene_joints()
            ),
        ));
    }
    let s = stack.singular_values();
    let (lo, hi) = (s.min(), s.max());
    if !(lo.is_finite() && hi.is_finite()) || lo < STACK_RANK_TOLERANCE * hi {
        return Err(err(
            "arms",
            format!(
                "the ports' rows of all arms are dependent over the scene's {} joints at the \
                 start (smallest singular value {lo:.3e}, largest {hi:.3e}): the shared joints \
                 cannot hold every port at once; start elsewhere or share fewer joints",
                scene.scene_joints()
            ),
        ));
    }
    Ok(())
}
