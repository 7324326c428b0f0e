//! Scenes of several arms, each through its own port, run by one step
//! ([`trocar::control::scene`]): `three-ports`, two instrument arms and an endoscope arm on
//! separate bases around the patient, the three ports 6.9 cm apart on a circle of 4 cm, the
//! instruments' tips sent past the circle's centre, where their shafts would meet.
//!
//! The arms are Franka Pandas with the laparoscope of `panda-laparoscope` (its URDF's ranges,
//! speeds, accelerations and jerks as hard limits, the QP step), each port 0.25 m along the shaft
//! from the flange and the tips 0.15 m below the ports at the start. The endoscope is a camera ([`Camera`]): its view axis, from its port
//! through its tip, kept on the midpoint of the instruments' tips, its tip 8 cm below
//! its port (above the instruments' tips, which are 0.15 m deep); the scene starts with the camera
//! on its point (the endoscope's arm brought there alone before the scene's first step). Every pair
//! of shafts is kept at least 10 mm apart by a velocity damper (influence 30 mm, gain
//! 0.1 m/s). The arms, their bases, starts and couplings and the camera are the scene file's
//! ([`description`]); the paths are this module's.
//!
//! The trace's columns: `t`, the scene's joints `q1..q21` and rates `qd1..qd21` (the arms in the
//! order of [`ARMS`]), each arm's `NAME.rcm_drift` (m, the distance from its port to its shaft's
//! axis, from forward kinematics) and `NAME.ep_norm` (m, its tip's distance from its reference),
//! `endoscope.view_error` (rad, the angle between the endoscope's view axis and the direction
//! from its port to the instruments' midpoint), `min_shaft_distance` (m, the smallest distance between two shafts inside the body, port to
//! tip, from forward kinematics) and `coupling_active` (1 where a coupling changed the rates).

use crate::closed_chain::{MechanismTrace, Panel};
use crate::plot::view3d::{ArmModel, ArmPose};
use nalgebra::{SVector, Vector3};
use trocar::control::scene::{camera_point, Camera, Coupling, Scene, SceneError, SceneOutput};
use trocar::control::{
    ChainKinematics, ConstrainedKinematics, Controller, Damper, Gains, HardLimits, MethodKind, Rcm,
    Reference,
};
use trocar::distance::segment_distance;
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_model::scene::SceneDescription;

pub mod dual;

/// The Panda laparoscope's kinematics, as the scene's arms use them.
pub type Kin = ChainKinematics<f64, 7, 2, 4>;
/// The Panda laparoscope's controller, as the scene's arms use it.
pub type Ctrl = Controller<f64, 7, 7, 2, 4, 4, 4>;

/// The Panda laparoscope's kinematics and its URDF's ranges, speeds, accelerations and jerks as
/// hard limits.
pub fn panda() -> Result<(Kin, HardLimits<f64, 7>), SceneRunError> {
    let description =
        RobotDescription::preset("panda-laparoscope").map_err(|e| model_error(&e.to_string()))?;
    let kin: Kin = NumericModel::<f64>::from_description(&description, &[])
        .and_then(|m| m.to_kinematics::<7, 2, 4>())
        .map_err(|e| model_error(&e.to_string()))?;
    let j = &description.joints;
    let limit = |k: usize, what: &str, v: Option<f64>| {
        v.ok_or_else(|| model_error(&format!("joint {} has no {what}", k + 1)))
    };
    let mut lower = SVector::<f64, 7>::zeros();
    let mut upper = SVector::<f64, 7>::zeros();
    let mut speed = SVector::<f64, 7>::zeros();
    let mut acceleration = SVector::<f64, 7>::zeros();
    let mut jerk = SVector::<f64, 7>::zeros();
    for k in 0..7 {
        let [lo, hi] = j[k]
            .limits
            .ok_or_else(|| model_error(&format!("joint {} has no range", k + 1)))?;
        lower[k] = lo;
        upper[k] = hi;
        speed[k] = limit(k, "speed limit", j[k].speed_limit)?;
        acceleration[k] = limit(k, "acceleration limit", j[k].acceleration_limit)?;
        jerk[k] = limit(k, "jerk limit", j[k].jerk_limit)?;
    }
    let limits = HardLimits::none()
        .with_joint_limits(lower, upper)
        .with_speed_limits(speed)
        .with_acceleration_limits(acceleration)
        .with_jerk_limits(jerk);
    Ok((kin, limits))
}

