//! A dense, fixed-size, allocation-free quadratic program solver for one control step.
//!
//! # The problem
//!
//! In the joint rates `x ∈ Rⁿ` (`n = N`, a dozen at most in practice):
//!
//! ```text
//! minimise    ½ xᵀ H x + fᵀ x                                          (1)
//! subject to  A x = b            E equality rows (the trocar)          (2)
//!             lo ≤ G x ≤ hi      C general two-sided rows              (3)
//!             lb ≤ x ≤ ub        the box (speed limits, dampers)       (4)
//! ```
//!
//! with `H` symmetric positive semidefinite (only `(H + Hᵀ)/2` is used). Rows (3) and (4) are
//! handled alike: an *inequality row* `i` is `lᵢ ≤ aᵢᵀ x ≤ uᵢ`, `aᵢ` a row of `G` or a unit vector.
//! Every number must be finite (a missing bound is a large finite one) and `lo ≤ hi`,
//! `lb ≤ ub`; otherwise the solver returns [`Status::NonFinite`] or [`Status::InvalidBounds`]
//! with `x = 0` without iterating.
//!
//! # The method: a primal active-set method on an orthogonal null-space basis
//!
//! The method is the primal active-set method for convex QPs (Nocedal & Wright, *Numerical
//! Optimization*, 2nd ed., Algorithm 16.3; Gill, Murray & Wright, *Practical Optimization*, §5.3)
//! with a working set `W` of linearly independent rows held at their bounds, in three phases.
//!
//! **Phase 0, the equalities.** The rows of `A` are orthogonalised one by one, each time taking
//! the row with the largest component outside the span of those taken (Householder QR with
//! pivoting); a row whose remaining component is below `ε^{2/3}` of the largest row norm is
//! linearly dependent and left out. With `R₁₁` the triangle of the `r` independent rows `A₁`
//! and `S = A Q₁` all rows in that basis, the point `x = Q₁ z` solves
//!
//! ```text
//! R₁₁ᵀ z = b₁        when every row is met by it (the consistent case),          (5)
//! Sᵀ S z = Sᵀ b      otherwise (least squares, one step of refinement),          (6)
//! ```
//!
//! and the rows `A₁ x = b̂₁ = R₁₁ᵀ z` are the equality part of every working set from then on:
//! the equalities are met first, exactly when they are consistent and in the least-squares
//! sense (`‖A x − b‖₂` minimal) when they are not ([`Status::EqualitiesInconsistent`]).
//!
//! **The working set and its step.** `V = [A₁ᵀ | aᵢ, i ∈ W]` (`n × k`) is kept as `V = Q R`
//! (`Q` orthogonal `n × n`, accumulated from Householder reflections; a row joins in `O(n²)`
//! by one reflection and leaves in `O(n k)` by Givens rotations that restore the triangle of
//! `R` (Gill, Golub, Murray & Saunders 1974; Golub & Van Loan §6.5.2)), and `Z = Q[:, k..n]` is an orthonormal basis of
//! the directions that keep every row of `W` at its bound. At a point `x` with gradient
//! `g = H x + f` the step is the minimiser over those directions,
//!
//! ```text
//! p = Z p_z,    (Zᵀ H Z) p_z = −Zᵀ g,                                        (7)
//! ```
//!
//! solved by a Cholesky factorisation `Pᵀ L D Lᵀ P` of the reduced Hessian with diagonal
//! pivoting, which stops at the first pivot below `ε^{2/3}` of the largest diagonal entry (rank
//! `ρ`). If `Zᵀ g` lies in the range of the reduced Hessian, (7) is solved with the `m − ρ`
//! trailing (pivoted) components of `p_z` zero — a minimiser on the working set. Otherwise the
//! working set leaves a direction of zero curvature along which `g` descends: with `ĝ = P Zᵀ g`
//! split as `(ĝ₁, ĝ₂)` and the residual `ρ₂ = −ĝ₂ + L₂₁ L₁₁⁻¹ ĝ₁`,
//!
//! ```text
//! p_z = Pᵀ [ −L₁₁⁻ᵀ L₂₁ᵀ ρ₂ ;  ρ₂ ],   Zᵀ H Z p_z = 0,   gᵀ p = −‖ρ₂‖² < 0,       (8)
//! ```
//!
//! and the step along it is limited only by the rows it meets. The box (4) bounds every
//! direction, so such a step always ends on a row: this is how a rank-deficient `H` (the task's
//! `JᵀJ` with no damping, `κ = 0`) is handled exactly, with no regularisation.
//!
//! **Phase 1, feasibility** (the feasibility phase of Gill, Murray & Wright, §5.9.2, and of
//! QPOPT, with the `ℓ₁` release rule of an elastic/`ℓ₁` program). From the minimiser (7) of the
//! warm-start working set, while some inequality row is violated, the method minimises the
//! *sum of infeasibilities*
//!
//! ```text
//! φ(x) = Σᵢ max(0, lᵢ − aᵢᵀx) + max(0, aᵢᵀx − uᵢ),    ∇φ = c = Σ_{above} aᵢ − Σ_{below} aᵢ,   (9)
//! ```
//!
//! over the equalities by projected steepest descent `p = −Z Zᵀ c`, stepping to the first row
//! that becomes active or satisfied and adding it to `W`. When `Zᵀ c = 0` the multipliers
//! `c = V μ` are examined: a row at its lower bound lowers `φ` by leaving it upwards (feasible)
//! when `μᵢ < 0` and downwards (into violation) when `μᵢ > 1`; at its upper bound, when
//! `μᵢ > 0` or `μᵢ < −1` — the subgradient of the row's own term is `[0, 1] aᵢ`. The row with
//! the largest gain is released (into violation if so). If `φ` reaches zero the point is
//! feasible. If none can be released, `x` minimises `φ` over the equality set (every kink's
//! multiplier is within its subgradient interval: the optimality condition of the convex,
//! piecewise-linear `φ`) and, `φ > 0`, the inequalities cannot be met together with the
//! equalities: each violated row's bound is moved to the value the row has at `x` and the
//! solve goes on with these relaxed bounds ([`Status::InequalitiesRelaxed`],
//! [`Solution::violation`] the least total violation).
//!
//! **Phase 2, optimality** (Nocedal & Wright, Algorithm 16.3). From a feasible point: take the
//! step (7) or (8); if a row not in `W` blocks it, stop on that row and add it (a row is only
//! added when `|aᵢᵀ p| > ε^{2/3} ‖aᵢ‖ ‖p‖`, so `W` stays linearly independent and parallel or
//! duplicated rows never enter it together); at a minimiser on `W` compute the multipliers
//!
//! ```text
//! g = V λ,   λ = R⁻¹ Q₁ᵀ g,                                                  (10)
//! ```
//!
//! and release the row with the most negative scaled multiplier `λᵢ ‖aᵢ‖` of the wrong sign (a
//! row at its lower bound needs `λᵢ ≥ 0`, at its upper bound `λᵢ ≤ 0`, a row with `lᵢ = uᵢ`
//! either sign; the tolerance is `ε^{2/3} (1 + ‖g‖∞)`); if there is none, `x` satisfies the
//! Karush–Kuhn–Tucker conditions of (1)–(4) and is optimal. Each row that joins or leaves `W`
//! is an *iteration*; [`Settings::max_iterations`] bounds them, and with them the time: each
//! costs `O(n³)` operations (`n²` to add a row, `n k` to release one, `n²(n − k)` for the
//! reduced Hessian), so a solve costs at most `max_iterations × O(n³)`.
//!
//! # Why this method
//!
//! - *Exact.* The optimum is the solution of a linear system on the final working set,
//!   computed from orthogonal factors: `x` is as accurate as the conditioning of the active
//!   rows and of the reduced Hessian allow (1e-12 and better on well-scaled problems), not to
//!   the tolerance of an interior-point or first-order iteration.
//! - *Positive semidefinite `H`.* The dual method of Goldfarb & Idnani, the classic for small
//!   dense QPs, needs `H` positive definite (it starts from the unconstrained minimiser and
//!   works with `H⁻¹`); the controller's task Hessian `JᵀJ + κ²I` is singular when `κ = 0`. The
//!   primal method works on the reduced Hessian only, and (8) takes its zero-curvature
//!   directions to the box. Where `H` is positive definite (a scene's QP, whose objective
//!   weights every rate), [`solve_definite`] runs the dual method first, warm-started (11)–(12).
//! - *Warm start.* Given the previous step's active set, the first point is the minimiser (7)
//!   on that working set; when the active set has not changed it is feasible and its
//!   multipliers have the right signs, and the solve ends after one factorisation: no
//!   iteration.
//! - *Bounded time, no allocation, no panic.* Fixed-size arrays throughout, a bounded number of
//!   iterations of bounded cost, every division guarded.
//! - *Fast enough.* On the controller's problem (`n = 7`, 2 trocar rows, 14 box bounds and one
//!   two-sided depth row) a warm-started solve takes about a microsecond, well within a control
//!   step and far below an interior-point solve (Clarabel) of the same problems (see
//!   BENCHMARKS.md; `cargo bench -p trocar --bench qp`).
//!
//! # What is guaranteed
//!
//! - `x` is always finite; on [`Status::NonFinite`] and [`Status::InvalidBounds`] it is zero.
//! - The equalities are met (up to rounding) or, when inconsistent, met in least squares; this
//!   holds on every status but those two, [`Status::IterationLimit`] included.
//! - [`Status::Optimal`], [`Status::EqualitiesInconsistent`], [`Status::InequalitiesRelaxed`]:
//!   `x` is a minimiser of (1) under the (least-squares) equalities and the inequalities (relaxed
//!   as above, if so), with multipliers in [`Solution`].
//! - [`Status::IterationLimit`] in phase 2: `x` meets every (relaxed) inequality and its
//!   objective is no higher than that of the first feasible point; in phase 1: `x` meets the
//!   equalities and its total violation is no higher than at the start.
//! - *When the inequalities have a common point* (the controller's always do: its box need not
//!   hold `x = 0` — with acceleration limits the rates stay near the previous step's — but the
//!   depth row is clipped to its range over the box, `trocar::control::hard_limits` (Q4')): the
//!   inequality rows are consistent on their own, so a relaxation can only come from the
//!   equalities. The start need not be feasible: phase 1 reaches the inequalities from the
//!   minimiser of the warm start's working set, wherever that is. Without equality rows, the
//!   status is [`Status::Optimal`] unless the iteration limit is reached. With them,
//!   [`Status::InequalitiesRelaxed`] says that no joint rates keep the trocar and every limit;
//!   the trocar is kept and the limits are exceeded by the least total amount.
//! - A relaxation is minimal in total (`ℓ₁`) violation over the (least-squares) equality set;
//!   when several points reach that least total with different rows violated, `x` is optimal
//!   for the relaxation of the one phase 1 stopped at, not necessarily the best of them. The
//!   relaxed bounds are not part of [`ActiveSet`]: a warm start of a still-infeasible problem
//!   runs phase 1 again.
//!
//! The tolerances scale with the machine epsilon `ε` of `T`: `ε^{2/3}` (4e-11 for `f64`,
//! 2e-5 for `f32`) for rank, dependence and multiplier signs, `64 n ε` relative for the
//! feasibility of a row (`64 n ε (1 + |bound| + Σ|aᵢⱼ xⱼ|)`, each bound of its own size: a
//! missing bound, a large finite one, does not loosen the other). A curvature below `ε^{2/3}` of the largest is treated as zero: a
//! direction that flat is followed to the box like an exactly flat one.

