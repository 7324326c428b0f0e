//! Dense linear algebra for closed chains: ranks, pseudo-inverses, null spaces, the annihilator
//! `Ã` of (19)/(31)/(41) and the singular-value analysis of the source's §5.4.
//!
//! Thin wrappers over faer's dense decompositions (SVD, LU) for nalgebra's dynamic [`DMatrix`],
//! which the closed-chain API uses: a `DMatrix` is viewed in place as a faer matrix (both are
//! column-major), and the factors are copied back. Empty matrices (a mechanism without passive
//! joints has an `r × 0` block `J_Cp`) are handled without calling a decomposition.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef};
use nalgebra::DMatrix;

/// Relative tolerance on singular values used for ranks: `σ_i` counts when
/// `σ_i > tol · max(σ_1, 1)` (the one rule of [`trocar_model::singularity`]).
pub use trocar_model::singularity::RELATIVE_TOLERANCE as RANK_TOLERANCE;

/// `m` viewed as a faer matrix (no copy).
fn view(m: &DMatrix<f64>) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(m.as_slice(), m.nrows(), m.ncols())
}

/// A faer matrix (or a block of one) copied into a `DMatrix`.
fn to_dmatrix(m: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// Singular values (descending) and full orthogonal factors `U` (`r × r`), `V` (`c × c`) of a
/// non-empty `m` (faer's full SVD).
fn full_svd(m: &DMatrix<f64>) -> (Vec<f64>, Mat<f64>, Mat<f64>) {
    match view(m).svd() {
        Ok(svd) => {
            let s = svd.S().column_vector().iter().copied().collect();
            (s, svd.U().to_owned(), svd.V().to_owned())
        }
        // The SVD did not converge (non-finite entries): no direction counts.
        Err(_) => {
            let (r, c) = m.shape();
            (
                vec![0.0; r.min(c)],
                Mat::identity(r, r),
                Mat::identity(c, c),
            )
        }
    }
}

/// Singular values of `m`, descending (empty for an empty matrix).
pub fn singular_values(m: &DMatrix<f64>) -> Vec<f64> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Vec::new();
    }
    view(m)
        .singular_values()
        .unwrap_or_else(|_| vec![f64::NAN; m.nrows().min(m.ncols())])
}

/// The singular-value decomposition `J = U Σ Vᵀ = Σ σ_i u_i v_iᵀ` read as in the source's §5.4.
#[derive(Clone, Debug, PartialEq)]
pub struct SvdAnalysis {
    /// Singular values `σ_1 ≥ σ_2 ≥ … ≥ 0` (`min(m, n)` of them).
    pub singular_values: Vec<f64>,
    /// The rank `k`: the number of `σ_i > tol · max(σ_1, 1)` ([`RANK_TOLERANCE`]).
    pub rank: usize,
    /// `true` when `k = m` (full rank: every end-effector velocity is feasible).
    pub full_rank: bool,
    /// Basis of the feasible end-effector velocities `R(J) = span{u_1, …, u_k}` (columns, `m × k`).
    pub range: DMatrix<f64>,
    /// Basis of the null-space velocities `N(J) = span{v_{k+1}, …, v_n}` (columns, `n × (n − k)`).
    pub null_space: DMatrix<f64>,
    /// Basis of the lost end-effector directions `span{u_{k+1}, …, u_m}` (columns, `m × (m − k)`):
    /// empty at a regular configuration.
    pub lost_directions: DMatrix<f64>,
    /// Condition number `σ_1 / σ_min` (infinite when rank-deficient or empty).
    pub condition: f64,
}

/// The SVD analysis of §5.4 of a Jacobian `J ∈ R^{m×n}`: rank, feasible velocities `R(J)`,
/// null-space velocities `N(J)` and the directions lost at a singularity.
pub fn svd_analysis(j: &DMatrix<f64>) -> SvdAnalysis {
    let (m, n) = j.shape();
    if m == 0 || n == 0 {
        return SvdAnalysis {
            singular_values: Vec::new(),
            rank: 0,
            full_rank: m == 0,
            range: DMatrix::zeros(m, 0),
            null_space: DMatrix::identity(n, n),
            lost_directions: DMatrix::identity(m, m),
            condition: f64::INFINITY,
        };
    }
    let (sv, u, v) = full_svd(j);
    let k = rank_of_values(&sv);
    let condition = if k == m.min(n) && k > 0 {
        sv[0] / sv[k - 1]
    } else {
        f64::INFINITY
    };
    SvdAnalysis {
        singular_values: sv,
        rank: k,
        full_rank: k == m,
        range: to_dmatrix(u.as_ref().subcols(0, k)),
        null_space: to_dmatrix(v.as_ref().subcols(k, n - k)),
        lost_directions: to_dmatrix(u.as_ref().subcols(k, m - k)),
        condition,
    }
}

fn rank_of_values(sv: &[f64]) -> usize {
    trocar_model::singularity::rank(sv)
}

/// Numerical rank (see [`RANK_TOLERANCE`]).
pub fn rank(m: &DMatrix<f64>) -> usize {
    rank_of_values(&singular_values(m))
}

/// Smallest singular value `σ_min` (`0` for an empty dimension).
pub fn sigma_min(m: &DMatrix<f64>) -> f64 {
    if m.nrows() == 0 || m.ncols() == 0 {
        return 0.0;
    }
    singular_values(m).into_iter().fold(f64::INFINITY, f64::min)
}

