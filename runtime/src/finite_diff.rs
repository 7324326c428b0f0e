//! Finite-difference references: body Jacobians by central differences of forward kinematics through
//! the SE(3) logarithm.
//!
//! Column `k` of the body Jacobian is the body velocity per unit `θ̇_k` (2.41)–(2.42); with
//! `g = g_0e(θ)`:
//! `ξ†_k ≈ (log(g⁻¹ g(θ + h e_k)) − log(g⁻¹ g(θ − h e_k)))^∨ / 2h`, an `O(h²)` approximation
//! independent of the kinematics code it checks (only `exp`, composition and `log` are shared).

use crate::kinematics::{forward_kinematics, Chain, Joint};
use crate::se3::{log, Se3, Twist};
use nalgebra::{convert, RealField, SMatrix, SVector};

/// A good step for central differences of `T`: `ε^{1/3}` (about `6e-6` for `f64`, `5e-3` for `f32`).
pub fn default_step<T: RealField + Copy>() -> T {
    T::default_epsilon().powf(convert(1.0 / 3.0))
}

/// The finite-difference body Jacobian of `joints` + `tool` at `q`, step `h`, into `columns`.
/// `q` is perturbed in place and restored (bit for bit) before returning.
///
/// # Panics
/// If `q.len()` or `columns.len()` differ from `joints.len()`.
pub fn body_jacobian_columns<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &mut [T],
    tool: &Se3<T>,
    h: T,
    columns: &mut [Twist<T>],
) {
    assert_eq!(joints.len(), columns.len(), "one column per joint");
    let g = forward_kinematics(joints, q, tool);
    let two: T = convert(2.0);
    for k in 0..joints.len() {
        let q0 = q[k];
        q[k] = q0 + h;
        let plus = log(&g.inverse_compose(&forward_kinematics(joints, q, tool)));
        q[k] = q0 - h;
        let minus = log(&g.inverse_compose(&forward_kinematics(joints, q, tool)));
        q[k] = q0;
        columns[k] = (plus - minus) / (two * h);
    }
}

/// The finite-difference body Jacobian of a chain, step `h` (see the module documentation).
pub fn body_jacobian<T: RealField + Copy, const N: usize>(
    chain: &Chain<T, N>,
    q: &SVector<T, N>,
    h: T,
) -> SMatrix<T, 6, N> {
    let mut qq = *q;
    let mut cols = [Twist::zeros(); N];
    body_jacobian_columns(&chain.joints, qq.as_mut_slice(), &chain.tool, h, &mut cols);
    crate::kinematics::matrix_from_columns(&cols)
}

/// The finite-difference spatial Jacobian of a chain: `(g(θ + h e_k) g⁻¹)` through the log, column
/// `k ≈ (log(g(θ + h e_k) g⁻¹) − log(g(θ − h e_k) g⁻¹))^∨ / 2h` (2.53).
pub fn spatial_jacobian<T: RealField + Copy, const N: usize>(
    chain: &Chain<T, N>,
    q: &SVector<T, N>,
    h: T,
) -> SMatrix<T, 6, N> {
    let mut qq = *q;
    let g_inv = chain.forward_kinematics(q).inverse();
    let two: T = convert(2.0);
    let mut m = SMatrix::<T, 6, N>::zeros();
    for k in 0..N {
        let q0 = qq[k];
        qq[k] = q0 + h;
        let plus = log(&chain.forward_kinematics(&qq).compose(&g_inv));
        qq[k] = q0 - h;
        let minus = log(&chain.forward_kinematics(&qq).compose(&g_inv));
        qq[k] = q0;
        m.set_column(k, &((plus - minus) / (two * h)));
    }
    m
}
