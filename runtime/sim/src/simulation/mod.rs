//! Kinematic simulations of the thesis's scenarios (chapter 4; `docs/reference-robots.md`) on the reference arm
//! `dia10_like`, with the controller of [`trocar::control`].
//!
//! # Model
//! - Joints are integrated with **explicit Euler** at the sample time (2 ms):
//!   `q_{k+1} = q_k + dt θ̇_k`. The velocity-level constraint then holds only to first order in
//!   `dt`, and the link drifts from the trocar: this is the thesis's behaviour, which the drift
//!   correction (`K_r`, [`ScenarioConfig::drift_correction`]) removes.
//! - The trocar is a point fixed in space (scenarios 1–3), or moved by the commanded RCM velocity
//!   (scenario 4, experiment 4.2.1): `p_t ← p_t + dt R_0r(q_k) Hᵀ dv_0r(t_k)` (linear part).
//!   With the unidirectional constraint (scenario 1, `H = x_r`) the trocar is a slot: `z_r` is
//!   free, and the tracked trocar point slides with the link along `z_r` (after each step its
//!   `z_r` offset from the link axis is set to zero).
//! - `l_a = (p_t − p_0i) · y_i` is recomputed every step.
//!
//! The controller is driven by the numeric runtime ([`ChainKinematics`]: [`trocar::kinematics`],
//! [`trocar::constraint`]); the measurements are taken from forward kinematics of the same chain
//! ([`trocar::kinematics::Chain::forward_kinematics`], [`trocar::kinematics::Chain::link_frame`]), independently of the controller's
//! Jacobians.
//!
//! # Measurements (independent of the controller; from forward kinematics only)
//! - `vr = (vr_x, vr_z)`: lateral velocity, in `F_r`, of the shaft at the trocar over step `k`:
//!   how far the shaft's line moved across the place of its point at the trocar,
//!   `R_0r(q_k)ᵀ P(q_{k+1}) (m(q_{k+1}) − m(q_k)) / dt`, `m(q) = p of g_0i(q) g_ir(l_a(k))` and
//!   `P(q)` the projection normal to the shaft at `q` ([`trocar::control::Shaft::moved_across`]),
//!   along the axes of `F_r` normal to the shaft (`x_r`, `z_r` on the reference arm; `x_r`,
//!   `y_r` on the Panda). Without `P` the point's slide along a turning shaft (`v ω dt`) would
//!   count as lateral motion though the line keeps to the trocar.
//! - `rcm_drift`: distance from the trocar point to the axis of link 6.
//! - `ep_norm = ‖dp − p_0e‖`, `eo_norm = ‖ε̃‖` (vector part of `Q_d ⊗ Q⁻¹`).

mod arm;
mod scenario;
mod trace;

pub use arm::{ArmModel, StepRecord};
pub use scenario::{
    panda_limits_reference, PANDA_DEPTH_LIMITS, PANDA_LIMITS_DURATION, PANDA_LIMITS_ROLL,
    PANDA_LIMITS_WITHDRAWAL,
};
pub use scenario::{
    panda_reference, Method, Scenario, ScenarioConfig, SimulationError, A, EXP421_AMPLITUDE,
    MAX_JOINT_SPEED, OMEGA, OMEGA_K_421, PANDA_CIRCLE_RADIUS, PANDA_DURATION, PANDA_Q0, PANDA_RAMP,
    PANDA_ROLL_AMPLITUDE, PANDA_TIP_DEPTH, S4_RCM_AMPLITUDE, S4_RCM_AMPLITUDE_THESIS,
};
pub use trace::{CsvRows, Summary, Trace, TraceRow, CSV_HEADER};

use nalgebra::{Const, SVector, Vector3};
use trocar::constraint::Constraint;
use trocar::control::Reference;
use trocar::control::{
    ChainKinematics, Controller, ControllerConfig, HardLimits, NullSpaceObjective, Rcm, Shaft,
};
use trocar::linalg::SquareDim;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

/// Number of joints of `dia10_like`.
pub const JOINTS: usize = 8;

/// Runs a scenario; `progress` is called with the fraction done (0 to 1) about every 1 %.
pub fn run(config: &ScenarioConfig, progress: impl FnMut(f64)) -> Result<Trace, SimulationError> {
    let d = RobotDescription::preset(config.scenario.robot())
        .map_err(|e| SimulationError::Description(e.to_string()))?;
    let desc = |e: &dyn std::fmt::Display| SimulationError::Description(e.to_string());
    let robot = NumericModel::<f64>::from_description(&d, &[]).map_err(|e| desc(&e))?;
    let arm = ArmModel::from_model(&robot).map_err(|e| desc(&e))?;
    if config.scenario.is_panda() {
        return run_panda(config, &robot, arm, progress);
    }
    let chain = robot.to_chain::<8>().map_err(|e| desc(&e))?;
    if config.scenario.constrained_directions() == 1 {
        let kin = ChainKinematics::thesis(
            chain,
            Constraint::<f64, 1>::thesis(6, L_A0).map_err(|e| desc(&e))?,
        );
        run_arm::<1, 5, 7>(config, &kin, arm, progress)
    } else {
        let kin = ChainKinematics::thesis(
            chain,
            Constraint::<f64, 2>::thesis(6, L_A0).map_err(|e| desc(&e))?,
        );
        run_arm::<2, 4, 6>(config, &kin, arm, progress)
    }
}

