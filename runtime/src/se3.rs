//! Rigid motions SE(3), twists, hat/vee, the exponential of twists and the Adjoint (thesis chapter 2).
//!
//! Conventions (thesis chapter 2; `docs/reference-robots.md`): twists are `ξ = (v, ω)` with the **linear part first**;
//! `Ad_g = [[R, p̂R], [0, R]]` (2.43).
//!
//! Everything here is allocation-free and works in `#![no_std]` builds.

use core::ops::Mul;
use nalgebra::{convert, Matrix3, Matrix4, Matrix6, RealField, Vector3, Vector6};

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

/// The skew-symmetric matrix `ω̂` of a vector, `ω̂ x = ω × x` (A.4).
#[inline]
pub fn hat<T: RealField + Copy>(w: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -w.z, w.y, w.z, z, -w.x, -w.y, w.x, z)
}

/// The vector of a skew-symmetric matrix, inverse of [`hat`] (A.4). Only the
/// skew-symmetric part of `m` is read: `(m − mᵀ)^∨ / 2`.
#[inline]
pub fn vee<T: RealField + Copy>(m: &Matrix3<T>) -> Vector3<T> {
    let half: T = convert(0.5);
    Vector3::new(
        (m[(2, 1)] - m[(1, 2)]) * half,
        (m[(0, 2)] - m[(2, 0)]) * half,
        (m[(1, 0)] - m[(0, 1)]) * half,
    )
}

/// The 4×4 matrix `ξ̂ = [[ω̂, v], [0, 0]]` of a twist (the `∧` of (2.29)).
#[inline]
pub fn twist_hat<T: RealField + Copy>(xi: &Twist<T>) -> Matrix4<T> {
    let w = hat(&angular(xi));
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
    m[(0, 3)] = xi[0];
    m[(1, 3)] = xi[1];
    m[(2, 3)] = xi[2];
    m
}

/// The twist coordinates of `ξ̂ = [[ω̂, v], [0, 0]]`, inverse of [`twist_hat`].
#[inline]
pub fn twist_vee<T: RealField + Copy>(m: &Matrix4<T>) -> Twist<T> {
    let w = vee(&m.fixed_view::<3, 3>(0, 0).into_owned());
    Twist::new(m[(0, 3)], m[(1, 3)], m[(2, 3)], w.x, w.y, w.z)
}

/// Linear part `v` of a twist.
#[inline]
pub fn linear<T: RealField + Copy>(xi: &Twist<T>) -> Vector3<T> {
    Vector3::new(xi[0], xi[1], xi[2])
}

/// Angular part `ω` of a twist.
#[inline]
pub fn angular<T: RealField + Copy>(xi: &Twist<T>) -> Vector3<T> {
    Vector3::new(xi[3], xi[4], xi[5])
}

/// The twist `(v, ω)` from its linear and angular parts.
#[inline]
pub fn twist<T: RealField + Copy>(v: &Vector3<T>, w: &Vector3<T>) -> Twist<T> {
    Twist::new(v.x, v.y, v.z, w.x, w.y, w.z)
}

/// The twist of a revolute joint with unit axis `ω` through the point `q`: `ξ = (−ω × q, ω)` (2.30).
#[inline]
pub fn revolute_twist<T: RealField + Copy>(axis: &Vector3<T>, point: &Vector3<T>) -> Twist<T> {
    twist(&(-axis.cross(point)), axis)
}

/// The twist of a prismatic joint with unit direction `v`: `ξ = (v, 0)` (2.31).
#[inline]
pub fn prismatic_twist<T: RealField + Copy>(direction: &Vector3<T>) -> Twist<T> {
    twist(direction, &Vector3::zeros())
}

/// Series coefficients of the SO(3)/SE(3) exponential at angle `a = ‖φ‖`:
/// `(sin a / a, (1 − cos a)/a², (a − sin a)/a³)`, with Taylor expansions near 0.
#[inline]
fn exp_coefficients<T: RealField + Copy>(a2: T) -> (T, T, T) {
    let small: T = T::default_epsilon().sqrt().sqrt();
    if a2 < small * small {
        // Taylor series to a⁴: accurate to machine precision for a < ε^{1/4}.
        let c6: T = convert(6.0);
        let c120: T = convert(120.0);
        let c2: T = convert(2.0);
        let c24: T = convert(24.0);
        let c720: T = convert(720.0);
        let c5040: T = convert(5040.0);
        (
            T::one() - a2 / c6 + a2 * a2 / c120,
            T::one() / c2 - a2 / c24 + a2 * a2 / c720,
            T::one() / c6 - a2 / c120 + a2 * a2 / c5040,
        )
    } else {
        let a = a2.sqrt();
        let (s, c) = a.sin_cos();
        (s / a, (T::one() - c) / a2, (a - s) / (a2 * a))
    }
}

