//! What emitted code runs on: the one module of this crate that code written by
//! `trocar-codegen` (a build script, the attribute `#[constrained_robot]`, `trocar generate`) may call.
//!
//! The generator writes every runtime path as `::trocar::emitted::…` (or `<runtime>::emitted::…`
//! for a crate that reaches `trocar` through a re-export), and names nothing else of this crate
//! in code (its doc comments still point readers at the public API, e.g. `trocar::control`).
//! What is here:
//!
//! - the scalar traits generated functions are generic over, [`Real`] and [`Arith`] (also at the
//!   crate's root, for code written against generated functions), implemented for `f32` and
//!   `f64` with `std` or with `libm` (`#![no_std]`);
//! - the kernels only generated code uses: [`fast`] (the `sin_cos` of [`Real::sin_cos`] and
//!   [`Real::sin_cos_array`]), [`paired_rows`] (the chain walked with the rows of a transform as
//!   SSE2 pairs), [`fma`] (fused multiply-adds chosen at run time), `lanes` (feature `lanes`:
//!   four `f64` or eight `f32` configurations side by side);
//! - re-exports of the items of the rest of the crate that emitted code names: [`nalgebra`], the
//!   controller's types ([`ConstrainedKinematics`], [`ConstrainedState`], [`Controller`] and
//!   its configuration, for the controller glue and the C ABI's step), the port's registration
//!   ([`PortRegistration`], for the C ABI's `register_port`) and [`Se3`].
//!
//! Nothing else in the crate depends on this module: the numeric runtime ([`crate::kinematics`],
//! [`crate::control`]) has its own arithmetic (`nalgebra`'s `RealField`, `std`'s or `libm`'s
//! `sin_cos`), so that it stays an independent reference for the generated code checked
//! against it. The arrows point one way: `emitted` → `control`, `se3`, `nalgebra`.

mod real;

pub mod fast;
pub mod fma;
#[cfg(feature = "lanes")]
pub mod lanes;
pub mod paired_rows;

pub use real::{Arith, Real};

pub use crate::control::scene::{
    camera_point, Between, Camera, Coupling, Scene, SceneError, SceneOutput, SharedJoint,
};
pub use crate::control::{
    ConstrainedKinematics, ConstrainedState, ControlError, Controller, ControllerConfig, Damper,
    Damping, Gains, HardLimits, Method, MethodKind, NullSpaceObjective, Rcm, Reference, Shaft,
    StepOutput, StepStatus,
};
pub use crate::port::{least_spread_admitted, PortError, PortFollower, PortRegistration};
pub use crate::se3::{is_rotation, Se3};
pub use crate::trajectory::{FlatPath, OrientationKind, PathRows};

/// The linear-algebra crate of the controller's types (as [`crate::nalgebra`]).
pub use nalgebra;
