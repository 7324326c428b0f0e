//! The robot as a physics plant: an MJCF model (MuJoCo's XML) built from the description.
//!
//! The kinematic simulations integrate `q += dt θ̇`: a robot that moves exactly as commanded.
//! A physics plant adds what a real arm does with the command: inertia, gravity, joint damping
//! and friction, a velocity servo with torque limits, and the body wall's reaction at the
//! port. [`mjcf`] writes the model; the Python package's `trocar.physics` runs the controller on
//! it in MuJoCo.
//!
//! What the model holds:
//! - one body per joint, at the joint's frame at `q = 0` (the description's origins, its
//!   parameters at their nominal values), with the link's mass properties
//!   ([`trocar_model::description::JointDynamics::inertia`]: a URDF's `<inertial>` elements, the
//!   links on fixed joints folded in) — a joint without them is refused;
//! - hinge or slide joints with the description's range, damping (`damping`) and dry friction
//!   (`frictionloss`), and the torque limit (`actuatorfrcrange`, the URDF's `effort`) that
//!   bounds everything the joint's actuator exerts;
//! - gravity compensated by the actuators (`gravcomp` on every body, routed through the
//!   actuators with `actuatorgravcomp`, so that it counts against the torque limit): what arms
//!   with a joint-velocity interface do inside their servo;
//! - a `velocity` actuator per joint (the command interface of libfranka's joint-velocity mode
//!   or the dVRK's `servo_jv`); its gain is set when the model is loaded (see
//!   `trocar.physics`), so `kv` is written as 1;
//! - the instrument (`[instrument]`, when the constraint is on the last link): a capsule of the
//!   given mass and radius from the shaft's origin (the constraint point at insertion 0) to the
//!   end effector, a site `port_contact` moved each step to where the shaft crosses the port,
//!   and a `wrist` site with force and torque sensors (what a wrist force/torque sensor
//!   measures of the instrument).
//!
//! Contacts are off (no geometry collides): the arm's links are drawn as capsules between joint
//! origins for pictures only, and a `port` site marks the trocar (placed by the loop).

use crate::{Error, Result, Robot};
use std::fmt::Write as _;
use trocar_model::description::{JointKind, Linear, Origin, RobotDescription, Rotation};
use trocar_sim::breathing;
use trocar_sim::simulation::Method;

/// The MuJoCo time step the model is written with (s): two physics steps per 1 kHz control
/// sample.
pub const PLANT_TIMESTEP: f64 = 0.0005;

/// The instrument's geometry as the plant places it, in the last link's frame at `q = 0`:
/// where the shaft starts (the constraint point with the insertion at 0), its unit direction
/// toward the tip, and its length to the end effector (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaft {
    /// Start of the shaft in the last joint's frame (m).
    pub start: [f64; 3],
    /// Unit direction from the start toward the tip, in the last joint's frame.
    pub direction: [f64; 3],
    /// Length from the start to the end effector (m).
    pub length: f64,
    /// Radius (m).
    pub radius: f64,
    /// Mass (kg).
    pub mass: f64,
}

fn value(x: &Linear, params: &[(String, f64)]) -> f64 {
    x.constant
        + x.terms
            .iter()
            .map(|(c, name)| {
                c * params
                    .iter()
                    .find(|(n, _)| n == name)
                    .map_or(0.0, |(_, v)| *v)
            })
            .sum::<f64>()
}

fn rotation(r: &Rotation) -> [[f64; 3]; 3] {
    match r {
        Rotation::Matrix(m) => *m,
        Rotation::Rpy(rpy) => {
            let m = trocar::se3::rotation_from_rpy_sin_cos(
                rpy[0].sin_cos(),
                rpy[1].sin_cos(),
                rpy[2].sin_cos(),
            );
            [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
        }
    }
}

/// `w x y z` of a rotation matrix.
fn quaternion(m: &[[f64; 3]; 3]) -> [f64; 4] {
    let r = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(r),
    );
    [q.w, q.i, q.j, q.k]
}

fn origin(o: &Origin, params: &[(String, f64)]) -> ([f64; 3], [[f64; 3]; 3]) {
    (
        o.xyz.clone().map(|x| value(&x, params)),
        rotation(&o.rotation),
    )
}

