//! # trocar — kinematics for robots constrained at a point of their chain
//!
//! The numeric runtime of trocar: rigid motions and twists ([`se3`]), serial-chain kinematics
//! ([`kinematics`]), the constrained Jacobian of a remote centre of motion ([`constraint`]),
//! fixed-size dense linear algebra ([`linalg`]), manipulability ([`manipulability`]), finite-difference references ([`finite_diff`]), the
//! constrained kinematic controller ([`control`]) and the dense QP solver for its hard limits
//! ([`qp`]). Generated code runs on [`Real`] (one number) or [`Arith`] (also the lane types of
//! `lanes`, feature `lanes`); [`fma`] chooses fused multiply-adds at run time for the `f64` entry
//! points of modules generated with `fma_at_run_time`.
//!
//! Everything a control loop calls is allocation-free, works on `nalgebra` fixed-size types and
//! builds with `#![no_std]` (`default-features = false`; `libm` supplies the math functions).
//! Equation numbers refer to F. de G. Coutinho, *Redundant manipulator control with kinematic
//! constraint for robotic assisted surgery*, MSc thesis, COPPE/UFRJ, 2015.
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub mod constraint;
pub mod control;
pub mod finite_diff;
pub mod fma;
pub mod kinematics;
#[cfg(feature = "lanes")]
pub mod lanes;
pub mod linalg;
pub mod manipulability;
pub mod paired_rows;
pub mod qp;
pub mod real;
pub mod se3;

pub use real::{Arith, Real};

/// Re-export of the linear-algebra crate the runtime's types come from.
pub use nalgebra;
