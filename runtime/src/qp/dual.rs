//! The dual active-set method of Goldfarb & Idnani for a positive definite `H`, from a warm
//! start: [`super::solve_range_space`].
//!
//! With `H = L Lᵀ` (Cholesky) and the working set's rows oriented as `nⱼᵀ x ≥ τⱼ` (a row at
//! its lower bound as it is, at its upper bound negated; the equalities as `nⱼᵀ x = τⱼ`), its
//! columns `Y = L⁻¹ [n₁ … n_m] = Q R` (`Q` with orthonormal columns, `R` upper triangular) give
//! the minimiser of (1) on the working set and its multipliers `u` (`H x + f = Σ uⱼ nⱼ`):
//!
//! ```text
//! Rᵀ ζ = τ + Rᵀ Qᵀ w,   R u = ζ,   x = L⁻ᵀ (Q ζ − w),   L w = f                  (11)
//! ```
//!
//! The method keeps `x` the minimiser on its working set with every inequality multiplier
//! `uⱼ ≥ 0` (dual feasible) and takes in violated rows until none is left (Goldfarb & Idnani,
//! *Math. Programming* 27, 1983, §3). The row `n₊ᵀ x ≥ τ₊` violated most (`s = n₊ᵀ x − τ₊ < 0`)
//! has `y = L⁻¹ n₊`, `d = Qᵀ y`, `y⊥ = y − Q d`, and along
//!
//! ```text
//! z = L⁻ᵀ y⊥ (primal),   r = R⁻¹ d (dual),   n₊ᵀ z = ‖y⊥‖²                       (12)
//! ```
//!
//! `x + t z` stays the minimiser on the working set with the new row's multiplier `t` and the
//! others `u − t r`. The full step `t = −s / ‖y⊥‖²` brings the row to its bound, and it joins
//! (`Q`, `R` take the column `y⊥ / ‖y⊥‖`, `[d; ‖y⊥‖]`: `O(n m)`); a multiplier reaching zero
//! first (`min uⱼ / rⱼ` over `rⱼ > 0`) stops a partial step and its row leaves (Givens
//! rotations restore the triangle of `R`: `O(n m)`), and the same row is tried again. A row
//! that depends on the working set (`y⊥ = 0`) is taken in by partial steps only, each releasing
//! a row; one with nothing to release cannot be met (the problem is infeasible here).
//!
//! The warm start's working set is taken in first as equalities (a dependent row left out) and
//! its rows whose multipliers have the wrong sign are released, all at once, until the point is
//! dual feasible (a row released too many is violated and taken in again by the steps); from
//! the optimum's own working set the method ends there, with no step: what a controller's warm
//! start usually is. The answer is the minimiser (11) on the last working set computed afresh,
//! kept only where it meets the Karush–Kuhn–Tucker conditions within the solver's tolerances.

// Dense factorisations read best as index loops over the fixed-size arrays; `!(a > b)` is
// meant wherever it appears: a NaN fails the test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use super::{all_finite, feasibility, row_tolerance, ActiveSet, Problem, Side, Solution, Status};
use nalgebra::{RealField, SMatrix, SVector};

/// `H = L Lᵀ` within `H`'s envelope: row `i` of `L` starts where row `i` of `H` does
/// (`first[i]`, its first nonzero), and so do the substitutions — a scene's `H`, one block per
/// arm, costs its blocks' work.
#[derive(Clone)]
struct Factor<T: RealField + Copy, const N: usize> {
    l: SMatrix<T, N, N>,
    /// `1 / L_ii`: one division a row, the substitutions multiply.
    inv: SVector<T, N>,
    first: [usize; N],
}

impl<T: RealField + Copy, const N: usize> Factor<T, N> {
    /// No factor yet.
    #[inline(always)]
    fn new() -> Self {
        Factor {
            l: SMatrix::zeros(),
            inv: SVector::zeros(),
            first: [0; N],
        }
    }

    /// The factor of `(H + Hᵀ)/2` in place; `false` where it is not positive definite with its
    /// least pivot above `√ε` of its largest diagonal entry. (Entries of `L` left of `first`
    /// are never read.)
    fn factorise<const E: usize, const C: usize>(&mut self, p: &Problem<T, N, E, C>) -> bool {
        let half = nalgebra::convert::<f64, T>(0.5);
        let h = |i: usize, j: usize| (p.h[(i, j)] + p.h[(j, i)]) * half;
        let (l, inv, first) = (&mut self.l, &mut self.inv, &mut self.first);
        for (i, f) in first.iter_mut().enumerate() {
            *f = (0..i)
                .find(|&j| p.h[(i, j)] != T::zero() || p.h[(j, i)] != T::zero())
                .unwrap_or(i);
        }
        for i in 0..N {
            for j in first[i]..=i {
                let mut v = h(i, j);
                for k in first[i].max(first[j])..j {
                    v -= l[(i, k)] * l[(j, k)];
                }
                if i == j {
                    if v <= T::zero() || !v.is_finite() {
                        return false;
                    }
                    l[(i, i)] = v.sqrt();
                    inv[i] = T::one() / l[(i, i)];
                } else {
                    l[(i, j)] = v * inv[j];
                }
            }
        }
        let largest = (0..N).fold(T::zero(), |m, k| m.max(h(k, k)));
        let smallest = (0..N).fold(largest, |m, k| m.min(l[(k, k)] * l[(k, k)]));
        N > 0 && smallest.is_finite() && !(smallest < T::default_epsilon().sqrt() * largest)
    }

