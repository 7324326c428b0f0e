//! # trocar-sim — simulations, traces and plots
//!
//! The thesis's scenarios on the reference arm ([`simulation`]), the second source's closed-chain
//! simulations ([`closed_chain`]), CSV traces and plots ([`plot`]), the dynamic-size numeric
//! robot on faer ([`robot::NumericRobot`]) and the dense linear algebra of dynamic size, on faer
//! ([`linalg`]). Generated code is checked against the numeric runtime
//! by `trocar-check` (`trocar_check::verify`), which needs none of this crate.
#![warn(missing_docs)]

pub mod breathing;
pub mod closed_chain;
pub mod linalg;
pub mod plot;
pub mod robot;
pub mod scene;
pub mod simulation;
