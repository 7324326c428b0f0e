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
//!
//! Each joint's motion is read from its twist: a revolute joint about a coordinate axis `±e_a`
//! of its frame (every URDF revolute joint with `axis="0 0 1"` and the like), about another unit
//! axis through the frame's origin, a prismatic joint, or a general screw. The sweeps never form a
//! joint's transform or a 6×6 Adjoint: a forward sweep applies `origin_k` (one 3×3 product) and
//! then the joint's rotation (2.7) to the running frame, a coordinate axis mixing two of its
//! columns; the body Jacobian's backward sweep reads column `k`, `Ad⁻¹_{g_ke} ξ_k` (2.45), off the
//! running frame's rows and translation and then applies the joint's rotation to two of its rows
//! and `origin_k` (one 3×3 product). Sines and cosines come from [`RealField`] (`std`'s or
//! `libm`'s), not from the crate's own kernel that generated code uses: this runtime is the
//! independent reference generated code is checked against.

use crate::se3::{Adjoint, Se3, Twist};
use nalgebra::{convert, Matrix3, RealField, SMatrix, SVector, Vector3};

/// `f::<A, I, J>(args)` for the coordinate axis `a`, with `(A, I, J)` the cyclic triple starting
/// at `a`: the indices are constants in each instance (no bounds checks, no index arithmetic).
macro_rules! on_axis {
    ($axis:expr, $f:ident ( $($arg:expr),* )) => {
        match $axis {
            CoordinateAxis::X => $f::<_, 0, 1, 2>($($arg),*),
            CoordinateAxis::Y => $f::<_, 1, 2, 0>($($arg),*),
            CoordinateAxis::Z => $f::<_, 2, 0, 1>($($arg),*),
        }
    };
}

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
    /// A revolute joint about a unit axis `ω` through its frame's origin (`ξ = (0, ω)`,
    /// `‖ω‖ = 1`, every URDF revolute joint) takes Rodrigues' formula (2.7) with `sin θ`,
    /// `cos θ` directly, `exp(ω̂ θ) = cos θ I + sin θ ω̂ + (1 − cos θ) ω ωᵀ`, and keeps the
    /// origin's translation; about a coordinate axis `±e_a` of the joint frame (URDF's
    /// `axis="0 0 1"` and the like) that rotation only mixes two columns of `R_o`. A prismatic
    /// joint is `(R_o, R_o v θ + p_o)` (2.27); other joints take the exponential (2.25), (2.27).
    #[inline]
    pub fn transform(&self, theta: T) -> Se3<T> {
        match Motion::of(&self.twist) {
            Motion::Prismatic(v) => Se3::new(
                self.origin.rotation,
                self.origin.rotation * (v * theta) + self.origin.translation,
            ),
            Motion::General => self.origin.compose(&Se3::exp(&self.twist, theta)),
            Motion::Axis(..) | Motion::Revolute(_) => Step::new(self, theta).transform(),
        }
    }
}

/// How a joint moves, read from its twist `ξ = (v, ω)`: what lets the sweeps below replace the
/// exponential and the full Adjoint by a few products.
#[derive(Clone, Copy, Debug)]
enum Motion<T: RealField + Copy> {
    /// Revolute about the coordinate axis `±e_a` of the joint frame, through its origin:
    /// `v = 0`, `ω = ±e_a` exactly (`negative` for `−e_a`).
    Axis(CoordinateAxis, bool),
    /// Revolute about the unit axis `ω` through the frame's origin: `v = 0`, `‖ω‖ = 1`.
    Revolute(Vector3<T>),
    /// Prismatic along `v`: `ω = 0`.
    Prismatic(Vector3<T>),
    /// Any other screw: the exponential (2.25).
    General,
}

/// A coordinate axis `e_a` of a joint frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CoordinateAxis {
    X,
    Y,
    Z,
}

impl<T: RealField + Copy> Motion<T> {
    #[inline(always)]
    fn of(xi: &Twist<T>) -> Self {
        let v = crate::se3::linear(xi);
        let w = crate::se3::angular(xi);
        let zero = T::zero();
        let one = T::one();
        if v == Vector3::zeros() {
            // `ω = ±e_a` exactly: the other two entries zero.
            let axis = if w.y == zero && w.z == zero && w.x.abs() == one {
                Some((CoordinateAxis::X, w.x))
            } else if w.z == zero && w.x == zero && w.y.abs() == one {
                Some((CoordinateAxis::Y, w.y))
            } else if w.x == zero && w.y == zero && w.z.abs() == one {
                Some((CoordinateAxis::Z, w.z))
            } else {
                None
            };
            if let Some((a, sign)) = axis {
                return Motion::Axis(a, sign < zero);
            }
            if (w.norm_squared() - one).abs() <= T::default_epsilon() * convert(4.0) {
                return Motion::Revolute(w);
            }
        } else if w == Vector3::zeros() {
            return Motion::Prismatic(v);
        }
        Motion::General
    }
}

