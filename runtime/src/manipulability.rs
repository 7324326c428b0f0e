//! Manipulability `w = sqrt(|det(J Jᵀ)|)` (3.36), the product of the singular values of `J` (3.39);
//! for a square `J`, `w = |det J|`. Allocation-free; every factorisation is nalgebra's fixed-size
//! LU with partial pivoting.

use nalgebra::{Const, DimMin, RealField, SMatrix, SVector, LU};

/// The square sizes `Const<D>` that nalgebra factors at compile-time size (`min(D, D) = D`; every
/// `D` up to 127). Write `where Const<D>: SquareDim` on a function generic over a size `D` that
/// calls [`SquareLu`], [`determinant`] or [`manipulability`].
pub trait SquareDim: DimMin<Self, Output = Self> {}

impl<D: DimMin<D, Output = D>> SquareDim for D {}

/// A square `J ∈ R^{D×D}` factored once (nalgebra's LU with partial pivoting), for the
/// determinant and for solving `J x = b` from the same factors: what a control step needs of a
/// square Jacobian, its manipulability `|det J|` (3.36) and its inverse applied to one vector.
#[derive(Clone, Debug)]
pub struct SquareLu<T: RealField + Copy, const D: usize>
where
    Const<D>: SquareDim,
{
    lu: LU<T, Const<D>, Const<D>>,
    det: T,
}

impl<T: RealField + Copy, const D: usize> SquareLu<T, D>
where
    Const<D>: SquareDim,
{
    /// Factors `m`.
    pub fn new(m: &SMatrix<T, D, D>) -> Self {
        let lu = LU::new(*m);
        let det = lu.determinant();
        SquareLu { lu, det }
    }

    /// `det J`.
    pub fn determinant(&self) -> T {
        self.det
    }

    /// `x = J⁻¹ b`; `None` if `J` is singular (a zero pivot) or `x` is not finite.
    pub fn solve(&self, b: &SVector<T, D>) -> Option<SVector<T, D>> {
        if self.det == T::zero() {
            return None;
        }
        self.lu
            .solve::<Const<D>, Const<1>, _>(b)
            .filter(|x| x.iter().all(|v| v.is_finite()))
    }
}

/// The determinant of a square matrix (LU with partial pivoting).
pub fn determinant<T: RealField + Copy, const D: usize>(m: &SMatrix<T, D, D>) -> T
where
    Const<D>: SquareDim,
{
    LU::new(*m).determinant()
}

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
        let square = SMatrix::<T, R, R>::from_fn(|r, c| j[(r, c)]);
        return determinant(&square).abs();
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
    fn determinant_matches_nalgebra() {
        let m: Matrix3<f64> = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, -1.0, 1.0);
        assert!((determinant(&m) - m.determinant()).abs() < 1e-14);
        let j = SMatrix::<f64, 2, 3>::new(1.0, 2.0, 0.5, -1.0, 0.0, 2.0);
        let svd = j.svd(false, false);
        let prod: f64 = svd.singular_values.iter().product();
        assert!((manipulability(&j) - prod).abs() < 1e-13);
        assert!((manipulability(&m) - m.determinant().abs()).abs() < 1e-14);
        assert_eq!(manipulability_square(&Matrix3::<f64>::zeros()), 0.0);
    }

    #[test]
    fn square_lu_solves_and_agrees_with_nalgebra() {
        // Needs row swaps: a zero leading entry and a larger entry below the diagonal.
        let m = nalgebra::Matrix4::<f64>::new(
            0.0, 2.0, 1.0, -1.0, 3.0, 1.0, 0.0, 2.0, 1.0, -1.0, 4.0, 0.5, 2.0, 0.0, 1.0, 1.0,
        );
        let lu = SquareLu::new(&m);
        assert!((lu.determinant() - m.determinant()).abs() < 1e-13);
        let b = nalgebra::Vector4::new(1.0, -2.0, 0.5, 3.0);
        let x = lu.solve(&b).unwrap();
        assert!((m * x - b).norm() < 1e-13);
        assert!((x - m.lu().solve(&b).unwrap()).norm() < 1e-13);
        let singular = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        let lu = SquareLu::new(&singular);
        assert_eq!(lu.determinant(), 0.0);
        assert_eq!(lu.solve(&nalgebra::Vector3::new(1.0, 0.0, 0.0)), None);
        let nan = SquareLu::new(&Matrix3::new(
            f64::NAN,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
            0.0,
            1.0,
        ));
        assert_eq!(nan.solve(&nalgebra::Vector3::new(1.0, 1.0, 1.0)), None);
    }
}
