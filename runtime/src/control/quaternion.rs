//! Unit quaternions `Q = {η, ε}` as the thesis writes them (2.11)–(2.16), and the orientation
//! error `e_q = Q_d ⊗ Q⁻¹` (2.62)–(2.63).
//!
//! Two misprints of the extracted thesis text are corrected here: (2.13) lacks the factor `1/2`
//! in front of each square root (`ε_1 = ½ sgn(r32 − r23) √(r11 − r22 − r33 + 1)`, …), and the
//! scalar part of the product (2.16) reads `η1 η2 + ε1ᵀ ε2`; the product of rotations needs
//! `η1 η2 − ε1ᵀ ε2` (checked in the tests against `R(Q1 ⊗ Q2) = R1 R2`). The quaternion of a
//! matrix is not computed as (2.12)–(2.14) write it, which breaks down near a half turn (see
//! [`Quaternion::from_rotation`]).

use nalgebra::{Matrix3, RealField, Vector3};

/// A unit quaternion `Q = {η, ε}`: scalar part `η`, vector part `ε`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quaternion<T: RealField + Copy> {
    /// Scalar part `η`.
    pub eta: T,
    /// Vector part `ε`.
    pub eps: Vector3<T>,
}

impl<T: RealField + Copy> Quaternion<T> {
    /// The identity `Q_I = {1, 0}`.
    pub fn identity() -> Self {
        Quaternion {
            eta: T::one(),
            eps: Vector3::zeros(),
        }
    }

    /// The quaternion of a rotation matrix, with `η ≥ 0` (rotation angle in `[−π, π]`).
    ///
    /// (2.12)–(2.14) take every component from a square root of the diagonal and its sign from
    /// an off-diagonal difference. Both fail in floating point: near a half turn (`η → 0`) the
    /// differences `r32 − r23`, … are rounding noise and the signs come out independently wrong
    /// (a different rotation, not just `−Q`), and a small component from `√(1 + r11 − r22 − r33)`
    /// keeps only half the digits. So the largest of `η, |ε1|, |ε2|, |ε3|` is taken from its
    /// square root, as in (2.12)–(2.13), and the other three from the off-diagonal sums and
    /// differences divided by it (Shepperd's method), which is exact to rounding everywhere.
    pub fn from_rotation(r: &Matrix3<T>) -> Self {
        let quarter: T = nalgebra::convert(0.25);
        let one = T::one();
        let (r11, r22, r33) = (r[(0, 0)], r[(1, 1)], r[(2, 2)]);
        // 4η², 4ε1², 4ε2², 4ε3² from the diagonal; the largest is at least 1.
        let d = [
            one + r11 + r22 + r33,
            one + r11 - r22 - r33,
            one - r11 + r22 - r33,
            one - r11 - r22 + r33,
        ];
        let k = (1..4).fold(0, |k, j| if d[j] > d[k] { j } else { k });
        // `s` = 4 × the largest component, so each other component is a sum or difference / s.
        let s = d[k].sqrt() * nalgebra::convert::<f64, T>(2.0);
        let (a, b, c) = (
            r[(2, 1)] - r[(1, 2)], // 4 η ε1
            r[(0, 2)] - r[(2, 0)], // 4 η ε2
            r[(1, 0)] - r[(0, 1)], // 4 η ε3
        );
        let (e, f, g) = (
            r[(1, 0)] + r[(0, 1)], // 4 ε1 ε2
            r[(0, 2)] + r[(2, 0)], // 4 ε1 ε3
            r[(2, 1)] + r[(1, 2)], // 4 ε2 ε3
        );
        let inv = T::one() / s;
        let (eta, e1, e2, e3) = match k {
            0 => (quarter * s, a * inv, b * inv, c * inv),
            1 => (a * inv, quarter * s, e * inv, f * inv),
            2 => (b * inv, e * inv, quarter * s, g * inv),
            _ => (c * inv, f * inv, g * inv, quarter * s),
        };
        if eta < T::zero() {
            Quaternion {
                eta: -eta,
                eps: Vector3::new(-e1, -e2, -e3),
            }
        } else {
            Quaternion {
                eta,
                eps: Vector3::new(e1, e2, e3),
            }
        }
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
///
/// Computed as the quaternion of the product `R_Δ` rather than as the product of two
/// quaternions: one extraction instead of two, and while tracking `R_Δ` is near the identity,
/// where the extraction is best conditioned.
pub fn orientation_error<T: RealField + Copy>(
    desired: &Matrix3<T>,
    current: &Matrix3<T>,
) -> Quaternion<T> {
    Quaternion::from_rotation(&(desired * current.transpose()))
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

    /// Two rotations a few 1e-8 rad apart near a half turn (the Panda laparoscope's start pose:
    /// the tip's z pointing down) have a small error, in f64 and f32. (2.12)–(2.14) as printed
    /// take the signs of `ε` from off-diagonal differences that are rounding noise there, and
    /// gave an error of a whole rotation.
    #[test]
    fn error_is_small_between_nearby_half_turns() {
        let base = rot(
            [0.9238795325112867, -0.3826834323650898, 0.0],
            std::f64::consts::PI,
        );
        for (axis, angle) in [
            ([1.0, 0.0, 0.0], 3e-8),
            ([0.0, 1.0, 0.0], -5e-8),
            ([0.3, -0.2, 0.9], 2e-8),
            ([0.0, 0.0, 1.0], 1e-3),
        ] {
            let rd = rot(axis, angle) * base;
            let e = orientation_error(&rd, &base);
            let want = Unit::new_normalize(Vector3::from(axis)).into_inner() * (angle / 2.0).sin();
            assert!(
                (e.eps - want).norm() < 1e-15,
                "{axis:?} {angle}: {:?}",
                e.eps
            );
            let e32 = orientation_error(&rd.cast::<f32>(), &base.cast::<f32>());
            assert!(
                (e32.eps.cast::<f64>() - want).norm() < 1e-6,
                "f32 {axis:?} {angle}: {:?}",
                e32.eps
            );
        }
    }

    /// Small components keep their digits: a 1e-9 rad rotation's `ε` to 1e-6 relative (the
    /// square roots of (2.13) keep about half of them).
    #[test]
    fn small_rotations_keep_their_digits() {
        for (axis, angle) in [([0.2, -0.5, 0.9], 1e-9), ([1.0, 1.0, 0.0], 1e-6)] {
            let q = Quaternion::from_rotation(&rot(axis, angle));
            let want = Unit::new_normalize(Vector3::from(axis)).into_inner() * (angle / 2.0).sin();
            assert!((q.eps - want).norm() <= 1e-6 * want.norm(), "{:?}", q.eps);
        }
    }

    /// Every branch of the extraction (the largest of `η, |ε1|, |ε2|, |ε3|`) round-trips.
    #[test]
    fn every_branch_round_trips() {
        for (axis, angle) in [
            ([1.0, 0.0, 0.0], 3.0),
            ([0.0, 1.0, 0.0], -3.0),
            ([0.0, 0.0, 1.0], 3.1),
            ([0.5, 0.5, 0.7], std::f64::consts::PI),
            ([0.1, 0.2, 0.3], 0.5),
        ] {
            let r = rot(axis, angle);
            let q = Quaternion::from_rotation(&r);
            assert!(q.eta >= 0.0);
            assert!((q.to_rotation() - r).norm() < 1e-14, "{axis:?} {angle}");
        }
    }
}