    /// `L y = c` in place, returning the rows `start..end` where `y` can be nonzero (a row of
    /// one arm's joints stays within that arm's block of `L`).
    fn forward(&self, y: &mut SVector<T, N>) -> (usize, usize) {
        let start = (0..N).find(|&i| y[i] != T::zero()).unwrap_or(N);
        let mut end = start;
        for i in start..N {
            if self.first[i] >= end && y[i] == T::zero() {
                continue;
            }
            let mut v = y[i];
            for k in self.first[i].max(start)..i {
                v -= self.l[(i, k)] * y[k];
            }
            y[i] = v * self.inv[i];
            end = i + 1;
        }
        (start, end)
    }

    /// `Lᵀ x = v`.
    fn backward(&self, v: &SVector<T, N>) -> SVector<T, N> {
        let mut x = *v;
        for k in (0..N).rev() {
            x[k] *= self.inv[k];
            let xk = x[k];
            for i in self.first[k]..k {
                x[i] -= self.l[(k, i)] * xk;
            }
        }
        x
    }
}

/// A row of the problem: `id < E` an equality, `E + g` the general row `g`, `E + C + k` the
/// bound of variable `k`.
fn normal<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    id: usize,
) -> SVector<T, N> {
    if id < E {
        p.a_eq.row(id).transpose()
    } else if id < E + C {
        p.g.row(id - E).transpose()
    } else {
        let mut a = SVector::zeros();
        a[id - E - C] = T::one();
        a
    }
}

/// The bounds `(l, u)` of row `id` (an equality's are both its right-hand side).
fn bounds<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    id: usize,
) -> (T, T) {
    if id < E {
        (p.b_eq[id], p.b_eq[id])
    } else if id < E + C {
        (p.lo[id - E], p.hi[id - E])
    } else {
        (p.lb[id - E - C], p.ub[id - E - C])
    }
}

/// The working set: `m` oriented rows, `Y = L⁻¹ [n₁ … n_m] = Q R`, and the multipliers.
#[derive(Clone)]
struct Working<T: RealField + Copy, const N: usize> {
    /// `Q`'s columns `0..m`, column `j` nonzero only in rows `span[j].0..span[j].1`.
    q: SMatrix<T, N, N>,
    span: [(usize, usize); N],
    /// `R`'s leading `m × m` triangle.
    r: SMatrix<T, N, N>,
    /// Each row's id (as [`normal`]), orientation (`1` at a lower bound or an equality, `−1` at
    /// an upper bound), target `τ` (oriented) and whether it may leave (an inequality whose
    /// bounds differ).
    id: [usize; N],
    sign: [T; N],
    target: [T; N],
    free: [bool; N],
    /// The multipliers `u` of the oriented rows.
    u: SVector<T, N>,
    m: usize,
}

impl<T: RealField + Copy, const N: usize> Working<T, N> {
    #[inline(always)]
    fn new() -> Self {
        Working {
            q: SMatrix::zeros(),
            span: [(0, 0); N],
            r: SMatrix::zeros(),
            id: [0; N],
            sign: [T::zero(); N],
            target: [T::zero(); N],
            free: [false; N],
            u: SVector::zeros(),
            m: 0,
        }
    }

    /// No row: the columns and the triangle used zeroed again (an append writes a column's
    /// span only).
    fn clear(&mut self) {
        for j in 0..self.m {
            for c in self.span[j].0..self.span[j].1 {
                self.q[(c, j)] = T::zero();
            }
            for i in 0..=j {
                self.r[(i, j)] = T::zero();
            }
            self.span[j] = (0, 0);
        }
        self.u = SVector::zeros();
        self.m = 0;
    }

