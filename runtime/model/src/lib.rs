//! # trocar-model — robot and mechanism descriptions
//!
//! Serial robots (TOML, URDF) and closed planar mechanisms (TOML) are read into one validated
//! model, and converted to the numeric types of [`trocar`] ([`numeric::NumericModel`]).
#![warn(missing_docs)]

pub mod catalogue;
pub mod closed_chain;
pub mod description;
pub mod expr;
pub mod numeric;
