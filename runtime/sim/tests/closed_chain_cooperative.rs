//! Cooperating arms (source §5): the contact formulation (35)–(41) with selections H against the
//! chain formulation with passive contact joints; redundancy resolution (44)–(46): null-space
//! objectives improve their index without disturbing the task.

use faer::{Col, ColRef, Mat, Scale};
use trocar_sim::closed_chain::cooperative::{contact_jacobians, two_arms, ContactModel};
use trocar_sim::closed_chain::mechanism::reduce_blocks;
use trocar_sim::closed_chain::redundancy::{null_projector, resolve, Objective};
use trocar_sim::closed_chain::Mechanism;
use trocar_sim::closed_chain::{simulate, SimOptions};
use trocar_sim::linalg::{self, as_slice};

fn assembled(model: &ContactModel) -> (Mechanism, Col<f64>) {
    let m = two_arms(model).unwrap();
    let guess = col(m.initial.as_deref().unwrap());
    let th = m.assemble(&guess, Some(&col(&[1.05, 1.15, 0.1]))).unwrap();
    (m, th)
}

/// Arm i's planar Jacobian at its contact point, written out from the joint positions
/// (column k = (−(p_c − p_k)_y, (p_c − p_k)_x, 1) for revolute joint k), plus the contact angle
/// and r = p_c(object) − p_contact.
fn arm_data(m: &Mechanism, th: &Col<f64>, i: usize) -> (Mat<f64>, f64, [f64; 2]) {
    let r = m.chain_range(i);
    let (frames, end) = m.chain_frames(i, &as_slice(th)[r]);
    // frames[0..3]: arm joints; frames[3]: the contact joint's frame = the contact point.
    let pc = frames[3];
    let mut j = Mat::zeros(3, 3);
    for k in 0..3 {
        j[(0, k)] = -(pc.y - frames[k].y);
        j[(1, k)] = pc.x - frames[k].x;
        j[(2, k)] = 1.0;
    }
    (j, pc.angle, [end.x - pc.x, end.y - pc.y])
}

#[test]
fn contact_formulation_39_41_matches_the_chain_formulation() {
    let (m, th) = assembled(&ContactModel::PointWithFriction);
    assert_eq!(m.n_joints(), 8);
    assert_eq!(m.active_indices().len(), 6);
    assert_eq!(m.passive_indices().len(), 2);
    assert_eq!(m.n_constraints(), 3);
    let (j1, a1, r1) = arm_data(&m, &th, 0);
    let (j2, a2, r2) = arm_data(&m, &th, 1);
    let h = vec![vec![[0.0, 0.0, 1.0]], vec![[0.0, 0.0, 1.0]]];
    let cj = contact_jacobians(&[j1, j2], &[a1, a2], &h, &[r1, r2]).unwrap();
    assert_eq!(cj.j_c.shape(), (3, 8));
    // Object pose task: all of (x, y, φ).
    let red_v = reduce_blocks(&cj.j_c, &cj.j_a, &cj.active, &cj.passive).unwrap();
    let red_m = m.reduced(&th).unwrap();
    // Column order: the chain formulation has (arm1, w1, arm2, w2); the velocity one (arm1, arm2, w1, w2).
    assert!(
        (&red_v.jacobian - &red_m.jacobian).norm_l2() < 1e-12,
        "{:?}\n{:?}",
        red_v.jacobian,
        red_m.jacobian
    );
    assert!((&red_v.passive_map - &red_m.passive_map).norm_l2() < 1e-12);
    // The admissible active velocities (one internal constraint: the grip distance) agree.
    let pv = null_projector(&Mat::zeros(0, 6), &red_v.active_constraint);
    let pm = null_projector(&Mat::zeros(0, 6), &red_m.active_constraint);
    assert_eq!(red_m.active_constraint.nrows(), 1);
    assert!((pv - pm).norm_l2() < 1e-12);
}