// Dense factorisations read best as index loops over the fixed-size arrays; `!(a > b)` is
// meant wherever it appears: a NaN fails the test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use crate::linalg::Cholesky;

mod dual;

pub use dual::Dual;
use nalgebra::{RealField, SMatrix, SVector};

/// Which bound of an inequality row holds it in the active set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Side {
    /// Not in the active set.
    #[default]
    Inactive,
    /// At its lower bound (`lo` or `lb`).
    Lower,
    /// At its upper bound (`hi` or `ub`).
    Upper,
}

/// The inequality rows held at a bound: what a solve reports and what the next solve starts
/// from (the warm start). The equality rows are always active and not listed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActiveSet<const N: usize, const C: usize> {
    /// The general rows `lo ≤ G x ≤ hi`, by row.
    pub general: [Side; C],
    /// The box `lb ≤ x ≤ ub`, by variable.
    pub bounds: [Side; N],
}

impl<const N: usize, const C: usize> ActiveSet<N, C> {
    /// No inequality active: a cold start.
    pub const EMPTY: Self = ActiveSet {
        general: [Side::Inactive; C],
        bounds: [Side::Inactive; N],
    };

    /// The number of active inequality rows.
    pub fn len(&self) -> usize {
        self.general
            .iter()
            .chain(self.bounds.iter())
            .filter(|s| **s != Side::Inactive)
            .count()
    }

    /// `true` when no inequality row is active.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<const N: usize, const C: usize> Default for ActiveSet<N, C> {
    fn default() -> Self {
        Self::EMPTY
    }
}

/// A QP (1)–(4) of `N` variables, `E` equality rows and `C` general inequality rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Problem<T: RealField + Copy, const N: usize, const E: usize, const C: usize> {
    /// The Hessian `H` (symmetric positive semidefinite; `(H + Hᵀ)/2` is used).
    pub h: SMatrix<T, N, N>,
    /// The linear term `f`.
    pub f: SVector<T, N>,
    /// The equality rows `A`.
    pub a_eq: SMatrix<T, E, N>,
    /// The equality right-hand side `b`.
    pub b_eq: SVector<T, E>,
    /// The general inequality rows `G`.
    pub g: SMatrix<T, C, N>,
    /// Lower bounds `lo` of `G x`.
    pub lo: SVector<T, C>,
    /// Upper bounds `hi` of `G x`.
    pub hi: SVector<T, C>,
    /// Lower bounds `lb` of `x`.
    pub lb: SVector<T, N>,
    /// Upper bounds `ub` of `x`.
    pub ub: SVector<T, N>,
}

/// The outcome of a solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Every constraint is met and `x` is optimal.
    Optimal,
    /// The equality rows have no common solution: `x` meets them in least squares (smallest
    /// `‖A x − b‖₂`), meets the inequalities and is optimal under those constraints.
    EqualitiesInconsistent,
    /// The inequalities cannot be met together with the equalities: `x` meets the equalities
    /// (in least squares if they are inconsistent too: see [`Solution::equality_residual`]),
    /// exceeds the inequalities by the least total amount ([`Solution::violation`]) and is
    /// optimal under the relaxed bounds.
    InequalitiesRelaxed,
    /// [`Settings::max_iterations`] rows joined or left the active set before the optimum was
    /// reached: `x` meets the equalities and is the last iterate (see the module docs).
    IterationLimit,
    /// Some input is NaN or infinite, or the computation overflowed: `x = 0`.
    NonFinite,
    /// Some `lo > hi` or `lb > ub`: `x = 0`.
    InvalidBounds,
}

/// The solver's settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// The most rows that may join or leave the active set in one solve (phases 1 and 2
    /// together); it bounds the time of a solve.
    pub max_iterations: usize,
}

impl Settings {
    /// The default limit: 100 changes of the active set, many times what a cold start of the
    /// controller's problems takes (a warm start usually takes none).
    pub const DEFAULT: Settings = Settings {
        max_iterations: 100,
    };
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The result of a solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<T: RealField + Copy, const N: usize, const E: usize, const C: usize> {
    /// The joint rates `x` (always finite).
    pub x: SVector<T, N>,
    /// How the solve ended.
    pub status: Status,
    /// The rows that joined or left the active set (0 when the warm start was right).
    pub iterations: usize,
    /// The inequality rows at a bound at `x`: the next solve's warm start.
    pub active: ActiveSet<N, C>,
    /// `½ xᵀ H x + fᵀ x`.
    pub objective: T,
    /// Multipliers of the equality rows, with those below: `H x + f = Aᵀ y + Gᵀ z_g + z_b`.
    /// Dependent rows get 0. Meaningful when the status is [`Status::Optimal`],
    /// [`Status::EqualitiesInconsistent`] or [`Status::InequalitiesRelaxed`].
    pub y_eq: SVector<T, E>,
    /// Multipliers of the general rows: `≥ 0` at a lower bound, `≤ 0` at an upper bound, 0 when
    /// inactive.
    pub z_general: SVector<T, C>,
    /// Multipliers of the box, signed as [`Solution::z_general`].
    pub z_bounds: SVector<T, N>,
    /// `‖A x − b‖∞`: zero up to rounding unless the equalities are inconsistent.
    pub equality_residual: T,
    /// The total violation of the inequality rows at `x`, `Σ max(0, lᵢ − aᵢᵀx, aᵢᵀx − uᵢ)`:
    /// zero up to rounding unless the status is [`Status::InequalitiesRelaxed`].
    pub violation: T,
}

/// `true` when every value is finite: one pass without an early exit, which the compiler
/// turns into vector compares (an iterator that stops at the first failure does not vectorise,
/// and a 21-rate scene's problem has some 800 values).
pub(crate) fn all_finite<T: RealField + Copy>(values: &[T]) -> bool {
    values.iter().fold(true, |ok, v| ok & v.is_finite())
}

impl<T: RealField + Copy, const N: usize, const E: usize, const C: usize> Problem<T, N, E, C> {
    /// `true` when every number of the problem is finite (the solvers refuse the others).
    pub fn is_finite(&self) -> bool {
        all_finite(self.h.as_slice())
            & all_finite(self.f.as_slice())
            & all_finite(self.a_eq.as_slice())
            & all_finite(self.b_eq.as_slice())
            & all_finite(self.g.as_slice())
            & all_finite(self.lo.as_slice())
            & all_finite(self.hi.as_slice())
            & all_finite(self.lb.as_slice())
            & all_finite(self.ub.as_slice())
    }

    /// Solves the problem from the warm start `warm` (the previous step's
    /// [`Solution::active`], or [`ActiveSet::EMPTY`]): see [`solve`].
    pub fn solve(&self, warm: &ActiveSet<N, C>, settings: &Settings) -> Solution<T, N, E, C> {
        solve(self, warm, settings)
    }

    /// `true` when `x` meets every inequality row, `lo ≤ G x ≤ hi` and `lb ≤ x ≤ ub`, within the
    /// solver's feasibility tolerance (the test it applies to its own iterates). A NaN does not
    /// meet them.
    pub fn meets_inequalities(&self, x: &SVector<T, N>) -> bool {
        all_finite(x.as_slice()) && self.most_violated(x).is_none()
    }

    /// The inequality row that `x` (finite) violates most beyond the solver's feasibility
    /// tolerance, the violation of a general row measured along its normal (over `‖g_r‖`), and
    /// the side it violates: `(Violated::General(r), side)` or `(Violated::Bound(k), side)`;
    /// `None` where `x` meets every row.
    fn most_violated(&self, x: &SVector<T, N>) -> Option<(Violated, Side)> {
        let feas = feasibility::<T, N>();
        let mut most: Option<(T, Violated, Side)> = None;
        let mut consider = |by: T, row: Violated, side: Side| {
            if most.is_none_or(|(m, _, _)| by > m) {
                most = Some((by, row, side));
            }
        };
        for r in 0..C {
            let row = self.g.row(r);
            let mag = (0..N).fold(T::zero(), |m, j| m + (row[j] * x[j]).abs());
            let (tol_lo, tol_hi) = side_tolerances(feas, self.lo[r], self.hi[r], mag);
            let s = (row * x)[0];
            if s < self.lo[r] - tol_lo {
                consider(
                    (self.lo[r] - s) / row.norm(),
                    Violated::General(r),
                    Side::Lower,
                );
            } else if s > self.hi[r] + tol_hi {
                consider(
                    (s - self.hi[r]) / row.norm(),
                    Violated::General(r),
                    Side::Upper,
                );
            }
        }
        for k in 0..N {
            let (tol_lo, tol_hi) = side_tolerances(feas, self.lb[k], self.ub[k], x[k].abs());
            if x[k] < self.lb[k] - tol_lo {
                consider(self.lb[k] - x[k], Violated::Bound(k), Side::Lower);
            } else if x[k] > self.ub[k] + tol_hi {
                consider(x[k] - self.ub[k], Violated::Bound(k), Side::Upper);
            }
        }
        most.map(|(_, row, side)| (row, side))
    }
}

/// An inequality row of a [`Problem`]: general row `r`, or the bound of variable `k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Violated {
    General(usize),
    Bound(usize),
}

/// `64 n ε`: the solver's feasibility tolerance per unit of a row's size.
fn feasibility<T: RealField + Copy, const N: usize>() -> T {
    T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * N.max(1) as f64)
}

