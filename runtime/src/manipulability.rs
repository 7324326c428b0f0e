//! Manipulability `w = sqrt(|det(J Jᵀ)|)` (3.36), the product of the singular values of `J` (3.39);
//! for a square `J`, `w = |det J|`. Allocation-free; every determinant is the LU's of
//! [`crate::linalg`].

use crate::linalg::{as_square, determinant, SquareDim};
use nalgebra::{Const, RealField, SMatrix};

/// Manipulability (3.36): `w = sqrt(|det(J Jᵀ)|)`, the product of the singular values (3.39).
/// A square `J` gives `|det J|` directly (better conditioned than squaring), a tall one
/// `sqrt(|det(Jᵀ J)|)`.
pub fn manipulability<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
) -> T
where
    Const<R>: SquareDim,
    Const<C>: SquareDim,
{
    if R == C {
        return determinant(&as_square(j)).abs();
    }
    if R > C {
        // Tall: the product of the singular values is √|det(Jᵀ J)|.
        return determinant(&(j.transpose() * j)).abs().sqrt();
    }
    determinant(&(j * j.transpose())).abs().sqrt()
}

/// Manipulability of a square Jacobian: `w = |det J|` (3.36).
pub fn manipulability_square<T: RealField + Copy, const D: usize>(j: &SMatrix<T, D, D>) -> T
where
    Const<D>: SquareDim,
{
    determinant(j).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, SMatrix};

    #[test]
    fn matches_the_singular_values_and_the_determinant() {
        let m: Matrix3<f64> = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, -1.0, 1.0);
        assert!((determinant(&m) - m.determinant()).abs() < 1e-14);
        let j = SMatrix::<f64, 2, 3>::new(1.0, 2.0, 0.5, -1.0, 0.0, 2.0);
        let svd = j.svd(false, false);
        let prod: f64 = svd.singular_values.iter().product();
        assert!((manipulability(&j) - prod).abs() < 1e-13);
        assert!((manipulability(&m) - m.determinant().abs()).abs() < 1e-14);
        assert_eq!(manipulability_square(&Matrix3::<f64>::zeros()), 0.0);
    }
}