#[test]
fn gripped_contact_has_no_passive_joint_and_three_dof() {
    let (m, th) = assembled(&ContactModel::Gripped);
    assert_eq!(m.passive_indices().len(), 0);
    assert_eq!(m.effective_dof(), 3);
    let red = m.reduced(&th).unwrap();
    assert_eq!(red.active_constraint.nrows(), 3);
    // H = 0: the velocity-level formulation with empty H rows agrees.
    let (j1, a1, r1) = {
        let r = m.chain_range(0);
        let (frames, end) = m.chain_frames(0, &as_slice(&th)[r]);
        // Gripped: the contact point is not a frame; use the tip of link 3 = end − object offset.
        let half = m.parameter("half").unwrap();
        let pc = [
            end.x - half * end.angle.cos(),
            end.y - half * end.angle.sin(),
        ];
        let mut j = Mat::zeros(3, 3);
        for k in 0..3 {
            j[(0, k)] = -(pc[1] - frames[k].y);
            j[(1, k)] = pc[0] - frames[k].x;
            j[(2, k)] = 1.0;
        }
        (j, end.angle, [end.x - pc[0], end.y - pc[1]])
    };
    let (j2, a2, r2) = {
        let r = m.chain_range(1);
        let (frames, end) = m.chain_frames(1, &as_slice(&th)[r]);
        let half = m.parameter("half").unwrap();
        let pc = [
            end.x + half * end.angle.cos(),
            end.y + half * end.angle.sin(),
        ];
        let mut j = Mat::zeros(3, 3);
        for k in 0..3 {
            j[(0, k)] = -(pc[1] - frames[k].y);
            j[(1, k)] = pc[0] - frames[k].x;
            j[(2, k)] = 1.0;
        }
        (j, end.angle, [end.x - pc[0], end.y - pc[1]])
    };
    let cj = contact_jacobians(&[j1, j2], &[a1, a2], &[vec![], vec![]], &[r1, r2]).unwrap();
    let red_v = reduce_blocks(&cj.j_c, &cj.j_a, &cj.active, &cj.passive).unwrap();
    // Same admissible subspace, and the same object velocity on it.
    let pv = null_projector(&Mat::zeros(0, 6), &red_v.active_constraint);
    let pm = null_projector(&Mat::zeros(0, 6), &red.active_constraint);
    assert!((&pv - &pm).norm_l2() < 1e-12);
    assert!((&red_v.jacobian * &pv - &red.jacobian * &pm).norm_l2() < 1e-12);
}

#[test]
fn reduced_jacobian_equals_finite_differences_along_admissible_motions() {
    let (m, th) = assembled(&ContactModel::PointWithFriction);
    let red = m.reduced(&th).unwrap();
    let basis = linalg::null_space(red.active_constraint.as_ref()); // 6 × 5 admissible active velocities
    assert_eq!(basis.ncols(), 5);
    for c in 0..basis.ncols() {
        let u = basis.col(c).to_owned();
        let pd = &red.passive_map * &u;
        let thd = m.join(&u, &pd);
        assert!((m.differential(&th).unwrap().j_c * &thd).norm_l2() < 1e-12);
        // Move along θ̇, project back onto c(θ) = 0 (minimum-norm Newton), difference the task.
        let h = 1e-4;
        let at = |s: f64| {
            let t = m.assemble(&(&th + Scale(s) * &thd), None).unwrap();
            m.task(&t)
        };
        let fd = Scale(1.0 / (2.0 * h)) * (at(h) - at(-h));
        let e = (&red.jacobian * &u - fd).norm_l2();
        assert!(e < 1e-7, "direction {c}: {e}");
    }
}

#[test]
fn null_space_term_leaves_the_task_velocity_unchanged() {
    let (m, th) = assembled(&ContactModel::PointWithFriction);
    let red = m.reduced(&th).unwrap();
    let v = col(&[0.1, -0.2, 0.05]);
    let rows = &red.active_constraint;
    let rhs = Col::zeros(rows.nrows());
    let u_plain = resolve(&red.jacobian, &v, rows, &rhs, None).unwrap();
    for obj in [
        Objective::Manipulability,
        Objective::JointLimits,
        Objective::ObstacleDistance { point: [-0.6, 0.7] },
    ] {
        let g = obj.gradient(&m, &th).unwrap();
        let u = resolve(&red.jacobian, &v, rows, &rhs, Some(&(Scale(5.0) * &g))).unwrap();
        assert!((&red.jacobian * &u - &v).norm_l2() < 1e-12);
        assert!((&red.jacobian * (&u - &u_plain)).norm_l2() < 1e-12);
        assert!((rows * &u).norm_l2() < 1e-12);
        // The objective rises at rate gᵀ(u − u_plain) = 5 ‖P g‖² ≥ 0.
        let rate: f64 = g.transpose() * (&u - &u_plain);
        assert!(rate > 0.0, "{}: {rate}", obj.name());
    }
}

