//! Dense linear algebra of dynamic size, on faer (over [`RobotScalar`]): the one pseudo-inverse of the crate
//! (singular values counted by the one rule of [`trocar_model::singularity`]), ranks, null spaces
//! and ranges, the annihilator `Ã` of (19)/(31)/(41) of Freitas, Leite & Lizarralde (2010), the
//! singular-value analysis of their §5.4, inverses and determinants by LU.
//!
//! The closed chains (`closed_chain`) and the numeric robot (`robot`) call
//! these; this module calls neither. Empty matrices (a mechanism without passive joints has an
//! `r × 0` block `J_Cp`) are handled without calling a decomposition.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::DenseSolveCore;
use faer::{Col, Mat, MatRef};

/// A scalar of the dynamic matrices here and of the numeric robot: a real field for both
/// nalgebra (the typed kernels) and faer (the dynamic matrices), i.e. `f32` or `f64`.
pub trait RobotScalar: nalgebra::RealField + Copy + faer::traits::RealField {}

impl<T: nalgebra::RealField + Copy + faer::traits::RealField> RobotScalar for T {}

/// Relative tolerance on singular values used for ranks and the pseudo-inverse: `σ_i` counts when
/// `σ_i > tol · max(σ_1, 1)` (the one rule of [`trocar_model::singularity`]).
pub use trocar_model::singularity::RELATIVE_TOLERANCE as RANK_TOLERANCE;

/// Singular values (descending) and full orthogonal factors `U` (`r × r`), `V` (`c × c`) of a
/// non-empty `m` (faer's full SVD).
fn full_svd(m: MatRef<'_, f64>) -> (Vec<f64>, Mat<f64>, Mat<f64>) {
    match m.svd() {
        Ok(svd) => {
            let s = svd.S().column_vector().iter().copied().collect();
            (s, svd.U().to_owned(), svd.V().to_owned())
        }
        // The SVD did not converge (non-finite entries): no direction counts.
        Err(_) => {
            let (r, c) = (m.nrows(), m.ncols());
            (
                vec![0.0; r.min(c)],
                Mat::identity(r, r),
                Mat::identity(c, c),
            )
        }
    }
}

/// Singular values of `m`, descending (empty for an empty matrix; NaN when the SVD does not
/// converge).
pub fn singular_values(m: MatRef<'_, f64>) -> Vec<f64> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Vec::new();
    }
    m.singular_values()
        .unwrap_or_else(|_| vec![f64::NAN; m.nrows().min(m.ncols())])
}

/// The singular-value decomposition `J = U Σ Vᵀ = Σ σ_i u_i v_iᵀ` read as in §5.4 of Freitas,
/// Leite & Lizarralde (2010).
#[derive(Clone, Debug, PartialEq)]
pub struct SvdAnalysis {
    /// Singular values `σ_1 ≥ σ_2 ≥ … ≥ 0` (`min(m, n)` of them).
    pub singular_values: Vec<f64>,
    /// The rank `k`: the number of `σ_i > tol · max(σ_1, 1)` ([`RANK_TOLERANCE`]).
    pub rank: usize,
    /// `true` when `k = m` (full rank: every end-effector velocity is feasible).
    pub full_rank: bool,
    /// Basis of the feasible end-effector velocities `R(J) = span{u_1, …, u_k}` (columns, `m × k`).
    pub range: Mat<f64>,
    /// Basis of the null-space velocities `N(J) = span{v_{k+1}, …, v_n}` (columns, `n × (n − k)`).
    pub null_space: Mat<f64>,
    /// Basis of the lost end-effector directions `span{u_{k+1}, …, u_m}` (columns, `m × (m − k)`):
    /// empty at a regular configuration.
    pub lost_directions: Mat<f64>,
    /// Condition number `σ_1 / σ_min` (infinite when rank-deficient or empty).
    pub condition: f64,
}

