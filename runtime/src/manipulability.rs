//! Manipulability `w = sqrt(|det(J Jᵀ)|)` (3.36), the product of the singular values of `J` (3.39);
//! for a square `J`, `w = |det J|`. Allocation-free.

use nalgebra::{RealField, SMatrix};

/// The determinant of a square `n×n` matrix (column-major `a`, `a.len() == n²`) by Gaussian
/// elimination with partial pivoting; `a` is destroyed.
pub fn determinant_in_place<T: RealField + Copy>(a: &mut [T], n: usize) -> T {
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
        if best != c {
            for k in 0..n {
                a.swap(k * n + c, k * n + best);
            }
            det = -det;
        }
        det *= p;
        for r in c + 1..n {
            let f = a[c * n + r] / p;
            for k in c + 1..n {
                let v = a[k * n + c];
                a[k * n + r] -= f * v;
            }
        }
    }
    det
}

/// The determinant of a square matrix (LU with partial pivoting).
pub fn determinant<T: RealField + Copy, const D: usize>(m: &SMatrix<T, D, D>) -> T {
    let mut a = *m;
    determinant_in_place(a.as_mut_slice(), D)
}

/// Manipulability (3.36): `w = sqrt(|det(J Jᵀ)|)`. For a wide `J` of full row rank, the product of
/// its singular values (3.39). For a square `J` this equals `|det J|` (see [`manipulability_square`],
/// better conditioned).
pub fn manipulability<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
) -> T {
    if R == C {
        let mut a = *j;
        return determinant_in_place(a.as_mut_slice(), R).abs();
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
}