    /// `d = Qᵀ y` and `y⊥ = y − Q d` in place of `y` (Gram–Schmidt, a second pass only where the
    /// first cancelled much of `y`: Kahan's "twice is enough"), widening `span` as `y⊥` fills.
    fn project(
        &self,
        y: &mut SVector<T, N>,
        span: &mut (usize, usize),
        before: T,
    ) -> SVector<T, N> {
        let half = nalgebra::convert::<f64, T>(0.5);
        let mut d = SVector::<T, N>::zeros();
        for pass in 0..2 {
            for i in 0..self.m {
                let (a, b) = (self.span[i].0.max(span.0), self.span[i].1.min(span.1));
                if a >= b {
                    continue;
                }
                let rij = (a..b).fold(T::zero(), |s, c| s + self.q[(c, i)] * y[c]);
                for c in self.span[i].0..self.span[i].1 {
                    y[c] -= self.q[(c, i)] * rij;
                }
                *span = (span.0.min(self.span[i].0), span.1.max(self.span[i].1));
                d[i] += rij;
            }
            if pass == 0 && norm_in(y, *span) >= half * before {
                break;
            }
        }
        d
    }

    /// Appends the row `id` (oriented by `sign`, target `target`) whose projection is `y⊥` of
    /// norm `norm > 0` with `d = Qᵀ y`, and multiplier `u`.
    #[allow(clippy::too_many_arguments)]
    fn append(
        &mut self,
        y_perp: &SVector<T, N>,
        span: (usize, usize),
        norm: T,
        d: &SVector<T, N>,
        (id, sign, target, free): (usize, T, T, bool),
        u: T,
    ) {
        let j = self.m;
        let scale = T::one() / norm;
        // Columns from `m` on are zero ([`Working::remove`] clears the one it frees).
        for c in span.0..span.1 {
            self.q[(c, j)] = y_perp[c] * scale;
        }
        self.span[j] = span;
        for i in 0..j {
            self.r[(i, j)] = d[i];
        }
        self.r[(j, j)] = norm;
        self.id[j] = id;
        self.sign[j] = sign;
        self.target[j] = target;
        self.free[j] = free;
        self.u[j] = u;
        self.m += 1;
    }

    /// Removes row `j`: `R` without its column is upper Hessenberg from `j` on, and Givens
    /// rotations of rows `i, i + 1` of `R` (columns `i, i + 1` of `Q`) restore its triangle
    /// (Golub & Van Loan §6.5.2); `Q R` is `Y` without its column `j`.
    fn remove(&mut self, j: usize) {
        let m = self.m;
        for c in j..m - 1 {
            for i in 0..m {
                self.r[(i, c)] = self.r[(i, c + 1)];
            }
            self.id[c] = self.id[c + 1];
            self.sign[c] = self.sign[c + 1];
            self.target[c] = self.target[c + 1];
            self.free[c] = self.free[c + 1];
            self.u[c] = self.u[c + 1];
        }
        for i in 0..m {
            self.r[(i, m - 1)] = T::zero();
        }
        for i in j..m - 1 {
            let (a, b) = (self.r[(i, i)], self.r[(i + 1, i)]);
            // `hypot` scaled by the larger, which does not overflow.
            let big = a.abs().max(b.abs());
            let h = if big > T::zero() {
                let (a, b) = (a / big, b / big);
                big * (a * a + b * b).sqrt()
            } else {
                T::zero()
            };
            if h == T::zero() {
                continue;
            }
            let (c, s) = (a / h, b / h);
            for k in i..m - 1 {
                let (x, y) = (self.r[(i, k)], self.r[(i + 1, k)]);
                self.r[(i, k)] = c * x + s * y;
                self.r[(i + 1, k)] = c * y - s * x;
            }
            self.r[(i + 1, i)] = T::zero();
            let span = (
                self.span[i].0.min(self.span[i + 1].0),
                self.span[i].1.max(self.span[i + 1].1),
            );
            for k in span.0..span.1 {
                let (x, y) = (self.q[(k, i)], self.q[(k, i + 1)]);
                self.q[(k, i)] = c * x + s * y;
                self.q[(k, i + 1)] = c * y - s * x;
            }
            self.span[i] = span;
            self.span[i + 1] = span;
        }
        for k in 0..N {
            self.q[(k, m - 1)] = T::zero();
        }
        self.span[m - 1] = (0, 0);
        self.u[m - 1] = T::zero();
        self.m -= 1;
    }

    /// One step of refinement of the minimiser `x` (11) on its own rows: with the residual
    /// `ρ = τ − Nᵀ x`, `ζ` moves by `R⁻ᵀ ρ`, `x` by `L⁻ᵀ Q R⁻ᵀ ρ` and `u` by `R⁻¹ R⁻ᵀ ρ`
    /// (`Nᵀ L⁻ᵀ Q = Rᵀ`). Where the unconstrained minimiser is far from the working set's, (11)
    /// cancels much of `L⁻¹ f` and meets the rows only to that cancellation's rounding.
    fn refine<const E: usize, const C: usize>(
        &mut self,
        p: &Problem<T, N, E, C>,
        factor: &Factor<T, N>,
        x: &mut SVector<T, N>,
    ) {
        let m = self.m;
        let mut delta = SVector::<T, N>::zeros();
        for i in 0..m {
            let mut t = self.target[i] - normal(p, self.id[i]).dot(x) * self.sign[i];
            for j in 0..i {
                t -= self.r[(j, i)] * delta[j];
            }
            delta[i] = t / self.r[(i, i)];
        }
        let mut v = SVector::<T, N>::zeros();
        for j in 0..m {
            for c in self.span[j].0..self.span[j].1 {
                v[c] += self.q[(c, j)] * delta[j];
            }
        }
        *x += factor.backward(&v);
        self.u += self.solve_r(&delta);
    }

