//! `trocar::qp` against Clarabel (an interior-point solver: an independent method and
//! implementation) on random QPs of the controller's shape (7 joint rates, 2 trocar rows, the
//! 14 box bounds, 2 general rows) and of other sizes, degenerate ones included.
//!
//! Each QP is checked
//! - against its own optimality conditions (independent of any reference), to 1e-9: the
//!   equalities (least-squares ones when inconsistent) and the inequalities (widened to `x`
//!   when relaxed) met, `H x + f = Aᵀ y + Gᵀ z_g + z_b`, the multipliers' signs, every active
//!   row at its bound;
//! - against Clarabel (tolerances 1e-12): the same verdict (solved / primal infeasible); when
//!   solved, the objective within 1e-8 (relative to `1 + |objective|`) and, where the optimum
//!   is unique (`H` positive definite), `x` within 1e-8 of Clarabel's solution polished on its
//!   active set (an interior-point `x` alone is good to about 1e-8: it must be within 1e-6);
//!   when infeasible, the total violation equal (1e-8) to the least one, a linear program
//!   solved by Clarabel, and the objective equal to Clarabel's on the relaxed problem;
//! - solved again from its own active set (a warm start), which must take no iteration and give
//!   the same `x` (a relaxed problem: the same violation).
//!
//! Most families also solve a perturbed copy (the next control step) from the first solution's
//! active set. Fixed seeds: every run checks the same 13,300 QPs (6,000 controller-shaped,
//! 2,000 with a singular `H`, 2,000 with parallel/duplicate/fixed rows, 1,000 with dependent
//! equalities, 1,500 with often-infeasible limits, 800 of other sizes), plus 3,000 wild inputs
//! and 1,000 `f32` solves; `QP_CASES_SCALE=10` multiplies the counts for a longer local run.

mod qp_common;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed, TestRunner};
use qp_common::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use trocar::nalgebra::{SMatrix, SVector};
use trocar::qp::{solve, ActiveSet, Problem, Settings, Side, Solution, Status};

use clarabel::solver::SolverStatus;

/// Outcomes counted per test: QPs checked, and how many Clarabel found infeasible.
#[derive(Default)]
struct Counts {
    checked: AtomicUsize,
    infeasible: AtomicUsize,
    inconsistent: AtomicUsize,
    /// The most working-set changes one solve took.
    max_iterations: AtomicUsize,
}

thread_local! {
    static COUNTS: std::cell::RefCell<Option<std::sync::Arc<Counts>>> = const { std::cell::RefCell::new(None) };
}

fn count(f: impl Fn(&Counts)) {
    COUNTS.with(|c| {
        if let Some(c) = c.borrow().as_ref() {
            f(c)
        }
    });
}

/// `cases` cases (times `QP_CASES_SCALE` from the environment, for longer local runs) from
/// the fixed seed `seed`; returns the counts.
fn run<S: Strategy>(
    cases: u32,
    seed: u64,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) -> std::sync::Arc<Counts> {
    let scale: u32 = std::env::var("QP_CASES_SCALE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let counts = std::sync::Arc::new(Counts::default());
    COUNTS.with(|c| *c.borrow_mut() = Some(counts.clone()));
    let mut runner = TestRunner::new(config(cases * scale, seed));
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{e}");
    }
    let c = &counts;
    eprintln!(
        "{} QPs checked, {} infeasible, {} with inconsistent equalities, at most {} iterations",
        c.checked.load(Ordering::Relaxed),
        c.infeasible.load(Ordering::Relaxed),
        c.inconsistent.load(Ordering::Relaxed),
        c.max_iterations.load(Ordering::Relaxed)
    );
    counts
}

fn config(cases: u32, seed: u64) -> Config {
    Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        max_shrink_iters: 0,
        ..Config::default()
    }
}