/// The feasibility tolerance of a row with bounds `l`, `u` and `Σ|a_j x_j| = mag` at `x`:
/// `feas (1 + max(|l|, |u|) + mag)` (whether the bounds are one, a fixed row).
fn row_tolerance<T: RealField + Copy>(feas: T, l: T, u: T, mag: T) -> T {
    feas * (T::one() + l.abs().max(u.abs()) + mag)
}

/// The feasibility tolerances of a row's lower and upper bound, each of its own bound's size:
/// `feas (1 + |l| + mag)` and `feas (1 + |u| + mag)` (a missing bound, a large finite one, does
/// not loosen the other).
fn side_tolerances<T: RealField + Copy>(feas: T, l: T, u: T, mag: T) -> (T, T) {
    (
        feas * (T::one() + l.abs() + mag),
        feas * (T::one() + u.abs() + mag),
    )
}

/// Solves `problem` from the warm start `warm` (see the [module docs](self) for the method and
/// what each [`Status`] guarantees). Allocates nothing and does not panic (with the bench-only
/// feature `qp-record`, [`record`] keeps a copy of every problem while it records).
pub fn solve<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    problem: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
    settings: &Settings,
) -> Solution<T, N, E, C> {
    let out = solve_from(problem, warm, settings);
    #[cfg(feature = "qp-record")]
    record::push(problem, warm, &out);
    out
}

/// [`solve`] for a positive definite `H`: the dual active-set method of Goldfarb & Idnani
/// ([`solve_range_space`]) from the warm start's working set first. With `H = L Lᵀ` and the
/// working set's rows `N` held at their targets `τ`,
///
/// ```text
/// Y = L⁻¹ N = Q R,   Rᵀ ζ = τ + Rᵀ Qᵀ L⁻¹ f,   R u = ζ,   x = L⁻ᵀ (Q ζ − L⁻¹ f)      (11)
/// ```
///
/// is the minimiser of (1) on the working set and `u` its multipliers (`H x + f = N u`). The
/// warm start's rows whose multipliers have the wrong sign leave it, and violated rows join
/// it one at a time along the dual method's step, each change an update of `Q R` in `O(n m)`,
/// until `x` meets every row: the optimum ([`Status::Optimal`]; [`Solution::iterations`]
/// counts the rows that joined or left). From the optimum's own working set — a controller's
/// warm start, usually — that is one Cholesky of `H` and one QR of `Y`, where the primal
/// method orthogonalises the working set and factors the reduced Hessian; a coupling coming in
/// or a joint leaving its bound costs a step each. Where the dual method declines — `H` not
/// positive definite to `√ε` of its largest diagonal entry, an equality row dependent on the
/// others, inequalities that cannot be met together with the equalities, or an answer that
/// does not meet the Karush–Kuhn–Tucker conditions within the solver's tolerances (an `H` or a
/// working set too ill-conditioned for (11)) — [`solve`] solves the problem. Allocates nothing
/// and does not panic.
pub fn solve_definite<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    problem: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
    settings: &Settings,
) -> Solution<T, N, E, C> {
    match solve_range_space(problem, warm) {
        Some(out) => {
            #[cfg(feature = "qp-record")]
            record::push(problem, warm, &out);
            out
        }
        None => solve(problem, warm, settings),
    }
}

/// The dual active-set method of Goldfarb & Idnani (*Math. Programming* 27, 1983) from the
/// warm start's working set, the first half of [`solve_definite`]: the warm start's rows taken
/// in as equalities (a dependent one left out), the rows whose multipliers have the wrong sign
/// released (all at once, until none is left), then the most violated row taken in along
///
/// ```text
/// z = L⁻ᵀ (I − Q Qᵀ) L⁻¹ n₊ (primal),   r = R⁻¹ Qᵀ L⁻¹ n₊ (dual)                      (12)
/// ```
///
/// by the full step that brings it to its bound, or a partial step where an active row's
/// multiplier reaches zero first (that row leaves, and the step is taken again). The optimum
/// with its multipliers, or `None` where `H` is not positive definite to `√ε`, an equality row
/// depends on the others, the rows cannot be met together, or the answer does not meet the
/// Karush–Kuhn–Tucker conditions within the solver's tolerances; [`solve_definite`] falls back
/// on [`solve`] then. Allocates nothing and does not panic.
pub fn solve_range_space<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    p: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
) -> Option<Solution<T, N, E, C>> {
    dual::solve(p, warm)
}

/// [`solve`]'s work.
fn solve_from<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
    problem: &Problem<T, N, E, C>,
    warm: &ActiveSet<N, C>,
    settings: &Settings,
) -> Solution<T, N, E, C> {
    let mut out = Solution {
        x: SVector::zeros(),
        status: Status::NonFinite,
        iterations: 0,
        active: ActiveSet::EMPTY,
        objective: T::zero(),
        y_eq: SVector::zeros(),
        z_general: SVector::zeros(),
        z_bounds: SVector::zeros(),
        equality_residual: T::zero(),
        violation: T::zero(),
    };
    let p = problem;
    if !p.is_finite() {
        return out;
    }
    if p.lo.iter().zip(p.hi.iter()).any(|(l, u)| l > u)
        || p.lb.iter().zip(p.ub.iter()).any(|(l, u)| l > u)
    {
        out.status = Status::InvalidBounds;
        return out;
    }
    let mut w = Work::new(p);
    let (status, iterations) = w.run(p, warm, settings.max_iterations);
    out.iterations = iterations;
    w.finish(p, status, &mut out);
    if !(out.x.iter().all(|v| v.is_finite())
        && out.objective.is_finite()
        && out.y_eq.iter().all(|v| v.is_finite())
        && out.z_general.iter().all(|v| v.is_finite())
        && out.z_bounds.iter().all(|v| v.is_finite()))
    {
        out = Solution {
            x: SVector::zeros(),
            status: Status::NonFinite,
            iterations,
            active: ActiveSet::EMPTY,
            objective: T::zero(),
            y_eq: SVector::zeros(),
            z_general: SVector::zeros(),
            z_bounds: SVector::zeros(),
            equality_residual: T::zero(),
            violation: T::zero(),
        };
    }
    out
}

#[inline(always)]
fn dot<T: RealField + Copy, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    let mut s = T::zero();
    for i in 0..N {
        s += a[i] * b[i];
    }
    s
}

#[inline(always)]
fn norm_inf<T: RealField + Copy, const N: usize>(a: &[T; N]) -> T {
    let mut m = T::zero();
    for v in a {
        m = m.max(v.abs());
    }
    m
}

/// `V = Q R` for the working set's normals `V` (`n × k`), `Q` kept explicitly.
#[derive(Clone, Copy)]
struct Basis<T: RealField + Copy, const N: usize> {
    /// Columns of `Q`: `q[j][t] = Q_{t j}`.
    q: [[T; N]; N],
    /// Columns of `R`: `r[j][i] = R_{i j}`, `i ≤ j < k`.
    r: [[T; N]; N],
    k: usize,
}

impl<T: RealField + Copy, const N: usize> Basis<T, N> {
    fn identity() -> Self {
        let mut q = [[T::zero(); N]; N];
        for (j, col) in q.iter_mut().enumerate() {
            col[j] = T::one();
        }
        Basis {
            q,
            r: [[T::zero(); N]; N],
            k: 0,
        }
    }

    /// `Qᵀ a`.
    #[inline(always)]
    fn coords(&self, a: &[T; N]) -> [T; N] {
        let mut w = [T::zero(); N];
        for (wj, qj) in w.iter_mut().zip(self.q.iter()) {
            *wj = dot(qj, a);
        }
        w
    }

    /// The norm of the part of `a` outside the span of the first `k` columns, from `w = Qᵀ a`.
    fn outside(&self, w: &[T; N]) -> T {
        let mut s = T::zero();
        for v in &w[self.k..] {
            s += *v * *v;
        }
        s.sqrt()
    }

    /// Appends the column `a` (`w = Qᵀ a` given) by one Householder reflection on `Q`'s columns
    /// `k..n`. `false` (and nothing changed) if `a` is within `tol ‖a‖` of the span.
    fn push_coords(&mut self, w: &[T; N], anorm: T, tol: T) -> bool {
        let k = self.k;
        if k >= N {
            return false;
        }
        let sigma = self.outside(w);
        if !(sigma > tol * anorm) {
            return false;
        }
        let alpha = if w[k] > T::zero() { -sigma } else { sigma };
        let mut v = [T::zero(); N];
        v[k..].copy_from_slice(&w[k..]);
        v[k] -= alpha;
        // vᵀv = 2σ(σ + |w_k|) > 0.
        let vtv = (sigma + w[k].abs()) * sigma * (T::one() + T::one());
        let scale = (T::one() + T::one()) / vtv;
        // Q ← Q (I − 2 v vᵀ / vᵀv) on columns k..n: `u = Q v` column by column (whole columns
        // of `Q` at a time, contiguous), then `Q[:, i] −= (scale v_i) u`.
        let mut u = [T::zero(); N];
        for i in k..N {
            let (qi, vi) = (&self.q[i], v[i]);
            for t in 0..N {
                u[t] += qi[t] * vi;
            }
        }
        for ut in u.iter_mut() {
            *ut *= scale;
        }
        for i in k..N {
            let vi = v[i];
            let qi = &mut self.q[i];
            for t in 0..N {
                qi[t] -= u[t] * vi;
            }
        }
        let mut col = [T::zero(); N];
        col[..k].copy_from_slice(&w[..k]);
        col[k] = alpha;
        self.r[k] = col;
        self.k = k + 1;
        true
    }

    fn push(&mut self, a: &[T; N], tol: T) -> bool {
        let w = self.coords(a);
        let anorm = dot(a, a).sqrt();
        self.push_coords(&w, anorm, tol)
    }

    /// Removes column `c` of `V` (`c < k`) in `O(n k)`: the columns after it shift left,
    /// which leaves `R` upper Hessenberg from column `c` on; Givens rotations of rows `j, j + 1`
    /// (`j = c..k − 1`) restore the triangle, and the same rotations of `Q`'s columns `j, j + 1`
    /// keep `V = Q R`. The columns of `Q` before `c` (the equality rows' among them) do not
    /// change.
    fn remove_column(&mut self, c: usize) {
        let k = self.k;
        if c >= k {
            return;
        }
        for j in c..k - 1 {
            self.r[j] = self.r[j + 1];
        }
        self.r[k - 1] = [T::zero(); N];
        for j in c..k - 1 {
            let (a, b) = (self.r[j][j], self.r[j][j + 1]);
            let rho = (a * a + b * b).sqrt();
            if !(rho > T::zero()) {
                continue;
            }
            let (cs, sn) = (a / rho, b / rho);
            // Rows j and j + 1 of R, in the columns j..k − 1 that remain.
            for col in self.r[j..k - 1].iter_mut() {
                let (x, y) = (col[j], col[j + 1]);
                col[j] = cs * x + sn * y;
                col[j + 1] = cs * y - sn * x;
            }
            self.r[j][j + 1] = T::zero();
            // Q ← Q Gᵀ on columns j and j + 1.
            let (left, right) = self.q.split_at_mut(j + 1);
            let (qj, qj1) = (&mut left[j], &mut right[0]);
            for t in 0..N {
                let (x, y) = (qj[t], qj1[t]);
                qj[t] = cs * x + sn * y;
                qj1[t] = cs * y - sn * x;
            }
        }
        self.k = k - 1;
    }

