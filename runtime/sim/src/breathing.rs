//! `panda-breathing`: the Panda laparoscope's port moves with the patient's tissue (thesis
//! §5.2) — it rises and falls with breathing, 8 mm at 0.25 Hz along the wall's normal (the
//! instrument enters 45° from it), and the patient shifts 2 cm across between 8 and 12 s — while
//! the tip's target moves with the anatomy. The body wall at the port is a spring-damper across
//! the shaft ([`trocar::port::Wall`], 4000 N/m and 40 N s/m), and the controller (the QP step
//! with the Panda's URDF limits, 1 kHz) holds the shaft at a port that is:
//!
//! - [`PortMode::Fixed`]: where it was at the start, as if it did not move;
//! - [`PortMode::Known`]: the true port, its trajectory fed forward ((3.33)–(3.34));
//! - [`PortMode::Estimated`]: followed from the wall's force on the shaft
//!   ([`trocar::port::PortFollower`], closing with 30 ms, the wall's normal known), its rate fed
//!   forward;
//! - [`PortMode::Registered`] (`panda-registration` only): found without a force from the
//!   shaft's motion — the instrument pivots about the port for [`PIVOT_DURATION`] while the arm
//!   yields to the wall (hand-guided, or compliant under a short pivot motion), every step's
//!   shaft line from the measured joints (with encoder noise) goes into a
//!   [`trocar::port::PortRegistration`], and the controller then holds the point nearest the
//!   lines.
//!
//! `panda-registration` keeps the port still but starts the controller from a nominal port
//! 10 mm across the shaft from the true one (a port registered that far off): `fixed` pushes
//! the tissue by that much, `estimated` finds the port from the wall's force, `registered` from
//! the shaft's lines during a pivot.
//!
//! The trace has the joints and their rates, the true port (`port_x..z`) and its displacement
//! from the start (`port_dx..dz`), the port the controller holds — its estimate (`estimate_x..z`,
//! the true port with `known`, the start with `fixed`; with `registered`, during the pivot, the
//! registration's estimate so far) — and its distance from the true port
//! (`estimate_error`), the wall's force (`port_force`, N), the shaft's distance from the true
//! port (`port_offset`) and from the port held (`rcm_drift`), the tip's error (`ep_norm`), and
//! whether the step held the port's rows (`port_held`, 0 where they gave way to the joints'
//! limits: a port asked to jump, as a misregistered one is, cannot be reached in one step from
//! rest).

use crate::closed_chain::{MechanismTrace, Panel};
use crate::scene::{controller, panda, SceneRunError};
use nalgebra::{SVector, Vector3};
use trocar::control::{ConstrainedKinematics, Rcm, Reference, StepStatus};
use trocar::port::{PortFollower, PortRegistration, Wall};
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

/// The breathing scenario's name.
pub const NAME: &str = "panda-breathing";
/// The registration scenario's name: the port still, but 10 mm across the shaft from where the
/// controller believes it at the start.
pub const REGISTRATION: &str = "panda-registration";
/// How far the registration scenario's port is from its nominal place, across the shaft (m).
pub const REGISTRATION_OFFSET: f64 = 0.01;
/// The registration scenario's duration (s).
pub const REGISTRATION_DURATION: f64 = 3.0;

/// The names of the moving-port scenarios.
pub fn scenario_names() -> &'static [&'static str] {
    &[NAME, REGISTRATION]
}

