//! `dia10-dual`: the two arms of the thesis's robot on one torso, each through its own port (the
//! thesis's §5.2: the DIA10's two arms, a kinematic constraint on each, one holding tissue while
//! the other cuts).
//!
//! The right arm is the reference arm (`dia10_like_zy`: the torso joint, then 7 joints, the
//! shoulder at `x = +0.194` m, the port on link 6 at `l_a` = 0.15 m); the left arm is its mirror
//! image in the plane `x = 0` (the shoulder at `x = −0.194` m, both arms reaching along `+y`,
//! [`trocar_model::scene::mirrored`]: its angles count the other way); they share the torso joint
//! (S6 of [`trocar::control::scene`]). The right arm starts at
//! `q = (0, −0.3, 0.9, 0.28, −0.62, 0.1, 0.5, 0.3)` (the reference arm's start with its forearm
//! rolled and its wrist pitched inward), the left one at its negation, its mirror image; their
//! tips 3.5 cm apart and their ports 34 cm apart; a coupling would keep their shafts 10 mm apart
//! (in this run they stay beyond its 30 mm influence: the cut leads away from the other tip). The
//! left instrument holds its tip still; the right one cuts: its tip moves 4 cm along `+x` over 4
//! s and back over 4 s (smooth steps from 0.5 s). Each arm's own step is the QP with the reference
//! arm's gains (those of scenario 1); the torso's rate each arm's step chooses for its own task is
//! reconciled by the scene, and each arm's other joints keep its port and its task. With one
//! torso the scene has one joint fewer than the two ports and the two full poses ask: the tips'
//! orientations give way first (orientation weight 0.01).
//!
//! The arms, their starts and the coupling are the scene file's
//! (`runtime/model/scenes/dia10-dual.toml`, [`super::description`]); the paths are this module's.
//!
//! The trace's columns: `t`, the scene's 15 joints `q1..q15` (the torso, then the left arm's 7,
//! then the right arm's 7) and their rates `qd1..qd15`, for each arm `NAME.rcm_drift` (m, the
//! distance from its port to its shaft's axis, from forward kinematics) and `NAME.ep_norm` (m,
//! its tip's distance from its reference), and `min_shaft_distance` (m, between the shafts inside
//! the body, port to tip).

use super::{arm_panels, line, SceneArm, SceneGeometry, SceneRunError};
use crate::closed_chain::{MechanismTrace, Panel};
use crate::plot::view3d::ArmModel;
use crate::simulation::{Method, Scenario, ScenarioConfig};
use nalgebra::{SVector, Vector3};
use trocar::constraint::Constraint;
use trocar::control::scene::{Between, Coupling, Scene, SceneError, SceneOutput, SharedJoint};
use trocar::control::{ChainKinematics, Controller, Damper, Rcm, Reference, StepStatus};
use trocar::distance::segment_distance;
use trocar::se3::Se3;
use trocar_model::numeric::NumericModel;

/// The arms of `dia10-dual`, in the scene's order.
pub const ARMS: [&str; 2] = ["left", "right"];

/// The sample time (s) of `dia10-dual`.
pub const DT: f64 = 0.002;
/// The duration of `dia10-dual` (s).
pub const DURATION: f64 = 9.0;

/// The reference arm's kinematics, as the scene's arms use them.
pub type Kin = ChainKinematics<f64, 8, 2>;
/// The reference arm's controller, as the scene's arms use it.
pub type Ctrl = Controller<f64, 8, 6, 2, 4, 6>;

/// The scene's arms as its file describes them (left: the mirror image, right: the reference
/// arm), each with the thesis's constraint on link 6 at its `l_a`: their kinematics, their ports
/// and starts, the reference arm's model, and the coupling's damper.
#[allow(clippy::type_complexity)]
fn arms(
    d: &trocar_model::scene::SceneDescription,
) -> Result<
    (
        [Kin; 2],
        [Vector3<f64>; 2],
        [SVector<f64, 8>; 2],
        NumericModel<f64>,
        Damper<f64>,
    ),
    SceneRunError,
