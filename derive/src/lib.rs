//! `#[constrained_robot(...)]`: a thin front over [`trocar_codegen`] (one call to
//! `trocar_codegen::attribute::expand`, where the grammar lives).
//!
//! Applied to a unit struct, the attribute reads a robot description, lets the generator derive
//! the closed-form constrained kinematics, and puts the generated module next to the struct with
//! every function re-exposed as an associated function of the struct:
//!
//! ```ignore
//! use trocar_derive::constrained_robot;
//!
//! #[constrained_robot(preset = "bidirectional-zy")]
//! pub struct Arm;
//!
//! let p = ArmParams::<f64>::nominal();          // = arm::Params<f64>
//! let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
//! let jr: [[f64; 6]; 6] = Arm::constrained_jacobian(&q, &p); // column-major
//! let w = Arm::manipulability(&q, &p);
//! ```
//!
//! # Forms
//!
//! Exactly one description source:
//!
//! - `preset = "bidirectional-zy"`: a description shipped with trocar
//!   (`trocar_model::description::PRESETS`).
//! - `file = "robots/arm.toml"`: a TOML description, relative to the calling crate's
//!   `CARGO_MANIFEST_DIR`. The expansion contains `include_bytes!` of the file, so editing it
//!   rebuilds the crate.
//! - `toml = r#"..."#`: the TOML description written inline.
//! - the structured inline form:
//!
//! ```ignore
//! #[constrained_robot(
//!     name = "small_arm",                                   // optional, default: the struct's
//!     params(l_a = 0.15, l_b = 0.18, l_8 = 0.21),
//!     joints(
//!         torso: revolute(z),
//!         shoulder: revolute(x, xyz = (0.194, 0, 1.037)),
//!         elbow: revolute(x, xyz = (0, 0.38, 0)),
//!         roll: revolute(y),
//!         pitch: revolute(x, xyz = (0, 0.39, 0)),
//!         wrist: revolute(y),
//!         shaft_7: revolute(z, xyz = (0, l_a + l_b, 0)),
//!         shaft_8: revolute(y),                          // also: prismatic(..), twist(v = .., w = ..)
//!     ),
//!     end_effector(name = "tool", xyz = (0, l_8, 0)),   // optional, also `rpy = (r, p, y)`
//!     constraint(link = 6, xyz = (0, l_a, 0), h = (x, z), wrist = zy),
//! )]
//! struct SmallArm;
//! ```
//!
//! Joint arguments: the axis as a letter (`x`, `y`, `z`) or `axis = -z` / `axis = (0, 0, 1)`,
//! `xyz = (..)` (numbers, parameter names or linear combinations such as `l_a + l_b`),
//! `rpy = (..)`; twist joints take `v = (..)` and `w = (..)`. `h` takes axis letters
//! (`x, y, z, rx, ry, rz`) or rows of six numbers; `wrist` is `unidirectional`, `zy` or `zx`.
//!
//! Options for every form: `real = "f32" | "f64" | "generic"` (default generic over
//! `T: trocar::Real`), `module = "name"` (default: the struct name in snake case),
//! `fma_at_run_time` (each fused function also as `<name>_f64` and `<name>_trig_f64`, `f64`
//! entry points with fused multiply-adds chosen at run time where `trocar` has its `std` feature:
//! see `trocar::emitted::fma`; generic modules only; needs Rust 1.89 or later).
//!
//! # What it generates
//!
//! For `struct Arm;`: the module `arm` (the generator's output: `N`, `Params`, `JointTrig`,
//! `constrained_jacobian`, `manipulability`, ... each with its `_trig` variant), type aliases
//! `ArmParams` and `ArmJointTrig`, and `impl Arm` with the module's constants and a delegating
//! associated function per generated function. The generated code names `::trocar::emitted`
//! (what generated code may call), so the calling crate depends on `trocar` (with or without its
//! `std` feature). The associated functions
//! take the module's types and sizes as the module's functions do (`&[T; N]`, `&Params<T>`), so
//! the struct cannot be named like one of them (`struct Params;`, `struct JointTrig;` are errors).
//!
//! # Errors
//!
//! Every problem is a `compile_error!` at the offending token: unknown keys, unknown presets
//! (listing the valid ones), unreadable files (with the resolved path), and invalid descriptions
//! (the description's own field, and line for files); several are reported at once.
#![warn(missing_docs)]

use proc_macro::TokenStream;

/// Generates the constrained kinematics of a robot as associated functions of a unit struct.
/// See the [crate documentation](crate) for the syntax.
#[proc_macro_attribute]
pub fn constrained_robot(attr: TokenStream, item: TokenStream) -> TokenStream {
    trocar_codegen::attribute::expand(attr.into(), item.into()).into()
}