/// `(sin x, cos x)` from [`RealField`] (`std`'s, or `libm`'s without `std`): not the crate's own
/// kernel ([`crate::emitted::fast`]) that generated code uses, so that this runtime, the reference
/// generated code is checked against, shares none of its arithmetic.
#[inline(always)]
fn sin_cos<T: RealField + Copy>(x: T) -> (T, T) {
    x.sin_cos()
}

/// `exp(ω̂ θ) = cos θ I + sin θ ω̂ + (1 − cos θ) ω ωᵀ` for a unit `ω` (Rodrigues (2.7), with
/// `ω̂² = ω ωᵀ − I`), from `s = sin θ`, `c = cos θ`.
#[inline(always)]
fn rodrigues<T: RealField + Copy>(w: &Vector3<T>, s: T, c: T) -> Matrix3<T> {
    let t = T::one() - c;
    let (x, y, z) = (w.x, w.y, w.z);
    let (tx, ty, tz) = (t * x, t * y, t * z);
    let (sx, sy, sz) = (s * x, s * y, s * z);
    Matrix3::new(
        tx * x + c,
        tx * y - sz,
        tx * z + sy,
        ty * x + sz,
        ty * y + c,
        ty * z - sx,
        tz * x - sy,
        tz * y + sx,
        tz * z + c,
    )
}

/// `R · Rot(e_A, θ)`: a rotation about the coordinate axis `e_A` only mixes columns `I`, `J`
/// (`(A, I, J)` cyclic): `col_I ← c col_I + s col_J`, `col_J ← c col_J − s col_I`.
#[inline(always)]
fn rotate_columns<T: RealField + Copy, const A: usize, const I: usize, const J: usize>(
    r: &Matrix3<T>,
    s: T,
    c: T,
) -> Matrix3<T> {
    let mut m = *r;
    for k in 0..3 {
        let (x, y) = (r[(k, I)], r[(k, J)]);
        m[(k, I)] = c * x + s * y;
        m[(k, J)] = c * y - s * x;
    }
    m
}

/// `Rot(e_A, θ) · (R, p)`: rows `I`, `J` of `R` and entries `I`, `J` of `p` mixed
/// (`x_I ← c x_I − s x_J`, `x_J ← s x_I + c x_J`).
#[inline(always)]
fn rotate_rows<T: RealField + Copy, const A: usize, const I: usize, const J: usize>(
    g: &Se3<T>,
    s: T,
    c: T,
) -> (Matrix3<T>, Vector3<T>) {
    let (r, p) = (&g.rotation, &g.translation);
    let mut m = *r;
    for k in 0..3 {
        let (x, y) = (r[(I, k)], r[(J, k)]);
        m[(I, k)] = c * x - s * y;
        m[(J, k)] = s * x + c * y;
    }
    let mut q = *p;
    q[I] = c * p[I] - s * p[J];
    q[J] = s * p[I] + c * p[J];
    (m, q)
}

/// `Ad⁻¹_g ξ` for `ξ = (0, e_A)` (2.45): `(−Rᵀ(p × e_A), Rᵀ e_A) = (p_I row_J − p_J row_I,
/// row_A)` with `row_k` row `k` of `R`.
#[inline(always)]
fn axis_column_inverse<T: RealField + Copy, const A: usize, const I: usize, const J: usize>(
    g: &Se3<T>,
) -> (Vector3<T>, Vector3<T>) {
    let (r, p) = (&g.rotation, &g.translation);
    let row = |k: usize| Vector3::new(r[(k, 0)], r[(k, 1)], r[(k, 2)]);
    (row(J) * p[I] - row(I) * p[J], row(A))
}

/// The transform `g` with its rotation's column `A`: `Rω` for `ω = e_A`.
#[inline(always)]
fn axis_column<T: RealField + Copy, const A: usize, const I: usize, const J: usize>(
    g: &Se3<T>,
) -> Vector3<T> {
    let r = &g.rotation;
    Vector3::new(r[(0, A)], r[(1, A)], r[(2, A)])
}