    /// `R v = b` on the leading triangle.
    fn solve_r(&self, b: &SVector<T, N>) -> SVector<T, N> {
        let mut v = SVector::<T, N>::zeros();
        for i in (0..self.m).rev() {
            let mut t = b[i];
            for j in i + 1..self.m {
                t -= self.r[(i, j)] * v[j];
            }
            v[i] = t / self.r[(i, i)];
        }
        v
    }

    /// (11): the minimiser on the working set and its multipliers, into `u`.
    fn minimiser(&mut self, factor: &Factor<T, N>, w: &SVector<T, N>) -> SVector<T, N> {
        let m = self.m;
        let mut v = -w;
        if m > 0 {
            // Rᵀ ζ = τ + Rᵀ Qᵀ w: ζ = R⁻ᵀ τ + Qᵀ w.
            let mut zeta = SVector::<T, N>::zeros();
            for i in 0..m {
                let mut t = self.target[i];
                for j in 0..i {
                    t -= self.r[(j, i)] * zeta[j];
                }
                zeta[i] = t / self.r[(i, i)];
            }
            for i in 0..m {
                zeta[i] += (self.span[i].0..self.span[i].1)
                    .fold(T::zero(), |s, c| s + self.q[(c, i)] * w[c]);
            }
            self.u = self.solve_r(&zeta);
            for j in 0..m {
                for c in self.span[j].0..self.span[j].1 {
                    v[c] += self.q[(c, j)] * zeta[j];
                }
            }
        }
        factor.backward(&v)
    }
}

/// `‖y‖` over `span`.
fn norm_in<T: RealField + Copy, const N: usize>(y: &SVector<T, N>, (a, b): (usize, usize)) -> T {
    (a..b).fold(T::zero(), |s, c| s + y[c] * y[c]).sqrt()
}

/// `H x` within the envelope of `(H + Hᵀ)/2`.
fn hessian_times<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    first: &[usize; N],
    x: &SVector<T, N>,
) -> SVector<T, N> {
    let half = nalgebra::convert::<f64, T>(0.5);
    let mut hx = SVector::<T, N>::zeros();
    for i in 0..N {
        hx[i] += p.h[(i, i)] * x[i];
        for j in first[i]..i {
            let hij = (p.h[(i, j)] + p.h[(j, i)]) * half;
            hx[i] += hij * x[j];
            hx[j] += hij * x[i];
        }
    }
    hx
}

/// Whether row `j` of the working set is free and its multiplier, scaled by `‖nⱼ‖`, is of the
/// wrong sign beyond `tol` (the primal method's release rule (10)).
fn wrong_sign<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    ws: &Working<T, N>,
    j: usize,
    tol: T,
) -> bool {
    ws.free[j] && -ws.u[j] * row_norm(p, ws.id[j]) > tol
}

/// The multipliers' sign tolerance `ε^{2/3} (1 + ‖H x + f‖∞)`, with `hx = H x`.
fn sign_tolerance<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    hx: &SVector<T, N>,
    tiny: T,
) -> T {
    tiny * (T::one() + (hx + p.f).amax())
}

/// See [`super::solve_range_space`].
pub(super) fn solve<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
) -> Option<Solution<T, N, E, C>> {
    let mut dual = Dual::new();
    dual.solve(p, warm)
}

/// `true` where every bound is in order (`lo ≤ hi`, `lb ≤ ub`), as the solvers ask (a NaN
/// passes: the finiteness checks catch it).
fn bounds_in_order<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
) -> bool {
    !((0..C).any(|r| p.lo[r] > p.hi[r]) || (0..N).any(|k| p.lb[k] > p.ub[k]))
}

