//! `qp::solve_definite`: the dual active-set method (Goldfarb–Idnani) from a warm start, against
//! the primal active-set solve of the same problems (an independent method): the same optimum,
//! status and active set wherever the dual method answers, and it answers for most
//! warm-started steps of a controller-like sequence, from warm starts rows off the optimum's
//! and from none; it declines a singular `H`, dependent equality rows and rows that cannot be
//! met together, and `solve_definite` then gives the primal method's answer.

mod qp_common;

use qp_common::{perturb, random_problem, rng, uniform, Shape};
use trocar::qp::{
    solve_definite, solve_range_space, ActiveSet, Dual, Problem, Settings, Side, Status,
};

/// A sequence of problems moving a little each step, each warm-started from the last solve:
/// `(steps answered by the range space, steps)`.
fn sequence<const N: usize, const E: usize, const C: usize>(
    seed: u64,
    kappa: f64,
) -> (usize, usize) {
    let mut r = rng(seed);
    let shape = Shape {
        kappa,
        j_rows: N.min(6),
        task: uniform(&mut r, 0.2, 3.0),
        feasible_eq: true,
        b_scale: 0.0,
    };
    let mut p: Problem<f64, N, E, C> = random_problem(&mut r, &shape);
    let settings = Settings::default();
    let mut warm = ActiveSet::<N, C>::EMPTY;
    let (mut answered, mut steps) = (0, 0);
    // The reference: the primal method with room for a cold start's many iterations.
    let reference = Settings {
        max_iterations: 10_000,
    };
    // A workspace kept over the sequence, as a controller keeps it: the same answers, bit for
    // bit, as a fresh one (what a solve leaves in it is cleared).
    let mut kept = Dual::new();
    for step in 0..40 {
        let general = p.solve(&warm, &reference);
        let fast = solve_definite(&p, &warm, &settings);
        let range = solve_range_space(&p, &warm);
        assert_eq!(kept.solve(&p, &warm), range, "seed {seed} step {step}");
        if let Some(range) = range {
            answered += 1;
            assert_eq!(
                range.x, fast.x,
                "solve_definite returns the range space's answer"
            );
            assert_eq!(range.status, Status::Optimal);
            assert_eq!(general.status, Status::Optimal, "seed {seed} step {step}");
            let scale = 1.0 + general.x.amax();
            let dx = (range.x - general.x).amax();
            assert!(
                dx <= 1e-9 * scale,
                "seed {seed} step {step}: x {dx:e} apart"
            );
            assert_eq!(range.active, general.active, "seed {seed} step {step}");
            let dz = (range.z_general - general.z_general)
                .amax()
                .max((range.z_bounds - general.z_bounds).amax())
                .max((range.y_eq - general.y_eq).amax());
            assert!(
                dz <= 1e-7
                    * (1.0
                        + general.z_bounds.amax()
                        + general.z_general.amax()
                        + general.y_eq.amax()),
                "seed {seed} step {step}: multipliers {dz:e} apart"
            );
            assert!(
                (range.objective - general.objective).abs()
                    <= 1e-9 * (1.0 + general.objective.abs())
            );
        } else {
            // Declined: the general solve is what solve_definite returns.
            assert_eq!(fast, p.solve(&warm, &settings), "seed {seed} step {step}");
        }
        steps += 1;
        warm = general.active;
        p = perturb(&p, seed.wrapping_mul(31).wrapping_add(step), 2e-3);
    }
    (answered, steps)
}

#[test]
fn the_range_space_gives_the_primal_optimum() {
    let (mut answered, mut steps) = (0, 0);
    for seed in 0..60 {
        let kappa = [1e-3, 0.05, 0.5][seed as usize % 3];
        let (a, s) = sequence::<21, 6, 6>(seed, kappa);
        answered += a;
        steps += s;
        let (a, s) = sequence::<7, 2, 1>(1000 + seed, kappa);
        answered += a;
        steps += s;
    }
    println!("the range space answered {answered} of {steps} warm-started solves");
    // The dual method answers nine in ten and more (the others: `H` or the rows too
    // ill-conditioned for (11), which the primal method solves).
    assert!(answered * 10 >= steps * 9, "{answered} of {steps}");
}