/// The scene's controller of one arm: the QP step (`κ = 0.01`, the task's variable damping at
/// its defaults) with `K_p = K_o = K_r = 10` and `limits` — the configuration a C or C++ loop
/// gives each arm of the scene's C object (`Gains::config`, as the C ABI maps it).
pub fn controller(limits: HardLimits<f64, 7>) -> Ctrl {
    let gains = Gains {
        kp: 10.0,
        ko: 10.0,
        kr: 10.0,
        dls_alpha0: 0.05,
        dls_w0_task: 1e-3,
        dls_w0_jb0i: 0.01,
        fi_gamma: 5.0,
        qp_kappa: 0.01,
        max_joint_speed: None,
    };
    Ctrl::new(gains.config(MethodKind::Qp)).with_limits(limits)
}

/// The names of the scenes.
pub fn scenario_names() -> &'static [&'static str] {
    &["three-ports", "dia10-dual"]
}

/// Whether `name` is a scene.
pub fn is_scene(name: &str) -> bool {
    scenario_names().contains(&name)
}

/// The arms of `three-ports`, in the scene's order.
pub const ARMS: [&str; 3] = ["left", "right", "endoscope"];

/// The shipped scene `name` as its file describes it (`runtime/model/scenes/NAME.toml`: its arms,
/// their bases and starts, its couplings, the endoscope's camera).
pub fn description(name: &str) -> Result<SceneDescription, SceneRunError> {
    SceneDescription::shipped(name).map_err(|e| model_error(&e.to_string()))
}

/// The smallest safety distance of the scene `name`'s couplings (m).
pub fn safety(name: &str) -> Result<f64, SceneRunError> {
    let d = description(name)?;
    Ok(d.couplings
        .iter()
        .map(|c| c.safety)
        .fold(f64::INFINITY, f64::min))
}

/// How far the endoscope of `three-ports` may look off the instruments' midpoint (rad), from
/// its file.
pub fn view_tolerance() -> Result<f64, SceneRunError> {
    description("three-ports")?
        .arms
        .iter()
        .find_map(|a| a.camera.as_ref().map(|c| c.tolerance))
        .ok_or_else(|| model_error("three-ports has no camera"))
}

/// The sample time (s) and the duration (s) of `three-ports`.
pub const DT: f64 = 0.002;
/// The duration of `three-ports` (s).
pub const DURATION: f64 = 4.0;

/// The scene `three-ports` ready to step: its arms' kinematics and controllers, their bases,
/// ports and references, and the scene's couplings.
#[derive(Clone, Debug)]
pub struct ThreePorts {
    /// Each arm's kinematics (in its own base frame).
    pub kins: [Kin; 3],
    /// Each arm's controller.
    pub arms: [Ctrl; 3],
    /// The scene's step and its couplings.
    pub scene: Scene<f64, 3, 21, 6>,
    /// Each arm's base in the scene's frame.
    pub bases: [Se3<f64>; 3],
    /// Each arm's port (in its own base frame).
    pub rcms: [Rcm<f64, 2>; 3],
    /// Each arm's start.
    pub q0: [SVector<f64, 7>; 3],
    /// The endoscope's camera task (its base frame).
    pub camera: Camera<f64>,
    /// Each tip's pose at the start, and how far its reference moves it (arm frame).
    start: Se3<f64>,
    shifts: [Vector3<f64>; 3],
    /// The camera's point at the last step and its time, for the point's velocity.
    last_look: Option<(f64, Vector3<f64>)>,
}