/// One joint of a sweep: its motion, its value and, for a revolute joint, `(sin θ, cos θ)` (the
/// sine negated for an axis `−e_a`, a rotation by `−θ` about `e_a`).
#[derive(Clone, Copy)]
struct Step<'a, T: RealField + Copy> {
    joint: &'a Joint<T>,
    motion: Motion<T>,
    theta: T,
    sin: T,
    cos: T,
}

impl<'a, T: RealField + Copy> Step<'a, T> {
    /// The joint at `θ`, its sine and cosine taken only where the motion needs them.
    #[inline(always)]
    fn new(joint: &'a Joint<T>, theta: T) -> Self {
        let motion = Motion::of(&joint.twist);
        let (sin, cos) = match motion {
            Motion::Axis(_, negative) => {
                let (s, c) = sin_cos(theta);
                (if negative { -s } else { s }, c)
            }
            Motion::Revolute(_) => sin_cos(theta),
            Motion::Prismatic(_) | Motion::General => (T::zero(), T::one()),
        };
        Step {
            joint,
            motion,
            theta,
            sin,
            cos,
        }
    }

    /// `origin · exp(ξ̂ θ)` ([`Joint::transform`]) from the step's sine and cosine.
    #[inline(always)]
    fn transform(&self) -> Se3<T> {
        let o = &self.joint.origin;
        let (s, c) = (self.sin, self.cos);
        match self.motion {
            Motion::Axis(axis, _) => Se3::new(
                on_axis!(axis, rotate_columns(&o.rotation, s, c)),
                o.translation,
            ),
            Motion::Revolute(w) => Se3::new(o.rotation * rodrigues(&w, s, c), o.translation),
            Motion::Prismatic(_) | Motion::General => self.joint.transform(self.theta),
        }
    }

    /// `g · origin · exp(ξ̂ θ)` (a forward sweep): `(R R_o Rot, R p_o + p)` for a revolute
    /// joint, without forming the joint's transform first.
    #[inline(always)]
    fn after(&self, g: &Se3<T>) -> Se3<T> {
        let o = &self.joint.origin;
        let (s, c) = (self.sin, self.cos);
        match self.motion {
            Motion::Axis(axis, _) => {
                let r = g.rotation * o.rotation;
                Se3::new(
                    on_axis!(axis, rotate_columns(&r, s, c)),
                    g.rotation * o.translation + g.translation,
                )
            }
            Motion::Revolute(w) => Se3::new(
                g.rotation * o.rotation * rodrigues(&w, s, c),
                g.rotation * o.translation + g.translation,
            ),
            Motion::Prismatic(v) => Se3::new(
                g.rotation * o.rotation,
                g.rotation * (o.rotation * (v * self.theta) + o.translation) + g.translation,
            ),
            Motion::General => g.compose(&self.joint.transform(self.theta)),
        }
    }

    /// `origin · exp(ξ̂ θ) · g` (a backward sweep): `(R_o (Rot R), R_o (Rot p) + p_o)`, the
    /// rotation about a coordinate axis mixing two rows of `R` and two entries of `p`.
    #[inline(always)]
    fn before(&self, g: &Se3<T>) -> Se3<T> {
        let o = &self.joint.origin;
        let (s, c) = (self.sin, self.cos);
        match self.motion {
            Motion::Axis(axis, _) => {
                let (r, p) = on_axis!(axis, rotate_rows(g, s, c));
                Se3::new(o.rotation * r, o.rotation * p + o.translation)
            }
            Motion::Revolute(w) => {
                let r = rodrigues(&w, s, c);
                Se3::new(
                    o.rotation * (r * g.rotation),
                    o.rotation * (r * g.translation) + o.translation,
                )
            }
            Motion::Prismatic(v) => Se3::new(
                o.rotation * g.rotation,
                o.rotation * (g.translation + v * self.theta) + o.translation,
            ),
            Motion::General => self.joint.transform(self.theta).compose(g),
        }
    }

