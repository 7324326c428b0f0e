//! # trocar-model — robot and mechanism descriptions
//!
//! Serial robots (TOML, URDF) and closed planar mechanisms (TOML) are read into one validated
//! model, and converted to the numeric types of [`trocar`]. [`Description::load`] decides which
//! reader a file or a shipped name goes to.
#![warn(missing_docs)]

pub mod closed_chain;
pub mod description;
mod load;
pub mod robot;
pub mod verify;

pub use load::Description;
