//! The root-free Cholesky factorisation `A = L D Lᵀ` of a fixed-size symmetric positive definite
//! matrix, and the Gram matrices `J Jᵀ + κ² I` it factors for the least-squares inverses
//! (3.43), (3.46).

use nalgebra::{convert, RealField, SMatrix};

/// The root-free Cholesky factorisation `A = L D Lᵀ` (`L` unit lower triangular, `D` diagonal)
/// of a symmetric positive definite `A` of fixed size `D`, with forward and back substitution
/// for `A X = B`: the Gram matrices of the least-squares inverses.
///
/// Root-free because each square root of `A = L Lᵀ` lies on the chain of dependent operations
/// that bounds a control step's latency; `sqrt(det A)` takes one at the end. Written out over the
/// fixed size (the compiler unrolls it for a 6 × 6 Gram matrix) rather than through
/// `nalgebra::Cholesky`, whose loops over matrix views dominated a control step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cholesky<T: RealField + Copy, const D: usize> {
    /// `L` below the diagonal, row by row (`l[i][k]`, `k < i`; the rest is not used).
    l: [[T; D]; D],
    /// `1 / D_kk`.
    inv_d: [T; D],
    /// `sqrt(Π D_kk)`.
    sqrt_det: T,
}

impl<T: RealField + Copy, const D: usize> Cholesky<T, D> {
    /// Factors `a` (only its lower triangle is read). `None` unless `a` is positive definite to
    /// working precision: every pivot finite and `D_jj > D ε A_jj` (`ε` the machine epsilon of
    /// `T`). `D_jj / A_jj` is the squared sine of the angle between row `j` of `J` and the span
    /// of the rows before it when `A = J Jᵀ`; below `D ε` it is rounding noise, and so would be
    /// the solution.
    pub fn new(a: &SMatrix<T, D, D>) -> Option<Self> {
        let tol = T::default_epsilon() * convert::<f64, T>(D as f64);
        let mut l = [[T::zero(); D]; D];
        for (i, row) in l.iter_mut().enumerate() {
            for (k, v) in row.iter_mut().enumerate().take(i + 1) {
                *v = a[(i, k)];
            }
        }
        let mut inv_d = [T::zero(); D];
        let mut det = T::one();
        // Tested once at the end: the loop stays free of branches.
        let mut positive = true;
        for j in 0..D {
            let (above, rest) = l.split_at_mut(j);
            let row = &mut rest[0];
            // Row j of W = L D left of the diagonal, from the rows above (already L).
            for k in 0..j {
                let mut w = row[k];
                for m in 0..k {
                    w -= row[m] * above[k][m];
                }
                row[k] = w;
            }
            let ajj = row[j];
            let mut dj = ajj;
            for k in 0..j {
                let ljk = row[k] * inv_d[k];
                dj -= ljk * row[k];
                row[k] = ljk;
            }
            // A NaN pivot fails the comparison too.
            positive &= dj > tol * ajj && dj.is_finite() && ajj.is_finite();
            det *= dj;
            inv_d[j] = T::one() / dj;
        }
        positive.then(|| Cholesky {
            l,
            inv_d,
            sqrt_det: det.sqrt(),
        })
    }

    /// `sqrt(det A) = sqrt(Π D_kk)`; for `A = J Jᵀ` the manipulability of `J` (3.36).
    pub fn sqrt_determinant(&self) -> T {
        self.sqrt_det
    }

    /// `X = A⁻¹ B` by `L Y = B`, `D Z = Y`, `Lᵀ X = Z`, for each of the `K` columns of `B`.
    pub fn solve<const K: usize>(&self, b: &SMatrix<T, D, K>) -> SMatrix<T, D, K> {
        let mut out = *b;
        for c in 0..K {
            let mut x = [T::zero(); D];
            for (i, v) in x.iter_mut().enumerate() {
                *v = b[(i, c)];
            }
            for i in 0..D {
                let (done, rest) = x.split_at_mut(i);
                let row = &self.l[i];
                rest[0] = done
                    .iter()
                    .zip(row)
                    .fold(rest[0], |v, (xk, lik)| v - *lik * *xk);
            }
            for i in (0..D).rev() {
                let (head, done) = x.split_at_mut(i + 1);
                head[i] = done
                    .iter()
                    .zip(&self.l[i + 1..])
                    .fold(head[i] * self.inv_d[i], |v, (xk, lk)| v - lk[i] * *xk);
            }
            for (i, v) in x.iter().enumerate() {
                out[(i, c)] = *v;
            }
        }
        out
    }
}

/// The lower triangle of the Gram matrix `J Jᵀ + κ² I` (given `k2 = κ²`; the upper triangle is
/// left zero: only [`Cholesky`] reads it).
pub(crate) fn gram_lower<T: RealField + Copy, const R: usize, const C: usize>(
    j: &SMatrix<T, R, C>,
    k2: T,
) -> SMatrix<T, R, R> {
    let mut a = SMatrix::<T, R, R>::zeros();
    for c in 0..C {
        for k in 0..R {
            let x = j[(k, c)];
            for i in k..R {
                a[(i, k)] += j[(i, c)] * x;
            }
        }
    }
    for i in 0..R {
        a[(i, i)] += k2;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SMatrix<f64, 6, 7> {
        SMatrix::<f64, 6, 7>::from_fn(|r, c| {
            ((r * 7 + c) as f64 * 0.731).sin() + if r == c { 2.0 } else { 0.0 }
        })
    }

    /// The factors agree with nalgebra's Cholesky (solve, `sqrt(det)`), and matrices that are not
    /// positive definite, or not finite, are refused.
    #[test]
    fn matches_nalgebra_and_refuses_indefinite() {
        let j = sample();
        let a = j * j.transpose();
        let ours = Cholesky::new(&a).expect("positive definite");
        let theirs = nalgebra::Cholesky::new(a).unwrap();
        let b = SMatrix::<f64, 6, 2>::from_fn(|i, c| (i as f64 - 2.0) * (c as f64 + 0.5));
        assert!((ours.solve(&b) - theirs.solve(&b)).norm() < 1e-12);
        assert!((a * ours.solve(&b) - b).norm() < 1e-12);
        assert!((ours.sqrt_determinant() - a.determinant().sqrt()).abs() < 1e-12);
        let mut indefinite = a;
        indefinite[(3, 3)] = -1.0;
        assert!(Cholesky::new(&indefinite).is_none());
        let mut nan = a;
        nan[(5, 5)] = f64::NAN;
        assert!(Cholesky::new(&nan).is_none());
        let mut inf = a;
        inf[(0, 0)] = f64::INFINITY;
        assert!(Cholesky::new(&inf).is_none());
        assert!(Cholesky::new(&SMatrix::<f64, 3, 3>::zeros()).is_none());
    }

    #[test]
    fn gram_lower_is_the_lower_triangle_of_j_jt_plus_k2() {
        let j = sample();
        let full = j * j.transpose() + SMatrix::<f64, 6, 6>::identity() * 0.09;
        let lower = gram_lower(&j, 0.09);
        for r in 0..6 {
            for c in 0..6 {
                let want = if c <= r { full[(r, c)] } else { 0.0 };
                assert!((lower[(r, c)] - want).abs() < 1e-14, "({r}, {c})");
            }
        }
    }
}
