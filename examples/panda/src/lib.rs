//! # trocar-panda — a Franka Panda holding a laparoscope through a trocar
//!
//! `build.rs` generates the kinematics of the shipped description `panda-laparoscope` (Franka's
//! URDF chain `panda_link0` → `panda_link8`, a 0.40 m straight laparoscope along the flange's
//! `z`, the trocar at `l_a` along the shaft, `H = (x_r, y_r)`, task `x y z rz`) in `f32`, and
//! includes them below as the module [`panda`]. Its `Kinematics` implements the runtime's
//! `ConstrainedKinematics`, so [`trocar::control::Controller`] runs on the generated closed
//! forms with no hand-written kinematics:
//!
//! 1. one `JointTrig` per step: `g_0i`, the trocar offset `l_a` (the point of the shaft nearest
//!    to the trocar), then `g_0e`, `J^B_0i` (6 × 7), `J^r_0e = Ad_{g_ei} Λ#` (constant: the
//!    constraint is on the last link), `J_c`, `Λ#`, `Λ†` at that `l_a`;
//! 2. `[v0i] = (S J^r)⁻¹ S (u − J_c dv_0r)` for the commanded tip position and roll (S selects
//!    `x y z rz` of the tip's body twist), with the drift correction on the trocar;
//! 3. `θ̇ = u0 + J^B_0i^† (Λ# v0i + Λ† dv_0r − J^B_0i u0)`: the arm's one spare freedom follows the
//!    joint-limit objective (44)–(46) of Freitas, Leite & Lizarralde (2010), from the URDF limits
//!    ([`panda::JOINT_LIMITS`]).
//!
//! [`qp_controller`] is the same controller with the control step as a quadratic program
//! ([`trocar::control::Method::Qp`], (Q1)–(Q7) of `trocar::control::hard_limits`): the trocar
//! as equality rows, the URDF's joint ranges ([`panda::JOINT_LIMITS`]), speeds
//! ([`SPEED_LIMITS`]), accelerations ([`ACCELERATION_LIMITS`]), jerks ([`JERK_LIMITS`]) and the insertion bounds ([`DEPTH_LIMITS`]) as hard inequalities, solved
//! in `f32` by the runtime's fixed-size QP solver.
//!
//! **No allocation, no `alloc`:** the crate is `#![no_std]`; `trocar` is built with
//! `default-features = false`. CI links it as a freestanding `staticlib` without a global
//! allocator (feature `image`); `tests/no_alloc.rs` counts allocations during steps.
#![no_std]
#![warn(missing_docs)]

include!(concat!(env!("OUT_DIR"), "/panda.rs"));

pub mod sequence;

use trocar::control::{
    ControlError, ControllerConfig, Damping, HardLimits, Method, NullSpaceObjective, QpWeights,
    Rcm, Reference, StepOutput,
};
use trocar::nalgebra::{SVector, Vector3};

/// The runtime controller sized for the Panda laparoscope (the generated module's
/// `Controller`: 7 joints, constraint on link 7, 2 constrained directions, 4 columns of `Λ#` and
/// of `J^r`, 4 task rows).
pub type PandaController = panda::Controller;

/// The start configuration `(0, −π/4, 0, −3π/4, 0, π/2, π/4)` (rad).
pub const Q0: [f32; panda::N] = [
    0.0,
    -core::f32::consts::FRAC_PI_4,
    0.0,
    -3.0 * core::f32::consts::FRAC_PI_4,
    0.0,
    core::f32::consts::FRAC_PI_2,
    core::f32::consts::FRAC_PI_4,
];

/// The controller with the gains of the `panda-laparoscope` scenario: `K_p = 5`, `K_o = 10`,
/// variable damping (3.44) with `α0 = 0.05` below `w0 = 1e-3` on `S J^r` (constant, the squared
/// trocar–tip distance) and `w0 = 0.01` on `J^B_0i`, drift correction `K_r = 20 /s`, and the
/// joint-limit objective with gain 10 /s on the spare freedom.
pub fn controller() -> PandaController {
    let limits = panda::JOINT_LIMITS;
    PandaController::new(ControllerConfig {
        kp: 5.0,
        ko: 10.0,
        method: Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 1e-3,
        }),
        jb0i_damping: Some(Damping::Variable {
            alpha0: 0.05,
            w0: 0.01,
        }),
        kr: 20.0,
        max_joint_speed: None,
    })
    .with_objective(NullSpaceObjective::JointLimits {
        gain: 10.0,
        lower: SVector::from_fn(|k, _| limits[k][0] as f32),
        upper: SVector::from_fn(|k, _| limits[k][1] as f32),
    })
}

/// The Panda's joint speed limits (rad/s): the `velocity` of the `<limit>` of each joint in
/// Franka's URDF (`runtime/model/robots/urdf/panda.urdf`).
pub const SPEED_LIMITS: [f32; panda::N] = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];

/// The Panda's joint acceleration limits (rad/s²): libfranka's, the `acceleration` of the URDF
/// 1.2 `<limit>` of each joint in `runtime/model/robots/urdf/panda.urdf`.
pub const ACCELERATION_LIMITS: [f32; panda::N] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];

/// The Panda's joint jerk limits (rad/s³): libfranka's, the `jerk` of the same `<limit>`s.
pub const JERK_LIMITS: [f32; panda::N] = [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0];

/// The insertion bounds `[l_min, l_max]` of the trocar's offset `l_a` along the shaft (m): the
/// tip between 0.10 m and 0.35 m below the trocar (those of the scenario
/// `panda-laparoscope-limits`).
pub const DEPTH_LIMITS: [f32; 2] = [0.05, 0.30];

/// [`controller`] with the QP step: `κ = 0.01`, `γ = κ²`, the second-order trocar rows (Q7),
/// the URDF's joint ranges, speeds, accelerations and jerks and [`DEPTH_LIMITS`] as hard limits (with the default
/// dampers of [`HardLimits::none`]).
pub fn qp_controller() -> PandaController {
    let limits = panda::JOINT_LIMITS;
    let lower = SVector::from_fn(|k, _| limits[k][0] as f32);
    let upper = SVector::from_fn(|k, _| limits[k][1] as f32);
    let mut ctrl = controller();
    ctrl.config.method = Method::Qp(QpWeights::with_kappa(0.01));
    ctrl.with_limits(
        HardLimits::none()
            .with_joint_limits(lower, upper)
            .with_speed_limits(SVector::from(SPEED_LIMITS))
            .with_acceleration_limits(SVector::from(ACCELERATION_LIMITS))
            .with_jerk_limits(SVector::from(JERK_LIMITS))
            .with_depth(DEPTH_LIMITS[0], DEPTH_LIMITS[1]),
    )
}

/// One control step at joints `q` toward `reference`, with the trocar fixed at `trocar` (base
/// frame, m) and sample time `dt` (s): joint velocities and what the step measured.
/// Allocation-free.
pub fn control_step(
    ctrl: &mut PandaController,
    q: &[f32; panda::N],
    reference: &Reference<f32>,
    trocar: &[f32; 3],
    dt: f32,
) -> Result<StepOutput<f32, { panda::N }, { panda::R }>, ControlError> {
    let rcm = Rcm {
        trocar: Vector3::from(*trocar),
        dv: SVector::zeros(),
    };
    ctrl.step(
        &panda::Kinematics::nominal(),
        &SVector::from(*q),
        reference,
        &rcm,
        dt,
    )
}

/// Freestanding builds (`--features image --crate-type staticlib`): nothing to unwind to.
#[cfg(feature = "image")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