/// Whether `name` is one of the moving-port scenarios.
pub fn is_moving_port(name: &str) -> bool {
    scenario_names().contains(&name)
}
/// The sample time (s): 1 kHz.
pub const DT: f64 = 0.001;
/// The duration (s): four breaths, the shift, and two breaths after it.
pub const DURATION: f64 = 16.0;
/// Breathing: the port's travel along the wall's normal, peak to peak (m).
pub const BREATH: f64 = 0.008;
/// Breathing frequency (Hz).
pub const BREATH_FREQUENCY: f64 = 0.25;
/// The patient's shift across (m), along the base's `y`, between [`SHIFT_START`] and
/// [`SHIFT_END`] (a smooth step).
pub const SHIFT: f64 = 0.02;
/// When the shift starts (s).
pub const SHIFT_START: f64 = 8.0;
/// When the shift ends (s).
pub const SHIFT_END: f64 = 12.0;
/// The follower's compliance as a time constant (s): `C = 1/(k τ)` for the wall's stiffness `k`;
/// with the wall's damping `c` it closes on the port with `τ + c/k` (30 ms for the default wall).
pub const FOLLOWER_TIME_CONSTANT: f64 = 0.02;
/// The largest rate of the port's estimate (m/s).
pub const FOLLOWER_MAX_RATE: f64 = 0.05;
/// [`PortMode::Registered`]: how long the instrument pivots about the port at the start (s).
pub const PIVOT_DURATION: f64 = 2.0;
/// [`PortMode::Registered`]: the pivot's largest angle from the shaft's start (rad): the tip
/// draws a loop of radius `depth · tan(angle)` about its start.
pub const PIVOT_ANGLE: f64 = 0.174_532_925_199_432_95; // 10°
/// [`PortMode::Registered`]: the standard deviation of the encoder noise on the joints the
/// registration reads (rad; uniform).
pub const JOINT_NOISE: f64 = 1e-4;
/// [`PortMode::Registered`]: the least spread of the shaft's lines accepted (rad, 2°).
pub const REGISTRATION_LEAST_SPREAD: f64 = 0.034_906_585_039_886_59;

/// How the controller knows the port.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortMode {
    /// Where it was at the start: the thesis's fixed trocar.
    Fixed,
    /// The true port's trajectory, fed forward.
    Known,
    /// Followed from the wall's force on the shaft.
    Estimated,
    /// Registered from the shaft's lines while the instrument pivots about the port at the
    /// start, no force measured (`panda-registration`).
    Registered,
}

impl PortMode {
    /// All modes, in the order compared.
    pub const ALL: [PortMode; 4] = [
        PortMode::Fixed,
        PortMode::Known,
        PortMode::Estimated,
        PortMode::Registered,
    ];

    /// The mode's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PortMode::Fixed => "fixed",
            PortMode::Known => "known",
            PortMode::Estimated => "estimated",
            PortMode::Registered => "registered",
        }
    }

    /// The mode of a name ([`PortMode::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// The wall's normal: 45° from the shaft at the start (which points down, `−z`), in the `x z`
/// plane.
pub fn wall_normal() -> Vector3<f64> {
    Vector3::new(1.0, 0.0, 1.0).normalize()
}

/// The port's displacement from its start at `t` (s) and its velocity: breathing along the
/// wall's normal, `B (1 − cos 2π f t)/2`, and the shift along `y`, a quintic step.
pub fn port_motion(t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let w = 2.0 * std::f64::consts::PI * BREATH_FREQUENCY;
    let n = wall_normal();
    let breath = n * (BREATH * (1.0 - (w * t).cos()) / 2.0);
    let breath_rate = n * (BREATH * w * (w * t).sin() / 2.0);
    let s = ((t - SHIFT_START) / (SHIFT_END - SHIFT_START)).clamp(0.0, 1.0);
    let step = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let step_rate = if s > 0.0 && s < 1.0 {
        30.0 * s * s * (1.0 - s) * (1.0 - s) / (SHIFT_END - SHIFT_START)
    } else {
        0.0
    };
    let y = Vector3::y();
    (
        breath + y * (SHIFT * step),
        breath_rate + y * (SHIFT * step_rate),
    )
}

/// The true port's displacement from its start at `t` (s) and its velocity in the moving-port
/// scenario `name` ([`port_motion`] in `panda-breathing`; still in `panda-registration`).
pub fn true_port_motion(name: &str, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    if name == NAME {
        port_motion(t)
    } else {
        (Vector3::zeros(), Vector3::zeros())
    }
}

/// Where the controller starts holding the port in the moving-port scenario `name`, from the
/// true port at the start: there, or [`REGISTRATION_OFFSET`] across the shaft (the base's `y`)
/// in `panda-registration`.
pub fn nominal_offset(name: &str) -> Vector3<f64> {
    if name == REGISTRATION {
        Vector3::y() * REGISTRATION_OFFSET
    } else {
        Vector3::zeros()
    }
}

