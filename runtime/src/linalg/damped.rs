//! Damped least squares `X = J†_κ V = Jᵀ (J Jᵀ + κ² I)⁻¹ V` (3.43), (3.46): one Cholesky
//! factorisation of the Gram matrix, `J†_κ` never formed.

use super::cholesky::{gram_lower, Cholesky};
use nalgebra::{RealField, SMatrix};

/// `X = J†_κ V = Jᵀ (J Jᵀ + κ² I)⁻¹ V` (3.43), (3.46), computed as `(Jᵀ J + κ² I)⁻¹ Jᵀ V` when
/// `J` is tall (the same matrix for `κ > 0`, and the smaller Gram matrix), for `K` right-hand
/// sides, without forming `J†_κ` (a control step has one, `V = v`): one [`Cholesky`]
/// factorisation of the Gram matrix. With `κ = 0` it is the Moore–Penrose pseudo-inverse of a
/// full-rank `J` applied to `V` by its normal equations; `V = I` gives `J†_κ` itself. `None` if
/// the Gram matrix is not positive definite (a rank-deficient `J` with `κ = 0`) or `X` is not
/// finite.
pub fn damped_solve<T: RealField + Copy, const R: usize, const C: usize, const K: usize>(
    j: &SMatrix<T, R, C>,
    kappa: T,
    v: &SMatrix<T, R, K>,
) -> Option<SMatrix<T, C, K>> {
    let k2 = kappa * kappa;
    let x = if R <= C {
        j.tr_mul(&Cholesky::new(&gram_lower(j, k2))?.solve(v))
    } else {
        Cholesky::new(&gram_lower(&j.transpose(), k2))?.solve(&j.tr_mul(v))
    };
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix6, SMatrix, Vector6};

    fn sample() -> SMatrix<f64, 6, 7> {
        SMatrix::<f64, 6, 7>::from_fn(|r, c| {
            ((r * 7 + c) as f64 * 0.731).sin() + if r == c { 2.0 } else { 0.0 }
        })
    }

    /// `J†_κ` against its definition computed independently: nalgebra's SVD,
    /// `J†_κ = V diag(σ / (σ² + κ²)) Uᵀ` — for a wide `J` and its transpose.
    #[test]
    fn agrees_with_the_svd_form() {
        let j = sample();
        let v = Vector6::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
        for kappa in [0.0, 0.05, 0.3] {
            let svd = nalgebra::linalg::SVD::new(j, true, true);
            let s = svd.singular_values.map(|s| s / (s * s + kappa * kappa));
            let reference = svd.v_t.unwrap().transpose()
                * Matrix6::from_diagonal(&s)
                * svd.u.unwrap().transpose();
            let x = damped_solve(&j, kappa, &v).unwrap();
            assert!((x - reference * v).norm() < 1e-12, "κ = {kappa}");
            let whole = damped_solve(&j, kappa, &Matrix6::identity()).unwrap();
            assert!((whole - reference).norm() < 1e-12, "κ = {kappa}");
            let tall = j.transpose();
            let w = SMatrix::<f64, 7, 1>::from_fn(|r, _| (r as f64 * 0.4).cos());
            let y = damped_solve(&tall, kappa, &w).unwrap();
            assert!(
                (y - reference.transpose() * w).norm() < 1e-12,
                "κ = {kappa}"
            );
        }
    }

    #[test]
    fn rank_deficient_needs_damping() {
        let mut s = sample();
        s.set_row(5, &(s.row(0) * 2.0));
        let v = Vector6::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
        assert!(damped_solve(&s, 0.0, &v).is_none());
        let x = damped_solve(&s, 0.05, &v).unwrap();
        assert!(x.norm() < 1e3);
        // The normal equations of (3.46): (Jᵀ J + κ² I) x = Jᵀ v.
        let lhs = (s.transpose() * s + SMatrix::<f64, 7, 7>::identity() * 0.0025) * x;
        assert!((lhs - s.transpose() * v).norm() < 1e-10);
    }
}
