//! Serial chains: forward kinematics, spatial and body Jacobians (2.53)–(2.55), the partial body
//! Jacobian `J^B_0i` (3.13) and the split `J^B_0e = [J^B_0e1 | J^B_0e2]` (3.12).

use crate::se3::{Se3, Twist};
use nalgebra::RealField;

/// One joint of a serial chain, URDF-style: link frame `k` is joint `k`'s frame.
///
/// The transform from the parent frame `F_{k-1}` to `F_k` is `origin · exp(ξ̂ θ_k)`, where `ξ`
/// is the joint's constant twist in its own frame `F_k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint<T: RealField + Copy> {
    /// Fixed transform from the parent frame to this joint's frame at `θ = 0`.
    pub origin: Se3<T>,
    /// Joint twist `ξ^k_k = (v, ω)` in the joint's own frame.
    pub twist: Twist<T>,
}