/// The dual active-set method's workspace (Goldfarb & Idnani; see
/// [`solve_range_space`](super::solve_range_space)): `H`'s factor, `w = L⁻¹ f` and the working
/// set with its factors, some `3 N²` numbers (11 KB for 21 `f64` rates), kept between solves as a
/// controller keeps its solver. Kept, it spares each solve the clearing of that much memory
/// (only what the last solve used is cleared); a solve whose problem differs from the last one's
/// in its bounds only (a scene's second solve, its couplings' rows asking more) starts from the
/// working set that one ended on and its factors ([`Dual::resolve`]): no factorisation, the
/// minimiser (11) with the new targets and the dual steps from there. Allocates nothing and
/// does not panic.
///
/// ```
/// use trocar::qp::{ActiveSet, Dual, Problem};
/// use nalgebra::{SMatrix, SVector};
///
/// // min ½‖x‖² − x₀ − x₁ subject to x₀ + x₁ = 1 and 0 ≤ x ≤ 0.8.
/// let mut p = Problem::<f64, 2, 1, 0> {
///     h: SMatrix::identity(),
///     f: SVector::from([-1.0, -1.0]),
///     a_eq: SMatrix::from_row_slice(&[1.0, 1.0]),
///     b_eq: SVector::from([1.0]),
///     g: SMatrix::zeros(),
///     lo: SVector::zeros(),
///     hi: SVector::zeros(),
///     lb: SVector::from([0.0, 0.0]),
///     ub: SVector::from([0.8, 0.8]),
/// };
/// let mut dual = Dual::new();
/// let first = dual.solve(&p, &ActiveSet::EMPTY).expect("definite and feasible");
/// assert!((first.x[0] - 0.5).abs() < 1e-12);
/// // The same problem asking x₀ ≥ 0.7: from the first solve's factors.
/// p.lb[0] = 0.7;
/// let second = dual.resolve(&p).expect("still feasible");
/// assert!((second.x[0] - 0.7).abs() < 1e-12 && (second.x[1] - 0.3).abs() < 1e-12);
/// ```
#[derive(Clone)]
pub struct Dual<T: RealField + Copy, const N: usize> {
    factor: Factor<T, N>,
    w: SVector<T, N>,
    ws: Working<T, N>,
    /// The last solve answered: the working set is the optimum's.
    answered: bool,
    /// `ε^{2/3}`.
    tiny: T,
}

impl<T: RealField + Copy, const N: usize> Dual<T, N> {
    /// An empty workspace: [`Dual::solve`] makes the factor and the working set.
    #[inline(always)]
    pub fn new() -> Self {
        Dual {
            factor: Factor::new(),
            w: SVector::zeros(),
            ws: Working::new(),
            answered: false,
            tiny: tiny::<T>(),
        }
    }

    /// The optimum of `p` from the warm start's working set (see
    /// [`super::solve_range_space`]); `None` where some number of `p` is not finite, some
    /// bounds are not in order, `H` is not positive definite to `√ε` or the dual method
    /// declines.
    pub fn solve<const E: usize, const C: usize>(
        &mut self,
        p: &Problem<T, N, E, C>,
        warm: &ActiveSet<N, C>,
    ) -> Option<Solution<T, N, E, C>> {
        let tiny = self.tiny;
        self.answered = false;
        self.ws.clear();
        if !p.is_finite() || !bounds_in_order(p) || !self.factor.factorise(p) {
            return None;
        }
        self.w = p.f;
        self.factor.forward(&mut self.w);
        let ws = &mut self.ws;
        // The equalities and the warm start's rows, as equalities (a dependent inequality left out).
        let warm_rows = (0..C)
            .filter(|&g| warm.general[g] != Side::Inactive)
            .map(|g| (E + g, warm.general[g]))
            .chain(
                (0..N)
                    .filter(|&k| warm.bounds[k] != Side::Inactive)
                    .map(|k| (E + C + k, warm.bounds[k])),
            );
        for (id, side) in (0..E).map(|e| (e, Side::Lower)).chain(warm_rows) {
            let row = oriented(p, id, side)?;
            if ws.m >= N {
                if id < E {
                    return None;
                }
                continue;
            }
            let mut y = normal(p, id) * row.1;
            let mut span = self.factor.forward(&mut y);
            let before = norm_in(&y, span);
            let d = ws.project(&mut y, &mut span, before);
            let norm = norm_in(&y, span);
            if !(norm > tiny * before) {
                if id < E {
                    return None;
                }
                continue;
            }
            ws.append(&y, span, norm, &d, row, T::zero());
        }
        self.settle(p)
    }

    /// The optimum of `p` after a solve that answered, where `p` is the problem of that solve
    /// with other bounds (`b_eq`, `lo`, `hi`, `lb`, `ub`; `H`, `f` and the rows the same): from
    /// the working set that solve ended on, with its factors. `None` where the last solve did
    /// not answer, the bounds are not finite and in order, or the dual method declines.
    pub fn resolve<const E: usize, const C: usize>(
        &mut self,
        p: &Problem<T, N, E, C>,
    ) -> Option<Solution<T, N, E, C>> {
        let bounds_finite = all_finite(p.b_eq.as_slice())
            & all_finite(p.lo.as_slice())
            & all_finite(p.hi.as_slice())
            & all_finite(p.lb.as_slice())
            & all_finite(p.ub.as_slice());
        if !self.answered || !bounds_finite || !bounds_in_order(p) {
            return None;
        }
        self.answered = false;
        let ws = &mut self.ws;
        for j in 0..ws.m {
            let side = if ws.sign[j] < T::zero() {
                Side::Upper
            } else {
                Side::Lower
            };
            let (_, _, target, free) = oriented(p, ws.id[j], side)?;
            ws.target[j] = target;
            ws.free[j] = free;
        }
        self.settle(p)
    }