/// The exponential of `φ̂` on SO(3) (Rodrigues' formula (2.7)): `I + (sin a/a) φ̂ + ((1 − cos a)/a²) φ̂²`,
/// `a = ‖φ‖`. `φ = ω θ` for a rotation by `θ` about the unit axis `ω`.
#[inline]
pub fn exp_so3<T: RealField + Copy>(phi: &Vector3<T>) -> Matrix3<T> {
    let (a, b, _) = exp_coefficients(phi.norm_squared());
    let w = hat(phi);
    Matrix3::identity() + w * a + w * w * b
}

/// The logarithm of a rotation: `φ` with `exp(φ̂) = R` and `‖φ‖ ∈ [0, π]`.
pub fn log_so3<T: RealField + Copy>(r: &Matrix3<T>) -> Vector3<T> {
    let one = T::one();
    let two: T = convert(2.0);
    let s = vee(r); // sin(a) ω
    let sin_a = s.norm();
    let cos_a = ((r.trace() - one) / two).clamp(-one, one);
    let a = sin_a.atan2(cos_a);
    if cos_a > T::zero() || sin_a > convert(1e-3) {
        // a / sin a is well conditioned away from a = π.
        let small: T = T::default_epsilon().sqrt().sqrt();
        let factor = if a < small {
            let c6: T = convert(6.0);
            one + a * a / c6
        } else {
            a / sin_a
        };
        s * factor
    } else {
        // Near π: (R + Rᵀ)/2 − cos a I = (1 − cos a) ω ωᵀ. Take the best-conditioned column.
        let b = (r + r.transpose()) / two - Matrix3::identity() * cos_a;
        let d = Vector3::new(b[(0, 0)], b[(1, 1)], b[(2, 2)]);
        let k = d.imax();
        let mut w: Vector3<T> = b.column(k).into_owned();
        w /= w.norm();
        // Sign from the skew part: s = sin a ω.
        if w.dot(&s) < T::zero() {
            w = -w;
        }
        w * a
    }
}

/// The exponential of a twist times a joint value, `exp(ξ̂ θ)` ((2.25) and (2.27)).
///
/// For a revolute twist `ξ = (−ω × q, ω)` with `‖ω‖ = 1` this is (2.25):
/// `(e^{ω̂θ}, (I − e^{ω̂θ})(ω × v) + ω ωᵀ v θ)`; for a prismatic twist `(v, 0)` it is `(I, vθ)` (2.27);
/// a general screw (any `ω`) uses `(e^{φ̂}, V(φ) v θ)` with `φ = ω θ`, the same map.
#[inline]
pub fn exp_twist<T: RealField + Copy>(xi: &Twist<T>, theta: T) -> Se3<T> {
    let v = linear(xi) * theta;
    let phi = angular(xi) * theta;
    let a2 = phi.norm_squared();
    if a2 == T::zero() {
        return Se3::from_translation(v);
    }
    let (a, b, c) = exp_coefficients(a2);
    // φ̂² = φ φᵀ − a² I, so R = I + a φ̂ + b φ̂² without 3×3 products.
    let w = hat(&phi);
    let w2 = phi * phi.transpose() - Matrix3::identity() * a2;
    let rotation = Matrix3::identity() + w * a + w2 * b;
    // V v = v + b φ × v + c φ × (φ × v).
    let pv = phi.cross(&v);
    let translation = v + pv * b + phi.cross(&pv) * c;
    Se3 {
        rotation,
        translation,
    }
}

