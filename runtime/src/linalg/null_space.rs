//! A basis of the null space of `r` constraint rows on twists, `null(H)` for `H ∈ R^{r×6}`
//! (3.1), read off the reduced row echelon form of `H`: the computed `Λ# = Ad_{g_ir} N_H` of a
//! constraint that is not the thesis's (3.23)/(3.27).

use crate::se3::Twist;
use core::fmt;
use nalgebra::{convert, RealField};

/// Why the rows have no null-space basis of `6 − r` columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowsError {
    /// There must be 1 to 5 rows (this many were given).
    BadRowCount(usize),
    /// The rows are linearly dependent (or zero) to working precision.
    DependentRows,
    /// An entry is not finite.
    NotFinite,
}

impl fmt::Display for RowsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadRowCount(r) => write!(f, "{r} rows; a null space of twists needs 1 to 5"),
            Self::DependentRows => write!(f, "the rows are linearly dependent"),
            Self::NotFinite => write!(f, "an entry is not finite"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for RowsError {}

/// The basis of `null(H)` read off the reduced row echelon form of the rows `h` of `H`
/// (Gauss–Jordan elimination with partial pivoting; a pivot counts when it exceeds
/// `64 ε max|H_jk|`), written into `out`: one column per free (non-pivot) coordinate `f`, with
/// `x_f = 1`, the other free coordinates 0, in increasing order of `f`. For a selection `H` (rows
/// of the identity) these are the unselected unit twists, in order.
///
/// # Panics
/// If `out.len() != 6 − h.len()` (with `1 ≤ h.len() ≤ 5`).
pub fn null_space_of_rows<T: RealField + Copy>(
    h: &[Twist<T>],
    out: &mut [Twist<T>],
) -> Result<(), RowsError> {
    let r = h.len();
    if r == 0 || r > 5 {
        return Err(RowsError::BadRowCount(r));
    }
    assert_eq!(out.len(), 6 - r, "6 − r columns");
    let mut a = [Twist::<T>::zeros(); 6];
    a[..r].copy_from_slice(h);
    let mut scale = T::zero();
    for row in &a[..r] {
        if !row.iter().all(|x| x.is_finite()) {
            return Err(RowsError::NotFinite);
        }
        scale = scale.max(row.amax());
    }
    let tol = scale * T::default_epsilon() * convert(64.0);
    let mut pivots = [0usize; 6];
    let mut row = 0;
    for col in 0..6 {
        if row == r {
            break;
        }
        // Partial pivoting on column `col`.
        let mut best = row;
        for k in row + 1..r {
            if a[k][col].abs() > a[best][col].abs() {
                best = k;
            }
        }
        if a[best][col].abs() <= tol {
            continue;
        }
        a.swap(row, best);
        let p = a[row][col];
        a[row] /= p;
        for k in 0..r {
            if k != row {
                let f = a[k][col];
                let pr = a[row];
                a[k] -= pr * f;
            }
        }
        pivots[row] = col;
        row += 1;
    }
    if row < r {
        return Err(RowsError::DependentRows);
    }
    let mut n = 0;
    for free in 0..6 {
        if pivots[..r].contains(&free) {
            continue;
        }
        let mut x = Twist::zeros();
        x[free] = T::one();
        for (k, &p) in pivots[..r].iter().enumerate() {
            x[p] = -a[k][free];
        }
        out[n] = x;
        n += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, Vector6};

    #[test]
    fn a_selection_leaves_the_unselected_unit_twists() {
        let e = |k: usize| Vector6::<f64>::from_fn(|r, _| if r == k { 1.0 } else { 0.0 });
        let mut out = [Twist::zeros(); 4];
        null_space_of_rows(&[e(2), e(0)], &mut out).unwrap();
        assert_eq!(out, [e(1), e(3), e(4), e(5)]);
    }

    /// For general rows: `H N = 0`, `N` of full column rank (its Gram determinant against
    /// nalgebra's), the free coordinates a unit pattern.
    #[test]
    fn general_rows_are_annihilated() {
        let h = [
            Vector6::new(0.3, -1.0, 0.2, 0.0, 0.5, 0.1),
            Vector6::new(1.0, 0.4, 0.0, -0.7, 0.0, 0.2),
        ];
        let mut out = [Twist::zeros(); 4];
        null_space_of_rows(&h, &mut out).unwrap();
        let n = SMatrix::<f64, 6, 4>::from_columns(&out);
        let hm = SMatrix::<f64, 2, 6>::from_rows(&[h[0].transpose(), h[1].transpose()]);
        assert!((hm * n).amax() < 1e-15);
        assert!((n.transpose() * n).determinant() > 1.0);
        // The pivots are columns 0 and 1: the free coordinates 2..6 carry the identity.
        for (c, col) in out.iter().enumerate() {
            for f in 2..6 {
                assert_eq!(col[f], if f == c + 2 { 1.0 } else { 0.0 });
            }
        }
    }

    #[test]
    fn bad_rows_are_errors() {
        let x = Vector6::<f64>::x();
        let mut out = [Twist::zeros(); 4];
        assert_eq!(
            null_space_of_rows(&[x, x * 2.0], &mut out),
            Err(RowsError::DependentRows)
        );
        assert_eq!(
            null_space_of_rows(&[x, Vector6::repeat(f64::NAN)], &mut out),
            Err(RowsError::NotFinite)
        );
        assert_eq!(
            null_space_of_rows::<f64>(&[], &mut []),
            Err(RowsError::BadRowCount(0))
        );
    }
}
