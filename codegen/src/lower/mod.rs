//! Lowering: from a derivation (symbolic polynomials) to the IR, a [`ModuleSpec`](crate::ir::ModuleSpec)
//! of straight-line programs that every backend reads and the evaluator runs.
//!
//! - [`poly`]: canonical polynomials, matrices and rigid transforms as program values
//!   ([`PolyBuilder`]: one shared `1/P` per `Inv` atom, one value per `Node`).
//! - [`chain`]: the serial chain in product form, `g_0e = T_1 ⋯ T_n g_ne` (2.21) and the
//!   body-Jacobian columns `Ad⁻¹_{g_ke} ξ_k` (2.45) walked from its end.
//! - [`form`]: of two forms of the same values, the one with fewer live operations.
//! - [`manipulability`]: `w` and `w²` (3.36), from a closed form or from the values of `J^r`.
//! - [`fused`]: several catalogue outputs as one program.
//! - [`controller`]: the data of the control step ([`ControllerSpec`](crate::ir::ControllerSpec)).
//! - [`robot`]: a serial robot's module ([`module_spec`], [`module_spec_with`]).
//! - [`mechanism`]: a closed mechanism's module (Freitas, Leite & Lizarralde 2010, (7)–(8)).

pub mod chain;
pub mod controller;
pub mod form;
pub mod fused;
pub mod manipulability;
pub mod mechanism;
pub mod poly;
pub mod robot;

pub use chain::paired_heads;
pub use controller::shaft_parameter;
pub use manipulability::{manipulability_by_gram_schmidt, manipulability_from_jr};
pub use poly::{matrix_program, transform_program, NumTransform, PolyBuilder};
pub use robot::{module_spec, module_spec_with};