#[test]
fn null_space_objectives_improve_without_disturbing_the_task() {
    let base = SimOptions {
        duration: Some(2.0),
        dt: 1e-3,
        record_every: 20,
        ..SimOptions::default()
    };
    let plain = simulate("cooperative", &base, None).unwrap();
    let e_plain: Vec<Vec<f64>> = ["e_x", "e_y", "e_phi"]
        .iter()
        .map(|c| plain.column(c).unwrap())
        .collect();
    let (m, _) = assembled(&ContactModel::PointWithFriction);
    let names = m.joint_names();
    for obj in [
        Objective::Manipulability,
        Objective::JointLimits,
        Objective::ObstacleDistance { point: [-0.6, 0.7] },
    ] {
        let opts = SimOptions {
            objective: Some(obj.clone()),
            null_gain: 2.0,
            ..base.clone()
        };
        let tr = simulate("cooperative", &opts, None).unwrap();
        // Task error trajectories identical to the run without null-space motion.
        let mut worst: f64 = 0.0;
        for (k, c) in ["e_x", "e_y", "e_phi"].iter().enumerate() {
            for (a, b) in tr.column(c).unwrap().iter().zip(&e_plain[k]) {
                worst = worst.max((a - b).abs());
            }
        }
        assert!(
            worst < 1e-9,
            "{}: task error changed by {worst:e}",
            obj.name()
        );
        // The index is higher at the end than along the plain run.
        let th_plain = Col::from_fn(names.len(), |k| plain.last(names[k]).unwrap());
        let f_plain = obj.value(&m, &th_plain).unwrap();
        let f_with = tr.last("objective").unwrap();
        let f0 = tr.column("objective").unwrap()[0];
        println!(
            "{}: f0 {f0:.6} plain {f_plain:.6} with {f_with:.6} task Δ {worst:.1e}",
            obj.name()
        );
        assert!(f_with > f_plain, "{}", obj.name());
    }
}

#[test]
fn stretched_arm_with_gripped_object_is_a_serial_singularity() {
    use trocar_sim::closed_chain::{ClosedChainError, SingularityKind};
    let m = two_arms(&ContactModel::Gripped).unwrap();
    // Arm 1 fully stretched along α; the object (gripped) continues along the same line.
    let a = 30f64.to_radians();
    let (l1, l2, l3, half) = (1.0, 0.8, 0.3, 0.3);
    let reach = l1 + l2 + l3;
    let centre = [(reach + half) * a.cos(), (reach + half) * a.sin()];
    // Arm 2 (base (2, 0)) holds the other end, pointing back along −α: two-link IK of its wrist.
    let c2 = [centre[0] + half * a.cos(), centre[1] + half * a.sin()];
    let psi = a + std::f64::consts::PI;
    let w = [c2[0] - l3 * psi.cos() - 2.0, c2[1] - l3 * psi.sin()];
    let q2 = ((w[0] * w[0] + w[1] * w[1] - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).acos();
    let q1 = w[1].atan2(w[0]) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
    let q3 = psi - q1 - q2;
    let th = col(&[a, 0.0, 0.0, q1, q2, q3]);
    assert!(m.structural(&th).norm_l2() < 1e-12);
    let rep = m.classify(&th).unwrap();
    assert_eq!(rep.kind, Some(SingularityKind::Serial), "{rep:?}");
    assert_eq!(rep.task_rank, 2);
    // The controller refuses to invert there instead of returning huge or NaN velocities.
    let red = m.reduced(&th).unwrap();
    let r = resolve(
        &red.jacobian,
        &col(&[0.1, 0.0, 0.0]),
        &red.active_constraint,
        &Col::zeros(red.active_constraint.nrows()),
        None,
    );
    assert!(matches!(
        r,
        Err(ClosedChainError::Singular {
            kind: SingularityKind::Serial,
            ..
        })
    ));
    // Bending the elbow makes it regular again.
    let (_, th2) = assembled(&ContactModel::Gripped);
    assert_eq!(m.classify(&th2).unwrap().kind, None);
}

fn col(values: &[f64]) -> Col<f64> {
    ColRef::from_slice(values).to_owned()
}