    /// The joint's twist seen from the frame `g` leads to: `Ad⁻¹_g ξ = (Rᵀ(v − p × ω), Rᵀω)`
    /// (2.45), read off `g`'s rows for a coordinate axis ([`axis_column_inverse`]); `(Rᵀv, 0)`
    /// for a prismatic joint.
    #[inline(always)]
    fn column_inverse(&self, g: &Se3<T>) -> Twist<T> {
        match self.motion {
            Motion::Axis(axis, negative) => {
                let (v, w) = on_axis!(axis, axis_column_inverse(g));
                if negative {
                    crate::se3::twist(&-v, &-w)
                } else {
                    crate::se3::twist(&v, &w)
                }
            }
            Motion::Prismatic(v) => crate::se3::twist(&g.rotation.tr_mul(&v), &Vector3::zeros()),
            Motion::Revolute(_) | Motion::General => Adjoint(*g).apply_inverse(&self.joint.twist),
        }
    }

    /// The joint's twist seen from the base when `g` is its frame: `Ad_g ξ = (R v + p × Rω, Rω)`
    /// (2.43); `Rω = ±col_a(R)` for `ω = ±e_a`.
    #[inline(always)]
    fn column(&self, g: &Se3<T>) -> Twist<T> {
        match self.motion {
            Motion::Axis(axis, negative) => {
                let c = on_axis!(axis, axis_column(g));
                let w = if negative { -c } else { c };
                crate::se3::twist(&g.translation.cross(&w), &w)
            }
            Motion::Prismatic(v) => crate::se3::twist(&(g.rotation * v), &Vector3::zeros()),
            Motion::Revolute(_) | Motion::General => Adjoint(*g).apply(&self.joint.twist),
        }
    }
}

/// Forward kinematics `g_0e = Π_k (origin_k exp(ξ̂_k θ_k)) · g_ne` of the chain `joints` with the
/// end-effector (tool) transform `tool` from the last joint's frame (2.35).
///
/// With `tool = Se3::identity()` this is `g_0n`, the frame of the last joint. One pass from the
/// base: per revolute joint one 3×3 product `R R_o`, then the joint's rotation (2.7) applied to
/// it (two columns mixed for a coordinate axis).
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
    match forward_sweep(joints, q, |_, _, _| {}) {
        Some(g) => g.compose(tool),
        None => *tool,
    }
}

/// All link frames `g_0k`, `k = 1..n` (0-based `frames[k-1]`), written into `frames`.
///
/// # Panics
/// If `q.len()` or `frames.len()` differ from `joints.len()`.
pub fn link_frames<T: RealField + Copy>(joints: &[Joint<T>], q: &[T], frames: &mut [Se3<T>]) {
    assert_eq!(joints.len(), q.len(), "one joint value per joint");
    assert_eq!(joints.len(), frames.len(), "one frame per joint");
    forward_sweep(joints, q, |k, _, g| frames[k] = *g);
}

/// The forward sweep from the base: `visit(k, step, g_0k)` for each joint `k` in turn, `g_0k`
/// the link frame after joint `k`; returns `g_0n` (`None` for no joints). The first joint's
/// frame is its transform (no product with the identity).
#[inline(always)]
fn forward_sweep<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &[T],
    mut visit: impl FnMut(usize, &Step<'_, T>, &Se3<T>),
) -> Option<Se3<T>> {
    let mut g: Option<Se3<T>> = None;
    for (k, (j, &theta)) in joints.iter().zip(q).enumerate() {
        let step = Step::new(j, theta);
        let next = match g {
            None => step.transform(),
            Some(g) => step.after(&g),
        };
        visit(k, &step, &next);
        g = Some(next);
    }
    g
}

/// The body Jacobian (2.54)–(2.55) of `joints` with end-effector transform `tool`, column `k`
/// being joint `k`'s twist in the end-effector frame: `ξ†_k = Ad⁻¹_{g_ke} ξ^k_k`. Written into
/// `columns`; returns `g_0e` as a by-product.
///
/// With `tool = Se3::identity()` and the chain cut at `F_i` (`&joints[..i]`) this is the partial
/// body Jacobian `J^B_0i` (3.13).
///
/// One pass from the end effector to the base: `g = g_ke` starts at `tool`; column `k` is
/// `Ad⁻¹_g ξ_k` read off `g`'s rotation rows and translation (no 6×6 matrix), then
/// `g ← origin_k exp(ξ̂_k θ_k) g` with the joint's rotation applied to `g`'s rows and one 3×3
/// product by `R_o`.
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
    body_sweep(joints, q, tool, |k, column| columns[k] = column)
}

