//! # trocar-codegen — closed-form constrained Jacobians as allocation-free Rust
//!
//! From a [`trocar_model::description::RobotDescription`], the generator derives symbolically the
//! constrained Jacobian `J^r_0e` (thesis (3.15), (3.24), (3.28), (3.29)), its manipulability and
//! what a controller needs around them, and emits fixed-size, `#![no_std]` Rust.
//!
//! Closed planar mechanisms ([`trocar_model::closed_chain`], second source: four-bar linkage, planar
//! Gough–Stewart platform) get the closed-form reduced Jacobian `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8)
//! and passive velocities (7), as polynomial numerators over `det J_Cp`
//! ([`closed_chain`], [`Builder::mechanism`]).
//!
//! Modules, one per concept: [`symbolic`] (the exact expression engine), [`derivation`] (the
//! thesis's steps on symbols), [`closed_chain`] (the same for closed mechanisms), [`emit`]
//! (optimisation and Rust tokens), [`builder`] (the `build.rs` API) and [`cli`] (the `trocar`
//! command line).
#![warn(missing_docs)]

pub mod builder;
pub mod closed_chain;
pub mod derivation;
pub mod emit;
pub mod evaluate;
pub mod symbolic;

pub use builder::{generate_module, generate_module_string, Builder, Error, ModuleOptions};
pub use emit::Real;
