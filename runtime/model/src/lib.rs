//! # trocar-model — robot and mechanism descriptions
//!
//! Serial robots (TOML, URDF) and closed planar mechanisms (TOML) are read into one validated
//! model, and converted to the numeric types of [`trocar`].
#![warn(missing_docs)]

pub mod closed_chain;
pub mod description;
pub mod expr;
pub mod robot;
pub mod verify;
