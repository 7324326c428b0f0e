//! The snippets of the README's tour and of `docs/generated-code.md`, compiled as they are
//! shown: `build.rs` generates the module of `robots/arm.toml` in `f32` with its checks
//! and evidence, included below, [`step`] runs the runtime controller on it,
//! [`tip_and_jacobians`] calls a fused function, and the unit tests
//! check the compiled module with `trocar_check`. `tests/readme.rs` checks that those pages show
//! exactly this code.
#![no_std]
#![warn(missing_docs)]

// src/lib.rs: the file is named after the description's `[robot] name` (here "arm")
include!(concat!(env!("OUT_DIR"), "/arm.rs"));

use trocar::control::{ControlError, ControllerConfig, Rcm, Reference, StepOutput};
use trocar::nalgebra::SVector;

/// One control step of a fresh controller with `config` at joints `q` (the README's controller
/// snippet).
pub fn step(
    config: ControllerConfig<f32>,
    q: SVector<f32, { arm::N }>,
    reference: Reference<f32>,
    rcm: Rcm<f32, { arm::R }>,
    dt: f32,
) -> Result<StepOutput<f32, { arm::N }, { arm::R }>, ControlError> {
    let kinematics = arm::Kinematics::nominal(); // one JointTrig per step, no allocation
    let mut controller = trocar::control::Controller::new(config);
    let out = controller.step(&kinematics, &q, &reference, &rcm, dt)?; // joint rates, errors, w
    Ok(out)
}

/// The tip's pose `g_0e`, `J^B_0i` and `J^r_0e` at `q` from one program (the README's fused
/// function snippet).
pub fn tip_and_jacobians(q: &[f32; arm::N], p: &arm::Params) -> [f32; 3] {
    let mut fk = ([[0.0; 3]; 3], [0.0; 3]);
    let (mut jb0i, mut jr) = ([[0.0; 6]; arm::I], [[0.0; 6]; arm::M]);
    arm::tip_and_jacobians(q, p, &mut fk, &mut jb0i, &mut jr); // written in place, no copies
    fk.1
}

#[cfg(test)]
mod tests {
    use super::arm;
    use trocar::nalgebra::{Matrix3, SMatrix, Vector3, Vector6};
    use trocar_check::proptest::prelude::*;

    #[test]
    fn generated_matches_numeric() {
        trocar_check::assert_matches_numeric::<arm::Checks>("robots/arm.toml", 2_000);
    }

    proptest! {
        // Every column of J^r moves the constrained link by Λ# (or only the joints after it):
        // the trocar, the origin of g_ir, has no lateral velocity (H Ad_{g_ir}^-1 Λ# = 0).
        #[test]
        fn the_trocar_has_no_lateral_velocity(
            c in trocar_check::configurations(&trocar_check::description("robots/arm.toml").unwrap())
        ) {
            let p = arm::Params { l_a: c.params[0] as f32, l_b: c.params[1] as f32, l_8: c.params[2] as f32 };
            // ... your property of the generated functions at c.q and p
            // (here one of g_ir, H and Λ#, which depend on p alone)
            let (r, o) = arm::constraint_frame(&p);
            let g_ir = trocar::se3::Se3::new(Matrix3::from_fn(|i, j| r[j][i]), Vector3::from(o));
            let h = SMatrix::<f32, { arm::R }, 6>::from_fn(|i, j| arm::constraint_selection(&p)[j][i]);
            for column in arm::lambda_null_space(&p) {
                let lateral = h * trocar::se3::Adjoint(g_ir).inverse_matrix() * Vector6::from(column);
                prop_assert!(lateral.norm() < 1e-5, "lateral velocity {lateral}");
            }
        }
    }
}