    /// `y` with `Rᵀ y = b` (forward substitution), then `Q₁ y`: the least-norm `x` with
    /// `Vᵀ x = b`.
    fn particular(&self, b: &[T; N]) -> [T; N] {
        let mut y = [T::zero(); N];
        for j in 0..self.k {
            let mut s = b[j];
            for (l, yl) in y.iter().enumerate().take(j) {
                s -= self.r[j][l] * *yl;
            }
            y[j] = s / self.r[j][j];
        }
        let mut x = [T::zero(); N];
        for (j, yj) in y.iter().enumerate().take(self.k) {
            for t in 0..N {
                x[t] += self.q[j][t] * *yj;
            }
        }
        x
    }

    /// `λ` with `R λ = Q₁ᵀ g`: the multipliers (10).
    fn multipliers(&self, g: &[T; N]) -> [T; N] {
        let mut lam = [T::zero(); N];
        for j in 0..self.k {
            lam[j] = dot(&self.q[j], g);
        }
        for j in (0..self.k).rev() {
            let mut s = lam[j];
            for l in j + 1..self.k {
                s -= self.r[l][j] * lam[l];
            }
            lam[j] = s / self.r[j][j];
        }
        lam
    }
}

/// The solver's state: the data as arrays, the (possibly relaxed) bounds, the working set.
struct Work<T: RealField + Copy, const N: usize, const C: usize> {
    h: [[T; N]; N],
    f: [T; N],
    rows: [[T; N]; C],
    row_norm: [T; C],
    lo: [T; C],
    hi: [T; C],
    lb: [T; N],
    ub: [T; N],
    side_g: [Side; C],
    side_b: [Side; N],
    /// Phase 1: rows released from the working set into violation (below: `Lower`), counted
    /// as violated while they stay at that bound.
    forced_g: [Side; C],
    forced_b: [Side; N],
    /// Inequality rows in the working set (ids: `< C` general, `C + j` the box of `x_j`), in
    /// the order of the basis columns after the `r` equality rows.
    act: [usize; N],
    nact: usize,
    /// Equality rows in the working set (pivot order: `eq_order[j]` is the row of `A`) and
    /// their right-hand sides `b̂₁`.
    r: usize,
    eq_order: [usize; N],
    eq_rhs: [T; N],
    eq_basis: Basis<T, N>,
    basis: Basis<T, N>,
    x: [T; N],
    relaxed: bool,
    eq_inconsistent: bool,
    /// `ε^{2/3}`.
    tiny: T,
    /// `64 n ε`.
    feas: T,
    /// `16 ε`.
    round: T,
}

enum Phase1 {
    Feasible,
    Relaxed,
    Limit,
}

impl<T: RealField + Copy, const N: usize, const C: usize> Work<T, N, C> {
    fn new<const E: usize>(p: &Problem<T, N, E, C>) -> Self {
        let half: T = nalgebra::convert(0.5);
        let h =
            core::array::from_fn(|i| core::array::from_fn(|j| (p.h[(i, j)] + p.h[(j, i)]) * half));
        let rows: [[T; N]; C] = core::array::from_fn(|i| core::array::from_fn(|j| p.g[(i, j)]));
        let row_norm = core::array::from_fn(|i| dot(&rows[i], &rows[i]).sqrt());
        let eps = T::default_epsilon();
        Work {
            h,
            f: core::array::from_fn(|i| p.f[i]),
            rows,
            row_norm,
            lo: core::array::from_fn(|i| p.lo[i]),
            hi: core::array::from_fn(|i| p.hi[i]),
            lb: core::array::from_fn(|i| p.lb[i]),
            ub: core::array::from_fn(|i| p.ub[i]),
            side_g: [Side::Inactive; C],
            side_b: [Side::Inactive; N],
            forced_g: [Side::Inactive; C],
            forced_b: [Side::Inactive; N],
            act: [0; N],
            nact: 0,
            r: 0,
            eq_order: [0; N],
            eq_rhs: [T::zero(); N],
            eq_basis: Basis::identity(),
            basis: Basis::identity(),
            x: [T::zero(); N],
            relaxed: false,
            eq_inconsistent: false,
            tiny: eps.powf(nalgebra::convert(2.0 / 3.0)),
            feas: feasibility::<T, N>(),
            round: eps * nalgebra::convert::<f64, T>(16.0),
        }
    }

    // ---- rows by id ----

    #[inline(always)]
    fn row_dot(&self, id: usize, v: &[T; N]) -> T {
        if id < C {
            dot(&self.rows[id], v)
        } else {
            v[id - C]
        }
    }

    #[inline(always)]
    fn normal(&self, id: usize) -> [T; N] {
        if id < C {
            self.rows[id]
        } else {
            let mut e = [T::zero(); N];
            e[id - C] = T::one();
            e
        }
    }

    #[inline(always)]
    fn norm(&self, id: usize) -> T {
        if id < C {
            self.row_norm[id]
        } else {
            T::one()
        }
    }

    #[inline(always)]
    fn bounds(&self, id: usize) -> (T, T) {
        if id < C {
            (self.lo[id], self.hi[id])
        } else {
            (self.lb[id - C], self.ub[id - C])
        }
    }

    #[inline(always)]
    fn side(&self, id: usize) -> Side {
        if id < C {
            self.side_g[id]
        } else {
            self.side_b[id - C]
        }
    }

    #[inline(always)]
    fn set_side(&mut self, id: usize, s: Side) {
        if id < C {
            self.side_g[id] = s;
        } else {
            self.side_b[id - C] = s;
        }
    }

    fn set_forced(&mut self, id: usize, s: Side) {
        if id < C {
            self.forced_g[id] = s;
        } else {
            self.forced_b[id - C] = s;
        }
    }

    /// Phase 1's view of row `id` at `x`: `Lower` if violated below (or released below and
    /// still at that bound), `Upper` if above, `Inactive` if satisfied.
    fn violated(&self, id: usize) -> Side {
        let s = self.row_dot(id, &self.x);
        let (l, u) = self.bounds(id);
        let (tol_l, tol_u) = self.side_tolerances(id, &self.x);
        let forced = if id < C {
            self.forced_g[id]
        } else {
            self.forced_b[id - C]
        };
        if s < l - tol_l || (forced == Side::Lower && s <= l + tol_l) {
            Side::Lower
        } else if s > u + tol_u || (forced == Side::Upper && s >= u - tol_u) {
            Side::Upper
        } else {
            Side::Inactive
        }
    }

    fn bound_at(&self, id: usize, s: Side) -> T {
        let (l, u) = self.bounds(id);
        if s == Side::Upper {
            u
        } else {
            l
        }
    }

    /// The feasibility tolerance of row `id` at `x`: `64 n ε (1 + |bounds| + Σ|a_j x_j|)`.
    fn feas_tol(&self, id: usize, x: &[T; N]) -> T {
        let (l, u) = self.bounds(id);
        row_tolerance(self.feas, l, u, self.magnitude(id, x))
    }

    /// The feasibility tolerances of row `id`'s lower and upper bound at `x`.
    fn side_tolerances(&self, id: usize, x: &[T; N]) -> (T, T) {
        let (l, u) = self.bounds(id);
        side_tolerances(self.feas, l, u, self.magnitude(id, x))
    }

    /// `Σ|a_j x_j|` of row `id`.
    fn magnitude(&self, id: usize, x: &[T; N]) -> T {
        if id < C {
            let mut m = T::zero();
            for j in 0..N {
                m += (self.rows[id][j] * x[j]).abs();
            }
            m
        } else {
            x[id - C].abs()
        }
    }

    /// Adds row `id` at side `s` to the working set; `false` if it is (numerically) dependent.
    fn add(&mut self, id: usize, s: Side) -> bool {
        if self.r + self.nact >= N {
            return false;
        }
        let a = self.normal(id);
        if !self.basis.push(&a, self.tiny) {
            return false;
        }
        self.act[self.nact] = id;
        self.nact += 1;
        self.set_side(id, s);
        self.set_forced(id, Side::Inactive);
        true
    }

    /// Removes the `t`-th inequality row of the working set: its column leaves the basis by
    /// Givens rotations ([`Basis::remove_column`]), `O(n²)`.
    fn remove(&mut self, t: usize) {
        let id = self.act[t];
        self.set_side(id, Side::Inactive);
        for u in t..self.nact - 1 {
            self.act[u] = self.act[u + 1];
        }
        self.nact -= 1;
        self.basis.remove_column(self.r + t);
    }

    /// The right-hand sides of the working set's rows.
    fn rhs(&self) -> [T; N] {
        let mut b = self.eq_rhs;
        for t in 0..self.nact {
            let id = self.act[t];
            b[self.r + t] = self.bound_at(id, self.side(id));
        }
        b
    }

    fn gradient(&self, x: &[T; N]) -> [T; N] {
        let mut g = self.f;
        for (i, gi) in g.iter_mut().enumerate() {
            *gi += dot(&self.h[i], x);
        }
        g
    }

    /// Sets the components of `v` on the active box rows to zero (the step keeps them there
    /// exactly) and, with `snap`, `x` on them to their bound.
    fn snap_box(&self, v: &mut [T; N], snap: bool) {
        for t in 0..self.nact {
            let id = self.act[t];
            if id >= C {
                v[id - C] = if snap {
                    self.bound_at(id, self.side(id))
                } else {
                    T::zero()
                };
            }
        }
    }

    // ---- phase 0: equalities ----