> {
    let model = |e: &dyn std::fmt::Display| SceneRunError(format!("dia10-dual: {e}"));
    let models = d.numeric_models().map_err(|e| model(&e))?;
    let ports = d.ports().map_err(|e| model(&e))?;
    let kin = |k: usize| -> Result<Kin, SceneRunError> {
        let l_a = d.arms[k]
            .robot
            .parameter("l_a")
            .ok_or_else(|| model(&"an arm without `l_a`"))?;
        // The thesis's constraint frame moves along `y_6`; the mirrored link frame `M R M` has
        // the mirrored `y` axis, so the same constraint holds the mirrored shaft.
        let constraint = Constraint::<f64, 2>::thesis(6, l_a).map_err(|e| model(&e))?;
        let chain = models[k].to_chain::<8>().map_err(|e| model(&e))?;
        Ok(ChainKinematics::thesis(chain, constraint))
    };
    let kins = [kin(0)?, kin(1)?];
    let q0 = [0, 1].map(|k| SVector::<f64, 8>::from_column_slice(&d.arms[k].q0));
    let c = d.couplings.first().ok_or_else(|| model(&"no coupling"))?;
    let damper = Damper {
        influence: c.influence,
        safety: c.safety,
        gain: c.gain,
    };
    Ok((kins, [ports[0], ports[1]], q0, models[1].clone(), damper))
}

/// How `dia10-dual` is drawn: the torso (the trace's `q1`) in both arms, then each arm's 7.
pub(super) fn geometry() -> Result<SceneGeometry, SceneRunError> {
    let (kins, ports, _, numeric, _) = arms(&super::description("dia10-dual")?)?;
    let model = ArmModel::from_model(&numeric)
        .map_err(|e| SceneRunError(format!("the reference arm: {e}")))?;
    let arms = (0..2)
        .map(|k| {
            let mut joints = vec![1];
            joints.extend(2 + 7 * k..2 + 7 * k + 7);
            let mut model = model.clone();
            model.joints = kins[k].chain.joints.to_vec();
            model.tool = kins[k].chain.tool;
            SceneArm {
                name: ARMS[k].to_string(),
                model,
                base: Se3::identity(),
                port: ports[k],
                joints,
            }
        })
        .collect();
    Ok(SceneGeometry {
        name: "dia10-dual".into(),
        arms,
        couplings: vec![(0, 1)],
        safety: Some(super::safety("dia10-dual")?),
    })
}

/// The cutting path's progress at `t` (s) and its rate: out over 4 s from 0.5 s, back over 4 s
/// (smooth steps).
fn cut(t: f64) -> (f64, f64) {
    let step = |t0: f64| {
        let s = ((t - t0) / 4.0).clamp(0.0, 1.0);
        let p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let v = if s > 0.0 && s < 1.0 {
            30.0 * s * s * (1.0 - s) * (1.0 - s) / 4.0
        } else {
            0.0
        };
        (p, v)
    };
    let (out, back) = (step(0.5), step(4.5));
    (out.0 - back.0, out.1 - back.1)
}

/// The scene `dia10-dual` ready to step: its arms' kinematics and controllers, their ports and
/// starts, and the scene's coupling and shared torso.
#[derive(Clone, Debug)]
pub struct Dia10Dual {
    /// Each arm's kinematics (left: the mirror image, right: the reference arm).
    pub kins: [Kin; 2],
    /// Each arm's controller.
    pub arms: [Ctrl; 2],
    /// The scene's step, its coupling between the shafts.
    pub scene: Scene<f64, 1, 16, 2>,
    /// Each arm's port.
    pub rcms: [Rcm<f64, 2>; 2],
    /// Each arm's start (the left arm's the right one's negated: its mirror image).
    pub q0: [SVector<f64, 8>; 2],
    /// Each tip's pose at the start.
    starts: [Se3<f64>; 2],
}

/// The torso, shared: joint 1 of both arms.
const SHARED: [SharedJoint; 1] = [SharedJoint {
    arms: (0, 1),
    joints: (0, 0),
}];

impl Dia10Dual {
    /// The scene at its start.
    pub fn new() -> Result<Self, SceneRunError> {
        let model = |e: &dyn std::fmt::Display| SceneRunError(format!("the reference arm: {e}"));
        let description = super::description("dia10-dual")?;
        let (kins, ports, q0, _, damper) = arms(&description)?;
        let weight = description.orientation_weight;
        let scenario = Scenario::from_name("1").map_err(|e| model(&e))?;
        let config = ScenarioConfig::new(scenario)
            .with_method(Method::Qp)
            .controller_config();
        let mut scene = Scene::<f64, 1, 16, 2>::new([Coupling {
            arms: (0, 1),
            between: Between::Shafts,
            damper,
        }]);
        // With the torso shared the tips' orientations give way first: the scene file's weight.
        scene.orientation_weight = weight;
        Ok(Dia10Dual {
            starts: [0, 1].map(|k| kins[k].chain.forward_kinematics(&q0[k])),
            kins,
            arms: [Ctrl::new(config); 2],
            scene,
            rcms: ports.map(|trocar| Rcm {
                trocar,
                dv: SVector::zeros(),
            }),
            q0,
        })
    }

