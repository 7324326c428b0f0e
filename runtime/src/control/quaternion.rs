//! Unit quaternions `Q = {η, ε}` as the thesis writes them (2.11)–(2.16), and the orientation
//! error `e_q = Q_d ⊗ Q⁻¹` (2.62)–(2.63).
//!
//! Two misprints of the extracted thesis text are corrected here: (2.13) lacks the factor `1/2`
//! in front of each square root (`ε_1 = ½ sgn(r32 − r23) √(r11 − r22 − r33 + 1)`, …), and the
//! scalar part of the product (2.16) reads `η1 η2 + ε1ᵀ ε2`; the product of rotations needs
//! `η1 η2 − ε1ᵀ ε2` (checked in the tests against `R(Q1 ⊗ Q2) = R1 R2`).

use nalgebra::{Matrix3, RealField, Vector3};

/// A unit quaternion `Q = {η, ε}`: scalar part `η`, vector part `ε`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quaternion<T: RealField + Copy> {
    /// Scalar part `η`.
    pub eta: T,
    /// Vector part `ε`.
    pub eps: Vector3<T>,
}

/// `sgn(x)` of (2.14): `1` for `x ≥ 0`, `−1` otherwise.
fn sgn<T: RealField + Copy>(x: T) -> T {
    if x >= T::zero() {
        T::one()
    } else {
        -T::one()
    }
}

/// `√max(x, 0)`: rounding can make the radicands of (2.12)–(2.13) slightly negative.
fn sqrt0<T: RealField + Copy>(x: T) -> T {
    if x > T::zero() {
        x.sqrt()
    } else {
        T::zero()
    }
}

impl<T: RealField + Copy> Quaternion<T> {
    /// The identity `Q_I = {1, 0}`.
    pub fn identity() -> Self {
        Quaternion {
            eta: T::one(),
            eps: Vector3::zeros(),
        }
    }

    /// The quaternion of a rotation matrix (2.12)–(2.14), with `η ≥ 0` (rotation angle in `[−π, π]`).
    pub fn from_rotation(r: &Matrix3<T>) -> Self {
        let half: T = nalgebra::convert(0.5);
        let one = T::one();
        let (r11, r22, r33) = (r[(0, 0)], r[(1, 1)], r[(2, 2)]);
        let eta = half * sqrt0(r11 + r22 + r33 + one);
        let eps = Vector3::new(
            half * sgn(r[(2, 1)] - r[(1, 2)]) * sqrt0(r11 - r22 - r33 + one),
            half * sgn(r[(0, 2)] - r[(2, 0)]) * sqrt0(r22 - r11 - r33 + one),
            half * sgn(r[(1, 0)] - r[(0, 1)]) * sqrt0(r33 - r11 - r22 + one),
        );
        Quaternion { eta, eps }
    }

    /// The rotation matrix `R(η, ε) = I + 2η ε̂ + 2 ε̂ ε̂` (2.11).
    pub fn to_rotation(&self) -> Matrix3<T> {
        let two: T = nalgebra::convert(2.0);
        let e = self.eps.cross_matrix();
        Matrix3::identity() + e * (two * self.eta) + e * e * two
    }

    /// The inverse `Q⁻¹ = {η, −ε}` (2.15), the quaternion of `Rᵀ`.
    pub fn inverse(&self) -> Self {
        Quaternion {
            eta: self.eta,
            eps: -self.eps,
        }
    }

    /// The product `Q1 ⊗ Q2 = {η1 η2 − ε1ᵀ ε2, η1 ε2 + η2 ε1 + ε1 × ε2}` (2.16, sign corrected):
    /// the quaternion of `R1 R2`.
    pub fn mul(&self, other: &Self) -> Self {
        Quaternion {
            eta: self.eta * other.eta - self.eps.dot(&other.eps),
            eps: other.eps * self.eta + self.eps * other.eta + self.eps.cross(&other.eps),
        }
    }
}

/// The orientation error `e_q = Q_d ⊗ Q⁻¹ = {η̃, ε̃}` of (2.62)–(2.63): the quaternion of
/// `R_Δ = dR_0e R_0eᵀ` (its vector part is in base coordinates). The sign is chosen so that
/// `η̃ ≥ 0` (the shorter of the two rotations `±e_q`, which represent the same `R_Δ`).
pub fn orientation_error<T: RealField + Copy>(
    desired: &Matrix3<T>,
    current: &Matrix3<T>,
) -> Quaternion<T> {
    let e = Quaternion::from_rotation(desired).mul(&Quaternion::from_rotation(current).inverse());
    if e.eta < T::zero() {
        Quaternion {
            eta: -e.eta,
            eps: -e.eps,
        }
    } else {
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    fn rot(axis: [f64; 3], angle: f64) -> Matrix3<f64> {
        Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::from(axis)), angle).into_inner()
    }

    #[test]
    fn round_trip_and_product_match_rotations() {
        let cases = [
            ([1.0, 0.0, 0.0], 0.3),
            ([0.2, -0.5, 0.9], 2.9),
            ([0.0, 1.0, 0.0], -1.4),
            ([-0.7, 0.1, 0.3], 3.1),
            ([0.3, 0.3, -0.9], 0.0),
        ];
        for (a, t) in cases {
            let r = rot(a, t);
            let q = Quaternion::from_rotation(&r);
            assert!(q.eta >= 0.0);
            assert!((q.eta * q.eta + q.eps.norm_squared() - 1.0).abs() < 1e-12);
            assert!((q.to_rotation() - r).norm() < 1e-12, "{a:?} {t}");
            for (b, s) in cases {
                let r2 = rot(b, s);
                let p = q.mul(&Quaternion::from_rotation(&r2));
                assert!((p.to_rotation() - r * r2).norm() < 1e-12);
            }
            assert!((q.inverse().to_rotation() - r.transpose()).norm() < 1e-12);
        }
    }

    #[test]
    fn error_is_identity_when_aligned_and_half_angle_otherwise() {
        let r = rot([0.2, -0.5, 0.9], 1.0);
        let e = orientation_error(&r, &r);
        assert!((e.eta - 1.0).abs() < 1e-12 && e.eps.norm() < 1e-12);
        // R_d = Rx(0.2) R: the error is a rotation of 0.2 rad about base x.
        let rd = rot([1.0, 0.0, 0.0], 0.2) * r;
        let e = orientation_error(&rd, &r);
        assert!((e.eps - Vector3::new((0.1f64).sin(), 0.0, 0.0)).norm() < 1e-12);
        // Both signs of a near-π rotation give η̃ ≥ 0.
        let rd = rot([0.0, 0.0, 1.0], 3.13) * r;
        assert!(orientation_error(&rd, &r).eta >= 0.0);
    }
}