    /// From the working set taken in: its minimiser, the rows with wrong-signed multipliers
    /// released, then the dual method's steps until no row is violated.
    fn settle<const E: usize, const C: usize>(
        &mut self,
        p: &Problem<T, N, E, C>,
    ) -> Option<Solution<T, N, E, C>> {
        let tiny = self.tiny;
        let (factor, w, ws) = (&self.factor, &self.w, &mut self.ws);
        let mut iterations = 0;
        let mut x = ws.minimiser(factor, w);
        // Dual feasibility: the rows whose multipliers have the wrong sign leave, all of them at
        // once (a row released too many is violated and taken in again by the steps below),
        // until none is left.
        let mut hx = hessian_times(p, &factor.first, &x);
        loop {
            let tol = sign_tolerance(p, &hx, tiny);
            let mut released = false;
            for j in (0..ws.m).rev() {
                if wrong_sign(p, ws, j, tol) {
                    ws.remove(j);
                    iterations += 1;
                    released = true;
                }
            }
            if !released {
                break;
            }
            x = ws.minimiser(factor, w);
            hx = hessian_times(p, &factor.first, &x);
        }
        if !all_finite(x.as_slice()) {
            return None;
        }
        // Every row joins once and leaves once in a pass without degeneracy; a few times that
        // bounds a pass that cycles.
        let cap = 4 * (E + C + N) + 8;
        // `x` moved since the multipliers' signs were last looked at (a step or a refinement).
        let mut moved = false;
        let mut refined = false;
        // `x` is the minimiser (11) computed afresh, not stepped to.
        let mut fresh = true;
        loop {
            let Some((violated, side)) = p.most_violated(&x) else {
                if fresh {
                    break;
                }
                // The point afresh on the last working set (the steps' rounding does not
                // build up), and the rows looked at again.
                x = ws.minimiser(factor, w);
                fresh = true;
                continue;
            };
            let id = match violated {
                super::Violated::General(g) => E + g,
                super::Violated::Bound(k) => E + C + k,
            };
            // A row of the working set that its minimiser breaks: (11) met the rows only to its
            // rounding. Afresh, then one refinement; where that is not enough, `H` or the rows
            // are too ill-conditioned here (the primal method's basis of the rows' null space
            // is the better-conditioned one).
            if ws.id[..ws.m].contains(&id) {
                if !fresh {
                    x = ws.minimiser(factor, w);
                    fresh = true;
                    continue;
                }
                if refined {
                    return None;
                }
                ws.refine(p, factor, &mut x);
                refined = true;
                moved = true;
                continue;
            }
            refined = false;
            let row = oriented(p, id, side)?;
            let n_plus = normal(p, id) * row.1;
            let mut y0 = n_plus;
            let span0 = factor.forward(&mut y0);
            let size = norm_in(&y0, span0);
            // s = n₊ᵀ x − τ₊ < 0, and the new row's multiplier.
            let mut s = n_plus.dot(&x) - row.2;
            let mut u_new = T::zero();
            loop {
                iterations += 1;
                if iterations > cap {
                    return None;
                }
                moved = true;
                let mut y = y0;
                let mut span = span0;
                let d = ws.project(&mut y, &mut span, size);
                let norm = norm_in(&y, span);
                let independent = norm > tiny * size && ws.m < N;
                let r = ws.solve_r(&d);
                let mut partial: Option<(T, usize)> = None;
                // A multiplier within the tolerance below zero counts as zero.
                for j in 0..ws.m {
                    if ws.free[j] && r[j] > T::zero() {
                        let t = ws.u[j].max(T::zero()) / r[j];
                        if partial.is_none_or(|(best, _)| t < best) {
                            partial = Some((t, j));
                        }
                    }
                }
                let full = if independent {
                    Some(-s / (norm * norm))
                } else {
                    None
                };
                let (t, leaving) = match (full, partial) {
                    (None, None) => return None,
                    (Some(f), Some((t, j))) if t < f => (t, Some(j)),
                    (Some(f), _) => (f, None),
                    (None, Some((t, j))) => (t, Some(j)),
                };
                if !t.is_finite() {
                    return None;
                }
                if independent {
                    let z = factor.backward(&y);
                    x += z * t;
                    s += t * norm * norm;
                }
                for j in 0..ws.m {
                    ws.u[j] -= t * r[j];
                }
                u_new += t;
                match leaving {
                    Some(j) => {
                        ws.u[j] = T::zero();
                        ws.remove(j);
                    }
                    None => {
                        ws.append(&y, span, norm, &d, row, u_new);
                        fresh = false;
                        break;
                    }
                }
            }
        }
        // The multipliers afresh (not clamped) must have their signs: the Karush–Kuhn–Tucker
        // conditions, checked where the point moved since the release loop looked.
        if moved {
            hx = hessian_times(p, &factor.first, &x);
            let tol = sign_tolerance(p, &hx, tiny);
            if (0..ws.m).any(|j| wrong_sign(p, ws, j, tol)) {
                return None;
            }
        }
        let out = finish(p, ws, x, &hx, iterations);
        self.answered = out.is_some();
        out
    }
}

