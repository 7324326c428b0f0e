//! Dense matrices of [`Poly`], rigid transforms and adjoints (thesis (2.21), (2.43)),
//! determinants and maximal minors (for manipulability (3.36)–(3.39)).

use super::number::Rational;
use super::poly::{Env, Poly, SymbolicError};
use std::collections::{BTreeSet, HashMap};

/// A dense `rows × cols` matrix of polynomials, stored **row-major**.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Matrix {
    rows: usize,
    cols: usize,
    data: Vec<Poly>,
}

impl Matrix {
    /// The zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Matrix {
            rows,
            cols,
            data: vec![Poly::zero(); rows * cols],
        }
    }

    /// The identity.
    pub fn identity(n: usize) -> Self {
        Self::from_fn(n, n, |i, j| if i == j { Poly::one() } else { Poly::zero() })
    }

    /// Builds entry `(i, j)` with `f(i, j)`.
    pub fn from_fn(rows: usize, cols: usize, mut f: impl FnMut(usize, usize) -> Poly) -> Self {
        let mut data = Vec::with_capacity(rows * cols);
        for i in 0..rows {
            for j in 0..cols {
                data.push(f(i, j));
            }
        }
        Matrix { rows, cols, data }
    }

    /// A constant matrix from rationals (row-major rows).
    pub fn from_rationals(rows: &[Vec<Rational>]) -> Self {
        let r = rows.len();
        let c = rows.first().map_or(0, |x| x.len());
        Self::from_fn(r, c, |i, j| Poly::constant(rows[i][j].clone()))
    }

    /// A column vector.
    pub fn column_vector(v: Vec<Poly>) -> Self {
        Matrix {
            rows: v.len(),
            cols: 1,
            data: v,
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Entry `(i, j)`.
    ///
    /// # Panics
    /// When out of range (like slice indexing).
    pub fn get(&self, i: usize, j: usize) -> &Poly {
        &self.data[i * self.cols + j]
    }

    /// Sets entry `(i, j)`.
    pub fn set(&mut self, i: usize, j: usize, p: Poly) {
        self.data[i * self.cols + j] = p;
    }

    /// All entries, row-major.
    pub fn entries(&self) -> &[Poly] {
        &self.data
    }

    /// Product `self · other`.
    ///
    /// # Panics
    /// When the inner dimensions differ (a bug in the caller, not a data error).
    pub fn mul(&self, other: &Matrix) -> Matrix {
        assert_eq!(self.cols, other.rows, "matrix product dimensions");
        Matrix::from_fn(self.rows, other.cols, |i, j| {
            let mut acc = Poly::zero();
            for k in 0..self.cols {
                let a = self.get(i, k);
                let b = other.get(k, j);
                if !a.is_zero() && !b.is_zero() {
                    acc = acc.add(&a.mul(b));
                }
            }
            acc
        })
    }

    /// Sum.
    pub fn add(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.rows, self.cols, |i, j| {
            self.get(i, j).add(other.get(i, j))
        })
    }

    /// Difference.
    pub fn sub(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.rows, self.cols, |i, j| {
            self.get(i, j).sub(other.get(i, j))
        })
    }

    /// Multiplication by a polynomial.
    pub fn scale(&self, k: &Poly) -> Matrix {
        Matrix::from_fn(self.rows, self.cols, |i, j| self.get(i, j).mul(k))
    }

    /// Transpose.
    pub fn transpose(&self) -> Matrix {
        Matrix::from_fn(self.cols, self.rows, |i, j| self.get(j, i).clone())
    }

    /// The block of `nr × nc` entries starting at `(r0, c0)`.
    pub fn block(&self, r0: usize, c0: usize, nr: usize, nc: usize) -> Matrix {
        Matrix::from_fn(nr, nc, |i, j| self.get(r0 + i, c0 + j).clone())
    }

    /// Columns side by side: `[self | other]`.
    pub fn hstack(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.rows, self.cols + other.cols, |i, j| {
            if j < self.cols {
                self.get(i, j).clone()
            } else {
                other.get(i, j - self.cols).clone()
            }
        })
    }

    /// Rows stacked: `[self; other]`.
    pub fn vstack(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.rows + other.rows, self.cols, |i, j| {
            if i < self.rows {
                self.get(i, j).clone()
            } else {
                other.get(i - self.rows, j).clone()
            }
        })
    }

    /// Is every entry zero?
    pub fn is_zero(&self) -> bool {
        self.data.iter().all(Poly::is_zero)
    }

    /// Numeric value, row-major.
    pub fn eval(&self, env: &Env<'_>) -> Vec<Vec<f64>> {
        (0..self.rows)
            .map(|i| (0..self.cols).map(|j| self.get(i, j).eval(env)).collect())
            .collect()
    }

    /// Joints (0-based) any entry depends on.
    pub fn joints(&self) -> BTreeSet<usize> {
        self.data.iter().flat_map(|p| p.joints()).collect()
    }

    /// Total number of terms over all entries (a size measure).
    pub fn total_terms(&self) -> usize {
        self.data.iter().map(Poly::len).sum()
    }

    /// `ω̂`, the skew matrix of a 3-vector (A.4): `ω̂ x = ω × x`.
    pub fn hat(w: &[Poly; 3]) -> Matrix {
        let z = Poly::zero();
        let rows = [
            [z.clone(), w[2].neg(), w[1].clone()],
            [w[2].clone(), z.clone(), w[0].neg()],
            [w[1].neg(), w[0].clone(), z],
        ];
        Matrix::from_fn(3, 3, |i, j| rows[i][j].clone())
    }

    /// All minors on the first `k` rows, indexed by the bit set of the `k` chosen columns,
    /// for every `k ≤ min(rows, cols)`; Laplace expansion along the last chosen row, memoised over
    /// column subsets (`O(cols · 2^cols)` products). Needs `cols ≤ 20`.
    fn leading_minors(&self, k_max: usize) -> HashMap<u32, Poly> {
        let mut memo: HashMap<u32, Poly> = HashMap::new();
        memo.insert(0, Poly::one());
        let mut layer: Vec<u32> = vec![0];
        for t in 1..=k_max {
            let row = t - 1;
            let mut next = BTreeSet::new();
            for &s in &layer {
                for j in 0..self.cols {
                    if s & (1 << j) == 0 {
                        next.insert(s | (1 << j));
                    }
                }
            }
            for &s in &next {
                let mut acc = Poly::zero();
                let mut pos = 0usize;
                for j in 0..self.cols {
                    if s & (1 << j) == 0 {
                        continue;
                    }
                    let a = self.get(row, j);
                    if !a.is_zero() {
                        let sub = &memo[&(s & !(1 << j))];
                        if !sub.is_zero() {
                            let term = a.mul(sub);
                            // sign of entry (row, pos) in the t×t minor
                            acc = if (row + pos) % 2 == 0 {
                                acc.add(&term)
                            } else {
                                acc.sub(&term)
                            };
                        }
                    }
                    pos += 1;
                }
                memo.insert(s, acc);
            }
            layer = next.into_iter().collect();
        }
        memo
    }

    /// Determinant of a square matrix (exact, fraction-free expansion).
    pub fn det(&self) -> Result<Poly, SymbolicError> {
        if self.rows != self.cols || self.cols > 20 {
            return Err(SymbolicError::Overflow);
        }
        let memo = self.leading_minors(self.rows);
        Ok(memo[&((1u32 << self.cols) - 1)].clone())
    }

    /// The maximal (`rows × rows`) minors of a wide matrix, columns in increasing lexicographic
    /// order of the chosen column sets, with the chosen columns.
    pub fn maximal_minors(&self) -> Result<Vec<(Vec<usize>, Poly)>, SymbolicError> {
        if self.rows > self.cols || self.cols > 20 {
            return Err(SymbolicError::Overflow);
        }
        let memo = self.leading_minors(self.rows);
        let mut out: Vec<(Vec<usize>, Poly)> = memo
            .into_iter()
            .filter(|(s, _)| s.count_ones() as usize == self.rows)
            .map(|(s, p)| ((0..self.cols).filter(|j| s & (1 << j) != 0).collect(), p))
            .collect();
        out.sort_by(|a, b| a.0.cmp(&b.0));
        Ok(out)
    }

    /// Inverse of a square matrix: entry-wise for a diagonal matrix (so `d · d⁻¹` cancels by
    /// rule `inverse_cancel`), otherwise adjugate over determinant (one `Inv` atom).
    pub fn inverse(&self) -> Result<Matrix, SymbolicError> {
        let n = self.rows;
        if n == self.cols && (0..n).all(|i| (0..n).all(|j| i == j || self.get(i, j).is_zero())) {
            let mut out = Matrix::zeros(n, n);
            for i in 0..n {
                out.set(i, i, self.get(i, i).inv()?);
            }
            return Ok(out);
        }
        let det = self.det()?;
        let inv_det = det.inv()?;
        if n == 1 {
            return Ok(Matrix::from_fn(1, 1, |_, _| inv_det.clone()));
        }
        Ok(self.adjugate()?.scale(&inv_det))
    }

    /// The adjugate `adj(A)` (transposed cofactors) of a square matrix, so `A adj(A) = det(A) I`.
    pub fn adjugate(&self) -> Result<Matrix, SymbolicError> {
        let n = self.rows;
        if n != self.cols {
            return Err(SymbolicError::Overflow);
        }
        if n == 0 {
            return Ok(Matrix::zeros(0, 0));
        }
        if n == 1 {
            return Ok(Matrix::identity(1));
        }
        let mut out = Matrix::zeros(n, n);
        for i in 0..n {
            for j in 0..n {
                // Entry (i, j) of adj(A) is the cofactor of A at (j, i).
                let minor = Matrix::from_fn(n - 1, n - 1, |r, c| {
                    let rr = if r < j { r } else { r + 1 };
                    let cc = if c < i { c } else { c + 1 };
                    self.get(rr, cc).clone()
                });
                let mut cof = minor.det()?;
                if (i + j) % 2 == 1 {
                    cof = cof.neg();
                }
                out.set(i, j, cof);
            }
        }
        Ok(out)
    }
}

