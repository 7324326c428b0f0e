//! LU factorisation with partial pivoting of a fixed-size square matrix, `P J = L U`: the
//! determinant (for the manipulability of a square Jacobian, `w = |det J|` (3.36)) and `J x = b`
//! from the same factors.

use nalgebra::{Const, DimMin, RealField, SMatrix, LU};

/// The square sizes `Const<D>` that nalgebra factors at compile-time size (`min(D, D) = D`; every
/// `D` up to 127). Write `where Const<D>: SquareDim` on a function generic over a size `D` that
/// calls [`Lu`] or [`determinant`], or anything built on them.
pub trait SquareDim: DimMin<Self, Output = Self> {}

impl<D: DimMin<D, Output = D>> SquareDim for D {}

/// A square `J ∈ R^{D×D}` factored once (nalgebra's fixed-size LU with partial pivoting), for the
/// determinant and for solving `J X = B` from the same factors: what a control step needs of a
/// square Jacobian, its manipulability `|det J|` (3.36) and its inverse applied to one vector.
#[derive(Clone, Debug)]
pub struct Lu<T: RealField + Copy, const D: usize>
where
    Const<D>: SquareDim,
{
    lu: LU<T, Const<D>, Const<D>>,
    det: T,
}

impl<T: RealField + Copy, const D: usize> Lu<T, D>
where
    Const<D>: SquareDim,
{
    /// Factors `m`.
    pub fn new(m: &SMatrix<T, D, D>) -> Self {
        let lu = LU::new(*m);
        let det = lu.determinant();
        Lu { lu, det }
    }

    /// `det J`, the product of `U`'s diagonal with the sign of the row permutation.
    pub fn determinant(&self) -> T {
        self.det
    }

    /// `X = J⁻¹ B` for the `K` columns of `B`; `None` if `J` is singular (a zero pivot) or `X` is
    /// not finite.
    pub fn solve<const K: usize>(&self, b: &SMatrix<T, D, K>) -> Option<SMatrix<T, D, K>> {
        if self.det == T::zero() {
            return None;
        }
        self.lu
            .solve::<Const<D>, Const<K>, _>(b)
            .filter(|x| x.iter().all(|v| v.is_finite()))
    }
}

/// The determinant of a square matrix (LU with partial pivoting).
pub fn determinant<T: RealField + Copy, const D: usize>(m: &SMatrix<T, D, D>) -> T
where
    Const<D>: SquareDim,
{
    Lu::new(m).determinant()
}

/// The `R × R` matrix whose entries are those of `m` (`R × C` with `R = C`): a square matrix seen
/// at its own size where a function generic over a shape has found `R = C` at run time.
///
/// # Panics
/// If `R ≠ C`.
pub(crate) fn as_square<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
) -> SMatrix<T, R, R> {
    assert_eq!(R, C, "a square matrix");
    SMatrix::<T, R, R>::from_fn(|r, c| m[(r, c)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

    #[test]
    fn solves_and_agrees_with_nalgebra() {
        // Needs row swaps: a zero leading entry and a larger entry below the diagonal.
        let m = Matrix4::<f64>::new(
            0.0, 2.0, 1.0, -1.0, 3.0, 1.0, 0.0, 2.0, 1.0, -1.0, 4.0, 0.5, 2.0, 0.0, 1.0, 1.0,
        );
        let lu = Lu::new(&m);
        assert!((lu.determinant() - m.determinant()).abs() < 1e-13);
        assert!((determinant(&m) - m.determinant()).abs() < 1e-13);
        let b = Vector4::new(1.0, -2.0, 0.5, 3.0);
        let x = lu.solve(&b).unwrap();
        assert!((m * x - b).norm() < 1e-13);
        assert!((x - m.lu().solve(&b).unwrap()).norm() < 1e-13);
        // Several right-hand sides at once: the inverse.
        let inv = lu.solve(&Matrix4::identity()).unwrap();
        assert!((m * inv - Matrix4::identity()).norm() < 1e-13);
        let singular = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        let lu = Lu::new(&singular);
        assert_eq!(lu.determinant(), 0.0);
        assert_eq!(lu.solve(&Vector3::new(1.0, 0.0, 0.0)), None);
        let mut nan = Matrix3::identity();
        nan[(0, 0)] = f64::NAN;
        assert_eq!(Lu::new(&nan).solve(&Vector3::new(1.0, 1.0, 1.0)), None);
    }
}