/// The SVD analysis of §5.4 of a Jacobian `J ∈ R^{m×n}`: rank, feasible velocities `R(J)`,
/// null-space velocities `N(J)` and the directions lost at a singularity.
pub fn svd_analysis(j: MatRef<'_, f64>) -> SvdAnalysis {
    let (m, n) = (j.nrows(), j.ncols());
    if m == 0 || n == 0 {
        return SvdAnalysis {
            singular_values: Vec::new(),
            rank: 0,
            full_rank: m == 0,
            range: Mat::zeros(m, 0),
            null_space: Mat::identity(n, n),
            lost_directions: Mat::identity(m, m),
            condition: f64::INFINITY,
        };
    }
    let (sv, u, v) = full_svd(j);
    let k = trocar_model::singularity::rank(&sv);
    let condition = if k == m.min(n) && k > 0 {
        sv[0] / sv[k - 1]
    } else {
        f64::INFINITY
    };
    SvdAnalysis {
        singular_values: sv,
        rank: k,
        full_rank: k == m,
        range: u.subcols(0, k).to_owned(),
        null_space: v.subcols(k, n - k).to_owned(),
        lost_directions: u.subcols(k, m - k).to_owned(),
        condition,
    }
}

/// Numerical rank (see [`RANK_TOLERANCE`]).
pub fn rank(m: MatRef<'_, f64>) -> usize {
    trocar_model::singularity::rank(&singular_values(m))
}

/// Smallest singular value `σ_min` (`0` for an empty dimension).
pub fn sigma_min(m: MatRef<'_, f64>) -> f64 {
    if m.nrows() == 0 || m.ncols() == 0 {
        return 0.0;
    }
    singular_values(m).into_iter().fold(f64::INFINITY, f64::min)
}

/// The Moore–Penrose pseudo-inverse `M† = V Σ⁺ Uᵀ` from faer's thin SVD, the one of the crate:
/// a singular value counts when `σ_i > RANK_TOLERANCE · max(σ_1, 1)` (the rule of
/// [`trocar_model::singularity`], [`RANK_TOLERANCE`]); the others are treated as zero. The zero
/// `c × r` matrix for an empty `M`; `None` when the SVD does not converge (entries not finite).
pub fn pseudo_inverse<T: RobotScalar>(m: MatRef<'_, T>) -> Option<Mat<T>> {
    let (r, c) = (m.nrows(), m.ncols());
    if r == 0 || c == 0 {
        return Some(Mat::zeros(c, r));
    }
    let svd = m.thin_svd().ok()?;
    let par = faer::Par::Seq;
    let mut pinv = Mat::zeros(c, r);
    let mut buffer = MemBuffer::new(faer::linalg::svd::pseudoinverse_from_svd_scratch::<T>(
        r, c, par,
    ));
    // σ > max(tol, tol · σ_1) = tol · max(σ_1, 1).
    let tol: T = nalgebra::convert(RANK_TOLERANCE);
    faer::linalg::svd::pseudoinverse_from_svd_with_tolerance(
        pinv.as_mut(),
        svd.S(),
        svd.U(),
        svd.V(),
        tol,
        tol,
        par,
        MemStack::new(&mut buffer),
    );
    Some(pinv)
}

/// Orthonormal basis (columns) of the null space `N(M)`.
pub fn null_space(m: MatRef<'_, f64>) -> Mat<f64> {
    let (r, c) = (m.nrows(), m.ncols());
    if r == 0 || c == 0 {
        return Mat::identity(c, c);
    }
    let (sv, _, v) = full_svd(m);
    let k = trocar_model::singularity::rank(&sv);
    v.subcols(k, c - k).to_owned()
}

/// Orthonormal basis (columns) of the range `R(M)`.
pub fn range_space(m: MatRef<'_, f64>) -> Mat<f64> {
    let (r, c) = (m.nrows(), m.ncols());
    if r == 0 || c == 0 {
        return Mat::zeros(r, 0);
    }
    let (sv, u, _) = full_svd(m);
    let k = trocar_model::singularity::rank(&sv);
    u.subcols(0, k).to_owned()
}

