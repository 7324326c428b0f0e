//! # trocar-sim — simulations, traces and plots
//!
//! The thesis's scenarios on the reference arm ([`simulation`]), the second source's closed-chain
//! simulations ([`closed_chain`]), CSV traces and plots ([`plot`]).
#![warn(missing_docs)]

pub mod closed_chain;
pub mod plot;
pub mod simulation;
