//! Shared by the QP property tests (`tests/qp_clarabel.rs`) and the QP benchmark
//! (`benches/qp.rs`): random problems of the controller's shape and the reference solve by
//! Clarabel (an interior-point method: an independent algorithm and implementation).
// Dense loops over rows and columns by index; not every item is used by both crates.
#![allow(dead_code, clippy::needless_range_loop)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT,
    SolverStatus, SupportedConeT, ZeroConeT,
};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use trocar::nalgebra::{SMatrix, SVector};
use trocar::qp::Problem;

/// Clarabel's verdict on a problem.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Clarabel's status.
    pub status: SolverStatus,
    /// Its `x`.
    pub x: Vec<f64>,
    /// Its objective.
    pub objective: f64,
    /// Its slacks `s` (rows in the order of [`clarabel_data`]).
    pub s: Vec<f64>,
    /// Its dual variables `z`.
    pub z: Vec<f64>,
}

/// A dense matrix (row-major) as a CSC matrix of its non-zeros.
pub fn csc(rows: usize, cols: usize, at: impl Fn(usize, usize) -> f64) -> CscMatrix<f64> {
    let mut colptr = vec![0];
    let mut rowval = vec![];
    let mut nzval = vec![];
    for c in 0..cols {
        for r in 0..rows {
            let v = at(r, c);
            if v != 0.0 {
                rowval.push(r);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(rows, cols, colptr, rowval, nzval)
}

/// Clarabel's data for (1)–(4): `A_cl x + s = b_cl`, `s` in `{0}^E × R₊^{2C + 2N}` (rows
/// `A x = b`, `G x ≤ hi`, `−G x ≤ −lo`, `x ≤ ub`, `−x ≤ −lb`).
pub struct ClarabelData {
    /// `P` (upper triangle).
    pub p: CscMatrix<f64>,
    /// `q`.
    pub q: Vec<f64>,
    /// `A_cl`.
    pub a: CscMatrix<f64>,
    /// `b_cl`.
    pub b: Vec<f64>,
    /// The cones.
    pub cones: Vec<SupportedConeT<f64>>,
}

/// [`ClarabelData`] of a problem.
pub fn clarabel_data<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
) -> ClarabelData {
    let m = E + 2 * C + 2 * N;
    let row = |r: usize, c: usize| -> f64 {
        if r < E {
            p.a_eq[(r, c)]
        } else if r < E + C {
            p.g[(r - E, c)]
        } else if r < E + 2 * C {
            -p.g[(r - E - C, c)]
        } else if r < E + 2 * C + N {
            f64::from(u8::from(r - E - 2 * C == c))
        } else {
            -f64::from(u8::from(r - E - 2 * C - N == c))
        }
    };
    let mut b = Vec::with_capacity(m);
    b.extend(p.b_eq.iter());
    b.extend(p.hi.iter());
    b.extend(p.lo.iter().map(|v| -v));
    b.extend(p.ub.iter());
    b.extend(p.lb.iter().map(|v| -v));
    let mut cones = vec![];
    if E > 0 {
        cones.push(ZeroConeT(E));
    }
    cones.push(NonnegativeConeT(2 * C + 2 * N));
    ClarabelData {
        p: csc(N, N, |r, c| if r <= c { p.h[(r, c)] } else { 0.0 }),
        q: p.f.iter().copied().collect(),
        a: csc(m, N, row),
        b,
        cones,
    }
}

/// Clarabel's settings: quiet; with `tight`, tolerances at 1e-12 instead of 1e-8.
pub fn clarabel_settings(tight: bool) -> DefaultSettings<f64> {
    let mut s = DefaultSettingsBuilder::default()
        .verbose(false)
        .build()
        .expect("settings");
    if tight {
        s.tol_gap_abs = 1e-12;
        s.tol_gap_rel = 1e-12;
        s.tol_feas = 1e-12;
        s.tol_ktratio = 1e-10;
        s.max_iter = 200;
    }
    s
}

/// Solves `data` with Clarabel.
pub fn clarabel_solve(data: &ClarabelData, settings: DefaultSettings<f64>) -> Reference {
    let mut solver = DefaultSolver::new(&data.p, &data.q, &data.a, &data.b, &data.cones, settings)
        .expect("setup");
    solver.solve();
    Reference {
        status: solver.solution.status,
        x: solver.solution.x.clone(),
        objective: solver.solution.obj_val,
        s: solver.solution.s.clone(),
        z: solver.solution.z.clone(),
    }
}

/// Uniform on `[lo, hi)`.
pub fn uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    rng.gen_range(lo..hi)
}

/// How the random problems are made.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Damping `κ` of `H = JᵀJ + κ² I`; 0 leaves `H` singular.
    pub kappa: f64,
    /// Rows of `J` (below `N`: `H` rank-deficient beyond what `κ = 0` gives).
    pub j_rows: usize,
    /// The scale of the task velocity (large: many bounds active).
    pub task: f64,
    /// The equalities' right-hand side is `A x_f` for a point `x_f` that meets the inequalities
    /// (`true`) or a random vector of size `b_scale` (`false`, often infeasible).
    pub feasible_eq: bool,
    /// Size of a random `b`.
    pub b_scale: f64,
}