/// The tip's pivot of [`PortMode::Registered`] at `t` (s): its offset from the start and its
/// velocity, a loop `R sin(πσ) (cos 2πσ u + sin 2πσ v)` with `σ` a quintic step from 0 to 1
/// over [`PIVOT_DURATION`], `u`, `v` across the shaft and `R` the tip's depth below the port
/// times `tan` [`PIVOT_ANGLE`]: it starts and ends at rest at the start.
pub fn pivot_motion(
    t: f64,
    radius: f64,
    u: &Vector3<f64>,
    v: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    use std::f64::consts::PI;
    let s = (t / PIVOT_DURATION).clamp(0.0, 1.0);
    let sigma = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    let sigma_rate = if s > 0.0 && s < 1.0 {
        30.0 * s * s * (1.0 - s) * (1.0 - s) / PIVOT_DURATION
    } else {
        0.0
    };
    let (a, b) = (PI * sigma, 2.0 * PI * sigma);
    let around = u * b.cos() + v * b.sin();
    let around_rate = (v * b.cos() - u * b.sin()) * (2.0 * PI);
    let offset = around * (radius * a.sin());
    let rate = (around * (PI * a.cos()) + around_rate * a.sin()) * (radius * sigma_rate);
    (offset, rate)
}

/// Encoder noise: the joints read with a deterministic uniform error of standard deviation
/// [`JOINT_NOISE`] (xorshift, the same on every run).
struct Encoders(u64);

impl Encoders {
    fn read(&mut self, q: &SVector<f64, 7>) -> SVector<f64, 7> {
        q.map(|v| {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            let unit = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
            v + (2.0 * unit - 1.0) * JOINT_NOISE * 3f64.sqrt()
        })
    }
}

/// The duration (s) of the moving-port scenario `name`.
pub fn duration_of(name: &str) -> f64 {
    if name == REGISTRATION {
        REGISTRATION_DURATION
    } else {
        DURATION
    }
}

/// Runs `name` (`panda-breathing` or `panda-registration`) with the port known as `mode`;
/// `progress` gets the fraction done. In `panda-registration` the port does not move, but it is
/// [`REGISTRATION_OFFSET`] across the shaft (along the base's `y`) from the nominal port the
/// controller starts from: `fixed` holds the nominal port, `known` the true one, `estimated`
/// starts from the nominal one and finds the true one from the wall's force.
pub fn simulate(
    name: &str,
    mode: PortMode,
    progress: impl FnMut(f64),
) -> Result<MechanismTrace, SceneRunError> {
    simulate_with(name, mode, None, progress)
}

/// A moving-port run's known port: its displacement from the port at the start (base frame,
/// m) and its velocity (m/s) at time `t` (s), from measured data.
pub type KnownPort<'a> = &'a dyn Fn(f64) -> (Vector3<f64>, Vector3<f64>);

