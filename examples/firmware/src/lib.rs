//! # trocar-firmware — an RCM control step for a surgical arm, as firmware would run it
//!
//! The kinematics of `dia10_like_zy` (the reference arm, bidirectional constraint, zy wrist) are
//! generated in `build.rs` with `trocar_codegen::Builder` (f32, closed form) and
//! included below. [`control_step`] is one iteration of the thesis's constrained controller
//! (3.17)–(3.18) with damped least squares (3.43)–(3.44):
//!
//! 1. `l_a = (p_trocar − p_0i) · y_i` from the trocar point fixed in space;
//! 2. `J^r_0e(q)` (generated, 6 × 6) → `[v0i; θ̇_7, θ̇_8] = J^rᵀ (J^r J^rᵀ + κ² I)⁻¹ u`, with the
//!    variable damping `κ = α0 (1 − w/w0)²` below the manipulability threshold `w0`;
//! 3. `V^B_0i = Λ# v0i` (basis (3.27)) → `θ̇_1..6 = J^B_0iᵀ (J^B_0i J^B_0iᵀ + κ_b² I)⁻¹ V^B_0i`.
//!
//! **No allocation, no `alloc`:** the crate is `#![no_std]` and never declares
//! `extern crate alloc`; its only dependency, `trocar`, is built with `default-features = false`
//! (no `std`, no `alloc`; `libm` for the math). CI links it as a freestanding `staticlib`
//! without a global allocator (feature `image`), which rustc refuses if any crate in the graph
//! uses `alloc`; `tests/no_alloc.rs` counts allocations during control steps.
#![no_std]
#![warn(missing_docs)]

include!(concat!(env!("OUT_DIR"), "/dia10.rs"));

use trocar::linalg::damped_solve;
use trocar::nalgebra::{SMatrix, SVector};

/// Number of joints.
pub const N: usize = dia10::N;
/// Columns of `J^r_0e`: `6 − r + n − i`.
pub const M: usize = dia10::M;
/// The constrained link `i`.
pub const I: usize = dia10::I;

/// Length of the constrained link 6 (`l_a + l_b`), m.
pub const LINK_6: f32 = 0.33;

/// Tuning of the control step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tuning {
    /// Manipulability threshold `w0` of the variable damping (3.44).
    pub w0: f32,
    /// Maximum damping `α0` of (3.44) (applied on `J^r` when `w = 0`).
    pub alpha0: f32,
    /// Constant damping `κ_b` on `J^B_0i`.
    pub kappa_b: f32,
}

impl Default for Tuning {
    fn default() -> Self {
        Tuning {
            w0: 0.05,
            alpha0: 0.05,
            kappa_b: 0.01,
        }
    }
}

/// What one step computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Joint velocities `θ̇`, base first, rad/s.
    pub qdot: [f32; N],
    /// `l_a` at this step (trocar distance along link 6), m.
    pub l_a: f32,
    /// Manipulability `w` of `J^r` (3.42).
    pub manipulability: f32,
    /// Damping `κ` used on `J^r`.
    pub kappa: f32,
}

/// Why a step was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepError {
    /// The trocar is not on the constrained link (`l_a` outside `(0, 0.33)` m).
    TrocarOffLink,
    /// `J Jᵀ + κ² I` is not positive definite (singular with no damping) or not finite.
    Singular,
}

/// Variable damping (3.44): `κ = 0` if `w ≥ w0`, else `α0 (1 − w/w0)²`.
pub fn damping(w: f32, w0: f32, alpha0: f32) -> f32 {
    if w >= w0 {
        0.0
    } else {
        let r = 1.0 - w / w0;
        alpha0 * r * r
    }
}

/// Damped least squares `x = Jᵀ (J Jᵀ + κ² I)⁻¹ b` (3.43) for a 6 × C matrix given column-major
/// (`j[col][row]`, as generated): the core's [`trocar::linalg::damped_solve`] (root-free Cholesky
/// of the 6 × 6 Gram matrix). `None` if `J Jᵀ + κ² I` is not positive definite to working
/// precision or `x` is not finite. Allocation-free.
pub fn dls<const C: usize>(j: &[[f32; 6]; C], b: &[f32; 6], kappa: f32) -> Option<[f32; C]> {
    let j = SMatrix::<f32, 6, C>::from_fn(|r, c| j[c][r]);
    let x = damped_solve(&j, kappa, &SVector::<f32, 6>::from(*b))?;
    Some(x.into())
}