/// A warm start one row short of the optimum's working set (an active row left out, as when a
/// coupling comes in): the minimiser breaks that row, and the dual method takes it in (with
/// whatever leaves on the way) and answers with the optimum, counting the rows that joined or
/// left; where it declines, `solve_definite` still gives the optimum.
#[test]
fn the_range_space_exchanges_rows_toward_the_optimum() {
    let settings = Settings::default();
    let (mut answered, mut tried) = (0, 0);
    for seed in 0..300u64 {
        let mut r = rng(500 + seed);
        let shape = Shape {
            kappa: [1e-3, 0.05, 0.5][seed as usize % 3],
            j_rows: 6,
            task: 3.0,
            feasible_eq: true,
            b_scale: 0.0,
        };
        let p: Problem<f64, 21, 6, 6> = random_problem(&mut r, &shape);
        let optimum = p.solve(&ActiveSet::EMPTY, &settings);
        if optimum.status != Status::Optimal {
            continue;
        }
        let mut short = optimum.active;
        if let Some(g) = (0..6).find(|&g| short.general[g] != Side::Inactive) {
            short.general[g] = Side::Inactive;
        } else if let Some(k) = (0..21).find(|&k| short.bounds[k] != Side::Inactive) {
            short.bounds[k] = Side::Inactive;
        } else {
            continue;
        }
        tried += 1;
        if let Some(s) = solve_range_space(&p, &short) {
            answered += 1;
            assert!(s.iterations >= 1);
            assert_eq!(s.active, optimum.active, "seed {seed}");
            assert!(
                (s.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()),
                "seed {seed}"
            );
        }
        let fast = solve_definite(&p, &short, &settings);
        assert!((fast.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()));
    }
    println!("the range space answered {answered} of {tried} warm starts one row short");
    assert!(tried >= 50, "only {tried} problems with active rows");
    assert!(answered * 10 >= tried * 9, "{answered} of {tried}");
}

#[test]
fn the_range_space_declines_what_it_cannot_answer() {
    let mut r = rng(7);
    let shape = Shape {
        kappa: 0.1,
        j_rows: 6,
        task: 2.0,
        feasible_eq: true,
        b_scale: 0.0,
    };
    let p: Problem<f64, 7, 2, 1> = random_problem(&mut r, &shape);
    let settings = Settings::default();
    let optimum = p.solve(&ActiveSet::EMPTY, &settings);
    assert_eq!(optimum.status, Status::Optimal);
    assert!(solve_range_space(&p, &optimum.active).is_some());
    // A bound held that the optimum leaves: its multiplier has the wrong sign, or the point
    // breaks another row. The range space exchanges rows toward the optimum's working set and
    // answers with the optimum, or declines; `solve_definite` gives the optimum either way.
    let free = (0..7)
        .find(|&k| optimum.active.bounds[k] == Side::Inactive)
        .expect("a free variable");
    let mut wrong = optimum.active;
    wrong.bounds[free] = if optimum.x[free] > 0.0 {
        Side::Lower
    } else {
        Side::Upper
    };
    if let Some(s) = solve_range_space(&p, &wrong) {
        assert!(s.iterations >= 1, "the wrong working set was exchanged");
        assert_eq!(s.active, optimum.active);
        assert!((s.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()));
    }
    let fast = solve_definite(&p, &wrong, &settings);
    assert_eq!(fast.status, Status::Optimal);
    assert!((fast.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()));
    // A singular H (no damping, fewer task rows than joints).
    let singular: Problem<f64, 7, 2, 1> = random_problem(
        &mut r,
        &Shape {
            kappa: 0.0,
            j_rows: 4,
            ..shape
        },
    );
    assert!(solve_range_space(&singular, &ActiveSet::EMPTY).is_none());
    // Dependent rows: the two equalities the same.
    let mut dependent = p;
    let row = dependent.a_eq.row(0).into_owned();
    dependent.a_eq.set_row(1, &row);
    dependent.b_eq[1] = dependent.b_eq[0];
    assert!(solve_range_space(&dependent, &ActiveSet::EMPTY).is_none());
    // A NaN anywhere.
    let mut nan = p;
    nan.h[(0, 0)] = f64::NAN;
    assert!(solve_range_space(&nan, &ActiveSet::EMPTY).is_none());
    assert_eq!(
        solve_definite(&nan, &ActiveSet::EMPTY, &settings).status,
        Status::NonFinite
    );
}