/// A random problem of `N` variables: `H = JᵀJ + κ²I` (`J` with [`Shape::j_rows`] rows),
/// `f = −Jᵀ v`, random equality rows, a box with `lb < 0 < ub`, general rows with
/// `lo < 0 < hi`.
pub fn random_problem<const N: usize, const E: usize, const C: usize>(
    rng: &mut StdRng,
    shape: &Shape,
) -> Problem<f64, N, E, C> {
    let jr = shape.j_rows;
    let j: Vec<[f64; N]> = (0..jr)
        .map(|_| core::array::from_fn(|_| uniform(rng, -1.0, 1.0)))
        .collect();
    let v: Vec<f64> = (0..jr)
        .map(|_| uniform(rng, -shape.task, shape.task))
        .collect();
    let mut h = SMatrix::<f64, N, N>::zeros();
    let mut f = SVector::<f64, N>::zeros();
    for (row, vr) in j.iter().zip(v.iter()) {
        for a in 0..N {
            f[a] -= row[a] * vr;
            for b in 0..N {
                h[(a, b)] += row[a] * row[b];
            }
        }
    }
    for a in 0..N {
        h[(a, a)] += shape.kappa * shape.kappa;
        f[a] += uniform(rng, -0.05, 0.05) * shape.task;
    }
    let lb = SVector::<f64, N>::from_fn(|_, _| uniform(rng, -1.0, -0.05));
    let ub = SVector::<f64, N>::from_fn(|_, _| uniform(rng, 0.05, 1.0));
    let g = SMatrix::<f64, C, N>::from_fn(|_, _| uniform(rng, -1.0, 1.0));
    let lo = SVector::<f64, C>::from_fn(|_, _| uniform(rng, -1.0, -0.01));
    let hi = SVector::<f64, C>::from_fn(|_, _| uniform(rng, 0.01, 1.0));
    let a_eq = SMatrix::<f64, E, N>::from_fn(|_, _| uniform(rng, -1.0, 1.0));
    let b_eq = if shape.feasible_eq {
        // A point in the box, shrunk towards 0 (which meets every inequality) until it meets
        // the general rows too.
        let mut xf = SVector::<f64, N>::from_fn(|i, _| uniform(rng, lb[i], ub[i]));
        for _ in 0..60 {
            let s = g * xf;
            if (0..C).all(|i| s[i] >= lo[i] && s[i] <= hi[i]) {
                break;
            }
            xf *= 0.8;
        }
        a_eq * xf
    } else {
        SVector::<f64, E>::from_fn(|_, _| uniform(rng, -shape.b_scale, shape.b_scale))
    };
    Problem {
        h,
        f,
        a_eq,
        b_eq,
        g,
        lo,
        hi,
        lb,
        ub,
    }
}