/// The start configuration of every scenario (`docs/reference-robots.md`).
pub const Q0: [f64; 8] = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];

/// `l_a` at `q0` (`docs/reference-robots.md`).
pub const L_A0: f64 = 0.15;

/// Names of the axes of `F_r`.
const AXIS_NAMES: [&str; 3] = ["x_r", "y_r", "z_r"];

/// The two axes of `F_r` normal to the shaft, in order (`[0, 2]` for a shaft along `y_r`): the
/// lateral velocity columns of a trace (`vr_x`, `vr_z` on the reference arm).
pub fn lateral_axes(shaft: &Shaft<f64>) -> [usize; 2] {
    let along = (shaft.rotation.transpose() * shaft.direction).abs().imax();
    match along {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

/// The row of a scenario's step ([`ArmModel::measure`]); `controller` is `(w_r, w_i, κ_r)`.
#[allow(clippy::too_many_arguments)]
fn measured<const N: usize>(
    arm: &ArmModel,
    t: f64,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    dt: f64,
    trocar: &Vector3<f64>,
    reference: &Reference<f64>,
    controller: (f64, f64, f64),
    dv_cmd: [f64; 2],
) -> TraceRow {
    arm.measure(&StepRecord {
        t,
        q: q.as_slice(),
        qd: qd.as_slice(),
        dt,
        trocar,
        position: &reference.position,
        rotation: Some(&reference.rotation),
        w_r: controller.0,
        w_i: controller.1,
        kappa_r: controller.2,
        dv_cmd,
    })
}

/// Runs with the numeric runtime (`kin`) driving the controller, and forward kinematics of its
/// chain measuring.
fn run_arm<const R: usize, const K: usize, const M: usize>(
    config: &ScenarioConfig,
    kin: &ChainKinematics<f64, 8, R>,
    arm: ArmModel,
    mut progress: impl FnMut(f64),
) -> Result<Trace, SimulationError>
where
    Const<R>: SquareDim,
    Const<M>: SquareDim,
{
    let dt = config.dt;
    let steps = (config.duration / dt).round() as usize;
    let chain = &kin.chain;
    let mut q = SVector::<f64, 8>::from(Q0);
    let g_0e0 = chain.forward_kinematics(&q);
    let g_0i0 = chain.link_frame(6, &q);
    let axis7 = chain.link_frame(7, &q).rotation.column(2).into_owned();
    let mut trocar = g_0i0.translation + g_0i0.rotation.column(1) * L_A0;
    let ctrl_config: ControllerConfig<f64> = config.controller_config();
    let mut ctrl = Controller::<f64, 8, 6, R, K, M>::new(ctrl_config);
    let mut rows = Vec::with_capacity(steps + 1);
    let report_every = (steps / 100).max(1);
    for k in 0..=steps {
        let t = k as f64 * dt;
        let reference = config.scenario.reference(t, dt, &g_0e0, &axis7);
        let dv_all = config.rcm_velocity(t);
        let mut dv = SVector::<f64, R>::zeros();
        for (r, v) in dv.iter_mut().enumerate() {
            *v = dv_all[r];
        }
        let rcm = Rcm { trocar, dv };
        let out = ctrl
            .step(kin, &q, &reference, &rcm, dt)
            .map_err(|e| SimulationError::Control { t, error: e })?;
        if !out.status.held() {
            return Err(SimulationError::Yielded {
                t,
                status: out.status,
            });
        }
        let q_next = q + out.qd * dt;

        // Measurements from forward kinematics.
        let g_0i = chain.link_frame(6, &q);
        rows.push(measured(
            &arm,
            t,
            &q,
            &out.qd,
            dt,
            &trocar,
            &reference,
            (out.w_r, out.w_i, out.kappa_r),
            [dv_all[0], if R == 2 { dv_all[1] } else { 0.0 }],
        ));

        // Trocar motion: commanded lateral velocity in F_r(q_k); a slot along z_r when R = 1.
        let lateral = Vector3::new(dv_all[0], 0.0, if R == 2 { dv_all[1] } else { 0.0 });
        trocar += g_0i.rotation * lateral * dt;
        q = q_next;
        if R == 1 {
            let g = chain.link_frame(6, &q);
            let z_r = g.rotation.column(2).into_owned();
            let off = trocar - g.translation;
            trocar -= z_r * off.dot(&z_r);
        }
        if k % report_every == 0 {
            progress(k as f64 / steps as f64);
        }
    }
    progress(1.0);
    Ok(Trace {
        scenario: Some(config.scenario),
        title: config.scenario.title().to_string(),
        arm,
        method: config.method,
        drift_correction: config.drift_correction,
        constrained_directions: R,
        dt,
        joints: 8,
        lateral_axes: ["x_r", "z_r"],
        joint_limits: None,
        speed_limits: None,
        depth_limits: None,
        rows,
    })
}

/// The Panda laparoscope ([`Scenario::Panda`]): the numeric runtime of `panda-laparoscope`
/// (7 joints, constraint on the last link, `H = (x_r, y_r)`, task `x y z rz`) drives the
/// controller; the spare freedom of the arm keeps the joints from their URDF limits.
fn run_panda(
    config: &ScenarioConfig,
    robot: &NumericModel<f64>,
    arm: ArmModel,
    mut progress: impl FnMut(f64),
) -> Result<Trace, SimulationError> {
    let desc = |e: &dyn std::fmt::Display| SimulationError::Description(e.to_string());
    let kin = robot.to_kinematics::<7, 2, 4>().map_err(|e| desc(&e))?;
    let limits: Vec<[f64; 2]> = robot
        .description()
        .joints
        .iter()
        .map(|j| j.limits.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]))
        .collect();
    let objective = NullSpaceObjective::JointLimits {
        gain: config.null_space_gain,
        lower: SVector::from_fn(|k, _| limits[k][0]),
        upper: SVector::from_fn(|k, _| limits[k][1]),
    };
    let dt = config.dt;
    let steps = (config.duration / dt).round() as usize;
    let chain = &kin.chain;
    let mut q = SVector::<f64, 7>::from(PANDA_Q0);
    let g_0e0 = chain.forward_kinematics(&q);
    let l_a0 = robot
        .parameters()
        .iter()
        .find(|(n, _)| n == "l_a")
        .map_or(0.0, |p| p.1);
    let trocar = kin
        .shaft
        .constraint_pose(&chain.link_frame(7, &q), l_a0)
        .translation;
    let axes = lateral_axes(&kin.shaft);
    let speeds: Vec<f64> = robot
        .description()
        .joints
        .iter()
        .map(|j| j.speed_limit.unwrap_or(f64::INFINITY))
        .collect();
    // The URDF's acceleration and jerk limits (libfranka's): the rates ramp up from rest and
    // brake in time for the ranges.
    let joints = &robot.description().joints;
    let accelerations =
        SVector::<f64, 7>::from_fn(|k, _| joints[k].acceleration_limit.unwrap_or(f64::INFINITY));
    let jerks = SVector::<f64, 7>::from_fn(|k, _| joints[k].jerk_limit.unwrap_or(f64::INFINITY));
    let mut hard = HardLimits::none()
        .with_joint_limits(
            SVector::from_fn(|k, _| limits[k][0]),
            SVector::from_fn(|k, _| limits[k][1]),
        )
        .with_speed_limits(SVector::from_fn(|k, _| speeds[k]))
        .with_acceleration_limits(accelerations)
        .with_jerk_limits(jerks);
    if config.scenario == Scenario::PandaLimits {
        hard = hard.with_depth(PANDA_DEPTH_LIMITS[0], PANDA_DEPTH_LIMITS[1]);
    }
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(config.controller_config())
        .with_objective(objective)
        .with_limits(hard);
    // The instrument's length bounds `l_a`: the trocar between the link (0) and the tip.
    let l_tip = kin
        .shaft
        .offset(&chain.link_frame(7, &q), &g_0e0.translation);
    let mut rows = Vec::with_capacity(steps + 1);
    let report_every = (steps / 100).max(1);
    let none = Vector3::zeros();
    for k in 0..=steps {
        let t = k as f64 * dt;
        let reference = config.scenario.reference(t, dt, &g_0e0, &none);
        let rcm = Rcm {
            trocar,
            dv: SVector::<f64, 2>::zeros(),
        };
        let out = ctrl
            .step(&kin, &q, &reference, &rcm, dt)
            .map_err(|e| SimulationError::Control { t, error: e })?;
        let outside = !(out.l_a > 0.0 && out.l_a < l_tip);
        if !out.status.held() || outside {
            return Err(SimulationError::Yielded {
                t,
                status: if outside {
                    trocar::control::StepStatus::DepthOutside
                } else {
                    out.status
                },
            });
        }
        let q_next = q + out.qd * dt;
        rows.push(measured(
            &arm,
            t,
            &q,
            &out.qd,
            dt,
            &trocar,
            &reference,
            (out.w_r, out.w_i, out.kappa_r),
            [0.0, 0.0],
        ));
        q = q_next;
        if k % report_every == 0 {
            progress(k as f64 / steps as f64);
        }
    }
    progress(1.0);
    Ok(Trace {
        scenario: Some(config.scenario),
        title: config.scenario.title().to_string(),
        arm,
        method: config.method,
        drift_correction: config.drift_correction,
        constrained_directions: 2,
        dt,
        joints: 7,
        lateral_axes: [AXIS_NAMES[axes[0]], AXIS_NAMES[axes[1]]],
        joint_limits: Some(limits),
        speed_limits: speeds.iter().all(|v| v.is_finite()).then(|| speeds.clone()),
        depth_limits: (config.scenario == Scenario::PandaLimits).then_some(PANDA_DEPTH_LIMITS),
        rows,
    })
}