/// [`body_jacobian_columns`] with column `k` handed to `put(k, column)` (written straight into
/// the caller's matrix).
#[inline(always)]
fn body_sweep<T: RealField + Copy>(
    joints: &[Joint<T>],
    q: &[T],
    tool: &Se3<T>,
    mut put: impl FnMut(usize, Twist<T>),
) -> Se3<T> {
    // Backward sweep: g = g_ke, starting from g_ne = tool.
    let mut g = *tool;
    for (k, (j, &theta)) in joints.iter().zip(q).enumerate().rev() {
        let step = Step::new(j, theta);
        put(k, step.column_inverse(&g));
        g = step.before(&g);
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
    forward_sweep(joints, q, |k, step, g| columns[k] = step.column(g)).unwrap_or_else(Se3::identity)
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
        let mut m = SMatrix::<T, 6, N>::zeros();
        self.body_columns(q, &mut m);
        m
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
        let mut m = SMatrix::<T, 6, I>::zeros();
        self.partial_columns(q, &mut m);
        m
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
        let mut m = SMatrix::<T, 6, I>::zeros();
        let g_0i = self.partial_columns(q, &mut m);
        (g_0i, m)
    }

    /// The split (3.12) `J^B_0e = [J^B_0e1 | J^B_0e2]` at link `I`: `J^B_0e1 = Ad_{g_ei} J^B_0i`
    /// (6×I) and `J^B_0e2(θ_j..θ_n)` (6×J). Checked at compile time: `I + J = N`.
    #[inline]
    pub fn body_jacobian_split<const I: usize, const J: usize>(
        &self,
        q: &SVector<T, N>,
    ) -> (SMatrix<T, 6, I>, SMatrix<T, 6, J>) {
        const { assert!(I + J == N, "the split must cover the chain: I + J = N") };
        let mut m = SMatrix::<T, 6, N>::zeros();
        self.body_columns(q, &mut m);
        (
            m.fixed_columns::<I>(0).into_owned(),
            m.fixed_columns::<J>(I).into_owned(),
        )
    }

    /// The body Jacobian (2.54)–(2.55) written into `m`; returns `g_0e`.
    #[inline(always)]
    fn body_columns(&self, q: &SVector<T, N>, m: &mut SMatrix<T, 6, N>) -> Se3<T> {
        body_sweep(&self.joints, q.as_slice(), &self.tool, |k, column| {
            m.set_column(k, &column)
        })
    }

    /// `J^B_0i` (3.13) written into `m`; returns `g_0i`. `I ≤ N` (checked by the callers).
    #[inline(always)]
    fn partial_columns<const I: usize>(
        &self,
        q: &SVector<T, N>,
        m: &mut SMatrix<T, 6, I>,
    ) -> Se3<T> {
        body_sweep(
            &self.joints[..I],
            &q.as_slice()[..I],
            &Se3::identity(),
            |k, column| m.set_column(k, &column),
        )
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

    /// The transform and twist columns the way they are defined, with no shortcut: the
    /// exponential (2.25)/(2.27) composed with the origin, and the Adjoint (2.43), (2.45).
    fn reference_transform(j: &Joint<f64>, theta: f64) -> Se3<f64> {
        j.origin.compose(&Se3::exp(&j.twist, theta))
    }

    /// A chain with every kind of joint motion: revolute about `±e_x`, `±e_y`, `±e_z`, about an
    /// oblique unit axis, prismatic, a screw with pitch, and a non-unit rotation axis.
    fn mixed_joints() -> [Joint<f64>; 10] {
        let at = |k: usize| {
            Se3::new(
                *Rotation3::from_euler_angles(0.3 * k as f64 - 0.7, 0.2, -0.4 + 0.1 * k as f64)
                    .matrix(),
                Vector3::new(0.05 * k as f64, -0.1, 0.2 + 0.01 * k as f64),
            )
        };
        [
            Joint::revolute(at(0), Vector3::z()),
            Joint::revolute(at(1), -Vector3::x()),
            Joint::revolute(at(2), Vector3::y()),
            Joint::revolute(at(3), -Vector3::z()),
            Joint::revolute(at(4), Vector3::new(0.3, -0.5, 0.8).normalize()),
            Joint::prismatic(at(5), Vector3::new(0.0, 0.6, 0.8)),
            Joint::from_twist(
                at(6),
                crate::se3::twist(&Vector3::new(0.1, 0.2, -0.1), &Vector3::x()),
            ),
            Joint::revolute(at(7), Vector3::x()),
            Joint::revolute(at(8), -Vector3::y()),
            Joint::from_twist(
                at(9),
                crate::se3::twist(&Vector3::zeros(), &Vector3::new(0.0, 0.0, 2.0)),
            ),
        ]
    }

    fn close(a: &Se3<f64>, b: &Se3<f64>, tol: f64) -> bool {
        (a.rotation - b.rotation).amax() <= tol && (a.translation - b.translation).amax() <= tol
    }

    /// Every sweep, for every kind of joint, agrees with the definitions to rounding: FK, link
    /// frames, body and spatial Jacobians (slice kernels and [`Chain`]), `J^B_0i` and the split.
    #[test]
    fn sweeps_match_the_definitions_for_every_kind_of_joint() {
        let joints = mixed_joints();
        let tool = origin();
        let chain = Chain::new(joints, tool);
        for s in 0..25 {
            let q =
                SVector::<f64, 10>::from_fn(|k, _| (-3.0 + 0.37 * (s * 10 + k) as f64).sin() * 2.9);
            // Reference link frames and columns.
            let mut frames = [Se3::identity(); 10];
            let mut g = Se3::identity();
            for k in 0..10 {
                g = g.compose(&reference_transform(&joints[k], q[k]));
                frames[k] = g;
            }
            let g_0e = g.compose(&tool);
            let tol = 1e-13;
            for k in 0..10 {
                assert!(close(
                    &joints[k].transform(q[k]),
                    &reference_transform(&joints[k], q[k]),
                    tol
                ));
            }
            assert!(close(&chain.forward_kinematics(&q), &g_0e, tol));
            assert!(close(
                &forward_kinematics(&joints, q.as_slice(), &tool),
                &g_0e,
                tol
            ));
            let got = chain.link_frames(&q);
            for k in 0..10 {
                assert!(close(&got[k], &frames[k], tol));
                assert!(close(&chain.link_frame(k + 1, &q), &frames[k], tol));
            }
            // Body Jacobian: column k = Ad⁻¹_{g_ke} ξ_k, g_ke = g_0k⁻¹ g_0e.
            let jb = chain.body_jacobian(&q);
            let js = chain.spatial_jacobian(&q);
            let mut cols = [Twist::zeros(); 10];
            let g_b = body_jacobian_columns(&joints, q.as_slice(), &tool, &mut cols);
            assert!(close(&g_b, &g_0e, tol));
            for k in 0..10 {
                let g_ke = frames[k].inverse_compose(&g_0e);
                let want = Adjoint(g_ke).apply_inverse(&joints[k].twist);
                assert!((jb.column(k) - want).amax() <= tol, "body column {k}");
                assert_eq!(jb.column(k).into_owned(), cols[k]);
                let want_s = Adjoint(frames[k]).apply(&joints[k].twist);
                assert!((js.column(k) - want_s).amax() <= tol, "spatial column {k}");
            }
            // J^B_0i and the split at i = 6.
            let (g6, j6): (_, SMatrix<f64, 6, 6>) = chain.frame_and_partial_body_jacobian::<6>(&q);
            assert!(close(&g6, &frames[5], tol));
            assert_eq!(j6, chain.partial_body_jacobian::<6>(&q));
            for k in 0..6 {
                let want =
                    Adjoint(frames[k].inverse_compose(&frames[5])).apply_inverse(&joints[k].twist);
                assert!((j6.column(k) - want).amax() <= tol, "J^B_0i column {k}");
            }
            let (a, b): (SMatrix<f64, 6, 6>, SMatrix<f64, 6, 4>) =
                chain.body_jacobian_split::<6, 4>(&q);
            assert_eq!(a, jb.fixed_columns::<6>(0).into_owned());
            assert_eq!(b, jb.fixed_columns::<4>(6).into_owned());
        }
    }

    /// An `f32` chain follows the `f64` one.
    #[test]
    fn f32_chain_follows_f64() {
        let chain = Chain::new(mixed_joints(), origin());
        let chain32 = Chain::<f32, 10>::from_f64(&chain);
        let q = SVector::<f64, 10>::from_fn(|k, _| 0.3 * k as f64 - 1.2);
        let j = chain.body_jacobian(&q);
        let j32 = chain32.body_jacobian(&q.map(|x| x as f32));
        assert!((j32.map(f64::from) - j).amax() < 1e-4);
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
