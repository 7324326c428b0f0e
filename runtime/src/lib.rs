//! # trocar — kinematics for robots constrained at a point of their chain
//!
//! The numeric runtime of trocar: rigid motions and twists ([`se3`]), serial-chain kinematics
//! ([`kinematics`]), the constrained Jacobian of a remote centre of motion ([`constraint`]),
//! fixed-size dense linear algebra ([`linalg`]), manipulability ([`manipulability`]), finite-difference references ([`finite_diff`]), the
//! constrained kinematic controller ([`control`]), the distance between two instruments' shafts and its
//! rate ([`distance`]), the port located from the shaft's lines ([`port`]), the tip's reference
//! along a path of rows ([`trajectory`]) and the dense QP solver for its hard limits ([`qp`]). Generated code runs on [`emitted`], the one module it may call: the scalar traits
//! [`Real`] (one number) and [`Arith`] (also the lane types of `emitted::lanes`, feature
//! `lanes`), the kernels only it uses (its `sin_cos`, the chain walked as SSE2 pairs, fused
//! multiply-adds chosen at run time) and re-exports of the controller's types it names. The rest
//! of the crate does not depend on that module.
//!
//! Everything a control loop calls is allocation-free, works on `nalgebra` fixed-size types and
//! builds with `#![no_std]` (`default-features = false`; `libm` supplies the math functions).
//! Equation numbers refer to F. de G. Coutinho, *Redundant manipulator control with kinematic
//! constraint for robotic assisted surgery*, MSc thesis, COPPE/UFRJ, 2015.
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub mod constraint;
pub mod control;
pub mod distance;
pub mod emitted;
pub mod finite_diff;
pub mod kinematics;
pub mod linalg;
pub mod manipulability;
pub mod port;
pub mod qp;
pub mod se3;
pub mod trajectory;

/// The scalar traits of generated code ([`emitted::Real`], [`emitted::Arith`]), at the root for
/// code written against generated functions.
pub use emitted::{Arith, Real};

/// Re-export of the linear-algebra crate the runtime's types come from.
pub use nalgebra;
