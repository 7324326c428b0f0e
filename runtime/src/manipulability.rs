//! Manipulability `w = sqrt(|det(J Jᵀ)|)` (3.36), the product of the singular values of `J` (3.39);
//! for a square `J`, `w = |det J|`. Allocation-free.

use nalgebra::{RealField, SMatrix, SVector};

/// LU factorisation with partial pivoting, in place, of a square `n×n` matrix (column-major `a`,
/// `a.len() == n²`): afterwards `a` holds `U` on and above the diagonal and the multipliers of
/// the unit lower `L` below it, and `pivot(c, r)` has been called with the row `r ≥ c` swapped
/// into row `c` at column `c`. Returns `det a`; stops early with `0` at an exactly zero pivot
/// (the factors are then incomplete).
pub fn lu_in_place<T: RealField + Copy>(
    a: &mut [T],
    n: usize,
    mut pivot: impl FnMut(usize, usize),
) -> T {
    assert_eq!(a.len(), n * n, "an n×n matrix");
    let mut det = T::one();
    for c in 0..n {
        let mut best = c;
        for r in c + 1..n {
            if a[c * n + r].abs() > a[c * n + best].abs() {
                best = r;
            }
        }
        let p = a[c * n + best];
        if p == T::zero() {
            return T::zero();
        }
        pivot(c, best);
        if best != c {
            for k in 0..n {
                a.swap(k * n + c, k * n + best);
            }
            det = -det;
        }
        det *= p;
        for r in c + 1..n {
            a[c * n + r] /= p;
        }
        for k in c + 1..n {
            let v = a[k * n + c];
            if v != T::zero() {
                for r in c + 1..n {
                    let l = a[c * n + r];
                    a[k * n + r] -= l * v;
                }
            }
        }
    }
    det
}

/// The determinant of a square `n×n` matrix (column-major `a`, `a.len() == n²`) by Gaussian
/// elimination with partial pivoting ([`lu_in_place`]); `a` is destroyed.
pub fn determinant_in_place<T: RealField + Copy>(a: &mut [T], n: usize) -> T {
    lu_in_place(a, n, |_, _| {})
}

/// A square `J ∈ R^{D×D}` factored once (LU with partial pivoting), for the determinant and for
/// solving `J x = b` from the same factors: what a control step needs of a square Jacobian, its
/// manipulability `|det J|` (3.36) and its inverse applied to one vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SquareLu<T: RealField + Copy, const D: usize> {
    factors: SMatrix<T, D, D>,
    pivots: [usize; D],
    det: T,
}

impl<T: RealField + Copy, const D: usize> SquareLu<T, D> {
    /// Factors `m`.
    pub fn new(m: &SMatrix<T, D, D>) -> Self {
        let mut factors = *m;
        let mut pivots = [0; D];
        let det = lu_in_place(factors.as_mut_slice(), D, |c, r| pivots[c] = r);
        SquareLu {
            factors,
            pivots,
            det,
        }
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
        let a = self.factors.as_slice();
        let mut x = *b;
        for (c, &r) in self.pivots.iter().enumerate() {
            x.swap_rows(c, r);
        }
        for c in 0..D {
            let xc = x[c];
            for r in c + 1..D {
                x[r] -= a[c * D + r] * xc;
            }
        }
        for c in (0..D).rev() {
            x[c] /= a[c * D + c];
            let xc = x[c];
            for r in 0..c {
                x[r] -= a[c * D + r] * xc;
            }
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

/// The determinant of a square matrix (LU with partial pivoting).
pub fn determinant<T: RealField + Copy, const D: usize>(m: &SMatrix<T, D, D>) -> T {
    let mut a = *m;
    determinant_in_place(a.as_mut_slice(), D)
}

/// Manipulability (3.36): `w = sqrt(|det(J Jᵀ)|)`, the product of the singular values (3.39).
/// A square `J` gives `|det J|` directly (better conditioned than squaring), a tall one
/// `sqrt(|det(Jᵀ J)|)`.
pub fn manipulability<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
) -> T {
    if R == C {
        let mut a = *j;
        return determinant_in_place(a.as_mut_slice(), R).abs();
    }
    if R > C {
        // Tall: the product of the singular values is √|det(Jᵀ J)|.
        return determinant(&(j.transpose() * j)).abs().sqrt();
    }
    let jjt = j * j.transpose();
    determinant(&jjt).abs().sqrt()
}

/// Manipulability of a square Jacobian: `w = |det J|` (3.36).
pub fn manipulability_square<T: RealField + Copy, const D: usize>(j: &SMatrix<T, D, D>) -> T {
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