    fn equalities<const E: usize>(&mut self, p: &Problem<T, N, E, C>) {
        let rows: [[T; N]; E] = core::array::from_fn(|i| core::array::from_fn(|j| p.a_eq[(i, j)]));
        let mut taken = [false; E];
        let mut order = [0usize; N];
        let mut maxnorm = T::zero();
        for row in &rows {
            maxnorm = maxnorm.max(dot(row, row).sqrt());
        }
        let mut basis = Basis::identity();
        loop {
            if basis.k >= N {
                break;
            }
            let mut best = None;
            let mut best_out = T::zero();
            for (i, row) in rows.iter().enumerate() {
                if taken[i] {
                    continue;
                }
                let o = basis.outside(&basis.coords(row));
                if o > best_out {
                    best_out = o;
                    best = Some(i);
                }
            }
            let Some(i) = best else { break };
            if !(best_out > self.tiny * maxnorm) {
                break;
            }
            if !basis.push(&rows[i], T::zero()) {
                break;
            }
            taken[i] = true;
            order[basis.k - 1] = i;
        }
        let r = basis.k;
        // (5): the independent rows exactly.
        let mut b1 = [T::zero(); N];
        for j in 0..r {
            b1[j] = p.b_eq[order[j]];
        }
        let x1 = basis.particular(&b1);
        let mut bmax = T::zero();
        for v in p.b_eq.iter() {
            bmax = bmax.max(v.abs());
        }
        let tol = self.tiny * (T::one() + bmax + maxnorm * norm_inf(&x1));
        let consistent = rows
            .iter()
            .enumerate()
            .all(|(i, row)| (dot(row, &x1) - p.b_eq[i]).abs() <= tol);
        self.r = r;
        self.eq_order = order;
        self.eq_basis = basis;
        self.basis = basis;
        for (e, o) in self.eq_rhs.iter_mut().zip(order.iter()).take(r) {
            *e = p.b_eq[*o];
        }
        if consistent || E == 0 {
            return;
        }
        self.eq_inconsistent = true;
        if r == 0 {
            return;
        }
        // (6): S = A Q₁ (E × r), z from the normal equations, refined once; b̂₁ = R₁₁ᵀ z.
        let s: [[T; N]; E] = core::array::from_fn(|i| {
            let mut c = [T::zero(); N];
            for (j, cj) in c.iter_mut().enumerate().take(r) {
                *cj = dot(&basis.q[j], &rows[i]);
            }
            c
        });
        // SᵀS in the leading r × r block, the identity beside it: the core's Cholesky factors
        // the block as it would alone (the identity adds unit pivots and no fill), and a
        // right-hand side that is zero past r solves to zero there.
        let m = SMatrix::<T, N, N>::from_fn(|a, b| {
            if a < r && b < r {
                s.iter().fold(T::zero(), |v, si| v + si[a] * si[b])
            } else if a == b {
                T::one()
            } else {
                T::zero()
            }
        });
        let Some(chol) = Cholesky::new(&m) else {
            return;
        };
        let mut z = [T::zero(); N];
        for _ in 0..2 {
            let mut rhs = [T::zero(); N];
            for (i, si) in s.iter().enumerate() {
                let mut res = p.b_eq[i];
                for j in 0..r {
                    res -= si[j] * z[j];
                }
                for j in 0..r {
                    rhs[j] += si[j] * res;
                }
            }
            let dz = chol.solve(&SVector::<T, N>::from(rhs));
            for j in 0..r {
                z[j] += dz[j];
            }
        }
        for j in 0..r {
            let mut v = T::zero();
            for l in 0..=j {
                v += basis.r[j][l] * z[l];
            }
            self.eq_rhs[j] = v;
        }
    }

    // ---- the step (7)/(8) ----

    /// The step from `x` with gradient `g` on the working set: `(p, newton)`, `newton` when `p`
    /// solves (7) (a minimiser on the working set is `x + p`), otherwise a descent direction of
    /// zero curvature (8).
    fn step(&self, g: &[T; N]) -> ([T; N], bool) {
        let k = self.basis.k;
        let m = N - k;
        let mut p = [T::zero(); N];
        if m == 0 {
            return (p, true);
        }
        let q = &self.basis.q;
        // M = Zᵀ H Z, gz = Zᵀ g.
        // H Z column by column as sums of H's (contiguous) columns; H is exactly symmetric, so
        // each entry is the same sum in the same order as the dot product of a row of H.
        let mut hz = [[T::zero(); N]; N];
        for (hzj, qj) in hz.iter_mut().zip(&q[k..]) {
            for (hi, c) in self.h.iter().zip(qj) {
                for (acc, v) in hzj.iter_mut().zip(hi) {
                    *acc += *v * *c;
                }
            }
        }
        let mut mm = [[T::zero(); N]; N];
        let mut maxdiag = T::zero();
        for a in 0..m {
            for b in 0..=a {
                let v = dot(&q[k + a], &hz[b]);
                mm[a][b] = v;
                mm[b][a] = v;
            }
            maxdiag = maxdiag.max(mm[a][a]);
        }
        let mut gz = [T::zero(); N];
        for (a, v) in gz.iter_mut().enumerate().take(m) {
            *v = dot(&q[k + a], g);
        }
        // Pᵀ L D Lᵀ P with diagonal pivoting (lower triangle of mm, in place).
        let mut perm = [0usize; N];
        for (i, v) in perm.iter_mut().enumerate() {
            *v = i;
        }
        let piv_tol = self.tiny * maxdiag;
        let mut rank = 0;
        while rank < m {
            let j = rank;
            let mut pbest = j;
            for i in j + 1..m {
                if mm[i][i] > mm[pbest][pbest] {
                    pbest = i;
                }
            }
            if !(mm[pbest][pbest] > piv_tol) || !(mm[pbest][pbest] > T::zero()) {
                break;
            }
            if pbest != j {
                mm.swap(j, pbest);
                for row in mm.iter_mut() {
                    row.swap(j, pbest);
                }
                perm.swap(j, pbest);
            }
            // The trailing block is kept whole (both triangles, for the symmetric swaps);
            // row j right of the diagonal keeps the unscaled column j.
            let d = mm[j][j];
            let inv_d = T::one() / d;
            for i in j + 1..m {
                let lij = mm[i][j] * inv_d;
                for l in j + 1..m {
                    let v = mm[i][l] - lij * mm[j][l];
                    mm[i][l] = v;
                }
            }
            for row in mm.iter_mut().take(m).skip(j + 1) {
                row[j] *= inv_d;
            }
            rank += 1;
        }
        // ĝ = P gz; w = L₁₁⁻¹ (−ĝ₁).
        let mut gh = [T::zero(); N];
        for i in 0..m {
            gh[i] = gz[perm[i]];
        }
        let mut w = [T::zero(); N];
        for i in 0..rank {
            let mut s = -gh[i];
            for (l, wl) in w.iter().enumerate().take(i) {
                s -= mm[i][l] * *wl;
            }
            w[i] = s;
        }
        // ρ₂ = −ĝ₂ − L₂₁ w.
        let mut rho = [T::zero(); N];
        let mut rho_max = T::zero();
        for i in rank..m {
            let mut s = -gh[i];
            for (l, wl) in w.iter().enumerate().take(rank) {
                s -= mm[i][l] * *wl;
            }
            rho[i] = s;
            rho_max = rho_max.max(s.abs());
        }
        let newton = !(rho_max > self.tiny * (T::one() + norm_inf(g)));
        let mut pz = [T::zero(); N];
        if newton {
            // D Lᵀ p₁ = w.
            for i in 0..rank {
                pz[i] = w[i] / mm[i][i];
            }
        } else {
            // (8): p₂ = ρ₂, p₁ = −L₁₁⁻ᵀ L₂₁ᵀ ρ₂.
            pz[rank..m].copy_from_slice(&rho[rank..m]);
            for i in 0..rank {
                let mut s = T::zero();
                for l in rank..m {
                    s -= mm[l][i] * rho[l];
                }
                pz[i] = s;
            }
        }
        // Back substitution with L₁₁ᵀ (unit diagonal): the columns below were filled above.
        for i in (0..rank).rev() {
            let mut s = pz[i];
            for l in i + 1..rank {
                s -= mm[l][i] * pz[l];
            }
            pz[i] = s;
        }
        for i in 0..m {
            let c = &q[k + perm[i]];
            let v = pz[i];
            for t in 0..N {
                p[t] += c[t] * v;
            }
        }
        self.snap_box(&mut p, false);
        (p, newton)
    }

    // ---- the solve ----

    /// Phases 0, 1 and 2; returns the status and the number of working-set changes.
    fn run<const E: usize>(
        &mut self,
        p: &Problem<T, N, E, C>,
        warm: &ActiveSet<N, C>,
        max_iter: usize,
    ) -> (Status, usize) {
        self.equalities(p);
        // The warm start's rows that are independent of the equalities and of each other.
        for i in 0..C {
            if warm.general[i] != Side::Inactive {
                self.add(i, warm.general[i]);
            }
        }
        for j in 0..N {
            if warm.bounds[j] != Side::Inactive {
                self.add(C + j, warm.bounds[j]);
            }
        }
        // The minimiser (7) on the warm working set, from its least-norm point.
        let mut x = self.basis.particular(&self.rhs());
        self.snap_box(&mut x, true);
        let g = self.gradient(&x);
        let (s, newton) = self.step(&g);
        for i in 0..N {
            x[i] += s[i];
        }
        self.x = x;
        let mut iters = 0;
        let feasible = (0..C + N).all(|id| {
            if self.side(id) != Side::Inactive {
                return true;
            }
            let v = self.row_dot(id, &self.x);
            let (l, u) = self.bounds(id);
            let (tol_l, tol_u) = self.side_tolerances(id, &self.x);
            v >= l - tol_l && v <= u + tol_u
        });
        let mut at_min = newton;
        if !feasible {
            at_min = false;
            match self.phase1(&mut iters, max_iter) {
                Phase1::Feasible => {}
                Phase1::Relaxed => self.relaxed = true,
                Phase1::Limit => return (Status::IterationLimit, iters),
            }
        }
        if !self.phase2(&mut iters, max_iter, at_min) {
            return (Status::IterationLimit, iters);
        }
        let status = if self.relaxed {
            Status::InequalitiesRelaxed
        } else if self.eq_inconsistent {
            Status::EqualitiesInconsistent
        } else {
            Status::Optimal
        };
        (status, iters)
    }