/// The logarithm of a rigid transform: the twist `ξθ` (vee'd) with `exp(ξ̂θ) = g`, angle in `[0, π]`.
///
/// Used by the finite-difference Jacobians ([`crate::finite_diff`]); the inverse of [`exp_twist`]
/// with `θ = 1`.
pub fn log<T: RealField + Copy>(g: &Se3<T>) -> Twist<T> {
    let phi = log_so3(&g.rotation);
    let a2 = phi.norm_squared();
    let w = hat(&phi);
    // V⁻¹ = I − φ̂/2 + (1/a²)(1 − (a sin a)/(2(1 − cos a))) φ̂²
    let small: T = T::default_epsilon().sqrt().sqrt();
    let coef = if a2 < small * small {
        let c12: T = convert(12.0);
        let c720: T = convert(720.0);
        T::one() / c12 + a2 / c720
    } else {
        let a = a2.sqrt();
        let (s, c) = a.sin_cos();
        let two: T = convert(2.0);
        (T::one() - a * s / (two * (T::one() - c))) / a2
    };
    let half: T = convert(0.5);
    let vinv = Matrix3::identity() - w * half + w * w * coef;
    twist(&(vinv * g.translation), &phi)
}

/// The rotation `R = Rz(yaw) Ry(pitch) Rx(roll)` of URDF's `rpy` (fixed axes x, then y, then z).
pub fn rotation_from_rpy<T: RealField + Copy>(roll: T, pitch: T, yaw: T) -> Matrix3<T> {
    rotation_from_rpy_sin_cos(roll.sin_cos(), pitch.sin_cos(), yaw.sin_cos())
}

/// [`rotation_from_rpy`] from the angles' `(sin, cos)`: `R = Rz(yaw) Ry(pitch) Rx(roll)`.
///
/// The one place the product is written; callers that must reproduce a given rounding (the
/// generator, which turns the entries into exact rationals) pass sines and cosines computed with
/// `f64::sin_cos`.
pub fn rotation_from_rpy_sin_cos<T: RealField + Copy>(
    (sr, cr): (T, T),
    (sp, cp): (T, T),
    (sy, cy): (T, T),
) -> Matrix3<T> {
    Matrix3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

impl<T: RealField + Copy> Default for Se3<T> {
    fn default() -> Self {
        Self::identity()
    }
}

impl<T: RealField + Copy> Se3<T> {
    /// The transform `(R, p)`.
    #[inline]
    pub fn new(rotation: Matrix3<T>, translation: Vector3<T>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// The identity `(I, 0)`.
    #[inline]
    pub fn identity() -> Self {
        Self::new(Matrix3::identity(), Vector3::zeros())
    }

    /// A pure translation `(I, p)`.
    #[inline]
    pub fn from_translation(translation: Vector3<T>) -> Self {
        Self::new(Matrix3::identity(), translation)
    }

    /// URDF-style origin: translation `xyz` and rotation `Rz(yaw) Ry(pitch) Rx(roll)`.
    #[inline]
    pub fn from_xyz_rpy(xyz: Vector3<T>, rpy: Vector3<T>) -> Self {
        Self::new(rotation_from_rpy(rpy.x, rpy.y, rpy.z), xyz)
    }

    /// Composition `g h = (R_g R_h, R_g p_h + p_g)` (2.21).
    #[inline]
    pub fn compose(&self, other: &Self) -> Self {
        Self::new(
            self.rotation * other.rotation,
            self.rotation * other.translation + self.translation,
        )
    }

    /// Inverse `g⁻¹ = (Rᵀ, −Rᵀ p)`.
    #[inline]
    pub fn inverse(&self) -> Self {
        let rt = self.rotation.transpose();
        Self::new(rt, -(rt * self.translation))
    }

    /// `g⁻¹ h`, without forming `g⁻¹`.
    #[inline]
    pub fn inverse_compose(&self, other: &Self) -> Self {
        let rt = self.rotation.transpose();
        Self::new(
            rt * other.rotation,
            rt * (other.translation - self.translation),
        )
    }

    /// Action on a point: `R x + p`.
    #[inline]
    pub fn transform_point(&self, x: &Vector3<T>) -> Vector3<T> {
        self.rotation * x + self.translation
    }

    /// Action on a free vector: `R x`.
    #[inline]
    pub fn transform_vector(&self, x: &Vector3<T>) -> Vector3<T> {
        self.rotation * x
    }

    /// The homogeneous 4×4 matrix `[[R, p], [0, 1]]`.
    pub fn to_homogeneous(&self) -> Matrix4<T> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rotation);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        m
    }

    /// The transform of a homogeneous 4×4 matrix (the last row is not checked).
    pub fn from_homogeneous(m: &Matrix4<T>) -> Self {
        Self::new(
            m.fixed_view::<3, 3>(0, 0).into_owned(),
            m.fixed_view::<3, 1>(0, 3).into_owned(),
        )
    }

    /// `exp(ξ̂ θ)`, see [`exp_twist`].
    #[inline]
    pub fn exp(xi: &Twist<T>, theta: T) -> Self {
        exp_twist(xi, theta)
    }

    /// `log g` as a twist, see [`log`].
    #[inline]
    pub fn log(&self) -> Twist<T> {
        log(self)
    }

    /// The Adjoint of this transform (2.43).
    #[inline]
    pub fn adjoint(&self) -> Adjoint<T> {
        Adjoint(*self)
    }

    /// Converts an `f64` transform to this scalar type (e.g. to `f32`).
    pub fn from_f64(g: &Se3<f64>) -> Self {
        Se3::new(g.rotation.map(convert), g.translation.map(convert))
    }
}

