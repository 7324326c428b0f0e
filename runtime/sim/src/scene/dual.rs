//! `dia10-dual`: two arms on one torso, each through its own port (the thesis's §5.2: the
//! DIA10's two arms, a kinematic constraint on each, one holding tissue while the other cuts).
//!
//! The reference arm (`dia10_like_zy`: the torso joint, then 7 joints, the port on link 6 at
//! `l_a` = 0.15 m) and a copy of it turned half a turn about the torso's axis (not its mirror
//! image) share the torso joint (S6 of [`trocar::control::scene`]). The left instrument holds
//! its tip still; the right one cuts: its tip moves 4 cm along its arm's `x` and 2 cm down over
//! 2 s (a smooth step starting at 0.5 s). Each arm's own step is the QP with the reference
//! arm's gains (those of scenario 1); the torso's rate each arm's step chooses for its own task
//! is reconciled by the scene, and each arm's other joints keep its port and its task. With one
//! torso the scene has one joint fewer than the two ports and the two full poses ask: the tips'
//! orientations give way first (orientation weight 0.01).
//!
//! The trace's columns: `t`, the scene's 15 joints `q1..q15` (the torso, then the left arm's 7,
//! then the right arm's 7) and their rates `qd1..qd15`, and for each arm `NAME.rcm_drift` (m,
//! the distance from its port to its shaft's axis, from forward kinematics) and `NAME.ep_norm`
//! (m, its tip's distance from its reference).

use super::{arm_panels, line, reference, SceneArm, SceneGeometry, SceneRunError};
use crate::closed_chain::{MechanismTrace, Panel};
use crate::plot::view3d::ArmModel;
use crate::simulation::{Method, Scenario, ScenarioConfig, L_A0, Q0};
use nalgebra::{Matrix3, SVector, Vector3};
use trocar::constraint::Constraint;
use trocar::control::scene::{Scene, SharedJoint};
use trocar::control::{ChainKinematics, Controller, Rcm, StepStatus};
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

/// The arms of `dia10-dual`, in the scene's order.
pub const ARMS: [&str; 2] = ["left", "right"];

/// The sample time (s) of `dia10-dual`.
pub const DT: f64 = 0.002;
/// The duration of `dia10-dual` (s).
pub const DURATION: f64 = 3.0;

type Kin = ChainKinematics<f64, 8, 2>;
type Ctrl = Controller<f64, 8, 6, 2, 4, 6>;

/// The reference arm, its constraint on link 6 at `l_a` = 0.15 m, and its port at the start.
fn arm() -> Result<(Kin, NumericModel<f64>, Vector3<f64>), SceneRunError> {
    let model = |e: &dyn std::fmt::Display| SceneRunError(format!("the reference arm: {e}"));
    let d = RobotDescription::preset("dia10_like_zy").map_err(|e| model(&e))?;
    let numeric = NumericModel::<f64>::from_description(&d, &[]).map_err(|e| model(&e))?;
    let chain = numeric.to_chain::<8>().map_err(|e| model(&e))?;
    let kin: Kin = ChainKinematics::thesis(
        chain,
        Constraint::<f64, 2>::thesis(6, L_A0).map_err(|e| model(&e))?,
    );
    let q0 = SVector::<f64, 8>::from(Q0);
    let g_0i = kin.chain.link_frame(6, &q0);
    let trocar = g_0i.translation + g_0i.rotation.column(1) * L_A0;
    Ok((kin, numeric, trocar))
}