    /// The ratio test along `p` from `x` over the rows not in the working set: the first row
    /// met (`(α, id, side)`), within `alpha_max`. In phase 1 (`phase1`), a violated row moving
    /// towards its bound is met where it becomes satisfied.
    fn ratio_test(
        &self,
        p: &[T; N],
        alpha_max: Option<T>,
        phase1: bool,
    ) -> Option<(T, usize, Side)> {
        let pnorm = dot(p, p).sqrt();
        let mut best: Option<(T, usize, Side)> = None;
        let mut best_rate = T::zero();
        for id in 0..C + N {
            if self.side(id) != Side::Inactive {
                continue;
            }
            let d = self.row_dot(id, p);
            let an = self.norm(id);
            if !(d.abs() > self.tiny * an * pnorm) {
                continue;
            }
            let s = self.row_dot(id, &self.x);
            let (l, u) = self.bounds(id);
            let class = if phase1 {
                self.violated(id)
            } else {
                Side::Inactive
            };
            let (target, side) = if class == Side::Lower {
                if d > T::zero() {
                    (l, Side::Lower)
                } else {
                    continue;
                }
            } else if class == Side::Upper {
                if d < T::zero() {
                    (u, Side::Upper)
                } else {
                    continue;
                }
            } else if d > T::zero() {
                (u, Side::Upper)
            } else {
                (l, Side::Lower)
            };
            let alpha = ((target - s) / d).max(T::zero());
            if let Some(am) = alpha_max {
                if alpha >= am {
                    continue;
                }
            }
            let rate = d.abs() / an;
            let better = match best {
                None => true,
                Some((ba, _, _)) => alpha < ba || (alpha == ba && rate > best_rate),
            };
            if better {
                best = Some((alpha, id, side));
                best_rate = rate;
            }
        }
        best
    }

    /// Moves `x` by `α p` and adds the row that stopped it.
    fn take_step(&mut self, p: &[T; N], alpha: T, id: usize, side: Side) {
        for i in 0..N {
            self.x[i] += alpha * p[i];
        }
        if self.add(id, side) && id >= C {
            self.x[id - C] = self.bound_at(id, side);
        }
    }

    /// The row of the working set whose multiplier (10) for the gradient `g` has the wrong sign
    /// by most (scaled by `‖aᵢ‖`), beyond the tolerance.
    fn worst_multiplier(&self, g: &[T; N]) -> Option<usize> {
        let lam = self.basis.multipliers(g);
        let tol = self.tiny * (T::one() + norm_inf(g));
        let mut worst = None;
        let mut worst_v = tol;
        for t in 0..self.nact {
            let id = self.act[t];
            let (l, u) = self.bounds(id);
            if u - l <= self.feas_tol(id, &self.x) {
                continue;
            }
            let v = lam[self.r + t] * self.norm(id);
            let wrong = if self.side(id) == Side::Upper { v } else { -v };
            if wrong > worst_v {
                worst_v = wrong;
                worst = Some(t);
            }
        }
        worst
    }

    /// Phase 1's release rule at a stationary point of `φ` on the working set: with `c = V μ`,
    /// a row at its lower bound lowers `φ` by moving up (off its bound, feasible) when `μ < 0`
    /// and by moving down (into violation) when `μ > 1`; at its upper bound, down when `μ > 0`
    /// and up when `μ < −1`; a row with `l = u` only into violation. `(t, side)` of the row
    /// with the largest gain beyond the tolerance, `side` the bound it is to violate
    /// (`Inactive`: released to the feasible side); `None` if `φ` is minimal.
    fn phase1_release(&self, c: &[T; N]) -> Option<(usize, Side)> {
        let lam = self.basis.multipliers(c);
        let tol = self.tiny * (T::one() + norm_inf(c));
        let mut best = None;
        let mut best_gain = tol;
        for t in 0..self.nact {
            let id = self.act[t];
            let (l, u) = self.bounds(id);
            let fixed = u - l <= self.feas_tol(id, &self.x);
            let v = lam[self.r + t];
            let upper = self.side(id) == Side::Upper;
            let feasible_gain = if fixed {
                T::zero()
            } else if upper {
                v
            } else {
                -v
            };
            if feasible_gain > best_gain {
                best = Some((t, Side::Inactive));
                best_gain = feasible_gain;
            }
            // Into violation below (μ > 1) or above (μ < −1); a row not fixed only on its
            // own side.
            if (fixed || !upper) && v - T::one() > best_gain {
                best = Some((t, Side::Lower));
                best_gain = v - T::one();
            }
            if (fixed || upper) && -v - T::one() > best_gain {
                best = Some((t, Side::Upper));
                best_gain = -v - T::one();
            }
        }
        best
    }

    /// Phase 1: least total violation (9) over the equalities.
    fn phase1(&mut self, iters: &mut usize, max_iter: usize) -> Phase1 {
        loop {
            // c = ∇φ over the violated rows.
            let mut c = [T::zero(); N];
            let mut any = false;
            for id in 0..C + N {
                if self.side(id) != Side::Inactive {
                    continue;
                }
                let sign = match self.violated(id) {
                    Side::Lower => -T::one(),
                    Side::Upper => T::one(),
                    Side::Inactive => continue,
                };
                any = true;
                let a = self.normal(id);
                for j in 0..N {
                    c[j] += sign * a[j];
                }
            }
            if !any {
                self.forced_g = [Side::Inactive; C];
                self.forced_b = [Side::Inactive; N];
                return Phase1::Feasible;
            }
            if *iters >= max_iter {
                return Phase1::Limit;
            }
            // p = −Z Zᵀ c.
            let k = self.basis.k;
            let mut p = [T::zero(); N];
            let mut cz_max = T::zero();
            for j in k..N {
                let cz = dot(&self.basis.q[j], &c);
                cz_max = cz_max.max(cz.abs());
                for t in 0..N {
                    p[t] -= self.basis.q[j][t] * cz;
                }
            }
            self.snap_box(&mut p, false);
            if cz_max > self.tiny * norm_inf(&c) {
                if let Some((alpha, id, side)) = self.ratio_test(&p, None, true) {
                    self.take_step(&p, alpha, id, side);
                    *iters += 1;
                    continue;
                }
            }
            // Stationary on the working set: release a row, or φ is minimal.
            if let Some((t, into)) = self.phase1_release(&c) {
                let id = self.act[t];
                self.remove(t);
                self.set_forced(id, into);
                *iters += 1;
                continue;
            }
            // Relax the violated rows' bounds to their values at x.
            for id in 0..C + N {
                if self.side(id) != Side::Inactive {
                    continue;
                }
                let s = self.row_dot(id, &self.x);
                match self.violated(id) {
                    Side::Lower if id < C => self.lo[id] = self.lo[id].min(s),
                    Side::Lower => self.lb[id - C] = self.lb[id - C].min(s),
                    Side::Upper if id < C => self.hi[id] = self.hi[id].max(s),
                    Side::Upper => self.ub[id - C] = self.ub[id - C].max(s),
                    Side::Inactive => {}
                }
            }
            self.forced_g = [Side::Inactive; C];
            self.forced_b = [Side::Inactive; N];
            return Phase1::Relaxed;
        }
    }

    /// Phase 2 from a feasible `x` (`at_min`: `x` is already the minimiser on the working
    /// set). `false` on the iteration limit.
    fn phase2(&mut self, iters: &mut usize, max_iter: usize, mut at_min: bool) -> bool {
        loop {
            if !at_min {
                let g = self.gradient(&self.x);
                let (p, newton) = self.step(&g);
                let tiny_step = norm_inf(&p) <= self.round * (T::one() + norm_inf(&self.x));
                if !tiny_step {
                    let alpha_max = if newton { Some(T::one()) } else { None };
                    if let Some((alpha, id, side)) = self.ratio_test(&p, alpha_max, false) {
                        if *iters >= max_iter {
                            return false;
                        }
                        self.take_step(&p, alpha, id, side);
                        *iters += 1;
                        continue;
                    }
                    if newton {
                        for i in 0..N {
                            self.x[i] += p[i];
                        }
                    }
                }
            }
            at_min = false;
            let g = self.gradient(&self.x);
            match self.worst_multiplier(&g) {
                None => return true,
                Some(t) => {
                    if *iters >= max_iter {
                        return false;
                    }
                    self.remove(t);
                    *iters += 1;
                }
            }
        }
    }