/// Moore–Penrose pseudo-inverse `M†` (singular values below the rank tolerance are dropped).
pub fn pseudo_inverse(m: &DMatrix<f64>) -> DMatrix<f64> {
    let (r, c) = m.shape();
    if r == 0 || c == 0 {
        return DMatrix::zeros(c, r);
    }
    let Ok(svd) = view(m).thin_svd() else {
        return DMatrix::zeros(c, r);
    };
    let s = svd.S().column_vector();
    let values: Vec<f64> = s.iter().copied().collect();
    let tol = trocar_model::singularity::threshold(&values);
    // M† = V Σ⁺ Uᵀ over the singular values above the tolerance.
    let (u, v) = (svd.U(), svd.V());
    let mut out = DMatrix::zeros(c, r);
    for (k, &sk) in s.iter().enumerate() {
        if sk > tol {
            let inv = 1.0 / sk;
            for j in 0..r {
                let ujk = u[(j, k)] * inv;
                for i in 0..c {
                    out[(i, j)] += v[(i, k)] * ujk;
                }
            }
        }
    }
    out
}

/// Orthonormal basis (columns) of the null space `N(M)`.
pub fn null_space(m: &DMatrix<f64>) -> DMatrix<f64> {
    let (r, c) = m.shape();
    if r == 0 || c == 0 {
        return DMatrix::identity(c, c);
    }
    let (sv, _, v) = full_svd(m);
    let k = rank_of_values(&sv);
    to_dmatrix(v.as_ref().subcols(k, c - k))
}

/// Orthonormal basis (columns) of the range `R(M)`.
pub fn range_space(m: &DMatrix<f64>) -> DMatrix<f64> {
    let (r, c) = m.shape();
    if r == 0 || c == 0 {
        return DMatrix::zeros(r, 0);
    }
    let (sv, u, _) = full_svd(m);
    let k = rank_of_values(&sv);
    to_dmatrix(u.as_ref().subcols(0, k))
}

/// An annihilator `Ã` of `A`: orthonormal rows spanning the left null space, so `Ã A = 0` and
/// `Ã` has full row rank `rows(A) − rank(A)` ((19), (31), (41)).
///
/// Any other annihilator differs by an invertible left factor, which cancels in (7) and (8).
pub fn annihilator(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (r, c) = a.shape();
    if r == 0 {
        return DMatrix::zeros(0, 0);
    }
    if c == 0 {
        return DMatrix::identity(r, r);
    }
    let (sv, u, _) = full_svd(a);
    let k = rank_of_values(&sv);
    to_dmatrix(u.as_ref().subcols(k, r - k).transpose())
}

/// The inverse of a square matrix by faer's LU with partial pivoting; `None` when it is singular
/// (a zero pivot) or the result is not finite.
pub fn inverse(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = m.nrows();
    if n != m.ncols() {
        return None;
    }
    if n == 0 {
        return Some(DMatrix::zeros(0, 0));
    }
    let lu = view(m).partial_piv_lu();
    let inv = to_dmatrix(lu.inverse().as_ref());
    all_finite(&inv).then_some(inv)
}

/// The determinant of a square matrix (faer's LU); `1` for an empty matrix.
pub fn determinant(m: &DMatrix<f64>) -> f64 {
    if m.nrows() == 0 {
        return 1.0;
    }
    view(m).determinant()
}

/// Left pseudo-inverse `A† = (AᵀA)⁻¹Aᵀ` of a full-column-rank `A`, so `A† A = I` ((19), (31), (41)).
///
/// Returns `None` when `A` does not have full column rank.
pub fn left_pseudo_inverse(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    if rank(a) < a.ncols() {
        return None;
    }
    inverse(&(a.transpose() * a)).map(|inv| inv * a.transpose())
}

/// `true` when every entry is finite.
pub fn all_finite(m: &DMatrix<f64>) -> bool {
    m.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn annihilator_and_left_inverse_of_stacked_identities() {
        let mut a = DMatrix::zeros(9, 3);
        for k in 0..3 {
            a.view_mut((3 * k, 0), (3, 3)).fill_with_identity();
        }
        let at = annihilator(&a);
        assert_eq!(at.shape(), (6, 9));
        assert!((&at * &a).norm() < 1e-12);
        assert_eq!(rank(&at), 6);
        let ad = left_pseudo_inverse(&a).unwrap();
        assert!((ad * &a - DMatrix::<f64>::identity(3, 3)).norm() < 1e-12);
    }

    #[test]
    fn svd_analysis_of_a_rank_deficient_matrix() {
        let j = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0]);
        let s = svd_analysis(&j);
        assert_eq!(s.rank, 1);
        assert!(!s.full_rank);
        assert_eq!(s.null_space.shape(), (3, 2));
        assert!((&j * &s.null_space).norm() < 1e-12);
        assert_eq!(s.lost_directions.shape(), (2, 1));
        assert!((j.transpose() * &s.lost_directions).norm() < 1e-12);
        assert!(s.condition.is_infinite());
    }

    #[test]
    fn empty_matrices_do_not_panic() {
        let e = DMatrix::<f64>::zeros(3, 0);
        assert_eq!(rank(&e), 0);
        assert_eq!(pseudo_inverse(&e).shape(), (0, 3));
        assert_eq!(null_space(&e).shape(), (0, 0));
        assert_eq!(range_space(&e).shape(), (3, 0));
    }
}
