//! Serial chains: forward kinematics, spatial and body Jacobians (2.53)–(2.55), the partial body
//! Jacobian `J^B_0i` (3.13) and the split `J^B_0e = [J^B_0e1 | J^B_0e2]` (3.12).
//!
//! Two layers:
//! - **slice kernels** ([`forward_kinematics`], [`body_jacobian_columns`],
//!   [`spatial_jacobian_columns`], ...) over `&[Joint<T>]` and `&[T]`, writing Jacobian columns
//!   into `&mut [Twist<T>]`; they serve both the typed API and the dynamic front end
//!   (`trocar_sim::robot::NumericRobot`, for sizes known at run time);
//! - the typed, const-generic [`Chain<T, N>`] returning `SMatrix<T, 6, N>`.
//!
//! Nothing here allocates. Joint `k` is 1-based in the thesis and 0-based in slices.

use crate::se3::{Adjoint, Se3, Twist};
use nalgebra::{convert, Matrix3, RealField, SMatrix, SVector, Vector3};

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

impl<T: RealField + Copy> Joint<T> {
    /// A revolute joint about the unit `axis` through the joint frame's origin: `ξ = (0, axis)`.
    pub fn revolute(origin: Se3<T>, axis: Vector3<T>) -> Self {
        Self {
            origin,
            twist: crate::se3::twist(&Vector3::zeros(), &axis),
        }
    }

    /// A prismatic joint along the unit `axis`: `ξ = (axis, 0)`.
    pub fn prismatic(origin: Se3<T>, axis: Vector3<T>) -> Self {
        Self {
            origin,
            twist: crate::se3::prismatic_twist(&axis),
        }
    }

    /// A joint with an arbitrary twist `ξ = (v, ω)` in its own frame.
    pub fn from_twist(origin: Se3<T>, twist: Twist<T>) -> Self {
        Self { origin, twist }
    }

    /// The transform from the parent frame to this joint's frame: `origin · exp(ξ̂ θ)`.
    ///
    /// A revolute joint about a unit axis through its frame's origin (`ξ = (0, ω)`, `‖ω‖ = 1`,
    /// every URDF revolute joint) takes Rodrigues' formula (2.7) with `sin θ`, `cos θ` directly:
    /// `R_o exp(ω̂ θ) = R_o + sin θ R_o ω̂ + (1 − cos θ) R_o ω̂²`, `ω̂² = ω ωᵀ − I`, and keeps the
    /// origin's translation; other joints the exponential (2.25), (2.27).
    #[inline]
    pub fn transform(&self, theta: T) -> Se3<T> {
        let v = crate::se3::linear(&self.twist);
        let w = crate::se3::angular(&self.twist);
        let unit = (w.norm_squared() - T::one()).abs() <= T::default_epsilon() * convert(4.0);
        if unit && v == Vector3::zeros() {
            let (s, c) = theta.sin_cos();
            let r_o = &self.origin.rotation;
            let rw = r_o * crate::se3::hat(&w);
            let rw2 = r_o * (w * w.transpose() - Matrix3::identity());
            Se3::new(r_o + rw * s + rw2 * (T::one() - c), self.origin.translation)
        } else {
            self.origin.compose(&Se3::exp(&self.twist, theta))
        }
    }
}

/// Forward kinematics `g_0e = Π_k (origin_k exp(ξ̂_k θ_k)) · g_ne` of the chain `joints` with the
/// end-effector (tool) transform `tool` from the last joint's frame (2.35).
///
/// With `tool = Se3::identity()` this is `g_0n`, the frame of the last joint.
///
/// # Panics
/// If `q.len() != joints.len()`.
#[inline]
pub fn forward_kinematics<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &[T],
    tool: &Se3<T>,
) -> Se3<T> {
    assert_eq!(joints.len(), q.len(), "one joint value per joint");
    let mut g = Se3::identity();
    for (j, &theta) in joints.iter().zip(q) {
        g = g.compose(&j.transform(theta));
    }
    g.compose(tool)
}