/// A generator seeded from `seed`.
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// The reference `x` polished: the rows Clarabel holds active (`z > s`, the equalities) taken
/// as equalities (the linearly dependent ones left out) and the KKT system
/// `[H Vᵀ; V 0] [x; λ] = [−f; b_V]` solved densely (LU with full pivoting); `None` unless the
/// result meets every row (1e-9) with multipliers of the right signs (−1e-8). An interior-point `x` is accurate to
/// about the square root of its tolerance; its polished `x` to rounding.
pub fn polish<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    reference: &Reference,
) -> Option<Vec<f64>> {
    let data = clarabel_data(p);
    let m = data.b.len();
    let row = |r: usize| -> Vec<f64> {
        let mut v = vec![0.0; N];
        for c in 0..N {
            for k in data.a.colptr[c]..data.a.colptr[c + 1] {
                if data.a.rowval[k] == r {
                    v[c] = data.a.nzval[k];
                }
            }
        }
        v
    };
    // Two guesses of the active rows: those whose multiplier exceeds their slack, then every
    // row with a negligible slack (weakly active rows included).
    let guesses: [Box<dyn Fn(usize) -> bool>; 2] = [
        Box::new(|r| reference.z[r] > reference.s[r]),
        Box::new(|r| reference.s[r] < 1e-8),
    ];
    guesses.iter().find_map(|active| {
        let active: Vec<usize> = (0..m).filter(|&r| r < E || active(r)).collect();
        polish_with::<N, E, C>(p, &data, &row, &active)
    })
}

fn polish_with<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    data: &ClarabelData,
    row: &dyn Fn(usize) -> Vec<f64>,
    active: &[usize],
) -> Option<Vec<f64>> {
    use trocar::nalgebra::{DMatrix, DVector};
    let m = data.b.len();
    // Linearly dependent active rows (duplicates, parallel rows) left out, by Gram–Schmidt
    // (twice): the KKT matrix is then non-singular where the optimum is unique.
    let mut basis: Vec<Vec<f64>> = vec![];
    let mut independent = vec![];
    for &r in active {
        let v = row(r);
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let mut w = v.clone();
        for _ in 0..2 {
            for q in &basis {
                let d: f64 = (0..N).map(|c| q[c] * w[c]).sum();
                for c in 0..N {
                    w[c] -= d * q[c];
                }
            }
        }
        let wn = w.iter().map(|a| a * a).sum::<f64>().sqrt();
        if wn > 1e-9 * norm.max(1e-300) {
            basis.push(w.iter().map(|a| a / wn).collect());
            independent.push(r);
        }
    }
    let active = &independent[..];
    let k = active.len();
    let mut kkt = DMatrix::<f64>::zeros(N + k, N + k);
    let mut rhs = DVector::<f64>::zeros(N + k);
    for a in 0..N {
        for b in 0..N {
            kkt[(a, b)] = p.h[(a, b)];
        }
        rhs[a] = -p.f[a];
    }
    for (t, &r) in active.iter().enumerate() {
        let v = row(r);
        for c in 0..N {
            kkt[(N + t, c)] = v[c];
            kkt[(c, N + t)] = v[c];
        }
        rhs[N + t] = data.b[r];
    }
    let sol = kkt.full_piv_lu().solve(&rhs)?;
    let x: Vec<f64> = (0..N).map(|i| sol[i]).collect();
    for r in 0..m {
        let v = row(r);
        let ax: f64 = (0..N).map(|c| v[c] * x[c]).sum();
        let slack = data.b[r] - ax;
        if r < E {
            if slack.abs() > 1e-9 {
                return None;
            }
        } else if slack < -1e-9 {
            return None;
        }
    }
    // In Clarabel's convention (A x + s = b, s ≥ 0), H x + f + A_Vᵀ λ = 0 with λ ≥ 0 on the
    // inequalities.
    for (t, &r) in active.iter().enumerate() {
        if r >= E && sol[N + t] < -1e-8 {
            return None;
        }
    }
    Some(x)
}