/// An annihilator `Ã` of `A`: orthonormal rows spanning the left null space, so `Ã A = 0` and
/// `Ã` has full row rank `rows(A) − rank(A)` ((19), (31), (41)).
///
/// Any other annihilator differs by an invertible left factor, which cancels in (7) and (8).
pub fn annihilator(a: MatRef<'_, f64>) -> Mat<f64> {
    let (r, c) = (a.nrows(), a.ncols());
    if r == 0 {
        return Mat::zeros(0, 0);
    }
    if c == 0 {
        return Mat::identity(r, r);
    }
    let (sv, u, _) = full_svd(a);
    let k = trocar_model::singularity::rank(&sv);
    u.subcols(k, r - k).transpose().to_owned()
}

/// The inverse of a square matrix by faer's LU with partial pivoting; `None` when it is not
/// square, singular (a zero pivot) or the result is not finite.
pub fn inverse(m: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let n = m.nrows();
    if n != m.ncols() {
        return None;
    }
    if n == 0 {
        return Some(Mat::zeros(0, 0));
    }
    let inv = m.partial_piv_lu().inverse();
    all_finite(inv.as_ref()).then_some(inv)
}

/// The determinant of a square matrix (faer's LU); `1` for an empty matrix.
pub fn determinant(m: MatRef<'_, f64>) -> f64 {
    if m.nrows() == 0 {
        return 1.0;
    }
    m.determinant()
}

/// The left inverse `A† = (AᵀA)⁻¹Aᵀ` of a full-column-rank `A`, so `A† A = I` ((19), (31), (41)):
/// [`pseudo_inverse`], which it equals for such an `A`.
///
/// Returns `None` when `A` does not have full column rank (or is not finite).
pub fn left_pseudo_inverse(a: MatRef<'_, f64>) -> Option<Mat<f64>> {
    if rank(a) < a.ncols() {
        return None;
    }
    pseudo_inverse(a)
}

/// `true` when every entry is finite.
pub fn all_finite(m: MatRef<'_, f64>) -> bool {
    (0..m.ncols()).all(|c| (0..m.nrows()).all(|r| m[(r, c)].is_finite()))
}

/// The rows of `top` above the rows of `bottom` (same number of columns).
///
/// # Panics
/// If the numbers of columns differ.
pub fn stack_rows(top: MatRef<'_, f64>, bottom: MatRef<'_, f64>) -> Mat<f64> {
    assert_eq!(
        top.ncols(),
        bottom.ncols(),
        "stacked blocks have equal widths"
    );
    let t = top.nrows();
    Mat::from_fn(t + bottom.nrows(), top.ncols(), |r, c| {
        if r < t {
            top[(r, c)]
        } else {
            bottom[(r - t, c)]
        }
    })
}

/// The columns `columns` of `m`, in that order.
pub fn select_columns(m: MatRef<'_, f64>, columns: &[usize]) -> Mat<f64> {
    Mat::from_fn(m.nrows(), columns.len(), |r, c| m[(r, columns[c])])
}