/// All link frames `g_0k`, `k = 1..n` (0-based `frames[k-1]`), written into `frames`.
///
/// # Panics
/// If `q.len()` or `frames.len()` differ from `joints.len()`.
pub fn link_frames<T: RealField + Copy>(joints: &[Joint<T>], q: &[T], frames: &mut [Se3<T>]) {
    assert_eq!(joints.len(), q.len(), "one joint value per joint");
    assert_eq!(joints.len(), frames.len(), "one frame per joint");
    let mut g = Se3::identity();
    for ((j, &theta), f) in joints.iter().zip(q).zip(frames.iter_mut()) {
        g = g.compose(&j.transform(theta));
        *f = g;
    }
}

/// The body Jacobian (2.54)–(2.55) of `joints` with end-effector transform `tool`, column `k`
/// being joint `k`'s twist in the end-effector frame: `ξ†_k = Ad⁻¹_{g_ke} ξ^k_k`. Written into
/// `columns`; returns `g_0e` as a by-product.
///
/// With `tool = Se3::identity()` and the chain cut at `F_i` (`&joints[..i]`) this is the partial
/// body Jacobian `J^B_0i` (3.13).
///
/// # Panics
/// If `q.len()` or `columns.len()` differ from `joints.len()`.
#[inline]
pub fn body_jacobian_columns<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &[T],
    tool: &Se3<T>,
    columns: &mut [Twist<T>],
) -> Se3<T> {
    assert_eq!(joints.len(), q.len(), "one joint value per joint");
    assert_eq!(joints.len(), columns.len(), "one column per joint");
    // Backward sweep: g = g_ke, starting from g_ne = tool.
    let mut g = *tool;
    for k in (0..joints.len()).rev() {
        columns[k] = Adjoint(g).apply_inverse(&joints[k].twist);
        g = joints[k].transform(q[k]).compose(&g);
    }
    g
}

/// The spatial Jacobian (2.53): column `k` is joint `k`'s twist in the base frame,
/// `ξ'_k = Ad_{g_0k} ξ^k_k`. Written into `columns`; returns `g_0n` (the last joint's frame).
/// It does not depend on the end effector; `J^S = Ad_{g_0e} J^B`.
///
/// # Panics
/// If `q.len()` or `columns.len()` differ from `joints.len()`.
#[inline]
pub fn spatial_jacobian_columns<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &[T],
    columns: &mut [Twist<T>],
) -> Se3<T> {
    assert_eq!(joints.len(), q.len(), "one joint value per joint");
    assert_eq!(joints.len(), columns.len(), "one column per joint");
    let mut g = Se3::identity();
    for k in 0..joints.len() {
        g = g.compose(&joints[k].transform(q[k]));
        columns[k] = Adjoint(g).apply(&joints[k].twist);
    }
    g
}

/// The constrained Jacobian (3.15) `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]` from the joints **after**
/// the constrained link (`joints_after = &joints[i..]`, `q_after = &q[i..]`), the end-effector
/// transform and the columns of `Λ#`. Writes `lambda_sharp.len() + joints_after.len()` columns
/// (`m = 6 − r + n − i`); returns `g_ie`.
///
/// It depends only on `θ_j..θ_n` and the geometry, as (3.15) says. See
/// [`crate::constraint::Constraint::constrained_jacobian`] for the typed version.
///
/// # Panics
/// If `q_after.len() != joints_after.len()` or `columns` has the wrong length.
#[inline]
pub fn constrained_jacobian_columns<T: RealField + Copy>(
    joints_after: &[Joint<T>],
    q_after: &[T],
    tool: &Se3<T>,
    lambda_sharp: &[Twist<T>],
    columns: &mut [Twist<T>],
) -> Se3<T> {
    let k = lambda_sharp.len();
    assert_eq!(
        columns.len(),
        k + joints_after.len(),
        "m = 6 − r + n − i columns"
    );
    let (first, second) = columns.split_at_mut(k);
    let g_ie = body_jacobian_columns(joints_after, q_after, tool, second);
    // Ad_{g_ei} = Ad⁻¹_{g_ie}.
    let ad = Adjoint(g_ie);
    for (c, l) in first.iter_mut().zip(lambda_sharp) {
        *c = ad.apply_inverse(l);
    }
    g_ie
}

/// Copies columns into a fixed-size matrix.
#[inline]
pub(crate) fn matrix_from_columns<T: RealField + Copy, const C: usize>(
    columns: &[Twist<T>; C],
) -> SMatrix<T, 6, C> {
    let mut m = SMatrix::<T, 6, C>::zeros();
    for (k, c) in columns.iter().enumerate() {
        m.set_column(k, c);
    }
    m
}