impl ThreePorts {
    /// The scene at its start, with its couplings (`coupled`) or without them.
    pub fn new(coupled: bool) -> Result<Self, SceneRunError> {
        let (kin, limits) = panda()?;
        let description = description("three-ports")?;
        let q0 = SVector::<f64, 7>::from_column_slice(&description.arms[0].q0);
        let g_0e = kin.chain.forward_kinematics(&q0);
        // The port: the constraint frame at the start (the shaft's point at `l_a`).
        let trocar = description
            .ports()
            .map_err(|e| model_error(&e.to_string()))?[0];
        // The ports on a circle of 4 cm about the origin of the scene, each arm's base outside,
        // facing the centre: the scene file's.
        let bases: [Se3<f64>; 3] = core::array::from_fn(|k| description.arms[k].base);
        // The instruments' tips 6 cm toward the centre and past it (2 cm beyond), 5 mm to their
        // left so that the shafts would pass close rather than through each other; the endoscope
        // still.
        let shifts = [
            Vector3::new(0.07, 0.001, 0.0),
            Vector3::new(0.07, 0.001, 0.0),
            Vector3::zeros(),
        ];
        let couplings: [Coupling<f64>; 3] = core::array::from_fn(|p| {
            let c = &description.couplings[p];
            Coupling {
                arms: c.arms,
                between: c.between,
                damper: if coupled {
                    Damper {
                        influence: c.influence,
                        safety: c.safety,
                        gain: c.gain,
                    }
                } else {
                    // An influence of zero: the damper never acts.
                    Damper {
                        influence: 0.0,
                        safety: 0.0,
                        gain: 0.0,
                    }
                },
            }
        });
        let scene = Scene::<f64, 3, 21, 6>::new(couplings);
        let arms = [controller(limits); 3];
        let kins = [kin; 3];
        let rcm = Rcm {
            trocar,
            dv: SVector::zeros(),
        };
        let rcms = [rcm; 3];
        let mut camera = Camera::at_start(trocar, &g_0e)
            .ok_or_else(|| model_error("the endoscope's tip is at its port"))?;
        if let Some(depth) = description.arms[2].camera.as_ref().and_then(|c| c.depth) {
            camera.depth = depth;
        }
        let mut setup = ThreePorts {
            camera,
            last_look: None,
            kins,
            arms,
            scene,
            bases,
            rcms,
            q0: [q0; 3],
            start: g_0e,
            shifts,
        };
        setup.aim_camera()?;
        Ok(setup)
    }

    /// Brings the endoscope's arm alone (the instruments still) until its camera is on its point,
    /// at most 3 s of its own steps; its controller then starts again from rest.
    fn aim_camera(&mut self) -> Result<(), SceneRunError> {
        let mut q = self.q0;
        for step in 0..1500 {
            let reference = self
                .references(&q, 0.0)
                .map_err(|e| SceneRunError(format!("aiming the endoscope, step {step}: {e}")))?[2];
            let o = self.arms[2]
                .step(&self.kins[2], &q[2], &reference, &self.rcms[2], DT)
                .map_err(|e| SceneRunError(format!("aiming the endoscope, step {step}: {e}")))?;
            if o.qd.norm() < 1e-9 {
                break;
            }
            q[2] += o.qd * DT;
        }
        let tip = self.kins[2].chain.forward_kinematics(&q[2]).translation;
        let error = self.camera.view_error(&tip, &self.look_at(&q));
        if error.is_nan() || error >= 1e-6 {
            return Err(SceneRunError(format!(
                "the endoscope could not be aimed at the instruments' midpoint ({error:.2e} rad off)"
            )));
        }
        self.arms[2].reset();
        self.last_look = None;
        self.q0 = q;
        Ok(())
    }

    /// The camera's point: the midpoint of the instruments' tips at `q`, in the endoscope's
    /// base frame.
    pub fn look_at(&self, q: &[SVector<f64, 7>; 3]) -> Vector3<f64> {
        // The Panda's forward kinematics cannot fail; the indices are the scene's.
        camera_point::<f64, Kin, 3, 7, 7, 2, 4, 4, 4>(&self.kins, q, &self.bases, &[0, 1], 2)
            .unwrap_or_else(|_| Vector3::from_element(f64::NAN))
    }