/// A column's entries as a slice (an owned [`Col`] is contiguous).
pub fn as_slice(c: &Col<f64>) -> &[f64] {
    c.try_as_col_major()
        .expect("an owned column is contiguous")
        .as_slice()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn annihilator_and_left_inverse_of_stacked_identities() {
        let a = Mat::from_fn(9, 3, |r, c| if r % 3 == c { 1.0 } else { 0.0 });
        let at = annihilator(a.as_ref());
        assert_eq!(at.shape(), (6, 9));
        assert!((&at * &a).norm_l2() < 1e-12);
        assert_eq!(rank(at.as_ref()), 6);
        let ad = left_pseudo_inverse(a.as_ref()).unwrap();
        assert!((ad * &a - Mat::<f64>::identity(3, 3)).norm_l2() < 1e-12);
    }

    #[test]
    fn svd_analysis_of_a_rank_deficient_matrix() {
        let j = Mat::from_fn(2, 3, |r, c| (r + 1) as f64 * (c + 1) as f64);
        let s = svd_analysis(j.as_ref());
        assert_eq!(s.rank, 1);
        assert!(!s.full_rank);
        assert_eq!(s.null_space.shape(), (3, 2));
        assert!((&j * &s.null_space).norm_l2() < 1e-12);
        assert_eq!(s.lost_directions.shape(), (2, 1));
        assert!((j.transpose() * &s.lost_directions).norm_l2() < 1e-12);
        assert!(s.condition.is_infinite());
    }

    /// The pseudo-inverse against its defining Penrose conditions, and the one tolerance rule:
    /// a singular value at `0.5e-9 · max(σ_1, 1)` is dropped, one at `2e-9 · max(σ_1, 1)` kept,
    /// for `σ_1` above and below 1.
    #[test]
    fn pseudo_inverse_penrose_conditions_and_the_tolerance_rule() {
        let m = Mat::from_fn(3, 4, |r, c| {
            ((r * 4 + c) as f64 * 0.7).sin() + (r == c) as u8 as f64
        });
        let p = pseudo_inverse(m.as_ref()).unwrap();
        assert!((&m * &p * &m - &m).norm_l2() < 1e-12);
        assert!((&p * &m * &p - &p).norm_l2() < 1e-12);
        let mp = &m * &p;
        assert!((&mp - mp.transpose()).norm_l2() < 1e-12);
        let pm = &p * &m;
        assert!((&pm - pm.transpose()).norm_l2() < 1e-12);
        for top in [10.0, 0.1] {
            let bound = RANK_TOLERANCE * f64::max(top, 1.0);
            let diag = |small: f64| {
                Mat::from_fn(2, 2, |r, c| match (r, c) {
                    (0, 0) => top,
                    (1, 1) => small,
                    _ => 0.0,
                })
            };
            let dropped = pseudo_inverse(diag(0.5 * bound).as_ref()).unwrap();
            assert_eq!(dropped[(1, 1)], 0.0, "σ_1 = {top}");
            let kept = pseudo_inverse(diag(2.0 * bound).as_ref()).unwrap();
            assert!(
                (kept[(1, 1)] * 2.0 * bound - 1.0).abs() < 1e-12,
                "σ_1 = {top}"
            );
        }
        assert!(pseudo_inverse(Mat::from_fn(2, 2, |_, _| f64::NAN).as_ref()).is_none());
    }

    #[test]
    fn empty_matrices_do_not_panic() {
        let e = Mat::<f64>::zeros(3, 0);
        assert_eq!(rank(e.as_ref()), 0);
        assert_eq!(pseudo_inverse(e.as_ref()).unwrap().shape(), (0, 3));
        assert_eq!(null_space(e.as_ref()).shape(), (0, 0));
        assert_eq!(range_space(e.as_ref()).shape(), (3, 0));
        assert_eq!(determinant(Mat::<f64>::zeros(0, 0).as_ref()), 1.0);
    }

    #[test]
    fn stacking_and_selecting() {
        let a = Mat::from_fn(2, 3, |r, c| (r * 3 + c) as f64);
        let b = Mat::from_fn(1, 3, |_, c| -(c as f64));
        let s = stack_rows(a.as_ref(), b.as_ref());
        assert_eq!(s.shape(), (3, 3));
        assert_eq!(s[(1, 2)], 5.0);
        assert_eq!(s[(2, 2)], -2.0);
        let sel = select_columns(s.as_ref(), &[2, 0]);
        assert_eq!(sel[(0, 0)], 2.0);
        assert_eq!(sel[(2, 1)], 0.0);
        assert_eq!(as_slice(&Col::from_fn(3, |i| i as f64)), &[0.0, 1.0, 2.0]);
    }
}