/// The largest KKT residuals of a solution: (primal, stationarity, sign, complementarity).
fn kkt<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    s: &Solution<f64, N, E, C>,
    eq_target: &SVector<f64, E>,
) -> (f64, f64, f64, f64) {
    let x = s.x;
    let grad = p.h * x + p.f;
    let r = grad - p.a_eq.transpose() * s.y_eq - p.g.transpose() * s.z_general - s.z_bounds;
    let scale = 1.0 + grad.amax() + p.h.amax() * x.amax();
    let stationarity = r.amax() / scale;
    let eq = (p.a_eq * x - eq_target).amax();
    let mut primal = eq;
    let mut sign = 0.0f64;
    let mut comp = 0.0f64;
    let gx = p.g * x;
    let mut row = |val: f64, lo: f64, hi: f64, side: Side, z: f64| {
        primal = primal.max(lo - val).max(val - hi);
        match side {
            Side::Inactive => sign = sign.max(z.abs()),
            Side::Lower => {
                sign = sign.max(-z);
                comp = comp.max((val - lo).abs());
            }
            Side::Upper => {
                sign = sign.max(z);
                comp = comp.max((val - hi).abs());
            }
        }
    };
    for i in 0..C {
        row(gx[i], p.lo[i], p.hi[i], s.active.general[i], s.z_general[i]);
    }
    for j in 0..N {
        row(x[j], p.lb[j], p.ub[j], s.active.bounds[j], s.z_bounds[j]);
    }
    (primal, stationarity, sign / (1.0 + grad.amax()), comp)
}

/// What a case expects.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Expect {
    /// Feasible: Clarabel solves it and the status is this one.
    Feasible(Status),
    /// The inequalities may be infeasible with the equalities: statuses must agree.
    Either,
}

/// Solves `p` from `warm`, then again from its own active set, and checks both against the
/// optimality conditions and Clarabel. Returns the first solution.
fn check<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    warm: &ActiveSet<N, C>,
    unique: bool,
    expect: Expect,
) -> Result<Solution<f64, N, E, C>, TestCaseError> {
    check_against(p, p, warm, unique, expect)
}