/// A rigid transform `g = (R, p)` with polynomial entries (2.21).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Transform {
    /// Rotation `R` (3×3).
    pub rot: Matrix,
    /// Translation `p` (3×1).
    pub pos: Matrix,
}

impl Transform {
    /// The identity.
    pub fn identity() -> Self {
        Transform {
            rot: Matrix::identity(3),
            pos: Matrix::zeros(3, 1),
        }
    }

    /// Composition `self · other` = `(R₁R₂, R₁p₂ + p₁)` (2.21).
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            rot: self.rot.mul(&other.rot),
            pos: self.rot.mul(&other.pos).add(&self.pos),
        }
    }

    /// Inverse `(Rᵀ, −Rᵀp)` (exact when `R` is exactly orthogonal).
    pub fn inverse(&self) -> Transform {
        let rt = self.rot.transpose();
        let p = rt.mul(&self.pos).scale(&Poly::integer(-1));
        Transform { rot: rt, pos: p }
    }

    fn pos3(&self) -> [Poly; 3] {
        [
            self.pos.get(0, 0).clone(),
            self.pos.get(1, 0).clone(),
            self.pos.get(2, 0).clone(),
        ]
    }

    /// `Ad_g = [[R, p̂R], [0, R]]` (2.43), twists linear part first.
    pub fn adjoint(&self) -> Matrix {
        let phr = Matrix::hat(&self.pos3()).mul(&self.rot);
        let top = self.rot.hstack(&phr);
        let bottom = Matrix::zeros(3, 3).hstack(&self.rot);
        top.vstack(&bottom)
    }

    /// `Ad_g⁻¹ = Ad_{g⁻¹} = [[Rᵀ, −Rᵀp̂], [0, Rᵀ]]`.
    pub fn adjoint_inverse(&self) -> Matrix {
        let rt = self.rot.transpose();
        let m = rt.mul(&Matrix::hat(&self.pos3())).scale(&Poly::integer(-1));
        rt.hstack(&m).vstack(&Matrix::zeros(3, 3).hstack(&rt))
    }

    /// `Ad_g⁻¹ ξ` for one twist (cheaper than forming the 6×6 matrix):
    /// `(Rᵀ(v + ω × p), Rᵀω)`.
    pub fn adjoint_inverse_apply(&self, xi: &Matrix) -> Matrix {
        let v = xi.block(0, 0, 3, 1);
        let w = xi.block(3, 0, 3, 1);
        let w3 = [
            w.get(0, 0).clone(),
            w.get(1, 0).clone(),
            w.get(2, 0).clone(),
        ];
        let wxp = Matrix::hat(&w3).mul(&self.pos);
        let rt = self.rot.transpose();
        rt.mul(&v.add(&wxp)).vstack(&rt.mul(&w))
    }

    /// The 4×4 homogeneous matrix `[[R, p], [0, 1]]`.
    pub fn homogeneous(&self) -> Matrix {
        let top = self.rot.hstack(&self.pos);
        let bottom = Matrix::from_fn(1, 4, |_, j| if j == 3 { Poly::one() } else { Poly::zero() });
        top.vstack(&bottom)
    }

    /// Joints (0-based) the transform depends on.
    pub fn joints(&self) -> BTreeSet<usize> {
        let mut s = self.rot.joints();
        s.extend(self.pos.joints());
        s
    }
}