/// The least total violation `min Σ max(0, lᵢ − aᵢᵀx, aᵢᵀx − uᵢ)` of the inequality rows
/// subject to `A x = b`, by Clarabel as a linear program in `(x, v)`, `v ∈ R^{2C+2N}`, `v ≥ 0`:
/// `[G; −G; I; −I] x − v ≤ [hi; −lo; ub; −lb]`. `None` unless Clarabel solves it.
pub fn least_violation<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
) -> Option<f64> {
    let d = clarabel_data(p);
    let k = 2 * C + 2 * N;
    let nv = N + k;
    let m = E + 2 * k;
    let dense_a = |r: usize, c: usize| -> f64 {
        let mut v = 0.0;
        for t in d.a.colptr[c]..d.a.colptr[c + 1] {
            if d.a.rowval[t] == r {
                v = d.a.nzval[t];
            }
        }
        v
    };
    let a = csc(m, nv, |r, c| {
        if r < E + k {
            if c < N {
                dense_a(r, c)
            } else if r >= E && c - N == r - E {
                -1.0
            } else {
                0.0
            }
        } else if c >= N && c - N == r - E - k {
            -1.0
        } else {
            0.0
        }
    });
    let mut b = d.b.clone();
    b.extend(std::iter::repeat_n(0.0, k));
    let mut q = vec![0.0; N];
    q.extend(std::iter::repeat_n(1.0, k));
    let mut cones = vec![];
    if E > 0 {
        cones.push(ZeroConeT(E));
    }
    cones.push(NonnegativeConeT(2 * k));
    let data = ClarabelData {
        p: csc(nv, nv, |_, _| 0.0),
        q,
        a,
        b,
        cones,
    };
    let r = clarabel_solve(&data, clarabel_settings(true));
    matches!(r.status, SolverStatus::Solved | SolverStatus::AlmostSolved).then_some(r.objective)
}

/// The problem with its inequality bounds widened to include `x` (what
/// [`trocar::qp::Status::InequalitiesRelaxed`] solves), and `margin` more where they move.
pub fn widened<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    x: &SVector<f64, N>,
    margin: f64,
) -> Problem<f64, N, E, C> {
    let mut q = *p;
    let gx = p.g * x;
    for i in 0..C {
        q.lo[i] = q.lo[i].min(gx[i] - margin);
        q.hi[i] = q.hi[i].max(gx[i] + margin);
    }
    for j in 0..N {
        q.lb[j] = q.lb[j].min(x[j] - margin);
        q.ub[j] = q.ub[j].max(x[j] + margin);
    }
    q
}

/// `A A⁺ b`: the right-hand side that the least-squares solution of `A x = b` meets.
pub fn projected_rhs<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
) -> SVector<f64, E> {
    if E == 0 {
        return p.b_eq;
    }
    // The orthogonal projection onto the range of A: the eigenvectors of A Aᵀ with a
    // non-zero eigenvalue.
    use trocar::nalgebra::DMatrix;
    let a = DMatrix::from_fn(E, N, |r, c| p.a_eq[(r, c)]);
    let eig = (&a * a.transpose()).symmetric_eigen();
    let top = eig.eigenvalues.amax();
    let mut out = SVector::<f64, E>::zeros();
    for k in 0..E {
        if eig.eigenvalues[k] > 1e-12 * top {
            let u = eig.eigenvectors.column(k);
            let ub: f64 = (0..E).map(|i| u[i] * p.b_eq[i]).sum();
            for i in 0..E {
                out[i] += u[i] * ub;
            }
        }
    }
    out
}

/// The next control step's problem: `p` with `H`, `f`, `A`, `b` moved by up to `size`
/// (`H` by `D Dᵀ`, so it stays positive semidefinite).
pub fn perturb<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    seed: u64,
    size: f64,
) -> Problem<f64, N, E, C> {
    let mut q = *p;
    if size == 0.0 {
        return q;
    }
    let mut r = rng(seed ^ 0x9e37_79b9_7f4a_7c15);
    let dh = SMatrix::<f64, N, N>::from_fn(|_, _| uniform(&mut r, -size, size));
    q.h += dh * dh.transpose();
    q.f += SVector::<f64, N>::from_fn(|_, _| uniform(&mut r, -size, size));
    q.a_eq += SMatrix::<f64, E, N>::from_fn(|_, _| uniform(&mut r, -size, size));
    q.b_eq += SVector::<f64, E>::from_fn(|_, _| uniform(&mut r, -size, size));
    q
}