/// A serial chain with `N` joints and an end-effector transform: the typed, allocation-free
/// front of the kernels above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chain<T: RealField + Copy, const N: usize> {
    /// Joints, base first.
    pub joints: [Joint<T>; N],
    /// Transform from the last joint's frame `F_n` to the end-effector frame `F_e`.
    pub tool: Se3<T>,
}

impl<T: RealField + Copy, const N: usize> Chain<T, N> {
    /// A chain from its joints and end-effector transform.
    pub fn new(joints: [Joint<T>; N], tool: Se3<T>) -> Self {
        Self { joints, tool }
    }

    /// Forward kinematics `g_0e(θ)`.
    #[inline]
    pub fn forward_kinematics(&self, q: &SVector<T, N>) -> Se3<T> {
        forward_kinematics(&self.joints, q.as_slice(), &self.tool)
    }

    /// The frame `g_0k` of link `k` (1-based; `k = 0` is the base, the identity).
    ///
    /// # Panics
    /// If `k > N`.
    #[inline]
    pub fn link_frame(&self, k: usize, q: &SVector<T, N>) -> Se3<T> {
        forward_kinematics(&self.joints[..k], &q.as_slice()[..k], &Se3::identity())
    }

    /// All link frames `g_0k`, `k = 1..N` (entry `k − 1`).
    pub fn link_frames(&self, q: &SVector<T, N>) -> [Se3<T>; N] {
        let mut frames = [Se3::identity(); N];
        link_frames(&self.joints, q.as_slice(), &mut frames);
        frames
    }

    /// The body Jacobian `J^B_0e(θ)` (2.54)–(2.55).
    #[inline]
    pub fn body_jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, 6, N> {
        let mut cols = [Twist::zeros(); N];
        body_jacobian_columns(&self.joints, q.as_slice(), &self.tool, &mut cols);
        matrix_from_columns(&cols)
    }

    /// The spatial Jacobian `J^S_0e(θ)` (2.53).
    #[inline]
    pub fn spatial_jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, 6, N> {
        let mut cols = [Twist::zeros(); N];
        spatial_jacobian_columns(&self.joints, q.as_slice(), &mut cols);
        matrix_from_columns(&cols)
    }

    /// The partial body Jacobian `J^B_0i(θ_1..θ_i)` (3.13): the body Jacobian of the chain cut at
    /// `F_i` (no end effector). Checked at compile time: `I ≤ N`.
    #[inline]
    pub fn partial_body_jacobian<const I: usize>(&self, q: &SVector<T, N>) -> SMatrix<T, 6, I> {
        const { assert!(I <= N, "the constrained link must be one of the chain's") };
        let mut cols = [Twist::zeros(); I];
        body_jacobian_columns(
            &self.joints[..I],
            &q.as_slice()[..I],
            &Se3::identity(),
            &mut cols,
        );
        matrix_from_columns(&cols)
    }

    /// The frame `g_0i` of link `I` and the partial body Jacobian `J^B_0i` (3.13) in one sweep
    /// over the joints (what [`Self::link_frame`] and [`Self::partial_body_jacobian`] give, at
    /// the cost of one). Checked at compile time: `I ≤ N`.
    #[inline]
    pub fn frame_and_partial_body_jacobian<const I: usize>(
        &self,
        q: &SVector<T, N>,
    ) -> (Se3<T>, SMatrix<T, 6, I>) {
        const { assert!(I <= N, "the constrained link must be one of the chain's") };
        let mut cols = [Twist::zeros(); I];
        let g_0i = body_jacobian_columns(
            &self.joints[..I],
            &q.as_slice()[..I],
            &Se3::identity(),
            &mut cols,
        );
        (g_0i, matrix_from_columns(&cols))
    }