fn numbers(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `s` with the five XML special characters escaped, for an attribute value.
fn escaped(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The instrument of `d` with the parameters at `params`: `None` without `[instrument]`;
/// an error when the constraint is not on the last link or the shaft has no length.
pub fn shaft(d: &RobotDescription, params: &[(String, f64)]) -> Result<Option<Shaft>> {
    let Some(instrument) = d.instrument else {
        return Ok(None);
    };
    let n = d.joints.len();
    let Some(c) = d.constraint.as_ref().filter(|c| c.link == n) else {
        return Err(Error::argument(
            "instrument",
            "a physics plant places the instrument on the last link, through the port: the description's constraint must be on the last link",
        ));
    };
    // The shaft starts where the constraint point is with its own parameters (the insertion)
    // at 0, and runs to the end effector.
    let mut at_zero: Vec<(String, f64)> = params.to_vec();
    for x in &c.origin.xyz {
        for (_, name) in &x.terms {
            if let Some(p) = at_zero.iter_mut().find(|(n, _)| n == name) {
                p.1 = 0.0;
            }
        }
    }
    let start = c.origin.xyz.clone().map(|x| value(&x, &at_zero));
    let tip = d.end_effector.origin.xyz.clone().map(|x| value(&x, params));
    let along = [0, 1, 2].map(|k| tip[k] - start[k]);
    let length = norm(&along);
    if length.is_nan() || length <= 1e-6 {
        return Err(Error::argument(
            "instrument",
            "the shaft from the constraint point (insertion 0) to the end effector has no length",
        ));
    }
    Ok(Some(Shaft {
        start,
        direction: along.map(|x| x / length),
        length,
        radius: instrument.radius,
        mass: instrument.mass,
    }))
}

/// The MJCF model of `robot` (a serial description) with its parameters at `params` (the
/// nominal values where empty). Refused, naming the field, when a joint has no mass properties.
pub fn mjcf(robot: &Robot, params: &[(String, f64)]) -> Result<String> {
    let Some(d) = robot.description() else {
        return Err(Error::argument(
            "robot",
            "a physics plant needs a serial robot; a closed mechanism has no MJCF model here",
        ));
    };
    let mut values: Vec<(String, f64)> = robot.params();
    for (name, v) in params {
        match values.iter_mut().find(|(n, _)| n == name) {
            Some(p) => p.1 = *v,
            None => {
                return Err(Error::argument(
                    "params",
                    format!("unknown parameter `{name}`"),
                ))
            }
        }
    }
    let missing: Vec<String> = d
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.dynamics.inertia.is_none())
        .map(|(k, j)| format!("joints[{k}] ({})", j.name))
        .collect();
    if !missing.is_empty() {
        return Err(Error::argument(
            "robot",
            format!(
                "a physics plant needs every link's mass properties (a URDF's <inertial>, or `mass`, `com`, `inertia` of a TOML joint); missing for {}",
                missing.join(", ")
            ),
        ));
    }
    let shaft = shaft(d, &values)?;
    let mut out = String::new();
    let name = escaped(&d.name);
    let _ = writeln!(
        out,
        "<mujoco model=\"{name}\">\n  <!-- Written by trocar from the description of {name}. -->\n  <compiler angle=\"radian\" balanceinertia=\"true\" autolimits=\"true\"/>\n  <option timestep=\"{PLANT_TIMESTEP:?}\" integrator=\"implicitfast\" gravity=\"0 0 -9.81\"/>\n  <visual><global offwidth=\"800\" offheight=\"600\"/></visual>\n  <default>\n    <geom contype=\"0\" conaffinity=\"0\" rgba=\"0.8 0.8 0.85 1\"/>\n  </default>\n  <worldbody>\n    <light pos=\"0 0 3\" dir=\"0 0 -1\"/>\n    <geom name=\"floor\" type=\"plane\" size=\"1.5 1.5 0.01\" rgba=\"0.3 0.3 0.35 1\"/>"
    );
    // The port (moved to the trocar by the loop) and the base column up to the first joint.
    let _ = writeln!(
        out,
        "    <site name=\"port\" type=\"sphere\" size=\"0.02\" rgba=\"1 0.5 0 0.8\"/>"
    );
    if let Some(first) = d.joints.first() {
        let p = origin(&first.origin, &values).0;
        if norm(&p) > 1e-9 {
            let _ = writeln!(
                out,
                "    <geom type=\"capsule\" fromto=\"0 0 0 {}\" size=\"0.04\" mass=\"0\"/>",
                numbers(&p)
            );
        }
    }
    let mut depth = 2;
    for (k, j) in d.joints.iter().enumerate() {
        let (p, r) = origin(&j.origin, &values);
        let indent = "  ".repeat(depth);
        let _ = writeln!(
            out,
            "{indent}<body name=\"link{}\" pos=\"{}\" quat=\"{}\" gravcomp=\"1\">",
            k + 1,
            numbers(&p),
            numbers(&quaternion(&r))
        );
        let inner = "  ".repeat(depth + 1);
        let (kind, axis, pos) = match &j.kind {
            JointKind::Revolute { axis } => ("hinge", *axis, [0.0; 3]),
            JointKind::Prismatic { axis } => ("slide", *axis, [0.0; 3]),
            JointKind::Twist { v, w } => {
                let v = v.clone().map(|x| value(&x, &values));
                if norm(w) == 0.0 {
                    ("slide", v, [0.0; 3])
                } else {
                    // A zero-pitch twist (v = −ω × p): the axis ω through p = ω × v.
                    let p = [
                        w[1] * v[2] - w[2] * v[1],
                        w[2] * v[0] - w[0] * v[2],
                        w[0] * v[1] - w[1] * v[0],
                    ];
                    ("hinge", *w, p)
                }
            }
        };
        let mut attributes = format!(
            "name=\"{}\" type=\"{kind}\" axis=\"{}\" pos=\"{}\"",
            escaped(&j.name),
            numbers(&axis),
            numbers(&pos)
        );
        if let Some([lo, hi]) = j.limits {
            let _ = write!(attributes, " range=\"{lo:?} {hi:?}\"");
        }
        if let Some(c) = j.dynamics.damping {
            let _ = write!(attributes, " damping=\"{c:?}\"");
        }
        if let Some(f) = j.dynamics.friction {
            let _ = write!(attributes, " frictionloss=\"{f:?}\"");
        }
        if let Some(e) = j.dynamics.effort_limit {
            let _ = write!(
                attributes,
                " actuatorfrcrange=\"{:?} {e:?}\" actuatorgravcomp=\"true\"",
                -e
            );
        } else {
            let _ = write!(attributes, " actuatorgravcomp=\"true\"");
        }
        let _ = writeln!(out, "{inner}<joint {attributes}/>");
        let i = j.dynamics.inertia.expect("checked above");
        let _ = writeln!(
            out,
            "{inner}<inertial pos=\"{}\" mass=\"{:?}\" fullinertia=\"{}\"/>",
            numbers(&i.com),
            i.mass,
            numbers(&i.inertia)
        );
        // The link drawn from its joint to the next joint's origin (the last one to where the
        // shaft starts, or to the end effector).
        let next = match (d.joints.get(k + 1), &shaft) {
            (Some(n), _) => origin(&n.origin, &values).0,
            (None, Some(s)) => s.start,
            (None, None) => origin(&d.end_effector.origin, &values).0,
        };
        if norm(&next) > 1e-9 {
            let _ = writeln!(
                out,
                "{inner}<geom type=\"capsule\" fromto=\"0 0 0 {}\" size=\"0.03\" mass=\"0\"/>",
                numbers(&next)
            );
        }
        depth += 1;
    }
    let inner = "  ".repeat(depth);
    if let Some(s) = &shaft {
        let end = [0, 1, 2].map(|k| s.start[k] + s.length * s.direction[k]);
        let _ = writeln!(
            out,
            "{inner}<body name=\"instrument\" pos=\"0 0 0\" gravcomp=\"1\">\n{inner}  <site name=\"wrist\" pos=\"{}\" size=\"0.01\"/>\n{inner}  <geom name=\"shaft\" type=\"capsule\" fromto=\"{} {}\" size=\"{:?}\" mass=\"{:?}\" rgba=\"0.2 0.5 0.9 1\"/>\n{inner}  <site name=\"port_contact\" pos=\"{}\" size=\"0.004\"/>\n{inner}  <site name=\"tip\" pos=\"{}\" size=\"0.006\" rgba=\"1 0.2 0.2 1\"/>\n{inner}</body>",
            numbers(&s.start),
            numbers(&s.start),
            numbers(&end),
            s.radius,
            s.mass,
            numbers(&s.start),
            numbers(&end)
        );
    } else {
        let (p, _) = origin(&d.end_effector.origin, &values);
        let _ = writeln!(
            out,
            "{inner}<site name=\"tip\" pos=\"{}\" size=\"0.006\"/>",
            numbers(&p)
        );
    }
    for depth in (2..depth).rev() {
        let _ = writeln!(out, "{}</body>", "  ".repeat(depth));
    }
    out.push_str("  </worldbody>\n  <actuator>\n");
    for j in &d.joints {
        let _ = writeln!(
            out,
            "    <velocity name=\"{0}\" joint=\"{0}\" kv=\"1\"/>",
            escaped(&j.name)
        );
    }
    out.push_str("  </actuator>\n");
    if shaft.is_some() {
        out.push_str("  <sensor>\n    <force name=\"wrist_force\" site=\"wrist\"/>\n    <torque name=\"wrist_torque\" site=\"wrist\"/>\n  </sensor>\n");
    }
    out.push_str("</mujoco>\n");
    Ok(out)
}

/// What a control loop outside the library needs to replay a run: the robot, the start
/// configuration, the trocar, the duration, the controller's options and the reference at any
/// time — of a shipped Panda scenario (`panda-laparoscope`, `panda-laparoscope-limits`) or of a
/// robot along its own trajectory (the description's `[simulation]` section, completed by a
/// [`RunRequest`](crate::RunRequest), as `trocar simulate ROBOT` runs it).
pub struct RunSetup {
    /// The start configuration.
    pub q0: Vec<f64>,
    /// The trocar (base frame, m).
    pub trocar: [f64; 3],
    /// How long the run lasts (s).
    pub duration: f64,
    /// The controller's options as the kinematic run uses them.
    pub controller: crate::ControllerOptions,
    source: Source,
}

enum Source {
    Scenario(trocar_sim::simulation::Scenario, trocar::se3::Se3<f64>),
    /// A moving-port scenario: its name, the tip's pose and the true port at the start.
    MovingPort(&'static str, trocar::se3::Se3<f64>, [f64; 3]),
    /// A trajectory of one's own: the path, the tip's pose at the start and the trocar.
    Trajectory(
        crate::Trajectory,
        trocar::se3::Se3<f64>,
        nalgebra::Vector3<f64>,
    ),
}

impl RunSetup {
    /// The setup of a shipped Panda scenario (`panda-laparoscope`, `panda-laparoscope-limits`):
    /// its robot, and its start configuration, trocar, duration, method, speed and insertion
    /// limits.
    pub fn scenario(name: &str) -> Result<(Robot, RunSetup)> {
        use trocar_sim::simulation::{Scenario, ScenarioConfig, PANDA_DEPTH_LIMITS, PANDA_Q0};
        if let Some(&moving) = breathing::scenario_names().iter().find(|n| **n == name) {
            // The kinematic run's controller: the QP step (κ = 0.01), K_p = K_o = K_r = 10, the
            // URDF's limits.
            let robot = Robot::load("panda-laparoscope")?;
            let q0 = PANDA_Q0.to_vec();
            let (port, g0) = start(&robot, &q0)?;
            let trocar = (nalgebra::Vector3::from(port) + breathing::nominal_offset(moving)).into();
            let controller = crate::ControllerOptions {
                method: Method::Qp,
                kp: 10.0,
                ko: 10.0,
                kr: 10.0,
                qp_kappa: 0.01,
                max_joint_speed: None,
                ..Default::default()
            };
            let setup = RunSetup {
                q0,
                trocar,
                duration: breathing::duration_of(moving),
                controller,
                source: Source::MovingPort(moving, g0, port),
            };
            return Ok((robot, setup));
        }
        let scenario =
            Scenario::from_name(name).map_err(|e| Error::argument("scenario", e.to_string()))?;
        if !scenario.is_panda() {
            return Err(Error::argument(
                "scenario",
                format!("`{name}` is not a Panda scenario: the physics plant runs panda-laparoscope, panda-laparoscope-limits, panda-breathing, panda-registration, or a robot along its own trajectory"),
            ));
        }
        let robot = Robot::load("panda-laparoscope")?;
        let config = ScenarioConfig::new(scenario);
        let mut controller = crate::ControllerOptions {
            method: config.method,
            max_joint_speed: config.max_joint_speed,
            ..Default::default()
        };
        if scenario == Scenario::PandaLimits {
            controller.depth_limits = Some(PANDA_DEPTH_LIMITS);
        }
        let q0 = PANDA_Q0.to_vec();
        let (trocar, g0) = start(&robot, &q0)?;
        let setup = RunSetup {
            q0,
            trocar,
            duration: config.duration,
            controller,
            source: Source::Scenario(scenario, g0),
        };
        Ok((robot, setup))
    }

    /// The setup of `robot` along its own trajectory: `request`'s entries, else the
    /// description's `[simulation]` section's, else the defaults (as
    /// [`simulate_robot`](crate::simulate_robot)).
    pub fn trajectory(robot: &Robot, request: &crate::RunRequest) -> Result<RunSetup> {
        let section = robot.simulation_section()?.unwrap_or_default();
        let (path, options) = request.resolve(robot, &section)?;
        let trajectory = crate::Trajectory::from_csv(&path)?;
        trajectory.check(&path.display().to_string())?;
        robot.check_joints("q0", &options.q0)?;
        let (at_q0, g0) = start(robot, &options.q0)?;
        let duration = trajectory.t.last().copied().unwrap_or(0.0);
        let trocar = options.trocar.unwrap_or(at_q0);
        Ok(RunSetup {
            q0: options.q0,
            trocar,
            duration,
            controller: options.controller,
            source: Source::Trajectory(trajectory, g0, nalgebra::Vector3::from(trocar)),
        })
    }

    /// The reference at time `t` (s), as [`RobotController::step`](crate::RobotController::step)
    /// takes it.
    pub fn reference(&self, t: f64) -> Result<crate::Target> {
        if !t.is_finite() {
            return Err(Error::argument("t", format!("{t}: must be finite")));
        }
        Ok(match &self.source {
            Source::Scenario(s, g0) => {
                let r = s.reference(t, 1e-3, g0, &nalgebra::Vector3::zeros());
                crate::Target {
                    position: r.position.into(),
                    rotation: Some(std::array::from_fn(|i| {
                        std::array::from_fn(|j| r.rotation[(i, j)])
                    })),
                    velocity: r.velocity.into(),
                    angular_velocity: r.angular_velocity.into(),
                }
            }
            // As the run builds it: a roll turned through the trocar (`Trajectory::reference`).
            Source::Trajectory(path, g0, trocar) => path.reference(t, g0, trocar),
            Source::MovingPort(name, g0, _) => {
                // The tip's target moves with the anatomy, as the port does.
                let (d, v) = breathing::true_port_motion(name, t);
                let p = g0.translation + d;
                crate::Target {
                    position: p.into(),
                    rotation: Some(std::array::from_fn(|i| {
                        std::array::from_fn(|j| g0.rotation[(i, j)])
                    })),
                    velocity: v.into(),
                    angular_velocity: [0.0; 3],
                }
            }
        })
    }

    /// The true port at time `t` (s) and its velocity (base frame) where the port moves
    /// (`panda-breathing`, `panda-registration`: there the controller starts from
    /// [`RunSetup::trocar`], 10 mm off); `None` for a port that is where [`RunSetup::trocar`]
    /// says.
    pub fn port(&self, t: f64) -> Option<([f64; 3], [f64; 3])> {
        match &self.source {
            Source::MovingPort(name, _, start) => {
                let (d, v) = breathing::true_port_motion(name, t);
                Some(((nalgebra::Vector3::from(*start) + d).into(), v.into()))
            }
            _ => None,
        }
    }

    /// How the kinematic run follows a moving port from the wall's force: the follower's time
    /// constant (s) and its largest rate (m/s) (`trocar::port::PortFollower`); `None` where
    /// the port does not move.
    pub fn follower(&self) -> Option<(f64, f64)> {
        match &self.source {
            Source::MovingPort(..) => Some((
                breathing::FOLLOWER_TIME_CONSTANT,
                breathing::FOLLOWER_MAX_RATE,
            )),
            _ => None,
        }
    }

    /// The wall's normal where the port moves along it (`panda-breathing`), for a follower of
    /// the port ([`trocar::port::PortFollower::with_normal`]).
    pub fn wall_normal(&self) -> Option<[f64; 3]> {
        match &self.source {
            Source::MovingPort(..) => Some(breathing::wall_normal().into()),
            _ => None,
        }
    }
}

/// The trocar (the constraint frame's origin with the nominal parameters) and the tip's pose
/// at `q0`.
fn start(robot: &Robot, q0: &[f64]) -> Result<([f64; 3], trocar::se3::Se3<f64>)> {
    let model = robot.numeric()?.model();
    let arm =
        trocar_sim::simulation::ArmModel::from_model(model).map_err(|message| Error::Robot {
            file: None,
            message,
        })?;
    let g_ir = model.constraint().map(|c| c.frame()).ok_or_else(|| {
        Error::argument(
            "robot",
            "the robot has no [constraint]: nothing holds a trocar",
        )
    })?;
    let trocar = arm.link_frame(q0).transform_point(&g_ir.translation);
    Ok(([trocar[0], trocar[1], trocar[2]], arm.tip(q0)))
}