    /// Each arm's reference at `t` (s) and joints `q`: the instruments' along their paths, the
    /// endoscope's from its camera looking at [`Self::look_at`] (the point's velocity from its
    /// place at the last call, which this call records: call it once a step).
    pub fn references(
        &mut self,
        q: &[SVector<f64, 7>; 3],
        t: f64,
    ) -> Result<[Reference<f64>; 3], SceneError> {
        let mut references = self.shifts.map(|s| reference(&self.start, s, t));
        let point = self.look_at(q);
        let velocity = match self.last_look {
            Some((t0, p0)) if t > t0 => (point - p0) / (t - t0),
            _ => Vector3::zeros(),
        };
        references[2] = self
            .camera
            .reference(&point, &velocity)
            .ok_or(SceneError::NonFinite)?;
        self.last_look = Some((t, point));
        Ok(references)
    }

    /// One step of the scene at the arms' joints `q`, time `t` (s): [`Self::references`], then
    /// [`Self::step_to`] with the scene's own kinematics.
    pub fn step(
        &mut self,
        q: &[SVector<f64, 7>; 3],
        t: f64,
    ) -> Result<SceneOutput<f64, 3, 7, 2, 3>, SceneError> {
        let references = self.references(q, t)?;
        let kins = self.kins;
        self.step_to(&kins, q, &references)
    }

    /// The scene's step ([`Scene::step`]) toward `references` with the arms' kinematics `kins`
    /// (the same Panda's, from the numeric model or generated).
    pub fn step_to<K: ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>(
        &mut self,
        kins: &[K; 3],
        q: &[SVector<f64, 7>; 3],
        references: &[Reference<f64>; 3],
    ) -> Result<SceneOutput<f64, 3, 7, 2, 3>, SceneError> {
        self.scene.step::<K, 3, 7, 7, 2, 4, 4, 4, 6>(
            &mut self.arms,
            kins,
            q,
            references,
            &self.rcms,
            &self.bases,
            &[],
            DT,
        )
    }
}