/// [`check`], with Clarabel given `consistent`: `p` with its equalities replaced by an
/// equivalent consistent set when they are dependent or inconsistent (their independent rows,
/// with the right-hand side `A A⁺ b` that the least-squares solution meets).
fn check_against<const N: usize, const E: usize, const E2: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
    consistent: &Problem<f64, N, E2, C>,
    warm: &ActiveSet<N, C>,
    unique: bool,
    expect: Expect,
) -> Result<Solution<f64, N, E, C>, TestCaseError> {
    let settings = Settings::default();
    let s = solve(p, warm, &settings);
    count(|c| {
        c.checked.fetch_add(1, Ordering::Relaxed);
        c.max_iterations.fetch_max(s.iterations, Ordering::Relaxed);
        if s.status == Status::EqualitiesInconsistent {
            c.inconsistent.fetch_add(1, Ordering::Relaxed);
        }
    });
    let consistent = *consistent;
    let reference = clarabel_solve(&clarabel_data(&consistent), clarabel_settings(true));
    prop_assert!(s.x.iter().all(|v| v.is_finite()));
    // The problem x is optimal for: the consistent one, widened when relaxed.
    let mut target = consistent;
    match reference.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            let want = match expect {
                Expect::Feasible(st) => st,
                Expect::Either => Status::Optimal,
            };
            prop_assert_eq!(s.status, want, "{:?} vs Clarabel {:?}", s, reference.status);
            let tol = 1e-8 * (1.0 + s.objective.abs());
            prop_assert!(
                (s.objective - reference.objective).abs() <= tol,
                "objective {} vs Clarabel {} ({:e})",
                s.objective,
                reference.objective,
                s.objective - reference.objective
            );
            if unique {
                let polished = polish(&consistent, &reference);
                prop_assert!(polished.is_some(), "Clarabel's active set did not polish");
                let px = polished.unwrap_or_default();
                let dx = (0..N).map(|i| (s.x[i] - px[i]).abs()).fold(0.0, f64::max);
                prop_assert!(dx <= 1e-8, "x differs by {:e}: {:?} vs {:?}", dx, s.x, px);
                let raw = (0..N)
                    .map(|i| (s.x[i] - reference.x[i]).abs())
                    .fold(0.0, f64::max);
                prop_assert!(raw <= 1e-6, "x differs from Clarabel's by {:e}", raw);
            }
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            prop_assert!(expect == Expect::Either, "Clarabel: infeasible");
            count(|c| {
                c.infeasible.fetch_add(1, Ordering::Relaxed);
            });
            prop_assert_eq!(s.status, Status::InequalitiesRelaxed);
            // The least total violation, and the optimum under the bounds so widened.
            let least = least_violation(&consistent);
            prop_assert!(least.is_some());
            let least = least.unwrap_or_default();
            prop_assert!(
                (s.violation - least).abs() <= 1e-8 * (1.0 + least),
                "violation {} vs least {}",
                s.violation,
                least
            );
            target = widened(&consistent, &s.x, 0.0);
            // Clarabel on the widened problem: exactly, or (a feasible set reduced to a face
            // is a hard case for an interior-point method, which may then stop short of full
            // accuracy) with the bounds 1e-12, 1e-10 or 1e-8 wider still, the first it solves
            // to full accuracy. A margin m moves the optimum by about Σ|zᵢ| · m.
            let zsum = s.z_general.abs().sum() + s.z_bounds.abs().sum();
            let solved = [0.0, 1e-12, 1e-10, 1e-8].into_iter().find_map(|m| {
                let r = clarabel_solve(
                    &clarabel_data(&widened(&consistent, &s.x, m)),
                    clarabel_settings(true),
                );
                (r.status == SolverStatus::Solved).then_some((m, r.objective))
            });
            prop_assert!(
                solved.is_some(),
                "Clarabel did not solve the relaxed problem"
            );
            let (margin, objective) = solved.unwrap_or_default();
            let tol = 1e-8 * (1.0 + s.objective.abs()) + 2.0 * margin * zsum;
            prop_assert!(
                (s.objective - objective).abs() <= tol,
                "relaxed objective {} vs Clarabel {} (margin {:e}, Σ|z| {})",
                s.objective,
                objective,
                margin,
                zsum
            );
        }
        other => return Err(TestCaseError::fail(format!("Clarabel: {other:?}"))),
    }
    let mut target_full = *p;
    target_full.b_eq = projected_rhs(p);
    (
        target_full.lo,
        target_full.hi,
        target_full.lb,
        target_full.ub,
    ) = (target.lo, target.hi, target.lb, target.ub);
    let (primal, stat, sign, comp) = kkt(&target_full, &s, &target_full.b_eq);
    prop_assert!(
        primal < 1e-9 && stat < 1e-9 && sign < 1e-9 && comp < 1e-9,
        "KKT {:?} {:?}",
        (primal, stat, sign, comp),
        s
    );
    // The same problem from its own active set: no iteration, the same x (a relaxation is
    // found again by phase 1: the active set does not record it).
    let again = solve(p, &s.active, &settings);
    prop_assert_eq!(again.status, s.status);
    if s.status == Status::InequalitiesRelaxed {
        prop_assert!((again.violation - s.violation).abs() <= 1e-9 * (1.0 + s.violation));
        return Ok(s);
    }
    prop_assert_eq!(again.iterations, 0, "warm start from its own active set");
    let dx = (again.x - s.x).amax();
    prop_assert!(
        dx <= 1e-10 * (1.0 + s.x.amax()),
        "warm x differs by {:e}",
        dx
    );
    Ok(s)
}

