//! Closed planar mechanisms (Freitas, Leite & Lizarralde, *Controle de sistemas robóticos com
//! restrições cinemáticas*, CBA 2010): the description read once into a symbolic
//! [`MechanismModel`].
//!
//! A mechanism is a list of open planar chains that all reach one common frame (the end effector
//! `E_e`, the platform `E_s` or the held object `E_c`); the structural equations (2), (9)–(10),
//! (23)–(24), (32)–(33) say every chain reaches the same pose. Lengths stay expressions of named
//! parameters (an [`Expr`](crate::expr::Expr) of the one length-expression parser,
//! [`crate::expr`], whose symbols are looked up by name), so the generator
//! derives closed forms with the parameters as symbols, and the numeric simulation (trocar-sim)
//! evaluates them at any parameter values.
//!
//! - [`MechanismModel::from_toml_file`], [`MechanismModel::from_toml_str`],
//!   [`MechanismModel::shipped`]: the TOML reader (see the format below); shipped files in
//!   `runtime/model/robots/mechanisms/`.
//! - [`MechanismModel::validate`], [`MechanismModel::check_values`]: the admission rules.
//!
//! ```
//! use trocar_model::closed_chain::MechanismModel;
//! let m = MechanismModel::shipped("four-bar").unwrap();
//! assert_eq!(m.joint_names(), ["theta1", "theta3", "theta2", "theta4"]);
//! assert_eq!(m.parameter_names(), ["l0", "l1", "l2", "l3", "l4"]);
//! ```
//!
//! # Format
#![doc = include_str!("format.md")]

mod model;
mod read;

pub use model::{
    contact_joint, eval, joint_limits, number, ChainModel, ContactJoint, ContactSpec, JointModel,
    Lookup, MechanismModel, MechanismParameter, Output, PlanarJointKind, PoseExpr,
};
pub use read::{shipped_text, COOPERATIVE_TOML, FOUR_BAR_TOML, SHIPPED, STEWART_TOML};

pub(crate) use read::parse_table;