    /// The split (3.12) `J^B_0e = [J^B_0e1 | J^B_0e2]` at link `I`: `J^B_0e1 = Ad_{g_ei} J^B_0i`
    /// (6×I) and `J^B_0e2(θ_j..θ_n)` (6×J). Checked at compile time: `I + J = N`.
    #[inline]
    pub fn body_jacobian_split<const I: usize, const J: usize>(
        &self,
        q: &SVector<T, N>,
    ) -> (SMatrix<T, 6, I>, SMatrix<T, 6, J>) {
        const { assert!(I + J == N, "the split must cover the chain: I + J = N") };
        let mut cols = [Twist::zeros(); N];
        body_jacobian_columns(&self.joints, q.as_slice(), &self.tool, &mut cols);
        let mut a = SMatrix::<T, 6, I>::zeros();
        let mut b = SMatrix::<T, 6, J>::zeros();
        for (k, c) in cols.iter().take(I).enumerate() {
            a.set_column(k, c);
        }
        for k in 0..J {
            b.set_column(k, &cols[I + k]);
        }
        (a, b)
    }

    /// Converts an `f64` chain to this scalar type (e.g. to `f32`).
    pub fn from_f64(chain: &Chain<f64, N>) -> Self {
        Chain {
            joints: chain.joints.map(|j| Joint {
                origin: Se3::from_f64(&j.origin),
                twist: j.twist.map(nalgebra::convert),
            }),
            tool: Se3::from_f64(&chain.tool),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Rotation3, Unit};

    fn origin() -> Se3<f64> {
        Se3::new(
            *Rotation3::from_euler_angles(0.3, -1.1, 0.7).matrix(),
            Vector3::new(0.1, -0.2, 0.333),
        )
    }

    /// A revolute joint's transform (Rodrigues with `sin θ`, `cos θ`) is the origin times a
    /// rotation by `θ` about the axis, for axes along z and oblique, and the general exponential
    /// agrees with it.
    #[test]
    fn revolute_transform_is_a_rotation_about_the_axis() {
        let axes = [
            Vector3::z(),
            Vector3::new(1.0, -2.0, 0.5).normalize(),
            -Vector3::x(),
        ];
        for axis in axes {
            let joint = Joint::revolute(origin(), axis);
            for k in 0..40 {
                let theta = -3.0 + 0.157 * k as f64;
                let g = joint.transform(theta);
                let r = Rotation3::from_axis_angle(&Unit::new_normalize(axis), theta);
                let want = origin().rotation * r.matrix();
                assert!(
                    (g.rotation - want).amax() < 1e-15,
                    "axis {axis:?}, θ = {theta}"
                );
                assert_eq!(g.translation, origin().translation);
                let general = origin().compose(&Se3::exp(&joint.twist, theta));
                assert!((g.rotation - general.rotation).amax() < 1e-15);
                assert!((g.translation - general.translation).amax() < 1e-15);
            }
        }
        // A twist with a moment (an axis off the frame's origin) takes the general path.
        let off = Joint::from_twist(
            origin(),
            crate::se3::twist(&Vector3::new(0.0, 0.2, 0.0), &Vector3::z()),
        );
        let g = off.transform(0.4);
        let general = origin().compose(&Se3::exp(&off.twist, 0.4));
        assert_eq!(g.rotation, general.rotation);
        assert_eq!(g.translation, general.translation);
        assert!((g.rotation - Matrix3::identity()).amax() > 0.1);
    }

    /// One sweep gives the frame of [`Chain::link_frame`] and the Jacobian of
    /// [`Chain::partial_body_jacobian`].
    #[test]
    fn frame_and_partial_body_jacobian_match_the_two_calls() {
        let joints: [Joint<f64>; 4] = core::array::from_fn(|k| {
            let axis = Vector3::new(k as f64 - 1.0, 0.5, 1.0).normalize();
            Joint::revolute(
                Se3::new(
                    *Rotation3::from_euler_angles(0.2 * k as f64, 0.1, -0.3).matrix(),
                    Vector3::new(0.0, 0.1, 0.3),
                ),
                axis,
            )
        });
        let chain = Chain::new(joints, origin());
        let q = SVector::<f64, 4>::new(0.3, -1.2, 2.0, 0.7);
        let (g, j): (_, SMatrix<f64, 6, 3>) = chain.frame_and_partial_body_jacobian::<3>(&q);
        let g2 = chain.link_frame(3, &q);
        assert!((g.rotation - g2.rotation).amax() < 1e-15);
        assert!((g.translation - g2.translation).amax() < 1e-15);
        assert!((j - chain.partial_body_jacobian::<3>(&q)).amax() < 1e-15);
    }
}