/// The scene's solve (`control::scene::solve_qp`: the range space from the warm start, else the
/// primal method from the warm start's general rows alone) gives the optimum of the primal
/// method from a cold start for the warm starts a controller hands it: the optimum's own rows,
/// the optimum of the problem a step before (moved by 2 % of its data), that with every bound
/// held on the other side, and none.
#[test]
fn the_scenes_solve_gives_the_optimum_from_a_controllers_warm_starts() {
    use trocar::control::scene::solve_qp;
    let settings = Settings::default();
    let (mut compared, mut fell_back) = (0, 0);
    // One workspace for every solve, as a scene keeps it.
    let mut dual = Dual::new();
    for seed in 0..160u64 {
        let mut r = rng(9000 + seed);
        let shape = Shape {
            // κ = 0: `H` singular, which the dual method declines.
            kappa: [1e-3, 0.05, 0.5, 0.0][seed as usize % 4],
            j_rows: 6,
            task: uniform(&mut r, 0.5, 4.0),
            feasible_eq: true,
            b_scale: 0.0,
        };
        let before: Problem<f64, 21, 6, 6> = random_problem(&mut r, &shape);
        let mut p = perturb(&before, seed, 2e-2);
        if shape.kappa == 0.0 {
            // The perturbation's `dh dhᵀ` made `H` definite: keep it singular.
            p.h = before.h;
        }
        let optimum = p.solve(&ActiveSet::EMPTY, &settings);
        let previous = before.solve(&ActiveSet::EMPTY, &settings);
        if optimum.status != Status::Optimal || previous.status != Status::Optimal {
            continue;
        }
        let mut flipped = previous.active;
        for b in flipped.bounds.iter_mut() {
            *b = match b {
                Side::Inactive => Side::Inactive,
                Side::Lower => Side::Upper,
                Side::Upper => Side::Lower,
            };
        }
        for warm in [optimum.active, previous.active, flipped, ActiveSet::EMPTY] {
            let s = solve_qp(&mut dual, &p, &warm, &settings);
            fell_back += usize::from(solve_range_space(&p, &warm).is_none());
            assert_eq!(s.status, Status::Optimal, "seed {seed} from {warm:?}");
            assert!(
                (s.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()),
                "seed {seed}: {:e} from the optimum",
                (s.x - optimum.x).amax()
            );
            compared += 1;
        }
    }
    println!("{compared} solves, {fell_back} by the primal method");
    assert!(compared >= 400, "only {compared} solves compared");
    // Both ways through `solve_qp` were taken: the dual method's answers and the fallback.
    assert!(
        fell_back >= 60 && compared - fell_back >= 300,
        "{fell_back} of {compared} solves by the primal method"
    );
}

/// The dual method from a cold start, with a row that depends on another (twice a row, its
/// bounds twice as far: the same constraint) and with two rows that cannot both be met: the
/// primal method's optimum where it answers, and where the rows cannot be met it declines and
/// `solve_definite` reports the primal method's relaxation.
#[test]
fn the_dual_method_takes_dependent_rows_and_declines_infeasible_ones() {
    let settings = Settings {
        max_iterations: 10_000,
    };
    let (mut answered, mut tried, mut infeasible) = (0, 0, 0);
    for seed in 0..120u64 {
        let mut r = rng(20_000 + seed);
        let shape = Shape {
            kappa: [0.05, 0.5][seed as usize % 2],
            j_rows: 6,
            task: uniform(&mut r, 1.0, 4.0),
            feasible_eq: true,
            b_scale: 0.0,
        };
        let mut p: Problem<f64, 21, 6, 6> = random_problem(&mut r, &shape);
        let row = p.g.row(0).into_owned();
        p.g.set_row(1, &(row * 2.0));
        p.lo[1] = 2.0 * p.lo[0];
        p.hi[1] = 2.0 * p.hi[0];
        // Pull the rows' optimum against their bounds: the unconstrained minimiser far along g₀.
        p.f -= row.transpose() * 50.0;
        let optimum = p.solve(&ActiveSet::EMPTY, &settings);
        if optimum.status != Status::Optimal {
            continue;
        }
        tried += 1;
        if let Some(s) = solve_range_space(&p, &ActiveSet::EMPTY) {
            answered += 1;
            assert!(
                (s.x - optimum.x).amax() <= 1e-9 * (1.0 + optimum.x.amax()),
                "seed {seed}: {:e} from the primal optimum",
                (s.x - optimum.x).amax()
            );
            assert!(
                (s.objective - optimum.objective).abs() <= 1e-9 * (1.0 + optimum.objective.abs())
            );
            // One of the two rows holds the pair at its bound, never both.
            assert!(
                !(s.active.general[0] != Side::Inactive && s.active.general[1] != Side::Inactive),
                "seed {seed}: both dependent rows active"
            );
        }
        // The second row beyond the first's upper bound: no point meets both.
        let mut q = p;
        q.lo[1] = 2.0 * p.hi[0] + 0.5;
        q.hi[1] = q.lo[1] + 1.0;
        if q.a_eq.nrows() > 0 {
            let relaxed = solve_definite(&q, &ActiveSet::EMPTY, &settings);
            assert!(
                solve_range_space(&q, &ActiveSet::EMPTY).is_none(),
                "seed {seed}"
            );
            assert_eq!(relaxed, q.solve(&ActiveSet::EMPTY, &settings));
            infeasible += usize::from(relaxed.status == Status::InequalitiesRelaxed);
        }
    }
    println!("the dual method answered {answered} of {tried} cold starts; {infeasible} relaxed");
    assert!(tried >= 60, "only {tried} problems");
    assert!(answered * 10 >= tried * 9, "{answered} of {tried}");
    assert!(infeasible >= 60, "only {infeasible} relaxations");
}