impl<T: RealField + Copy, const N: usize> Default for Dual<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: RealField + Copy, const N: usize> core::fmt::Debug for Dual<T, N> {
    /// The working set's size and whether the last solve answered (not the factors' numbers).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Dual")
            .field("rows", &self.ws.m)
            .field("answered", &self.answered)
            .finish_non_exhaustive()
    }
}

/// `‖aᵢ‖` of an inequality row `id` (a bound's is 1).
fn row_norm<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    id: usize,
) -> T {
    debug_assert!(id >= E, "an equality row has no sign to keep");
    if id < E + C {
        p.g.row(id - E).norm()
    } else {
        T::one()
    }
}

/// `ε^{2/3}`: the solver's tolerance of rank and of multipliers' signs.
fn tiny<T: RealField + Copy>() -> T {
    let eps = T::default_epsilon();
    (eps * eps).cbrt()
}

/// Row `id` held at its bound `side` as `sign · aᵀ x ≥ target`: `(id, sign, target, free)`,
/// `free` where it may leave (an inequality whose bounds differ); `None` for a bound of
/// magnitude `1e15` or more (a missing bound, which no row is held at).
fn oriented<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    id: usize,
    side: Side,
) -> Option<(usize, T, T, bool)> {
    let limit: T = nalgebra::convert(1e15);
    let (lo, hi) = bounds(p, id);
    let (sign, bound) = match side {
        Side::Upper => (-T::one(), -hi),
        _ => (T::one(), lo),
    };
    if !bound.is_finite() || bound.abs() >= limit {
        return None;
    }
    let free = id >= E && hi - lo > row_tolerance(feasibility::<T, N>(), lo, hi, T::zero());
    Some((id, sign, bound, free))
}

