//! Kinematic simulations of the thesis's scenarios (chapter 4, SPEC §3.2) on the reference arm
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
//! ([`Chain::forward_kinematics`], [`Chain::link_frame`]), independently of the controller's
//! Jacobians.
//!
//! # Measurements (independent of the controller; from forward kinematics only)
//! - `vr = (vr_x, vr_z)`: lateral velocity, in `F_r`, of the material point of link 6 that is at
//!   the trocar at step `k`: `R_0i(q_k)ᵀ (m(q_{k+1}) − m(q_k)) / dt`, `m(q) = p_0i(q) + l_a(k) y_i(q)`.
//! - `rcm_drift`: distance from the trocar point to the axis of link 6.
//! - `ep_norm = ‖dp − p_0e‖`, `eo_norm = ‖ε̃‖` (vector part of `Q_d ⊗ Q⁻¹`).

mod scenario;
mod trace;

pub use scenario::{
    Method, Scenario, ScenarioConfig, SimulationError, A, EXP421_AMPLITUDE, OMEGA, OMEGA_K_421,
    S4_RCM_AMPLITUDE, S4_RCM_AMPLITUDE_THESIS,
};
pub use trace::{Summary, Trace, TraceRow, CSV_HEADER};

use nalgebra::{Const, SVector, Vector3};
use trocar::constraint::Constraint;
use trocar::control::{self, ChainKinematics, Controller, ControllerConfig, Rcm};
use trocar::kinematics::Chain;
use trocar::manipulability::SquareDim;
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
    let chain = robot.to_chain::<8>().map_err(|e| desc(&e))?;
    if config.scenario.constrained_directions() == 1 {
        let kin = ChainKinematics {
            chain,
            constraint: Constraint::<f64, 1>::thesis(6, L_A0).map_err(|e| desc(&e))?,
        };
        run_arm::<1, 5, 7>(config, &kin, progress)
    } else {
        let kin = ChainKinematics {
            chain,
            constraint: Constraint::<f64, 2>::thesis(6, L_A0).map_err(|e| desc(&e))?,
        };
        run_arm::<2, 4, 6>(config, &kin, progress)
    }
}

/// The start configuration of every scenario (SPEC §3.2).
pub const Q0: [f64; 8] = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];

/// `l_a` at `q0` (SPEC §3.2).
pub const L_A0: f64 = 0.15;

/// The position of the point of link 6 at `l_a` along `y_6`: `p_06 + l_a y_6`.
fn link_point(chain: &Chain<f64, 8>, q: &SVector<f64, 8>, l_a: f64) -> Vector3<f64> {
    let g = chain.link_frame(6, q);
    g.translation + g.rotation.column(1) * l_a
}

/// Runs with the numeric runtime (`kin`) driving the controller, and forward kinematics of its
/// chain measuring.
fn run_arm<const R: usize, const K: usize, const M: usize>(
    config: &ScenarioConfig,
    kin: &ChainKinematics<f64, 8, R>,
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
        let q_next = q + out.qd * dt;

        // Measurements from forward kinematics.
        let g_0e = chain.forward_kinematics(&q);
        let g_0i = chain.link_frame(6, &q);
        let y_i = g_0i.rotation.column(1).into_owned();
        let rel = trocar - g_0i.translation;
        let l_a = rel.dot(&y_i);
        let rcm_drift = (rel - y_i * l_a).norm();
        let m_now = g_0i.translation + y_i * l_a;
        let m_next = link_point(chain, &q_next, l_a);
        let vr3 = g_0i.rotation.transpose() * (m_next - m_now) / dt;
        let ep = reference.position - g_0e.translation;
        let eq = control::orientation_error(&reference.rotation, &g_0e.rotation);
        rows.push(TraceRow {
            t,
            ep_norm: ep.norm(),
            eo_norm: eq.eps.norm(),
            vr: [vr3.x, vr3.z],
            rcm_drift,
            w_r: out.w_r,
            w_i: out.w_i,
            l_a,
            q: q.into(),
            qd: out.qd.into(),
            ep: (g_0e.rotation.transpose() * ep).into(),
            eo: eq.eps.into(),
            dv_cmd: [dv_all[0], if R == 2 { dv_all[1] } else { 0.0 }],
            kappa_r: out.kappa_r,
        });

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
        scenario: config.scenario,
        method: config.method,
        drift_correction: config.drift_correction,
        constrained_directions: R,
        dt,
        rows,
    })
}
