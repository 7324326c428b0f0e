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
//! # Use
//!
//! From a build script, in the style of prost-build:
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), trocar_codegen::Error> {
//!     trocar_codegen::Builder::new()
//!         .robot("robots/arm.toml")
//!         .real(trocar_codegen::Real::F64)
//!         .compile()?;
//!     Ok(())
//! }
//! ```
//!
//! and in the crate `include!(concat!(env!("OUT_DIR"), "/arm.rs"));`, which defines `pub mod arm`
//! (the module name is [`module_name`] of the robot's name). Generated code names the runtime
//! crate as `::trocar`; [`Builder::runtime_path`] changes that path.
//!
//! - [`Builder`], [`ModuleOptions`], [`generate_module`], [`generate_module_string`],
//!   [`generate_mechanism_string`]: generation; [`Error`] says why it failed.
//! - [`catalogue`]: every function a generated module holds (name, equation, shape).
//! - [`evaluate`]: the generated functions evaluated in `f64` exactly as emitted (`trocar eval`,
//!   `trocar verify`).
//! - [`attribute`]: the `#[constrained_robot(...)]` attribute of `trocar-derive`.
//! - [`symbolic`] (the exact expression engine), [`derivation`] (the thesis's steps on symbols)
//!   and [`closed_chain`] (the same for closed mechanisms): the derivation itself, for whoever
//!   wants the symbolic results.
//!
//! # The pipeline
//!
//! Each pass reads only the passes above it in this list:
//!
//! 1. [`symbolic`]: exact polynomials over joint sines and cosines and named parameters.
//! 2. [`derivation`] (serial robots, thesis (2.21)–(3.36)) and [`closed_chain`] (closed
//!    mechanisms, Freitas, Leite & Lizarralde 2010, (5)–(8)): the closed forms on symbols.
//! 3. `ir`: the straight-line program with its rewrite rules (CSE, constant folding, Horner
//!    factoring, dead code) and the module specification (`ModuleSpec`: what a generated
//!    module holds, independent of the output language).
//! 4. `lower`: derivation → IR (a robot's or a mechanism's `ModuleSpec`).
//! 5. `emit`: one backend per output, reading the IR: Rust (`emit::rust`, with the controller
//!    glue `emit::controller` and the mechanism wrappers `emit::mechanism`), the C ABI
//!    (`emit::c_api`) and the checks (`emit::checks`); and beside them [`evaluate`], which runs
//!    the IR in `f64` as the emitted code does.
//! 6. [`Builder`] and the generation functions: description → derivation → lowering →
//!    backends → files; [`attribute`] on top of them.
#![warn(missing_docs)]

pub mod attribute;
mod builder;
pub mod closed_chain;
pub mod derivation;
#[doc(hidden)]
pub mod emit;
mod error;
pub mod evaluate;
#[doc(hidden)]
pub mod ir;
#[doc(hidden)]
pub mod lower;
pub mod module;
mod naming;
pub mod scene;
pub mod symbolic;

pub use builder::Builder;
pub use emit::checks::ChecksGate;
pub use error::Error;
pub use ir::Real;
pub use module::{
    generate_c_header, generate_cpp_header, generate_mechanism_string, generate_module,
    generate_module_string, ModuleOptions,
};
pub use naming::module_name;
pub use trocar_model::catalogue;