/// Runs the scene `name`, with its couplings (`coupled`) or without them (to see what they
/// prevent); `progress` gets the fraction done.
pub fn simulate(
    name: &str,
    coupled: bool,
    mut progress: impl FnMut(f64),
) -> Result<MechanismTrace, SceneRunError> {
    if !is_scene(name) {
        return Err(SceneRunError(format!(
            "unknown scene `{name}` (expected one of: {})",
            scenario_names().join(", ")
        )));
    }
    if name == "dia10-dual" {
        return dual::simulate(progress);
    }
    let mut setup = ThreePorts::new(coupled)?;
    let (kin, trocar, bases) = (setup.kins[0], setup.rcms[0].trocar, setup.bases);
    let mut q = setup.q0;
    let mut columns = vec!["t".to_string()];
    columns.extend((1..=21).map(|k| format!("q{k}")));
    columns.extend((1..=21).map(|k| format!("qd{k}")));
    for arm in ARMS {
        columns.push(format!("{arm}.rcm_drift"));
        columns.push(format!("{arm}.ep_norm"));
    }
    columns.push("endoscope.view_error".into());
    columns.push("min_shaft_distance".into());
    columns.push("coupling_active".into());
    let steps = (DURATION / DT).round() as usize;
    let mut rows = Vec::with_capacity(steps + 1);
    for step in 0..=steps {
        let t = step as f64 * DT;
        let references = setup
            .references(&q, t)
            .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
        // The row at t: the joints, the rates commanded at t (none after the last step).
        let mut row = vec![t];
        row.extend(q.iter().flat_map(|x| x.iter().copied()));
        let (qd, coupling_active) = if step < steps {
            let kins = setup.kins;
            let o = setup
                .step_to(&kins, &q, &references)
                .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
            if !o.coupling_held {
                return Err(SceneRunError(format!(
                    "t = {t:.3} s: the couplings could not hold within the ports and the joint limits"
                )));
            }
            if let Some(k) = o
                .arms
                .iter()
                .position(|a| a.status == trocar::control::StepStatus::TrocarYielded)
            {
                return Err(SceneRunError(format!(
                    "t = {t:.3} s: the {} arm's port gave way to its joint limits",
                    ARMS[k]
                )));
            }
            (o.qd, o.coupling_active)
        } else {
            ([SVector::<f64, 7>::zeros(); 3], false)
        };
        row.extend(qd.iter().flat_map(|x| x.iter().copied()));
        let mut ends = [Vector3::zeros(); 6];
        for k in 0..3 {
            let tip = kin.chain.forward_kinematics(&q[k]);
            let flange = kin.chain.link_frame(7, &q[k]);
            let axis: Vector3<f64> = flange.rotation.column(2).into_owned();
            let rel = trocar - flange.translation;
            row.push((rel - axis * rel.dot(&axis)).norm());
            row.push((references[k].position - tip.translation).norm());
            ends[2 * k] = bases[k].transform_point(&trocar);
            ends[2 * k + 1] = bases[k].transform_point(&tip.translation);
        }
        let endoscope_tip = kin.chain.forward_kinematics(&q[2]).translation;
        row.push(setup.camera.view_error(&endoscope_tip, &setup.look_at(&q)));
        let min = [(0, 1), (0, 2), (1, 2)]
            .iter()
            .map(|&(a, b)| {
                segment_distance(
                    &ends[2 * a],
                    &ends[2 * a + 1],
                    &ends[2 * b],
                    &ends[2 * b + 1],
                )
                .distance
            })
            .fold(f64::INFINITY, f64::min);
        row.push(min);
        row.push(if coupling_active { 1.0 } else { 0.0 });
        if row.iter().any(|v| !v.is_finite()) {
            return Err(SceneRunError(format!("t = {t:.3} s: a non-finite value")));
        }
        rows.push(row);
        for k in 0..3 {
            q[k] += qd[k] * DT;
        }
        progress(step as f64 / steps as f64);
    }
    let mut panels = vec![Panel {
        title: "smallest distance between two shafts inside the body".into(),
        x_label: "t (s)".into(),
        y_label: "distance (m)".into(),
        lines: vec![line("min_shaft_distance", "min_shaft_distance")],
        non_negative: true,
    }];
    panels.extend(arm_panels(&ARMS, "each tip's error"));
    panels.push(Panel {
        title: "the endoscope's view axis off the instruments' midpoint".into(),
        x_label: "t (s)".into(),
        y_label: "angle (rad)".into(),
        lines: vec![line("endoscope.view_error", "endoscope")],
        non_negative: true,
    });
    Ok(MechanismTrace {
        name: name.to_string(),
        columns,
        rows,
        panels,
    })
}

/// One arm of a scene as it is drawn: its model, its base in the scene's frame, its port (its
/// own base frame) and where its joints are in a row of the scene's trace.
#[derive(Clone, Debug)]
pub struct SceneArm {
    /// The arm's name (its columns' prefix).
    pub name: String,
    /// The arm's kinematics.
    pub model: ArmModel,
    /// The arm's base in the scene's frame.
    pub base: Se3<f64>,
    /// The arm's port in its own base frame (m).
    pub port: Vector3<f64>,
    /// The indices in a trace row of the arm's joints, in its chain's order (a shared joint
    /// appears in every arm that holds it).
    pub joints: Vec<usize>,
}

impl SceneArm {
    /// The arm at the row `row` of the scene's trace, in the scene's frame: its stick figure,
    /// its shaft, its port (the point of the shaft nearest the port) and its tip.
    pub fn pose(&self, row: &[f64]) -> ArmPose {
        let q: Vec<f64> = self.joints.iter().map(|&j| row[j]).collect();
        let l_a = self
            .model
            .shaft()
            .offset(&self.model.link_frame(&q), &self.port);
        let pose = self.model.pose(&q, l_a);
        let to = |p: &Vector3<f64>| self.base.transform_point(p);
        ArmPose {
            points: pose.points.iter().map(to).collect(),
            shaft: pose.shaft.map(|p| to(&p)),
            trocar: to(&pose.trocar),
            tip: to(&pose.tip),
        }
    }

