//! Optimisation (CSE, constant folding, Horner factoring, dead-code removal) and emission of
//! Rust tokens.
//!
//! - [`program`]: the straight-line program representation and its rewrite rules, each stated
//!   once and tested; operation counts; an interpreter.
//! - [`rust`]: tokens for a robot module (`Params`, `JointTrig`, constants, one function and its
//!   `_trig` variant per output), formatted with prettyplease.
//!
//! # Array order
//! Every matrix is returned **column-major**: a `rows × cols` matrix is `[[T; rows]; cols]`
//! (`a[col][row]`), exactly nalgebra's `ArrayStorage`, so
//! `SMatrix::<T, rows, cols>::from_data(ArrayStorage(a))` is free.

pub mod bridge;
pub mod c_api;
pub mod checks;
pub mod controller;
pub mod program;
pub mod rust;

pub use program::{Const, Factor, Op, OpCounts, Program, Term, ValueId};
pub use rust::{
    format_file, module_items, module_items_in, module_tokens, module_tokens_in, wrap_module,
    ConstItem, EmittedFunction, FusedFunction, FusedOutput, Layout, ModuleSpec, Runtime, Scalar,
    DEFAULT_RUNTIME_PATH,
};