impl<T: RealField + Copy> Mul for Se3<T> {
    type Output = Se3<T>;
    #[inline]
    fn mul(self, rhs: Self) -> Self {
        self.compose(&rhs)
    }
}

impl<T: RealField + Copy> Mul<&Se3<T>> for &Se3<T> {
    type Output = Se3<T>;
    #[inline]
    fn mul(self, rhs: &Se3<T>) -> Se3<T> {
        self.compose(rhs)
    }
}

/// The Adjoint `Ad_g` of a rigid transform (2.43): `Ad_g = [[R, p̂R], [0, R]]`, acting on twists
/// `(v, ω)`: `Ad_g ξ = (R v + p × R ω, R ω)`. It maps twists from the coordinates of frame `B` to
/// those of frame `A` for `g = g_AB`, and `Ad_g Ad_h = Ad_{gh}` (2.46), `Ad_g⁻¹ = Ad_{g⁻¹}` (2.45).
///
/// Applying it with [`Adjoint::apply`] / [`Adjoint::apply_inverse`] never forms the 6×6 matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adjoint<T: RealField + Copy>(pub Se3<T>);

impl<T: RealField + Copy> Adjoint<T> {
    /// `Ad_g ξ = (R v + p × R ω, R ω)` (2.43).
    #[inline]
    pub fn apply(&self, xi: &Twist<T>) -> Twist<T> {
        let g = &self.0;
        let w = g.rotation * angular(xi);
        let v = g.rotation * linear(xi) + g.translation.cross(&w);
        twist(&v, &w)
    }

    /// `Ad_g⁻¹ ξ = (Rᵀ (v − p × ω), Rᵀ ω)` (2.45).
    #[inline]
    pub fn apply_inverse(&self, xi: &Twist<T>) -> Twist<T> {
        let g = &self.0;
        let rt = g.rotation.transpose();
        let w = angular(xi);
        let v = rt * (linear(xi) - g.translation.cross(&w));
        twist(&v, &(rt * w))
    }

    /// The 6×6 matrix `[[R, p̂R], [0, R]]` (2.43).
    pub fn matrix(&self) -> Matrix6<T> {
        let g = &self.0;
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&g.rotation);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&g.rotation);
        m.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(hat(&g.translation) * g.rotation));
        m
    }

    /// The 6×6 matrix `Ad_g⁻¹ = [[Rᵀ, −Rᵀ p̂], [0, Rᵀ]]` (2.45).
    pub fn inverse_matrix(&self) -> Matrix6<T> {
        let g = &self.0;
        let rt = g.rotation.transpose();
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
        m.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-(rt * hat(&g.translation))));
        m
    }

    /// `Ad_g⁻¹` as an Adjoint: `Ad_{g⁻¹}` (2.45).
    #[inline]
    pub fn inverse(&self) -> Self {
        Adjoint(self.0.inverse())
    }
}

/// How far `r` is from a proper rotation: the largest entry of `|RᵀR − I|` and `det R`, or
/// `None` when an entry is not finite. A matrix is taken as a rotation where the first is within
/// a tolerance (the command line's and the C ABI's: [`ROTATION_TOLERANCE`]) and the second is
/// positive — a zero matrix or a reflection would be read as some other orientation.
pub fn rotation_defect<T: RealField + Copy>(r: &Matrix3<T>) -> Option<(T, T)> {
    if !r.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut worst = T::zero();
    for i in 0..3 {
        for j in 0..3 {
            let dot = r[(0, i)] * r[(0, j)] + r[(1, i)] * r[(1, j)] + r[(2, i)] * r[(2, j)];
            let target = if i == j { T::one() } else { T::zero() };
            worst = worst.max((dot - target).abs());
        }
    }
    let det = r[(0, 0)] * (r[(1, 1)] * r[(2, 2)] - r[(1, 2)] * r[(2, 1)])
        - r[(0, 1)] * (r[(1, 0)] * r[(2, 2)] - r[(1, 2)] * r[(2, 0)])
        + r[(0, 2)] * (r[(1, 0)] * r[(2, 1)] - r[(1, 1)] * r[(2, 0)]);
    Some((worst, det))
}