/// Exact null-space basis of a constant rational matrix `A` (`r × c`), from its reduced row
/// echelon form: one column per free variable, in increasing order of the free column, with a
/// `1` at the free position and `−rref[row][free]` at the pivots. Returns `(rank, basis)`.
pub fn rational_null_space(a: &[Vec<Rational>], cols: usize) -> (usize, Vec<Vec<Rational>>) {
    let mut m: Vec<Vec<Rational>> = a.to_vec();
    let mut pivots = Vec::new();
    let mut row = 0;
    for col in 0..cols {
        let Some(p) = (row..m.len()).find(|&r| !m[r][col].is_zero()) else {
            continue;
        };
        m.swap(row, p);
        let inv = m[row][col].checked_recip().unwrap_or_else(Rational::one);
        for x in m[row].iter_mut() {
            *x = &*x * &inv;
        }
        for r in 0..m.len() {
            if r != row && !m[r][col].is_zero() {
                let f = m[r][col].clone();
                let pivot_row = m[row].clone();
                for (x, y) in m[r].iter_mut().zip(pivot_row.iter()) {
                    let d = y * &f;
                    *x = &*x - &d;
                }
            }
        }
        pivots.push(col);
        row += 1;
        if row == m.len() {
            break;
        }
    }
    let mut basis = Vec::new();
    for free in (0..cols).filter(|c| !pivots.contains(c)) {
        let mut v = vec![Rational::zero(); cols];
        v[free] = Rational::one();
        for (r, &pc) in pivots.iter().enumerate() {
            v[pc] = -&m[r][free];
        }
        basis.push(v);
    }
    (pivots.len(), basis)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(t: &str) -> Poly {
        Poly::parse(t, &["a", "b"]).unwrap()
    }

    #[test]
    fn det_and_minors() {
        let m = Matrix::from_fn(3, 3, |i, j| {
            p(["c1", "s1", "0", "-s1", "c1", "0", "0", "0", "a"][i * 3 + j])
        });
        assert_eq!(m.det().unwrap(), p("a"));
        let w = Matrix::from_fn(2, 3, |i, j| p(["1", "0", "a", "0", "1", "b"][i * 3 + j]));
        let minors = w.maximal_minors().unwrap();
        let sum: Poly = minors
            .iter()
            .fold(Poly::zero(), |s, (_, m)| s.add(&m.mul(m)));
        // Cauchy–Binet: det(W Wᵀ) = Σ minors²
        assert_eq!(w.mul(&w.transpose()).det().unwrap(), sum);
        assert_eq!(minors[0].0, vec![0, 1]);
    }

    #[test]
    fn inverse_times_matrix_is_identity() {
        let m = Matrix::from_fn(2, 2, |i, j| p(["1 + a^2", "b", "0", "a"][i * 2 + j]));
        let inv = m.inverse().unwrap();
        assert_eq!(m.mul(&inv), Matrix::identity(2));
    }

    #[test]
    fn adjoint_of_inverse_is_inverse_of_adjoint() {
        let rz = Matrix::from_fn(3, 3, |i, j| {
            p(["c1", "-s1", "0", "s1", "c1", "0", "0", "0", "1"][i * 3 + j])
        });
        let g = Transform {
            rot: rz,
            pos: Matrix::column_vector(vec![p("a"), p("b*c2"), p("1")]),
        };
        assert_eq!(g.adjoint().mul(&g.adjoint_inverse()), Matrix::identity(6));
        assert_eq!(g.inverse().adjoint(), g.adjoint_inverse());
        assert_eq!(g.compose(&g.inverse()), Transform::identity());
    }

    #[test]
    fn null_space_of_selection() {
        let h = vec![
            vec![Rational::one(), Rational::zero(), Rational::zero()],
            vec![Rational::zero(), Rational::zero(), Rational::integer(2)],
        ];
        let (rank, n) = rational_null_space(&h, 3);
        assert_eq!(rank, 2);
        assert_eq!(
            n,
            vec![vec![Rational::zero(), Rational::one(), Rational::zero()]]
        );
    }
}
