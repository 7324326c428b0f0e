//! # trocar-model — robot and mechanism descriptions
//!
//! Serial robots (TOML, URDF) and closed planar mechanisms (TOML) are read into one validated
//! model, and converted to the numeric types of [`trocar`] ([`numeric::NumericModel`]), whose
//! numeric reference of the catalogue ([`reference`](mod@reference)) `trocar-check` and `trocar-sim` share.
//! [`Description::load`] decides which reader a file or a shipped name goes to.
#![warn(missing_docs)]

pub mod catalogue;
pub mod closed_chain;
pub mod description;
pub mod expr;
mod load;
pub mod numeric;
pub mod reference;
pub mod scene;
pub mod singularity;
pub mod validity;

pub use load::Description;