    /// The arm's port in the scene's frame.
    pub fn port_in_scene(&self) -> Vector3<f64> {
        self.base.transform_point(&self.port)
    }
}

/// How a scene is drawn: its arms and the pairs whose shafts its couplings keep apart.
#[derive(Clone, Debug)]
pub struct SceneGeometry {
    /// The scene's name.
    pub name: String,
    /// Its arms, in the scene's order.
    pub arms: Vec<SceneArm>,
    /// The coupled pairs of arms (their shafts kept [`SceneGeometry::safety`] apart).
    pub couplings: Vec<(usize, usize)>,
    /// The couplings' safety distance (m), where there are couplings.
    pub safety: Option<f64>,
}

/// The geometry of the scene `name` ([`scenario_names`]).
pub fn geometry(name: &str) -> Result<SceneGeometry, SceneRunError> {
    match name {
        "three-ports" => {
            let setup = ThreePorts::new(true)?;
            let description = RobotDescription::preset("panda-laparoscope")
                .map_err(|e| model_error(&e.to_string()))?;
            let model = NumericModel::<f64>::from_description(&description, &[])
                .map_err(|e| model_error(&e.to_string()))
                .and_then(|m| ArmModel::from_model(&m).map_err(|e| model_error(&e)))?;
            let arms = (0..3)
                .map(|k| SceneArm {
                    name: ARMS[k].to_string(),
                    model: model.clone(),
                    base: setup.bases[k],
                    port: setup.rcms[k].trocar,
                    joints: (1 + 7 * k..1 + 7 * k + 7).collect(),
                })
                .collect();
            Ok(SceneGeometry {
                name: name.into(),
                arms,
                couplings: setup.scene.couplings.iter().map(|c| c.arms).collect(),
                safety: Some(safety("three-ports")?),
            })
        }
        "dia10-dual" => dual::geometry(),
        other => Err(SceneRunError(format!(
            "unknown scene `{other}` (expected one of: {})",
            scenario_names().join(", ")
        ))),
    }
}

/// Why a scene's run failed: the message names the time and what gave way.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRunError(pub String);

impl core::fmt::Display for SceneRunError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SceneRunError {}

/// A line of a panel: `column` over `t`.
fn line(column: &str, legend: &str) -> (String, String, String) {
    ("t".to_string(), column.to_string(), legend.to_string())
}

/// The panels every scene draws: each arm's drift and each tip's error.
fn arm_panels(arms: &[&str], tip_title: &str) -> [Panel; 2] {
    let panel = |title: &str, y_label: &str, suffix: &str| Panel {
        title: title.into(),
        x_label: "t (s)".into(),
        y_label: y_label.into(),
        lines: arms
            .iter()
            .map(|a| line(&format!("{a}.{suffix}"), a))
            .collect(),
        non_negative: true,
    };
    [
        panel("each port's drift", "drift (m)", "rcm_drift"),
        panel(tip_title, "|dp - p| (m)", "ep_norm"),
    ]
}

fn model_error(message: &str) -> SceneRunError {
    SceneRunError(format!("the Panda's description: {message}"))
}

/// The tip's reference: from its start by `shift` (arm frame) along a smooth step over 2 s,
/// starting at 0.5 s.
pub fn reference(start: &Se3<f64>, shift: Vector3<f64>, t: f64) -> Reference<f64> {
    let s = ((t - 0.5) / 2.0).clamp(0.0, 1.0);
    let p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let v = if s > 0.0 && s < 1.0 {
        30.0 * s * s * (1.0 - s) * (1.0 - s) / 2.0
    } else {
        0.0
    };
    Reference {
        position: start.translation + shift * p,
        rotation: start.rotation,
        velocity: shift * v,
        angular_velocity: Vector3::zeros(),
    }
}