/// [`simulate`], with [`PortMode::Known`] feeding forward `known` — the port's trajectory as it
/// was measured — instead of the scenario's own motion (`None`: the scenario's).
pub fn simulate_with(
    name: &str,
    mode: PortMode,
    known: Option<KnownPort<'_>>,
    mut progress: impl FnMut(f64),
) -> Result<MechanismTrace, SceneRunError> {
    let registration = match name {
        NAME => false,
        REGISTRATION => true,
        other => {
            return Err(SceneRunError(format!(
                "unknown moving-port scenario `{other}` (expected one of: {})",
                scenario_names().join(", ")
            )))
        }
    };
    if mode == PortMode::Registered && !registration {
        return Err(SceneRunError(format!(
            "--port registered finds a still port from a pivot at the start ({REGISTRATION}); \
             {name}'s port moves: follow it from the wall's force (--port estimated)"
        )));
    }
    let motion = |t: f64| true_port_motion(name, t);
    let duration = duration_of(name);
    let (kin, limits) = panda()?;
    let mut ctrl = controller(limits);
    let wall = Wall::<f64>::abdominal();
    let mut q = SVector::<f64, 7>::from(crate::simulation::PANDA_Q0);
    let g_0e0 = kin.chain.forward_kinematics(&q);
    // The Panda laparoscope's sizes: 7 joints, the constraint on link 7, 2 constrained
    // directions, the task `x y z rz`.
    type Panda = crate::scene::Kin;
    let shaft = <Panda as ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>::shaft(&kin);
    let h = <Panda as ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>::h(&kin);
    let g_0i = |q: &SVector<f64, 7>| {
        <Panda as ConstrainedKinematics<f64, 7, 7, 2, 4, 4, 4>>::g_0i(&kin, q)
    };
    let line_of = |g_0i: &Se3<f64>| {
        shaft
            .line(g_0i)
            .ok_or_else(|| SceneRunError("the shaft has no direction".into()))
    };
    // The port at the start: the constraint frame at the nominal insertion.
    let l_a = RobotDescription::preset("panda-laparoscope")
        .ok()
        .and_then(|d| NumericModel::<f64>::from_description(&d, &[]).ok())
        .and_then(|m| m.parameters().iter().find(|(n, _)| n == "l_a").map(|p| p.1))
        .ok_or_else(|| SceneRunError("the Panda laparoscope has no parameter l_a".into()))?;
    // The true port at the start: where the shaft crosses the wall at the nominal insertion.
    // The nominal port the controller starts from: the same, or 10 mm across for the
    // registration run.
    let port0 = shaft.constraint_pose(&g_0i(&q), l_a).translation;
    let nominal = port0 + nominal_offset(name);
    let mut follower = PortFollower::new(
        nominal,
        1.0 / (wall.stiffness * FOLLOWER_TIME_CONSTANT),
        FOLLOWER_MAX_RATE,
    )
    .and_then(|f| f.with_normal(wall_normal()))
    .map_err(|e| SceneRunError(e.to_string()))?;
    // `registered`: the lines of the shaft during the pivot, from the joints as the encoders
    // read them; the pivot's plane across the shaft at the start.
    let mut lines = PortRegistration::<f64>::new();
    let mut encoders = Encoders(0x9E37_79B9_7F4A_7C15);
    let mut registered: Option<Vector3<f64>> = None;
    let shaft_direction = line_of(&g_0i(&q))?.direction;
    let across = shaft_direction.cross(&Vector3::x());
    let pivot_u = if across.norm() > 0.1 {
        across.normalize()
    } else {
        shaft_direction.cross(&Vector3::y()).normalize()
    };
    let pivot_v = shaft_direction.cross(&pivot_u);
    let pivot_radius = (g_0e0.translation - port0).norm() * PIVOT_ANGLE.tan();
    let mut columns: Vec<String> = vec!["t".into()];
    columns.extend((1..=7).map(|k| format!("q{k}")));
    columns.extend((1..=7).map(|k| format!("qd{k}")));
    for c in [
        "port_x",
        "port_y",
        "port_z",
        "estimate_x",
        "estimate_y",
        "estimate_z",
        "port_dx",
        "port_dy",
        "port_dz",
        "estimate_error",
        "port_force",
        "port_offset",
        "rcm_drift",
        "ep_norm",
        "port_held",
    ] {
        columns.push(c.into());
    }
    let steps = (duration / DT).round() as usize;
    let mut rows = Vec::with_capacity(steps + 1);
    let mut last_offset: Option<Vector3<f64>> = None;
    let report_every = (steps / 100).max(1);
    for step in 0..=steps {
        let t = step as f64 * DT;
        let (displacement, port_rate) = motion(t);
        let port = port0 + displacement;
        // The wall's force on the shaft, from the shaft's offset from the true port and its rate.
        let g_0i_q = g_0i(&q);
        let line = line_of(&g_0i_q)?;
        let offset = line.offset_from(&port);
        let offset_rate = last_offset.map_or_else(Vector3::zeros, |e| (offset - e) / DT);
        last_offset = Some(offset);
        let force = wall.force(&offset, &offset_rate);
        // Where the controller holds the shaft, and how fast that place moves.
        let (trocar, trocar_rate) = match mode {
            PortMode::Fixed => (nominal, Vector3::zeros()),
            PortMode::Known => match known {
                Some(data) => {
                    let (d, v) = data(t);
                    (port0 + d, v)
                }
                None => (port, port_rate),
            },
            PortMode::Estimated => {
                let rate = follower
                    .update(&force, &line.direction, DT)
                    .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
                (follower.estimate, rate)
            }
            // While the instrument pivots, the arm yields to the wall: the shaft turns about
            // the true port (the plant, not the controller's knowledge); the registration sees
            // only the joints. Then the controller holds the point nearest the lines.
            PortMode::Registered => match registered {
                Some(found) => (found, Vector3::zeros()),
                None if t < PIVOT_DURATION => {
                    lines
                        .add(&line_of(&g_0i(&encoders.read(&q)))?)
                        .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
                    (port, Vector3::zeros())
                }
                None => {
                    let found = lines
                        .estimate(REGISTRATION_LEAST_SPREAD)
                        .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?
                        .point;
                    registered = Some(found);
                    (found, Vector3::zeros())
                }
            },
        };
        // What the controller believes the port to be (the trace's estimate): the point held,
        // or during the pivot the registration's estimate so far (the nominal port before it
        // has one).
        let believed = match mode {
            PortMode::Registered if registered.is_none() => lines
                .estimate(REGISTRATION_LEAST_SPREAD)
                .map_or(nominal, |e| e.point),
            _ => trocar,
        };
        let (pivot, pivot_rate) = if mode == PortMode::Registered && registered.is_none() {
            pivot_motion(t, pivot_radius, &pivot_u, &pivot_v)
        } else {
            (Vector3::zeros(), Vector3::zeros())
        };
        let dv = shaft.trocar_rate(&g_0i_q, &h, &trocar_rate);
        let reference = Reference {
            position: g_0e0.translation + displacement + pivot,
            rotation: g_0e0.rotation,
            velocity: port_rate + pivot_rate,
            angular_velocity: Vector3::zeros(),
        };
        let tip = kin.chain.forward_kinematics(&q).translation;
        let mut held = true;
        let mut row = vec![t];
        row.extend(q.iter().copied());
        let qd = if step < steps {
            let out = ctrl
                .step(&kin, &q, &reference, &Rcm { trocar, dv }, DT)
                .map_err(|e| SceneRunError(format!("t = {t:.3} s: {e}")))?;
            held = out.status != StepStatus::TrocarYielded;
            out.qd
        } else {
            SVector::zeros()
        };
        row.extend(qd.iter().copied());
        row.extend(port.iter().copied());
        row.extend(believed.iter().copied());
        row.extend(displacement.iter().copied());
        row.push((believed - port).norm());
        row.push(force.norm());
        row.push(offset.norm());
        row.push(line.offset_from(&trocar).norm());
        row.push((reference.position - tip).norm());
        row.push(if held { 1.0 } else { 0.0 });
        if row.iter().any(|v| !v.is_finite()) {
            return Err(SceneRunError(format!("t = {t:.3} s: a non-finite value")));
        }
        rows.push(row);
        q += qd * DT;
        if step % report_every == 0 {
            progress(step as f64 / steps as f64);
        }
    }
    progress(1.0);
    let panel = |title: &str, y: &str, lines: &[(&str, &str)], non_negative: bool| Panel {
        title: title.into(),
        x_label: "t (s)".into(),
        y_label: y.into(),
        lines: lines
            .iter()
            .map(|(c, l)| ("t".to_string(), c.to_string(), l.to_string()))
            .collect(),
        non_negative,
    };
    Ok(MechanismTrace {
        name: format!("{name} ({})", mode.name()),
        columns,
        rows,
        panels: vec![
            if registration {
                panel(
                    "Finding the port: the port held, from the true one (10 mm at the start)",
                    "m",
                    &[("estimate_error", "the port's estimate from the true port")],
                    false,
                )
            } else {
                panel(
                    "The port's motion from its start: breathing along the wall's normal, the shift across",
                    "m",
                    &[("port_dx", "x (under z)"), ("port_dy", "y"), ("port_dz", "z")],
                    false,
                )
            },
            panel(
                "The wall's force on the shaft",
                "N",
                &[("port_force", "|F|")],
                true,
            ),
            panel(
                "Distances: the shaft, the true port and the port held",
                "m",
                &[
                    ("port_offset", "shaft from the true port"),
                    ("rcm_drift", "shaft from the held port"),
                    ("estimate_error", "held port from the true port"),
                ],
                true,
            ),
        ],
    })
}
