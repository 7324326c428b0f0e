//! # trocar-sim — simulations, traces and plots
//!
//! The thesis's scenarios on the reference arm ([`simulation`]), the second source's closed-chain
//! simulations ([`closed_chain`]), CSV traces and plots ([`plot`]), and the dynamic-size numeric
//! reference on faer ([`robot::NumericRobot`]) against which generated code is checked
//! ([`verify`]).
#![warn(missing_docs)]

pub mod closed_chain;
pub mod plot;
pub mod robot;
pub mod simulation;
pub mod verify;
