//! The README's "Using generated code" snippets, compiled as they are shown: `build.rs`
//! generates the module of `robots/arm.toml` in `f32`, included below, and [`step`] runs the
//! runtime controller on it. `tests/readme.rs` checks that the README shows exactly this code.
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