    /// Fills the solution from the final state.
    fn finish<const E: usize>(
        &self,
        p: &Problem<T, N, E, C>,
        status: Status,
        out: &mut Solution<T, N, E, C>,
    ) {
        let x = self.x;
        out.x = SVector::from_fn(|i, _| x[i]);
        out.status = status;
        let g = self.gradient(&x);
        let mut obj = T::zero();
        for i in 0..N {
            obj += x[i] * (self.f[i] + (g[i] - self.f[i]) * nalgebra::convert(0.5));
        }
        out.objective = obj;
        let mut res = T::zero();
        for i in 0..E {
            let mut v = -p.b_eq[i];
            for j in 0..N {
                v += p.a_eq[(i, j)] * x[j];
            }
            res = res.max(v.abs());
        }
        out.equality_residual = res;
        let mut viol = T::zero();
        for i in 0..C {
            let s = dot(&self.rows[i], &x);
            viol += (p.lo[i] - s).max(T::zero()) + (s - p.hi[i]).max(T::zero());
        }
        for j in 0..N {
            viol += (p.lb[j] - x[j]).max(T::zero()) + (x[j] - p.ub[j]).max(T::zero());
        }
        out.violation = viol;
        out.active = ActiveSet {
            general: self.side_g,
            bounds: self.side_b,
        };
        if matches!(status, Status::IterationLimit) {
            return;
        }
        let lam = self.basis.multipliers(&g);
        for j in 0..self.r {
            if self.eq_order[j] < E {
                out.y_eq[self.eq_order[j]] = lam[j];
            }
        }
        for t in 0..self.nact {
            let id = self.act[t];
            let v = lam[self.r + t];
            // A row with l = u is reported at the bound its multiplier's sign belongs to.
            let (l, u) = self.bounds(id);
            let side = if u - l <= self.feas_tol(id, &x) {
                if v < T::zero() {
                    Side::Upper
                } else {
                    Side::Lower
                }
            } else {
                self.side(id)
            };
            if id < C {
                out.z_general[id] = v;
                out.active.general[id] = side;
            } else {
                out.z_bounds[id - C] = v;
                out.active.bounds[id - C] = side;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

    const S: Settings = Settings::DEFAULT;

    /// `½ xᵀ H x + fᵀ x` over the box `[lb, ub]`, no other rows.
    fn boxed(h: Matrix2<f64>, f: Vector2<f64>, lb: f64, ub: f64) -> Problem<f64, 2, 0, 0> {
        Problem {
            h,
            f,
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: Vector2::repeat(lb),
            ub: Vector2::repeat(ub),
        }
    }

    /// `½‖x‖²` under one equality row `a x = b` and the box `[-10, 10]`.
    fn with_eq(a: [f64; 2], b: f64) -> Problem<f64, 2, 1, 0> {
        Problem {
            h: Matrix2::identity(),
            f: Vector2::zeros(),
            a_eq: SMatrix::<f64, 1, 2>::new(a[0], a[1]),
            b_eq: SVector::<f64, 1>::new(b),
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: Vector2::repeat(-10.0),
            ub: Vector2::repeat(10.0),
        }
    }

    fn close(a: Vector2<f64>, b: [f64; 2]) -> bool {
        (a - Vector2::new(b[0], b[1])).amax() < 1e-12
    }

    #[test]
    fn meets_inequalities_is_the_solvers_feasibility_test() {
        // The box and one general row x0 + x1 ≤ 1, pulled past both by the linear term.
        let mut p = Problem::<f64, 2, 0, 1> {
            h: Matrix2::identity(),
            f: Vector2::new(-5.0, -5.0),
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::from_row_slice(&[1.0, 1.0]),
            lo: SVector::from_element(-10.0),
            hi: SVector::from_element(1.0),
            lb: Vector2::repeat(-2.0),
            ub: Vector2::repeat(2.0),
        };
        let s = solve(&p, &ActiveSet::EMPTY, &Settings::DEFAULT);
        assert_eq!(s.status, Status::Optimal);
        assert!(p.meets_inequalities(&s.x));
        assert!(
            !p.meets_inequalities(&(s.x + Vector2::new(1e-9, 0.0))),
            "past the row"
        );
        p.hi[0] = 10.0;
        assert!(
            !p.meets_inequalities(&Vector2::new(2.0 + 1e-9, 0.0)),
            "past the box"
        );
        assert!(
            p.meets_inequalities(&Vector2::new(2.0 + 1e-15, 0.0)),
            "within rounding"
        );
    }

    /// A box away from `x = 0` (a controller's rates when the joints move and may change only a
    /// little: acceleration limits): the start is outside it, and phase 1 finds it from any warm
    /// start; with an equality row whose solutions meet the box at one corner, and with a box of
    /// one point.
    #[test]
    fn a_box_away_from_zero_is_found_from_any_start() {
        // ½‖x‖² on [1, 2] × [−3, −2]: the corner (1, −2).
        let mut p = boxed(Matrix2::identity(), Vector2::zeros(), 0.0, 0.0);
        p.lb = Vector2::new(1.0, -3.0);
        p.ub = Vector2::new(2.0, -2.0);
        let sides = [Side::Inactive, Side::Lower, Side::Upper];
        for a in sides {
            for b in sides {
                let warm = ActiveSet {
                    general: [],
                    bounds: [a, b],
                };
                let s = p.solve(&warm, &S);
                assert_eq!(s.status, Status::Optimal, "{warm:?}");
                assert!(close(s.x, [1.0, -2.0]), "{warm:?}: {:?}", s.x);
            }
        }
        // With x₁ + x₂ = 0: only (2, −2) is within the box.
        let mut q = with_eq([1.0, 1.0], 0.0);
        q.lb = p.lb;
        q.ub = p.ub;
        for warm in [ActiveSet::EMPTY, s_upper_lower()] {
            let s = q.solve(&warm, &S);
            assert_eq!(s.status, Status::Optimal);
            assert!(close(s.x, [2.0, -2.0]), "{:?}", s.x);
        }
        // A box of one point in x₁, and x₁ − x₂ = 0: (½, ½).
        let mut r = with_eq([1.0, -1.0], 0.0);
        r.lb = Vector2::new(0.5, -1.0);
        r.ub = Vector2::new(0.5, 1.0);
        let s = r.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [0.5, 0.5]), "{:?}", s.x);
        // Past the box: the equalities hold and the box is exceeded least (x₁ + x₂ = 2 needs
        // x₂ = 1.5 at x₁ = ½).
        r.a_eq = SMatrix::<f64, 1, 2>::new(1.0, 1.0);
        r.b_eq = SVector::<f64, 1>::new(2.0);
        let s = r.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::InequalitiesRelaxed);
        assert!((s.x[0] + s.x[1] - 2.0).abs() < 1e-12);
        assert!((s.violation - 0.5).abs() < 1e-12, "{}", s.violation);
    }

    fn s_upper_lower() -> ActiveSet<2, 0> {
        ActiveSet {
            general: [],
            bounds: [Side::Upper, Side::Lower],
        }
    }

    #[test]
    fn interior_optimum_is_the_newton_point() {
        // ½‖x‖² − x₁ − 2x₂: x = (1, 2), inside the box.
        let s = boxed(Matrix2::identity(), Vector2::new(-1.0, -2.0), -5.0, 5.0)
            .solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [1.0, 2.0]), "{:?}", s.x);
        assert!((s.objective + 2.5).abs() < 1e-12);
        assert!(s.active.is_empty());
        assert_eq!(s.iterations, 0);
    }

    #[test]
    fn a_bound_stops_the_step_with_the_signed_multiplier() {
        // ½‖x‖² − 3x₁ + ½x₂ on [−1, 1]²: x₁ = 1 (upper, z = 1 − 3 = −2), x₂ = −½.
        let s = boxed(Matrix2::identity(), Vector2::new(-3.0, 0.5), -1.0, 1.0)
            .solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [1.0, -0.5]), "{:?}", s.x);
        assert_eq!(s.active.bounds, [Side::Upper, Side::Inactive]);
        assert!((s.z_bounds[0] + 2.0).abs() < 1e-12 && s.z_bounds[1] == 0.0);
        // The bound holds exactly, not up to rounding.
        assert_eq!(s.x[0], 1.0);
    }

    #[test]
    fn equality_and_bound_with_their_multipliers() {
        // ½‖x‖² with x₁ + x₂ = 1: (½, ½), y = ½.
        let s = with_eq([1.0, 1.0], 1.0).solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [0.5, 0.5]));
        assert!((s.y_eq[0] - 0.5).abs() < 1e-12);
        // And x₁ ≤ 0.2: (0.2, 0.8); x = y (1, 1) + z (1, 0) gives y = 0.8, z = −0.6.
        let mut p = with_eq([1.0, 1.0], 1.0);
        p.ub[0] = 0.2;
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [0.2, 0.8]), "{:?}", s.x);
        assert!((s.y_eq[0] - 0.8).abs() < 1e-12 && (s.z_bounds[0] + 0.6).abs() < 1e-12);
        assert_eq!(s.active.bounds, [Side::Upper, Side::Inactive]);
    }

    #[test]
    fn zero_hessian_is_a_linear_program_bounded_by_the_box() {
        // x₁ − x₂ on [−1, 2]²: (−1, 2), objective −3.
        let s = boxed(Matrix2::zeros(), Vector2::new(1.0, -1.0), -1.0, 2.0)
            .solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [-1.0, 2.0]), "{:?}", s.x);
        assert!((s.objective + 3.0).abs() < 1e-12);
        assert!((s.z_bounds[0] - 1.0).abs() < 1e-12 && (s.z_bounds[1] + 1.0).abs() < 1e-12);
    }

    #[test]
    fn rank_one_hessian_follows_its_flat_direction_to_the_box() {
        // ½(x₁ + x₂)² − 2x₁ on [−1, 1]² ≥ −2x₁ ≥ −2, with equality only at (1, −1).
        let h = Matrix2::new(1.0, 1.0, 1.0, 1.0);
        let s = boxed(h, Vector2::new(-2.0, 0.0), -1.0, 1.0).solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [1.0, -1.0]), "{:?}", s.x);
        assert!((s.objective + 2.0).abs() < 1e-12);
    }

    /// Three inconsistent rows of rank two in four variables (the normal equations of the
    /// least-squares right-hand side factored by the core's Cholesky): with `H = I` and a wide
    /// box the minimiser is the minimum-norm least-squares solution `A⁺ b`, here from nalgebra's
    /// SVD.
    #[test]
    fn inconsistent_rows_of_lower_rank_give_the_minimum_norm_least_squares_point() {
        let a_eq = SMatrix::<f64, 3, 4>::new(
            1.0, 2.0, 0.0, -1.0, //
            0.0, 1.0, 1.0, 0.5, //
            1.0, 3.0, 1.0, -0.5,
        );
        let b_eq = SVector::<f64, 3>::new(0.4, -0.2, 0.9);
        let p: Problem<f64, 4, 3, 0> = Problem {
            h: SMatrix::identity(),
            f: SVector::zeros(),
            a_eq,
            b_eq,
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: SVector::repeat(-10.0),
            ub: SVector::repeat(10.0),
        };
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::EqualitiesInconsistent);
        let want = a_eq.pseudo_inverse(1e-12).expect("svd") * b_eq;
        assert!((s.x - want).amax() < 1e-12, "{:?} vs {want:?}", s.x);
        let residual = (a_eq * want - b_eq).amax();
        assert!((s.equality_residual - residual).abs() < 1e-12);
    }

    #[test]
    fn inconsistent_equalities_are_met_in_least_squares() {
        // x₁ = 1 and x₁ = 3: x₁ = 2 (least squares), x₂ = 0 (½‖x‖²).
        let p: Problem<f64, 2, 2, 0> = Problem {
            h: Matrix2::identity(),
            f: Vector2::zeros(),
            a_eq: Matrix2::new(1.0, 0.0, 1.0, 0.0),
            b_eq: Vector2::new(1.0, 3.0),
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: Vector2::repeat(-10.0),
            ub: Vector2::repeat(10.0),
        };
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::EqualitiesInconsistent);
        assert!(close(s.x, [2.0, 0.0]), "{:?}", s.x);
        assert!((s.equality_residual - 1.0).abs() < 1e-12);
        // Dependent and consistent: x₁ + x₂ = 1 twice (once doubled) is the single row.
        let mut p = p;
        p.a_eq = Matrix2::new(1.0, 1.0, 2.0, 2.0);
        p.b_eq = Vector2::new(1.0, 2.0);
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [0.5, 0.5]));
        let g = p.h * s.x + p.f;
        assert!((g - p.a_eq.transpose() * s.y_eq).amax() < 1e-12);
    }

    #[test]
    fn infeasible_limits_are_exceeded_by_the_least_total() {
        // x₁ + x₂ = 3 on [−1, 1]²: every point of the line exceeds the box by at least 1.
        let mut p = with_eq([1.0, 1.0], 3.0);
        p.lb = Vector2::repeat(-1.0);
        p.ub = Vector2::repeat(1.0);
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::InequalitiesRelaxed);
        assert!((s.violation - 1.0).abs() < 1e-12, "{}", s.violation);
        assert!(s.equality_residual < 1e-12);
        assert!((s.x[0] + s.x[1] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn duplicate_and_parallel_rows_enter_once() {
        // x₁ ≤ ½ three times (as x₁, again, and 2x₁ ≤ 1), pulled towards x₁ = 3.
        let p: Problem<f64, 2, 0, 3> = Problem {
            h: Matrix2::identity(),
            f: Vector2::new(-3.0, 0.0),
            a_eq: SMatrix::zeros(),
            b_eq: SVector::zeros(),
            g: SMatrix::<f64, 3, 2>::new(1.0, 0.0, 1.0, 0.0, 2.0, 0.0),
            lo: SVector::<f64, 3>::repeat(-5.0),
            hi: SVector::<f64, 3>::new(0.5, 0.5, 1.0),
            lb: Vector2::repeat(-10.0),
            ub: Vector2::repeat(10.0),
        };
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!(close(s.x, [0.5, 0.0]), "{:?}", s.x);
        assert_eq!(s.active.len(), 1);
        let g = p.h * s.x + p.f;
        assert!((g - p.g.transpose() * s.z_general).amax() < 1e-12);
        // A warm start naming all three keeps one.
        let warm = ActiveSet {
            general: [Side::Upper; 3],
            bounds: [Side::Inactive; 2],
        };
        let w = p.solve(&warm, &S);
        assert!(close(w.x, [0.5, 0.0]) && w.active.len() == 1);
    }

    #[test]
    fn a_fixed_row_takes_either_sign() {
        // lo = hi = 0 on x₁ − x₂, pulled both ways in turn.
        for sign in [1.0, -1.0] {
            let p: Problem<f64, 2, 0, 1> = Problem {
                h: Matrix2::identity(),
                f: Vector2::new(-sign, sign),
                a_eq: SMatrix::zeros(),
                b_eq: SVector::zeros(),
                g: SMatrix::<f64, 1, 2>::new(1.0, -1.0),
                lo: SVector::<f64, 1>::new(0.0),
                hi: SVector::<f64, 1>::new(0.0),
                lb: Vector2::repeat(-10.0),
                ub: Vector2::repeat(10.0),
            };
            let s = p.solve(&ActiveSet::EMPTY, &S);
            assert_eq!(s.status, Status::Optimal);
            assert!(close(s.x, [0.0, 0.0]), "{:?}", s.x);
            // g = (−sign, sign) = z (1, −1): z = −sign, at the bound its sign belongs to.
            assert!((s.z_general[0] + sign).abs() < 1e-12);
            let side = if sign > 0.0 { Side::Upper } else { Side::Lower };
            assert_eq!(s.active.general[0], side);
        }
    }

    #[test]
    fn warm_start_from_the_optimum_takes_no_iteration() {
        let mut p = with_eq([1.0, 2.0], 1.0);
        p.f = Vector2::new(-4.0, 1.0);
        p.ub = Vector2::new(0.7, 10.0);
        let cold = p.solve(&ActiveSet::EMPTY, &S);
        assert!(cold.iterations > 0 && !cold.active.is_empty());
        let warm = p.solve(&cold.active, &S);
        assert_eq!(warm.iterations, 0);
        assert!((warm.x - cold.x).amax() < 1e-14);
    }

    #[test]
    fn iteration_limit_returns_a_point_on_the_equalities() {
        let mut p = with_eq([1.0, 2.0], 1.0);
        p.f = Vector2::new(-4.0, 1.0);
        p.ub = Vector2::new(0.7, 10.0);
        let s = p.solve(&ActiveSet::EMPTY, &Settings { max_iterations: 0 });
        assert_eq!(s.status, Status::IterationLimit);
        assert!(s.x.iter().all(|v| v.is_finite()));
        assert!(s.equality_residual < 1e-12);
    }

    #[test]
    fn bad_input_gives_a_status_and_x_zero() {
        let base = boxed(Matrix2::identity(), Vector2::new(-1.0, -2.0), -5.0, 5.0);
        let mut p = base;
        p.f[0] = f64::NAN;
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::NonFinite);
        assert_eq!(s.x, Vector2::zeros());
        let mut p = base;
        p.ub[1] = f64::INFINITY;
        assert_eq!(p.solve(&ActiveSet::EMPTY, &S).status, Status::NonFinite);
        let mut p = base;
        p.lb[1] = 6.0;
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::InvalidBounds);
        assert_eq!(s.x, Vector2::zeros());
        // Overflow inside the solve: finite data, no NaN out.
        let mut p = base;
        p.h = Matrix2::new(1e300, -1e300, -1e300, 1e300);
        p.f = Vector2::new(1e300, -1e300);
        p.lb = Vector2::repeat(-1e300);
        p.ub = Vector2::repeat(1e300);
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert!(s.x.iter().all(|v| v.is_finite()) && s.objective.is_finite());
    }

    #[test]
    fn f32_solves_the_same_problem() {
        let p: Problem<f32, 2, 1, 0> = Problem {
            h: Matrix2::identity(),
            f: Vector2::zeros(),
            a_eq: SMatrix::<f32, 1, 2>::new(1.0, 1.0),
            b_eq: SVector::<f32, 1>::new(1.0),
            g: SMatrix::zeros(),
            lo: SVector::zeros(),
            hi: SVector::zeros(),
            lb: Vector2::repeat(-10.0),
            ub: Vector2::new(0.2, 10.0),
        };
        let s = p.solve(&ActiveSet::EMPTY, &S);
        assert_eq!(s.status, Status::Optimal);
        assert!((s.x - Vector2::new(0.2, 0.8)).amax() < 1e-6, "{:?}", s.x);
    }
}

