//! Rigid motions SE(3), twists, hat/vee, the exponential of twists and the Adjoint (thesis chapter 2).
//!
//! Conventions (SPEC §2): twists are `ξ = (v, ω)` with the **linear part first**;
//! `Ad_g = [[R, p̂R], [0, R]]` (2.43).

use nalgebra::{Matrix3, RealField, Vector3, Vector6};

/// A twist `ξ = (v, ω)`, linear part first.
pub type Twist<T> = Vector6<T>;

/// A rigid transform `g = (R, p)`: rotation `R ∈ SO(3)` and translation `p ∈ R³` (2.21).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3<T: RealField + Copy> {
    /// Rotation part `R`.
    pub rotation: Matrix3<T>,
    /// Translation part `p`.
    pub translation: Vector3<T>,
}