/// The largest entry of `|RᵀR − I|` a desired orientation may have (1e-6).
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Whether `r` is a proper rotation to [`ROTATION_TOLERANCE`] ([`rotation_defect`]).
pub fn is_rotation<T: RealField + Copy>(r: &Matrix3<T>) -> bool {
    let tolerance: T = nalgebra::convert(ROTATION_TOLERANCE);
    rotation_defect(r).is_some_and(|(worst, det)| worst <= tolerance && det > T::zero())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g1() -> Se3<f64> {
        Se3::new(
            exp_so3(&Vector3::new(0.3, -1.1, 0.7)),
            Vector3::new(0.2, -0.5, 1.3),
        )
    }

    #[test]
    fn hat_vee_round_trip() {
        let w = Vector3::new(1.0, -2.0, 3.0);
        assert_eq!(vee(&hat(&w)), w);
        let x = Vector3::new(0.4, 0.1, -0.9);
        assert!((hat(&w) * x - w.cross(&x)).norm() < 1e-15);
        let xi = Twist::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        assert_eq!(twist_vee(&twist_hat(&xi)), xi);
    }

    #[test]
    fn adjoint_matrix_matches_apply() {
        let g = g1();
        let xi = Twist::new(0.1, 0.2, -0.3, 0.7, -0.4, 0.5);
        let ad = g.adjoint();
        assert!((ad.matrix() * xi - ad.apply(&xi)).norm() < 1e-14);
        assert!((ad.inverse_matrix() * xi - ad.apply_inverse(&xi)).norm() < 1e-14);
        assert!((ad.matrix() * ad.inverse_matrix() - Matrix6::identity()).norm() < 1e-14);
    }

    #[test]
    fn exp_matches_closed_forms() {
        // Revolute (2.25) with unit ω.
        let w = Vector3::new(1.0, 2.0, -2.0) / 3.0;
        let q = Vector3::new(0.5, -0.1, 0.3);
        let xi = revolute_twist(&w, &q);
        let th = 1.234;
        let g = exp_twist(&xi, th);
        let r = exp_so3(&(w * th));
        let v = linear(&xi);
        let p = (Matrix3::identity() - r) * w.cross(&v) + w * w.dot(&v) * th;
        assert!((g.rotation - r).norm() < 1e-14);
        assert!((g.translation - p).norm() < 1e-14);
        // Prismatic (2.27).
        let d = Vector3::new(0.0, 0.6, 0.8);
        let g = exp_twist(&prismatic_twist(&d), 0.7);
        assert_eq!(g.rotation, Matrix3::identity());
        assert!((g.translation - d * 0.7).norm() < 1e-15);
        // Against the matrix exponential of ξ̂θ.
        let xi = Twist::new(0.3, -0.2, 0.9, 0.4, 0.5, -0.6);
        let m = (twist_hat(&xi) * 0.8).exp();
        assert!((exp_twist(&xi, 0.8).to_homogeneous() - m).norm() < 1e-12);
    }

    #[test]
    fn log_near_pi_and_zero() {
        for a in [
            0.0,
            1e-9,
            1e-4,
            0.5,
            3.0,
            core::f64::consts::PI - 1e-7,
            core::f64::consts::PI,
        ] {
            let w = Vector3::new(0.6, 0.0, -0.8) * a;
            let r = exp_so3(&w);
            let back = log_so3(&r);
            assert!((exp_so3(&back) - r).norm() < 1e-12, "a = {a}");
            if a < 3.0 {
                assert!((back - w).norm() < 1e-12, "a = {a}");
            }
        }
    }

    #[test]
    fn rpy_is_rz_ry_rx() {
        let (r, p, y) = (0.3, -0.7, 1.9);
        let m = exp_so3(&Vector3::new(0.0, 0.0, y))
            * exp_so3(&Vector3::new(0.0, p, 0.0))
            * exp_so3(&Vector3::new(r, 0.0, 0.0));
        assert!((rotation_from_rpy(r, p, y) - m).norm() < 1e-15);
    }
}