fn controller_case(seed: u64, kind: u8) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let kappa = if kind % 3 == 0 {
        0.0
    } else {
        uniform(&mut r, 0.05, 0.5)
    };
    let shape = Shape {
        kappa,
        j_rows: 6,
        task: uniform(&mut r, 0.1, 4.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let p: Problem<f64, 7, 2, 2> = random_problem(&mut r, &shape);
    let s = check(
        &p,
        &ActiveSet::EMPTY,
        kappa > 0.0,
        Expect::Feasible(Status::Optimal),
    )?;
    // The next control step: the data move a little; warm start from this step.
    let q = perturb(&p, seed, 0.02);
    check(&q, &s.active, kappa > 0.0, Expect::Either)?;
    Ok(())
}

/// `H` of rank below `n` (`J` with 1–4 rows and no damping, or `H = 0`: a linear program),
/// bounded by the box.
fn singular_case(seed: u64, rank: usize) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let shape = Shape {
        kappa: 0.0,
        j_rows: rank,
        task: uniform(&mut r, 0.1, 3.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let mut p: Problem<f64, 7, 2, 2> = random_problem(&mut r, &shape);
    if rank == 0 {
        p.f = SVector::from_fn(|_, _| uniform(&mut r, -1.0, 1.0));
    }
    let s = check(
        &p,
        &ActiveSet::EMPTY,
        false,
        Expect::Feasible(Status::Optimal),
    )?;
    check(
        &perturb(&p, seed, 0.0),
        &s.active,
        false,
        Expect::Feasible(Status::Optimal),
    )?;
    Ok(())
}

/// Parallel and duplicated rows: general rows repeated, scaled, negated, equal to a box row;
/// fixed rows (`lo = hi = 0`, `lb = ub = 0`); tight bounds, so that many are active.
fn parallel_case(seed: u64, kind: u8) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let kappa = if kind % 2 == 0 { 0.0 } else { 0.2 };
    let shape = Shape {
        kappa,
        j_rows: 6,
        task: uniform(&mut r, 0.5, 4.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let mut p: Problem<f64, 7, 2, 5> = random_problem(&mut r, &shape);
    let j = (seed % 7) as usize;
    let row0 = p.g.row(0).into_owned();
    p.g.set_row(1, &row0);
    p.lo[1] = p.lo[0] * uniform(&mut r, 0.5, 1.5);
    p.hi[1] = p.hi[0] * uniform(&mut r, 0.5, 1.5);
    let row2 = p.g.row(2).into_owned();
    p.g.set_row(3, &(row2 * -2.0));
    p.g.set_row(
        4,
        &SMatrix::<f64, 1, 7>::from_fn(|_, c| f64::from(u8::from(c == j)) * 0.5),
    );
    p.lo[4] = p.lb[j] * 0.3;
    p.hi[4] = p.ub[j] * 0.7;
    if kind >= 2 {
        p.lo[2] = 0.0;
        p.hi[2] = 0.0;
        let jj = (j + 3) % 7;
        p.lb[jj] = 0.0;
        p.ub[jj] = 0.0;
        p.b_eq = SVector::zeros();
    }
    // With b = 0 the problem is feasible (x = 0); otherwise the rows replaced above may
    // exclude the point b was made from.
    let expect = if kind >= 2 {
        Expect::Feasible(Status::Optimal)
    } else {
        Expect::Either
    };
    let s = check(&p, &ActiveSet::EMPTY, false, expect)?;
    check(&perturb(&p, seed, 0.01), &s.active, false, Expect::Either)?;
    Ok(())
}

/// Three equality rows of rank 2 (the third a combination of the first two), with a
/// consistent or an inconsistent right-hand side.
fn dependent_case(seed: u64, consistent: bool) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let shape = Shape {
        kappa: 0.1,
        j_rows: 6,
        task: uniform(&mut r, 0.1, 3.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let mut p: Problem<f64, 7, 3, 2> = random_problem(&mut r, &shape);
    let (al, be) = (uniform(&mut r, -2.0, 2.0), uniform(&mut r, -2.0, 2.0));
    let row = p.a_eq.row(0) * al + p.a_eq.row(1) * be;
    p.a_eq.set_row(2, &row);
    p.b_eq[2] = al * p.b_eq[0] + be * p.b_eq[1];
    let want = if consistent {
        Status::Optimal
    } else {
        // Small enough that the projected right-hand side stays feasible for the box.
        p.b_eq[2] += uniform(&mut r, 0.01, 0.05);
        Status::EqualitiesInconsistent
    };
    let mut two: Problem<f64, 7, 2, 2> = Problem {
        h: p.h,
        f: p.f,
        a_eq: p.a_eq.fixed_rows::<2>(0).into_owned(),
        b_eq: projected_rhs(&p).fixed_rows::<2>(0).into_owned(),
        g: p.g,
        lo: p.lo,
        hi: p.hi,
        lb: p.lb,
        ub: p.ub,
    };
    if consistent {
        two.b_eq = p.b_eq.fixed_rows::<2>(0).into_owned();
    }
    check_against(&p, &two, &ActiveSet::EMPTY, true, Expect::Feasible(want))?;
    Ok(())
}

/// A random right-hand side for the equalities: often no joint rates keep them and the
/// limits together.
fn infeasible_case(seed: u64) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let shape = Shape {
        kappa: if seed % 2 == 0 { 0.0 } else { 0.1 },
        j_rows: 6,
        task: uniform(&mut r, 0.1, 3.0),
        feasible_eq: false,
        b_scale: uniform(&mut r, 0.5, 6.0),
    };
    let p: Problem<f64, 7, 2, 2> = random_problem(&mut r, &shape);
    check(&p, &ActiveSet::EMPTY, false, Expect::Either)?;
    Ok(())
}

fn sized_case<const N: usize, const E: usize, const C: usize>(
    seed: u64,
    kappa: f64,
) -> Result<(), TestCaseError> {
    let mut r = rng(seed);
    let shape = Shape {
        kappa,
        j_rows: N.saturating_sub(1).max(1),
        task: uniform(&mut r, 0.1, 4.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let p: Problem<f64, N, E, C> = random_problem(&mut r, &shape);
    let s = check(
        &p,
        &ActiveSet::EMPTY,
        kappa > 0.0,
        Expect::Feasible(Status::Optimal),
    )?;
    check(
        &perturb(&p, seed, 0.01),
        &s.active,
        kappa > 0.0,
        Expect::Either,
    )?;
    Ok(())
}

fn checked(c: &Counts) -> usize {
    c.checked.load(Ordering::Relaxed)
}

#[test]
fn controller_shaped() {
    let c = run(3000, 1, (any::<u64>(), 0u8..6), |(seed, kind)| {
        controller_case(seed, kind)
    });
    assert!(checked(&c) >= 6000);
}

#[test]
fn singular_hessian() {
    let c = run(1000, 2, (any::<u64>(), 0usize..5), |(seed, rank)| {
        singular_case(seed, rank)
    });
    assert!(checked(&c) >= 2000);
}

#[test]
fn parallel_and_duplicate_rows() {
    let c = run(1000, 3, (any::<u64>(), 0u8..4), |(seed, kind)| {
        parallel_case(seed, kind)
    });
    assert!(checked(&c) >= 2000);
}

#[test]
fn dependent_equalities() {
    let c = run(
        1000,
        4,
        (any::<u64>(), any::<bool>()),
        |(seed, consistent)| dependent_case(seed, consistent),
    );
    assert!(checked(&c) >= 1000);
    // About half have an inconsistent right-hand side.
    assert!(c.inconsistent.load(Ordering::Relaxed) >= checked(&c) * 2 / 5);
}

#[test]
fn infeasible_inequalities() {
    let c = run(1500, 5, any::<u64>(), infeasible_case);
    assert!(checked(&c) >= 1500);
    // Both outcomes, each in numbers.
    let infeasible = c.infeasible.load(Ordering::Relaxed);
    let all = checked(&c);
    assert!(
        infeasible >= all / 5 && infeasible <= all * 4 / 5,
        "{infeasible} of {all} infeasible"
    );
}

#[test]
fn other_sizes() {
    let c = run(400, 6, (any::<u64>(), 0u8..8), |(seed, kind)| {
        let kappa = if kind % 2 == 0 { 0.0 } else { 0.3 };
        match kind / 2 {
            0 => sized_case::<3, 1, 1>(seed, kappa),
            1 => sized_case::<12, 6, 4>(seed, kappa),
            2 => sized_case::<4, 0, 0>(seed, kappa),
            _ => sized_case::<9, 3, 6>(seed, kappa),
        }
    });
    assert!(checked(&c) >= 800);
}

/// Any finite data — an indefinite `H`, magnitudes from 1e-300 to 1e300, inverted bounds,
/// zero rows — and the occasional NaN or infinity: no panic, and `x` is finite (zero for
/// NonFinite and InvalidBounds).
#[test]
fn wild_input_never_panics_nor_gives_nan() {
    let values = prop_oneof![
        4 => -10.0f64..10.0,
        1 => Just(0.0),
        1 => (-300i32..300, -1.0f64..1.0).prop_map(|(e, m)| m * 10f64.powi(e)),
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(-f64::INFINITY), Just(1e308), Just(-1e308)],
    ];
    let c = run(
        3000,
        7,
        (
            proptest::collection::vec(values, 7 * 7 + 7 + 14 + 2 + 14 + 4 + 14),
            any::<ActiveSetSeed>(),
        ),
        |(v, warm)| {
            let mut it = v.into_iter();
            let mut next = || it.next().unwrap_or(0.0);
            let p: Problem<f64, 7, 2, 2> = Problem {
                h: SMatrix::from_fn(|_, _| next()),
                f: SVector::from_fn(|_, _| next()),
                a_eq: SMatrix::from_fn(|_, _| next()),
                b_eq: SVector::from_fn(|_, _| next()),
                g: SMatrix::from_fn(|_, _| next()),
                lo: SVector::from_fn(|_, _| next()),
                hi: SVector::from_fn(|_, _| next()),
                lb: SVector::from_fn(|_, _| next()),
                ub: SVector::from_fn(|_, _| next()),
            };
            let s = solve(&p, &warm.0, &Settings::default());
            count(|c| {
                c.checked.fetch_add(1, Ordering::Relaxed);
            });
            prop_assert!(s.x.iter().all(|v| v.is_finite()), "{:?}", s);
            prop_assert!(s.objective.is_finite());
            if matches!(s.status, Status::NonFinite | Status::InvalidBounds) {
                prop_assert_eq!(s.x, SVector::<f64, 7>::zeros());
            }
            Ok(())
        },
    );
    assert!(checked(&c) >= 3000);
}

/// A random warm start.
#[derive(Clone, Debug)]
struct ActiveSetSeed(ActiveSet<7, 2>);

impl Arbitrary for ActiveSetSeed {
    type Parameters = ();
    type Strategy = BoxedStrategy<Self>;
    fn arbitrary_with(_: ()) -> Self::Strategy {
        let side = prop_oneof![Just(Side::Inactive), Just(Side::Lower), Just(Side::Upper)];
        (proptest::collection::vec(side, 9))
            .prop_map(|v| {
                ActiveSetSeed(ActiveSet {
                    general: [v[0], v[1]],
                    bounds: core::array::from_fn(|j| v[2 + j]),
                })
            })
            .boxed()
    }
}

/// The controller's problems in `f32`: the same status and `x` within 1e-3 of the `f64`
/// solution where `H` is definite.
#[test]
fn f32_agrees_with_f64() {
    let c = run(1000, 8, any::<u64>(), |seed| {
        let mut r = rng(seed);
        let shape = Shape {
            kappa: uniform(&mut r, 0.1, 0.5),
            j_rows: 6,
            task: uniform(&mut r, 0.1, 4.0),
            feasible_eq: true,
            b_scale: 0.0,
        };
        let p: Problem<f64, 7, 2, 2> = random_problem(&mut r, &shape);
        let s = solve(&p, &ActiveSet::EMPTY, &Settings::default());
        let p32: Problem<f32, 7, 2, 2> = Problem {
            h: p.h.cast(),
            f: p.f.cast(),
            a_eq: p.a_eq.cast(),
            b_eq: p.b_eq.cast(),
            g: p.g.cast(),
            lo: p.lo.cast(),
            hi: p.hi.cast(),
            lb: p.lb.cast(),
            ub: p.ub.cast(),
        };
        let s32 = solve(&p32, &ActiveSet::EMPTY, &Settings::default());
        count(|c| {
            c.checked.fetch_add(1, Ordering::Relaxed);
        });
        prop_assert_eq!(s.status, Status::Optimal);
        prop_assert_eq!(s32.status, Status::Optimal);
        let dx = (s32.x.cast::<f64>() - s.x).amax();
        prop_assert!(dx < 1e-3, "f32 x differs by {:e}", dx);
        Ok(())
    });
    assert!(checked(&c) >= 1000);
}
