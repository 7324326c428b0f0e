//! The Moore–Penrose pseudo-inverse `M†` of a full-rank fixed-size matrix, applied or formed: the
//! inverse when square (by [`Lu`]), `Mᵀ (M Mᵀ)⁻¹` when wide and `(Mᵀ M)⁻¹ Mᵀ` when tall (by
//! [`Cholesky`](super::Cholesky) of the Gram matrix, [`damped_solve`] with `κ = 0`). The
//! constraint's `Λ† = Λᵀ (Λ Λᵀ)⁻¹` (3.31), `(J^B_0i)†` of (3.7)/(3.10) and the controller's
//! pseudo-inverse (3.18) are all this one.

use super::damped::damped_solve;
use super::lu::{as_square, Lu, SquareDim};
use nalgebra::{Const, RealField, SMatrix};

/// `X = M† V` for a full-rank `M` (`R × C`) and `K` right-hand sides: the exact solution when
/// square (LU: solving `M` itself is better conditioned than its Gram matrix), the minimum-norm
/// solution `Mᵀ (M Mᵀ)⁻¹ V` when wide, the least-squares solution `(Mᵀ M)⁻¹ Mᵀ V` when tall.
/// `None` if `M` is rank-deficient to working precision (use damped least squares there,
/// [`damped_solve`]) or `X` is not finite.
pub fn pseudo_inverse_apply<T: RealField + Copy, const R: usize, const C: usize, const K: usize>(
    m: &SMatrix<T, R, C>,
    v: &SMatrix<T, R, K>,
) -> Option<SMatrix<T, C, K>>
where
    Const<R>: SquareDim,
{
    if R == C {
        let x = Lu::new(&as_square(m)).solve(v)?;
        Some(SMatrix::<T, C, K>::from_fn(|r, c| x[(r, c)]))
    } else {
        damped_solve(m, T::zero(), v)
    }
}

/// The Moore–Penrose inverse `M†` (`C × R`) of a full-rank `M` (`R × C`):
/// [`pseudo_inverse_apply`] to the identity. `None` if `M` is rank-deficient.
pub fn pseudo_inverse<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
) -> Option<SMatrix<T, C, R>>
where
    Const<R>: SquareDim,
{
    pseudo_inverse_apply(m, &SMatrix::<T, R, R>::identity())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Matrix6, SMatrix, Vector6};

    fn sample() -> SMatrix<f64, 6, 7> {
        SMatrix::<f64, 6, 7>::from_fn(|r, c| {
            ((r * 7 + c) as f64 * 0.731).sin() + if r == c { 2.0 } else { 0.0 }
        })
    }

    /// Against nalgebra's SVD pseudo-inverse (an independent computation), square, wide and tall;
    /// and the Penrose conditions that single out `M†`.
    #[test]
    fn matches_the_svd_pseudo_inverse() {
        let j = sample();
        let reference = nalgebra::linalg::SVD::new(j, true, true)
            .pseudo_inverse(1e-14)
            .unwrap();
        let p = pseudo_inverse(&j).unwrap();
        assert!((p - reference).norm() < 1e-10);
        assert!((j * p - Matrix6::identity()).norm() < 1e-12);
        let tall = j.transpose();
        let pt = pseudo_inverse(&tall).unwrap();
        assert!((pt - reference.transpose()).norm() < 1e-10);
        assert!((pt * tall - Matrix6::identity()).norm() < 1e-12);
        let v = Vector6::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
        assert!((pseudo_inverse_apply(&j, &v).unwrap() - reference * v).norm() < 1e-10);
        let m = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let p = pseudo_inverse(&m).unwrap();
        assert!((p - m.try_inverse().unwrap()).norm() < 1e-14);
        let w = SMatrix::<f64, 2, 3>::new(1.0, 2.0, 3.0, -1.0, 0.0, 2.0);
        let p = pseudo_inverse(&w).unwrap();
        assert!((w * p - Matrix2::identity()).norm() < 1e-14);
        assert!((p * w * p - p).norm() < 1e-14);
        assert!(((p * w).transpose() - p * w).norm() < 1e-14);
    }

    #[test]
    fn rank_deficient_has_none() {
        assert!(pseudo_inverse(&SMatrix::<f64, 2, 2>::zeros()).is_none());
        let mut s = sample();
        s.set_row(5, &(s.row(0) * 2.0));
        assert!(pseudo_inverse(&s).is_none());
        assert!(pseudo_inverse(&s.transpose()).is_none());
        let singular = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        assert!(pseudo_inverse(&singular).is_none());
    }
}