/// Every QP [`solve`] is given, recorded in `f64` between [`record::start`] and
/// [`record::take`] — for a benchmark that replays a controller's QPs with other solvers. The
/// feature `qp-record` (bench only, needs `std`) adds it; without it nothing is recorded and
/// [`solve`] allocates nothing.
#[cfg(feature = "qp-record")]
pub mod record {
    extern crate std;
    use super::{ActiveSet, Problem, Side, Solution, Status};
    use nalgebra::RealField;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Mutex;
    use std::vec::Vec;

    /// One recorded QP: its sizes, its data (matrices column-major), the warm start it was
    /// solved from and trocar's solution.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Recorded {
        /// Variables, equality rows, general rows.
        pub sizes: (usize, usize, usize),
        /// `H`, `n × n`.
        pub h: Vec<f64>,
        /// `f`.
        pub f: Vec<f64>,
        /// `A`, `e × n`.
        pub a_eq: Vec<f64>,
        /// `b`.
        pub b_eq: Vec<f64>,
        /// `G`, `c × n`.
        pub g: Vec<f64>,
        /// `lo`, `hi`.
        pub lo: Vec<f64>,
        /// `hi`.
        pub hi: Vec<f64>,
        /// `lb`.
        pub lb: Vec<f64>,
        /// `ub`.
        pub ub: Vec<f64>,
        /// The warm start's general rows and bounds.
        pub warm: (Vec<Side>, Vec<Side>),
        /// trocar's solution and its status.
        pub x: Vec<f64>,
        /// How the solve ended.
        pub status: Status,
    }

    impl Recorded {
        /// The problem with its sizes checked (`None` for other sizes) and the warm start.
        pub fn problem<const N: usize, const E: usize, const C: usize>(
            &self,
        ) -> Option<(Problem<f64, N, E, C>, ActiveSet<N, C>)> {
            if self.sizes != (N, E, C) {
                return None;
            }
            let mut warm = ActiveSet::<N, C>::EMPTY;
            warm.general.copy_from_slice(&self.warm.0);
            warm.bounds.copy_from_slice(&self.warm.1);
            Some((
                Problem {
                    h: nalgebra::SMatrix::from_column_slice(&self.h),
                    f: nalgebra::SVector::from_column_slice(&self.f),
                    a_eq: nalgebra::SMatrix::from_column_slice(&self.a_eq),
                    b_eq: nalgebra::SVector::from_column_slice(&self.b_eq),
                    g: nalgebra::SMatrix::from_column_slice(&self.g),
                    lo: nalgebra::SVector::from_column_slice(&self.lo),
                    hi: nalgebra::SVector::from_column_slice(&self.hi),
                    lb: nalgebra::SVector::from_column_slice(&self.lb),
                    ub: nalgebra::SVector::from_column_slice(&self.ub),
                },
                warm,
            ))
        }
    }

    static ON: AtomicBool = AtomicBool::new(false);
    static LOG: Mutex<Vec<Recorded>> = Mutex::new(Vec::new());

    /// Starts recording (what was recorded before is dropped).
    pub fn start() {
        if let Ok(mut log) = LOG.lock() {
            log.clear();
        }
        ON.store(true, Ordering::SeqCst);
    }

    /// Stops recording and returns every QP solved since [`start`], in order.
    pub fn take() -> Vec<Recorded> {
        ON.store(false, Ordering::SeqCst);
        LOG.lock()
            .map(|mut l| std::mem::take(&mut *l))
            .unwrap_or_default()
    }

    pub(super) fn push<T: RealField + Copy, const N: usize, const E: usize, const C: usize>(
        p: &Problem<T, N, E, C>,
        warm: &ActiveSet<N, C>,
        s: &Solution<T, N, E, C>,
    ) {
        if !ON.load(Ordering::SeqCst) {
            return;
        }
        let v = |it: &mut dyn Iterator<Item = &T>| -> Vec<f64> {
            it.map(|x| x.to_subset().unwrap_or(f64::NAN)).collect()
        };
        let r = Recorded {
            sizes: (N, E, C),
            h: v(&mut p.h.iter()),
            f: v(&mut p.f.iter()),
            a_eq: v(&mut p.a_eq.iter()),
            b_eq: v(&mut p.b_eq.iter()),
            g: v(&mut p.g.iter()),
            lo: v(&mut p.lo.iter()),
            hi: v(&mut p.hi.iter()),
            lb: v(&mut p.lb.iter()),
            ub: v(&mut p.ub.iter()),
            warm: (warm.general.to_vec(), warm.bounds.to_vec()),
            x: v(&mut s.x.iter()),
            status: s.status,
        };
        if let Ok(mut log) = LOG.lock() {
            log.push(r);
        }
    }
}