/// The bases of the two arms: the copy turned half a turn about the torso's axis.
fn bases() -> [Se3<f64>; 2] {
    let turn = Matrix3::new(-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    [Se3::identity(), Se3::new(turn, Vector3::zeros())]
}

/// How `dia10-dual` is drawn: the torso (the trace's `q1`) in both arms, then each arm's 7.
pub(super) fn geometry() -> Result<SceneGeometry, SceneRunError> {
    let (_, numeric, trocar) = arm()?;
    let model = ArmModel::from_model(&numeric)
        .map_err(|e| SceneRunError(format!("the reference arm: {e}")))?;
    let bases = bases();
    let arms = (0..2)
        .map(|k| {
            let mut joints = vec![1];
            joints.extend(2 + 7 * k..2 + 7 * k + 7);
            SceneArm {
                name: ARMS[k].to_string(),
                model: model.clone(),
                base: bases[k],
                port: trocar,
                joints,
            }
        })
        .collect();
    Ok(SceneGeometry {
        name: "dia10-dual".into(),
        arms,
        couplings: Vec::new(),
        safety: None,
    })
}

/// Runs `dia10-dual`; `progress` gets the fraction done.
pub fn simulate(mut progress: impl FnMut(f64)) -> Result<MechanismTrace, SceneRunError> {
    let model = |e: &dyn std::fmt::Display| SceneRunError(format!("the reference arm: {e}"));
    let (kin, _, trocar) = arm()?;
    let scenario = Scenario::from_name("1").map_err(|e| model(&e))?;
    let config = ScenarioConfig::new(scenario)
        .with_method(Method::Qp)
        .controller_config();
    let mut arms = [Ctrl::new(config); 2];
    let q0 = SVector::<f64, 8>::from(Q0);
    let g_0e = kin.chain.forward_kinematics(&q0);
    let rcms = [Rcm {
        trocar,
        dv: SVector::zeros(),
    }; 2];
    let bases = bases();
    let shared = [SharedJoint {
        arms: (0, 1),
        joints: (0, 0),
    }];
    let shifts = [Vector3::zeros(), Vector3::new(0.04, 0.0, -0.02)];
    let mut scene = Scene::<f64, 0, 16, 0>::new([]);
    // With the torso shared the scene has one joint fewer than the two arms' ports and full
    // poses ask: the tips' orientations give way first (with 0.1 the tips' places drifted by
    // 4–5 mm; with 0.01 by 60–80 µm).
    scene.orientation_weight = 0.01;
    let kins = [kin; 2];
    let mut q = [q0; 2];
    let mut columns = vec!["t".to_string()];
    columns.extend((1..=15).map(|k| format!("q{k}")));
    columns.extend((1..=15).map(|k| format!("qd{k}")));
    for arm in ARMS {
        columns.push(format!("{arm}.rcm_drift"));
        columns.push(format!("{arm}.ep_norm"));
    }
    // The scene's joints: the torso once, then each arm's own.
    let scene_joints = |x: &[SVector<f64, 8>; 2]| {
        let mut v = vec![x[0][0]];
        v.extend(x[0].iter().skip(1));
        v.extend(x[1].iter().skip(1));
        v
    };
    let steps = (DURATION / DT).round() as usize;
    let mut rows = Vec::with_capacity(steps + 1);
    for step in 0..=steps {
        let t = step as f64 * DT;
        let references = shifts.map(|s| reference(&g_0e, s, t));
        let mut row = vec![t];
        row.extend(scene_joints(&q));
        let qd = if step < steps {
            let o = scene
                .step::<Kin, 2, 8, 6, 2, 4, 6, 6, 5>(
                    &mut arms,
                    &kins,
                    &q,
                    &references,
                    &rcms,
                    &bases,
                    &shared,
                    DT,
                )
                .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
            if let Some(k) = o
                .arms
                .iter()
                .position(|a| a.status == StepStatus::TrocarYielded)
            {
                return Err(SceneRunError(format!(
                    "t = {t:.3} s: the {} arm's port gave way",
                    ARMS[k]
                )));
            }
            if (o.qd[0][0] - o.qd[1][0]).abs() > 1e-9 * (1.0 + o.qd[0][0].abs()) {
                return Err(SceneRunError(format!(
                    "t = {t:.3} s: the arms disagree on the torso's rate ({} and {} rad/s)",
                    o.qd[0][0], o.qd[1][0]
                )));
            }
            // One torso: both arms take the same rate.
            let mut qd = o.qd;
            qd[1][0] = qd[0][0];
            qd
        } else {
            [SVector::zeros(); 2]
        };
        row.extend(scene_joints(&qd));
        for k in 0..2 {
            let g_0i = kin.chain.link_frame(6, &q[k]);
            let axis: Vector3<f64> = g_0i.rotation.column(1).into_owned();
            let rel = trocar - g_0i.translation;
            row.push((rel - axis * rel.dot(&axis)).norm());
            let tip = kin.chain.forward_kinematics(&q[k]).translation;
            row.push((references[k].position - tip).norm());
        }
        if row.iter().any(|v| !v.is_finite()) {
            return Err(SceneRunError(format!("t = {t:.3} s: a non-finite value")));
        }
        rows.push(row);
        for k in 0..2 {
            q[k] += qd[k] * DT;
        }
        progress(step as f64 / steps as f64);
    }
    let mut panels = arm_panels(&ARMS, "each tip's error (left holds, right cuts)").to_vec();
    panels.push(Panel {
        title: "the shared torso's rate".into(),
        x_label: "t (s)".into(),
        y_label: "rate (rad/s)".into(),
        lines: vec![line("qd1", "torso")],
        non_negative: false,
    });
    Ok(MechanismTrace {
        name: "dia10-dual".into(),
        columns,
        rows,
        panels,
    })
}