/// `l_a = (p_trocar − p_0i) · y_i` (trocar fixed in space, `docs/reference-robots.md`).
pub fn trocar_distance(t: &dia10::JointTrig, trocar: &[f32; 3]) -> f32 {
    let (r, p) = dia10::forward_kinematics_i_trig(t, &dia10::Params { l_a: 0.0 });
    let y = r[1];
    (0..3).map(|k| (trocar[k] - p[k]) * y[k]).sum()
}

/// One control step: joint velocities that realise the body twist `u = (v, ω)` of the end
/// effector while link 6 keeps passing through the trocar point `trocar` (base frame, m).
pub fn control_step(
    q: &[f32; N],
    trocar: &[f32; 3],
    u: &[f32; 6],
    tuning: &Tuning,
) -> Result<Step, StepError> {
    let t = dia10::JointTrig::new(q);
    let l_a = trocar_distance(&t, trocar);
    let on_link = l_a > 0.0 && l_a < LINK_6;
    if !on_link {
        return Err(StepError::TrocarOffLink);
    }
    let p = dia10::Params { l_a };
    let jr = dia10::constrained_jacobian_trig(&t, &p);
    let w = dia10::manipulability_trig(&t, &p);
    let kappa = damping(w, tuning.w0, tuning.alpha0);
    let x = dls(&jr, u, kappa).ok_or(StepError::Singular)?;
    // (3.27): V^B_0i = Λ# v0i = (v_x, v_y, v_z, −v_z/l_a, ω_y, v_x/l_a).
    let v0i = [x[0], x[1], x[2], x[3]];
    let twist_i = [v0i[0], v0i[1], v0i[2], -v0i[2] / l_a, v0i[3], v0i[0] / l_a];
    let jb = dia10::partial_body_jacobian_trig(&t, &p);
    let before = dls(&jb, &twist_i, tuning.kappa_b).ok_or(StepError::Singular)?;
    let mut qdot = [0.0f32; N];
    qdot[..I].copy_from_slice(&before);
    qdot[I..].copy_from_slice(&x[M - (N - I)..]);
    Ok(Step {
        qdot,
        l_a,
        manipulability: w,
        kappa,
    })
}

/// A fixed sequence of control steps, run the same way on the host and on a Cortex-M4F under
/// QEMU (`examples/firmware/run-qemu.sh`), so that the two runs can be compared step by step:
/// from [`sequence::Q0`] with the trocar at `l_a` = [`sequence::L_A0`] on link 6, the tip
/// commanded with the constant body twist [`sequence::TWIST`] for [`sequence::STEPS`] steps of
/// [`sequence::DT`].
pub mod sequence {
    use super::{control_step, dia10, Step, StepError, Tuning, N};

    /// The start configuration (rad).
    pub const Q0: [f32; N] = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    /// The trocar's offset along link 6 at the start (m).
    pub const L_A0: f32 = 0.15;
    /// The end effector's body twist `(v, ω)` commanded at every step (m/s, rad/s).
    pub const TWIST: [f32; 6] = [0.01, -0.02, 0.005, 0.0, 0.02, -0.01];
    /// The sample time (s).
    pub const DT: f32 = 0.002;
    /// The number of steps (1 s).
    pub const STEPS: usize = 500;

    /// The trocar point: link 6's point at [`L_A0`] with the arm at [`Q0`] (base frame, m).
    pub fn trocar() -> [f32; 3] {
        let t = dia10::JointTrig::new(&Q0);
        let (r, p) = dia10::forward_kinematics_i_trig(&t, &dia10::Params { l_a: 0.0 });
        [0, 1, 2].map(|k| p[k] + L_A0 * r[1][k])
    }

    /// One step: [`control_step`] at `q` with [`TWIST`], then `q += DT θ̇` in `f32` (where the
    /// step is refused, `q` stays).
    pub fn step(q: &mut [f32; N], trocar: &[f32; 3], tuning: &Tuning) -> Result<Step, StepError> {
        let s = control_step(q, trocar, &TWIST, tuning)?;
        for (qk, v) in q.iter_mut().zip(&s.qdot) {
            *qk += DT * v;
        }
        Ok(s)
    }
}

/// Freestanding builds (`--features image --crate-type staticlib`): nothing to unwind to.
#[cfg(feature = "image")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
