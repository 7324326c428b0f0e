//! The backends: one per output, each reading the IR ([`crate::ir`]) and none another's, except
//! that the Rust module holds the controller glue and a mechanism's module is a robot module
//! with wrappers.
//!
//! - [`rust`]: tokens for a robot module (`Params`, `JointTrig`, constants, one function and its
//!   `_trig` variant per output, the fused functions), formatted with prettyplease; the path of
//!   the runtime crate in emitted code ([`Runtime`]).
//! - [`mechanism`]: a closed mechanism's module, the functions that divide by `det J_Cp`
//!   wrapped around the polynomial ones.
//! - [`controller`]: the control step's items in a constrained robot's module
//!   (`StepKinematics`, `step_kinematics`, `Kinematics`, `Controller`), written by [`rust`].
//! - [`c_api`]: the C ABI (`extern "C"` functions) and its header; [`c_controller`], the
//!   stateful controller object within it; [`cpp_header`], the C++ header over them;
//!   [`c_scene`], a scene's C object and its C and C++ headers.
//! - [`checks`]: the module's checks and its evidence.
//! - `doc`: the `#[doc]` attributes of emitted items, written alike by the Rust backend and the
//!   controller glue.
//!
//! # Array order
//! Every matrix is returned **column-major**: a `rows × cols` matrix is `[[T; rows]; cols]`
//! (`a[col][row]`), exactly nalgebra's `ArrayStorage`, so
//! `SMatrix::<T, rows, cols>::from_data(ArrayStorage(a))` is free.

mod c_abi;
pub mod c_api;
pub mod c_controller;
pub mod c_port;
pub mod c_scene;
pub mod checks;
pub mod controller;
pub mod cpp_header;
mod doc;
pub mod mechanism;
pub mod rust;

pub use rust::{
    format_file, module_items, module_items_in, module_tokens, module_tokens_in, wrap_module,
    Runtime, DEFAULT_RUNTIME_PATH,
};