    /// Each arm's reference at `t` (s): the left tip held at its start, the right one cutting
    /// 4 cm along `+x` and back.
    pub fn references(&self, t: f64) -> [Reference<f64>; 2] {
        let (p, v) = cut(t);
        let shift = Vector3::new(0.04, 0.0, 0.0);
        [
            Reference {
                position: self.starts[0].translation,
                rotation: self.starts[0].rotation,
                velocity: Vector3::zeros(),
                angular_velocity: Vector3::zeros(),
            },
            Reference {
                position: self.starts[1].translation + shift * p,
                rotation: self.starts[1].rotation,
                velocity: shift * v,
                angular_velocity: Vector3::zeros(),
            },
        ]
    }

    /// One step of the scene at the arms' joints `q` (the torso the same in both) and time `t`
    /// (s): the rates of both arms, the torso's the same in both. The message of an error names
    /// the time.
    pub fn step(
        &mut self,
        q: &[SVector<f64, 8>; 2],
        t: f64,
    ) -> Result<SceneOutput<f64, 2, 8, 2, 1>, SceneRunError> {
        let references = self.references(t);
        let kins = self.kins;
        let o = self
            .scene
            .step::<Kin, 2, 8, 6, 2, 4, 6, 6, 5>(
                &mut self.arms,
                &kins,
                q,
                &references,
                &self.rcms,
                &[Se3::identity(); 2],
                &SHARED,
                DT,
            )
            .map_err(|e: SceneError| SceneRunError(format!("t = {t:.3} s: {e}")))?;
        Ok(o)
    }
}

/// The two arms' joints (or rates) as the scene's: the shared torso once, then each arm's own 7.
pub fn torso_once(x: &[SVector<f64, 8>; 2]) -> Vec<f64> {
    let mut v = vec![x[0][0]];
    v.extend(x[0].iter().skip(1));
    v.extend(x[1].iter().skip(1));
    v
}

/// Runs `dia10-dual`; `progress` gets the fraction done.
pub fn simulate(mut progress: impl FnMut(f64)) -> Result<MechanismTrace, SceneRunError> {
    let mut setup = Dia10Dual::new()?;
    let (kins, ports) = (setup.kins, setup.rcms.map(|r| r.trocar));
    let mut q = setup.q0;
    let mut columns = vec!["t".to_string()];
    columns.extend((1..=15).map(|k| format!("q{k}")));
    columns.extend((1..=15).map(|k| format!("qd{k}")));
    for arm in ARMS {
        columns.push(format!("{arm}.rcm_drift"));
        columns.push(format!("{arm}.ep_norm"));
    }
    columns.push("min_shaft_distance".into());
    let steps = (DURATION / DT).round() as usize;
    let mut rows = Vec::with_capacity(steps + 1);
    for step in 0..=steps {
        let t = step as f64 * DT;
        let references = setup.references(t);
        let mut row = vec![t];
        row.extend(torso_once(&q));
        let qd = if step < steps {
            let o = setup.step(&q, t)?;
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
            if !o.coupling_held {
                return Err(SceneRunError(format!(
                    "t = {t:.3} s: the shafts' coupling could not hold within the ports"
                )));
            }
            o.qd
        } else {
            [SVector::zeros(); 2]
        };
        row.extend(torso_once(&qd));
        let mut ends = [Vector3::zeros(); 4];
        for k in 0..2 {
            let g_0i = kins[k].chain.link_frame(6, &q[k]);
            let axis: Vector3<f64> = g_0i.rotation.column(1).into_owned();
            let rel = ports[k] - g_0i.translation;
            row.push((rel - axis * rel.dot(&axis)).norm());
            let tip = kins[k].chain.forward_kinematics(&q[k]).translation;
            row.push((references[k].position - tip).norm());
            ends[2 * k] = ports[k];
            ends[2 * k + 1] = tip;
        }
        row.push(segment_distance(&ends[0], &ends[1], &ends[2], &ends[3]).distance);
        if row.iter().any(|v| !v.is_finite()) {
            return Err(SceneRunError(format!("t = {t:.3} s: a non-finite value")));
        }
        rows.push(row);
        for k in 0..2 {
            q[k] += qd[k] * DT;
        }
        progress(step as f64 / steps as f64);
    }
    let mut panels = vec![Panel {
        title: "the distance between the shafts inside the body".into(),
        x_label: "t (s)".into(),
        y_label: "distance (m)".into(),
        lines: vec![line("min_shaft_distance", "min_shaft_distance")],
        non_negative: true,
    }];
    panels.extend(arm_panels(
        &ARMS,
        "each tip's error (left holds, right cuts)",
    ));
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
