//! The intermediate representation every later pass reads, independent of any output language.
//!
//! - [`program`]: the straight-line program (a hash-consed, value-numbered DAG) and its rewrite
//!   rules, each stated once and tested; operation counts; which products are fused.
//! - [`spec`]: what a generated module holds ([`ModuleSpec`]): sizes, parameters, one
//!   [`EmittedFunction`] (program and [`Layout`]) per catalogue output, fused functions and the
//!   control step's data.
//!
//! # Array order
//! Every matrix is laid out **column-major**: a `rows × cols` matrix's program outputs entry
//! `(r, c)` at `c · rows + r`, returned as `[[T; rows]; cols]` (`a[col][row]`), exactly
//! nalgebra's `ArrayStorage`, so `SMatrix::<T, rows, cols>::from_data(ArrayStorage(a))` is free.

pub mod program;
pub mod spec;

pub use program::{Const, Factor, Op, OpCounts, Program, Term, ValueId};
pub use spec::{
    ConstItem, ControllerSpec, EmittedFunction, FusedFunction, FusedOutput, Layout, ModuleSpec,
    Real,
};