/// The solution on the working set `ws` with the point `x` (its minimiser, meeting every
/// inequality, its multipliers of their signs) and `hx = H x`, where the equalities hold to the
/// solver's tolerance and every number is finite.
fn finish<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    ws: &Working<T, N>,
    x: SVector<T, N>,
    hx: &SVector<T, N>,
    iterations: usize,
) -> Option<Solution<T, N, E, C>> {
    if !(all_finite(x.as_slice()) & all_finite(&ws.u.as_slice()[..ws.m])) {
        return None;
    }
    let feas = feasibility::<T, N>();
    let mut equality_residual = T::zero();
    for e in 0..E {
        let a = p.a_eq.row(e);
        let mag = (0..N).fold(T::zero(), |s, c| s + (a[c] * x[c]).abs());
        let res = ((a * x)[0] - p.b_eq[e]).abs();
        if !(res <= row_tolerance(feas, p.b_eq[e], p.b_eq[e], mag)) {
            return None;
        }
        equality_residual = equality_residual.max(res);
    }
    let mut active = ActiveSet::EMPTY;
    let mut y_eq = SVector::<T, E>::zeros();
    let mut z_general = SVector::<T, C>::zeros();
    let mut z_bounds = SVector::<T, N>::zeros();
    for j in 0..ws.m {
        let (id, lambda) = (ws.id[j], ws.u[j] * ws.sign[j]);
        let side = if ws.sign[j] < T::zero() {
            Side::Upper
        } else {
            Side::Lower
        };
        if id < E {
            y_eq[id] = lambda;
        } else if id < E + C {
            z_general[id - E] = lambda;
            active.general[id - E] = side;
        } else {
            z_bounds[id - E - C] = lambda;
            active.bounds[id - E - C] = side;
        }
    }
    let half = nalgebra::convert::<f64, T>(0.5);
    let objective = x.dot(hx) * half + p.f.dot(&x);
    let gx = p.g * x;
    let mut violation = T::zero();
    for g in 0..C {
        violation += (p.lo[g] - gx[g]).max(T::zero()) + (gx[g] - p.hi[g]).max(T::zero());
    }
    for k in 0..N {
        violation += (p.lb[k] - x[k]).max(T::zero()) + (x[k] - p.ub[k]).max(T::zero());
    }
    if !(objective.is_finite() && violation.is_finite()) {
        return None;
    }
    Some(Solution {
        x,
        status: Status::Optimal,
        iterations,
        active,
        objective,
        y_eq,
        z_general,
        z_bounds,
        equality_residual,
        violation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::qp::{ActiveSet, Settings, Side};

    /// A definite problem of 9 rates (three blocks of three, as a scene's arms), 2 equality rows
    /// and 2 general rows, from `seed` (a linear congruential sequence: no dependency).
    fn problem(seed: u64) -> Problem<f64, 9, 2, 2> {
        let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut h = SMatrix::<f64, 9, 9>::zeros();
        for b in 0..3 {
            let j = SMatrix::<f64, 3, 3>::from_fn(|_, _| next());
            let block = j.transpose() * j + SMatrix::<f64, 3, 3>::identity() * 0.05;
            h.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(&block);
        }
        Problem {
            h,
            f: SVector::from_fn(|_, _| 2.0 * next()),
            a_eq: SMatrix::from_fn(|_, _| next()),
            b_eq: SVector::from_fn(|_, _| 0.1 * next()),
            g: SMatrix::from_fn(|_, _| next()),
            lo: SVector::from_fn(|_, _| -0.3 + 0.2 * next()),
            hi: SVector::from_element(1e9),
            lb: SVector::from_fn(|_, _| -0.6 + 0.1 * next()),
            ub: SVector::from_fn(|_, _| 0.6 + 0.1 * next()),
        }
    }

    /// A second solve with the general rows' lower bounds raised (a scene's (S5)), from the
    /// first solve's working set and factors, gives the optimum that the primal method finds
    /// from a cold start; and `resolve` without a solve that answered declines.
    #[test]
    fn a_second_solve_with_other_bounds_gives_the_optimum() {
        let settings = Settings {
            max_iterations: 10_000,
        };
        let mut resolved = 0;
        for seed in 0..200 {
            let mut p = problem(seed);
            let mut dual = Dual::new();
            assert!(dual.resolve(&p).is_none(), "nothing solved yet");
            let Some(first) = dual.solve(&p, &ActiveSet::EMPTY) else {
                continue;
            };
            let primal = p.solve(&ActiveSet::EMPTY, &settings);
            assert!((first.x - primal.x).amax() <= 1e-9 * (1.0 + primal.x.amax()));
            // Raise each row's lower bound to what the first rates give it and more.
            let gx = p.g * first.x;
            for r in 0..2 {
                p.lo[r] = p.lo[r].max(gx[r]) + 0.05 * (r + 1) as f64;
            }
            let optimum = p.solve(&ActiveSet::EMPTY, &settings);
            if optimum.status != Status::Optimal {
                continue;
            }
            if let Some(second) = dual.resolve(&p) {
                resolved += 1;
                assert_eq!(second.status, Status::Optimal);
                assert!(
                    (second.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()),
                    "seed {seed}: {:e} from the optimum",
                    (second.x - optimum.x).amax()
                );
                assert_eq!(second.active, optimum.active, "seed {seed}");
            }
        }
        assert!(resolved >= 150, "only {resolved} second solves answered");
    }

    /// A workspace whose last solve declined midway (a multiplier overflowed) answers the next
    /// problem as a fresh one does; and a solve whose objective overflows declines rather than
    /// return a non-finite number.
    #[test]
    fn a_declined_solve_leaves_nothing_behind_and_overflow_declines() {
        let mut p = Problem::<f64, 2, 0, 1> {
            h: SMatrix::identity(),
            f: SVector::from([1e300, 0.0]),
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::from_row_slice(&[1e-10, 0.0]),
            lo: SVector::from([0.0]),
            hi: SVector::from([1.0]),
            lb: SVector::from([-1.0, -1.0]),
            ub: SVector::from([1.0, 1.0]),
        };
        let mut kept = Dual::new();
        let mut warm = ActiveSet::EMPTY;
        warm.general[0] = Side::Lower;
        assert!(kept.solve(&p, &warm).is_none());
        p.f = SVector::zeros();
        p.g = SMatrix::from_row_slice(&[1.0, 0.0]);
        p.lo[0] = -1.0;
        let fresh = Dual::new().solve(&p, &ActiveSet::EMPTY);
        assert!(fresh.is_some());
        assert_eq!(kept.solve(&p, &ActiveSet::EMPTY), fresh);
        // x = 1e160 squared overflows the objective.
        let big = Problem::<f64, 1, 0, 0> {
            h: SMatrix::identity(),
            f: SVector::from([-1e160]),
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: SVector::from([-1.0]),
            ub: SVector::from([1e200]),
        };
        assert!(Dual::new().solve(&big, &ActiveSet::EMPTY).is_none());
    }
}
