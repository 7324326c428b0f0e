//! trocar's QP solver against DAQP and OSQP on the QPs of two runs:
//!
//! - the scene `three-ports`: it runs its 4 s (2,000 steps) and records every QP its step solves
//!   (`Scene::step_observed`: 21 joint rates, 6 port rows, 6 coupling rows and the 21 rates' box;
//!   the problem, the warm start it was solved from and trocar's solution);
//! - the single-arm Panda's QP control step in the scenario `panda-laparoscope-limits` (12 s at
//!   2 ms, `trocar_sim::simulation::run` with `Method::Qp`): every QP the controller solves
//!   (7 joint rates, 2 trocar rows, the insertion-depth row and the box), recorded by
//!   `trocar::qp::record` (the feature `qp-record`, on in this bench only).
//!
//! Each solver then solves the recorded sequence in order, warm-started as a controller would use
//! it:
//!
//! - trocar: from the recorded warm start (the previous solve's active set), the dual
//!   active-set method on that working set in one workspace for the whole sequence
//!   (`qp::Dual`, as a scene keeps it), the primal active-set method where it declines — for the
//!   scene as its step solves (`control::scene::solve_qp`: the primal method from the warm
//!   start's coupling rows), for the Panda as `qp::solve_definite` does; and `Problem::solve`,
//!   the primal method alone (`primal`), as the single arm's step solves;
//! - DAQP 0.11 (dual active set, C, `-O3`, `-march=native` with `QP_PEERS_NATIVE`): one workspace for the whole
//!   sequence, the data of each problem written into it (`daqp_update_ldp`), its working set
//!   the warm start;
//! - OSQP 0.6 (ADMM, the `osqp` crate): one solver for the whole sequence, the data updated,
//!   warm-started from its previous solution, tolerances 1e-9 with polishing (so that its
//!   optimum can be compared with an active-set solver's).
//!
//! Each solve is timed alone (`Instant`), its data written afresh just before (a copy of the
//! recorded problem for trocar, each peer's arrays built from it), as a controller builds its
//! problem before it solves: trocar's as the least of five runs from the same state (and its
//! first run alone, `1st run`, timed as the peers are), DAQP's and OSQP's once (their warm start
//! is their own state after the last solve). Prints the CPU, the median and the 99.9th
//! percentile of each solver's time, the ratios, and the largest difference of each peer's
//! optimum from trocar's.

use std::hint::black_box;
use std::time::Instant;
use trocar::qp::{ActiveSet, Dual, Problem, Settings, Side, Solution, Status};
use trocar_sim::scene::{Kin, ThreePorts, DT, DURATION};

/// Every QP of `three-ports`, with the warm start it was solved from and trocar's solution.
#[allow(clippy::type_complexity)]
fn record_scene() -> Vec<(
    Problem<f64, 21, 6, 6>,
    ActiveSet<21, 6>,
    Solution<f64, 21, 6, 6>,
)> {
    let mut setup = ThreePorts::new(true).expect("the scene");
    let mut q = setup.q0;
    let mut out = Vec::new();
    let steps = (DURATION / DT).round() as usize;
    for step in 0..steps {
        let t = step as f64 * DT;
        let references = setup.references(&q, t).expect("references");
        let kins: [Kin; 3] = setup.kins;
        let o = setup
            .scene
            .step_observed::<Kin, 3, 7, 7, 2, 4, 4, 4, 6, _>(
                &mut setup.arms,
                &kins,
                &q,
                &references,
                &setup.rcms,
                &setup.bases,
                &[],
                DT,
                |p, w, s| out.push((*p, *w, *s)),
            )
            .expect("a scene step");
        for (qk, qd) in q.iter_mut().zip(o.qd) {
            *qk += qd * DT;
        }
    }
    out
}

/// Every QP of the Panda's QP control step in `panda-laparoscope-limits`, with the warm start it
/// was solved from and trocar's solution (solved again here: the recorder keeps the solution's
/// `x` only).
#[allow(clippy::type_complexity)]
fn record_panda() -> Vec<(
    Problem<f64, 7, 2, 1>,
    ActiveSet<7, 1>,
    Solution<f64, 7, 2, 1>,
)> {
    use trocar_sim::simulation::{run, Method, Scenario, ScenarioConfig};
    let config = ScenarioConfig::new(Scenario::PandaLimits)
        .with_method(Method::Qp)
        .with_drift_correction(true);
    trocar::qp::record::start();
    let trace = run(&config, |_| {});
    let recorded = trocar::qp::record::take();
    trace.expect("the Panda's limits scenario");
    let settings = Settings::default();
    recorded
        .iter()
        .filter_map(|r| r.problem::<7, 2, 1>())
        .map(|(p, w)| {
            let s = p.solve(&w, &settings);
            (p, w, s)
        })
        .collect()
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn summary(name: &str, times: &mut [f64]) -> (f64, f64) {
    times.sort_by(|a, b| a.total_cmp(b));
    let (median, tail) = (percentile(times, 0.5), percentile(times, 0.999));
    println!(
        "{name:>7}: median {:8.2} µs, p99.9 {:8.2} µs ({:.2}x), max {:8.2} µs",
        median * 1e6,
        tail * 1e6,
        tail / median,
        times[times.len() - 1] * 1e6
    );
    (median, tail)
}

/// A bound at the solver's "no bound" (trocar's large finite one) as infinity.
fn bound(v: f64) -> f64 {
    if v.abs() >= 1e6 {
        v.signum() * 1e30
    } else {
        v
    }
}

mod daqp {
    use std::os::raw::{c_double, c_int, c_void};
    extern "C" {
        pub fn peer_daqp_new(n: c_int, m: c_int, ms: c_int) -> *mut c_void;
        #[allow(clippy::too_many_arguments)]
        pub fn peer_daqp_solve(
            p: *mut c_void,
            h: *const c_double,
            f: *const c_double,
            a: *const c_double,
            bu: *const c_double,
            bl: *const c_double,
            sense: *const c_int,
            x: *mut c_double,
            iter: *mut c_int,
        ) -> c_int;
        pub fn peer_daqp_free(p: *mut c_void);
    }
    /// DAQP's constraint states: an equality is an active, immutable row.
    pub const ACTIVE: c_int = 1;
    pub const IMMUTABLE: c_int = 4;
}

/// The problem in DAQP's layout: H row-major, the box first, then the port rows (equalities)
/// and the coupling rows.
struct DaqpData {
    h: Vec<f64>,
    f: Vec<f64>,
    a: Vec<f64>,
    bu: Vec<f64>,
    bl: Vec<f64>,
    sense: Vec<i32>,
}

fn daqp_data<const N: usize, const E: usize, const C: usize>(
    p: &Problem<f64, N, E, C>,
) -> DaqpData {
    let h = (0..N * N).map(|i| p.h[(i / N, i % N)]).collect();
    let f = p.f.iter().copied().collect();
    let mut a = Vec::with_capacity((E + C) * N);
    for r in 0..E {
        a.extend((0..N).map(|c| p.a_eq[(r, c)]));
    }
    for r in 0..C {
        a.extend((0..N).map(|c| p.g[(r, c)]));
    }
    let mut bu: Vec<f64> = p.ub.iter().map(|v| bound(*v)).collect();
    let mut bl: Vec<f64> = p.lb.iter().map(|v| bound(*v)).collect();
    let mut sense = vec![0; N];
    for r in 0..E {
        bu.push(p.b_eq[r]);
        bl.push(p.b_eq[r]);
        sense.push(daqp::ACTIVE | daqp::IMMUTABLE);
    }
    for r in 0..C {
        bu.push(bound(p.hi[r]));
        bl.push(bound(p.lo[r]));
        sense.push(0);
    }
    DaqpData {
        h,
        f,
        a,
        bu,
        bl,
        sense,
    }
}

fn main() {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    println!("on {cpu}");
    compare(
        "three-ports",
        &record_scene(),
        trocar::control::scene::solve_qp::<f64, 21, 6, 6>,
    );
    println!();
    compare(
        "panda-laparoscope-limits",
        &record_panda(),
        |dual: &mut Dual<f64, 7>, p: &Problem<f64, 7, 2, 1>, warm, settings| {
            dual.solve(p, warm).unwrap_or_else(|| p.solve(warm, settings))
        },
    );
}

/// Solves the recorded sequence with trocar (`fast`: the dual method first, in one workspace
/// for the sequence), DAQP and OSQP and prints their times and optima.
#[allow(clippy::type_complexity)]
fn compare<const N: usize, const E: usize, const C: usize>(
    name: &str,
    recorded: &[(
        Problem<f64, N, E, C>,
        ActiveSet<N, C>,
        Solution<f64, N, E, C>,
    )],
    fast: fn(
        &mut Dual<f64, N>,
        &Problem<f64, N, E, C>,
        &ActiveSet<N, C>,
        &Settings,
    ) -> Solution<f64, N, E, C>,
) {
    type Qp<const N: usize, const E: usize, const C: usize> = Problem<f64, N, E, C>;
    let settings = Settings::default();
    let count = recorded.len();
    println!("{count} QPs of {name} (n = {N}, {E} equality rows, {C} general rows, {N} bounds)");

    // trocar, from the recorded warm starts: `fast` (the range space first), and the primal
    // active-set method alone (`Problem::solve`).
    let mut ours = Vec::with_capacity(count);
    let mut ours_first = Vec::with_capacity(count);
    let mut primal = Vec::with_capacity(count);
    let mut iterations = 0usize;
    let mut answered = 0usize;
    let mut definite_differs = 0.0f64;
    let mut dual = Dual::new();
    for (recorded_problem, warm, s) in recorded {
        // The problem written afresh before it is solved, as a controller builds it and as
        // DAQP's data are below (a recorded problem read from the 10 MB sequence would cost its
        // first run the cache misses that a controller's solve does not have).
        let local = black_box(*recorded_problem);
        let p = &local;
        let mut least = f64::INFINITY;
        let mut least_primal = f64::INFINITY;
        for run in 0..5 {
            let start = Instant::now();
            let again = fast(&mut dual, black_box(p), black_box(warm), &settings);
            let elapsed = start.elapsed().as_secs_f64();
            if run == 0 {
                ours_first.push(elapsed);
            }
            least = least.min(elapsed);
            let x = again.x;
            let start = Instant::now();
            let again = black_box(p).solve(black_box(warm), &settings);
            least_primal = least_primal.min(start.elapsed().as_secs_f64());
            definite_differs = definite_differs.max((x - again.x).amax());
        }
        answered += usize::from(trocar::qp::solve_range_space(p, warm).is_some());
        iterations += s.iterations;
        ours.push(least);
        primal.push(least_primal);
    }
    println!(
        "trocar: the dual method answered {answered} of {count} solves; its optimum at most \
         {definite_differs:.2e} from the primal method's"
    );
    let optimal = recorded
        .iter()
        .filter(|(_, _, s)| s.status == Status::Optimal)
        .count();
    let active = |f: &dyn Fn(&ActiveSet<N, C>) -> usize| {
        recorded.iter().map(|(_, _, s)| f(&s.active)).sum::<usize>() as f64 / count as f64
    };
    println!(
        "trocar: {optimal} of {count} optimal, {:.2} working-set changes per solve; at the optimum \
         {:.1} bounds and {:.1} general rows active on average (and the {E} port rows)",
        iterations as f64 / count as f64,
        active(&|a| a.bounds.iter().filter(|s| **s != Side::Inactive).count()),
        active(&|a| a.general.iter().filter(|s| **s != Side::Inactive).count()),
    );

    // DAQP, one workspace through the sequence.
    let mut theirs = Vec::with_capacity(count);
    let mut daqp_differs = 0.0f64;
    let mut daqp_iterations = 0usize;
    let mut daqp_failed = 0usize;
    // SAFETY: the handle is DAQP's workspace behind the shim, used by this thread only and freed
    // once at the end; every array passed has the length the shim reads (n·n, n, (m − ms)·n, m).
    unsafe {
        let handle = daqp::peer_daqp_new(N as i32, (N + E + C) as i32, N as i32);
        assert!(!handle.is_null());
        for (p, _, s) in recorded {
            let d = daqp_data(p);
            let mut x = [0.0f64; N];
            let mut iter = 0;
            let start = Instant::now();
            let flag = daqp::peer_daqp_solve(
                handle,
                d.h.as_ptr(),
                d.f.as_ptr(),
                d.a.as_ptr(),
                d.bu.as_ptr(),
                d.bl.as_ptr(),
                d.sense.as_ptr(),
                x.as_mut_ptr(),
                &mut iter,
            );
            theirs.push(start.elapsed().as_secs_f64());
            if flag != 1 {
                daqp_failed += 1;
                continue;
            }
            daqp_iterations += iter as usize;
            for (a, b) in x.iter().zip(s.x.iter()) {
                daqp_differs = daqp_differs.max((a - b).abs());
            }
        }
        daqp::peer_daqp_free(handle);
    }
    println!(
        "DAQP: {} of {count} optimal, {:.2} iterations per solve, optimum at most {daqp_differs:.2e} \
         from trocar's",
        count - daqp_failed,
        daqp_iterations as f64 / count as f64
    );

    // OSQP, one solver through the sequence.
    let osqp_settings = osqp::Settings::default()
        .eps_abs(1e-9)
        .eps_rel(1e-9)
        .polish(true)
        .warm_start(true)
        .max_iter(100_000)
        .verbose(false);
    let matrices = |p: &Qp<N, E, C>| {
        let h = osqp::CscMatrix::from_column_iter_dense(N, N, p.h.iter().copied()).into_upper_tri();
        let rows = N + E + C;
        let a = osqp::CscMatrix::from_row_iter_dense(
            rows,
            N,
            (0..rows).flat_map(|r| {
                (0..N).map(move |c| {
                    if r < N {
                        if r == c {
                            1.0
                        } else {
                            0.0
                        }
                    } else if r < N + E {
                        p.a_eq[(r - N, c)]
                    } else {
                        p.g[(r - N - E, c)]
                    }
                })
            }),
        );
        let mut l: Vec<f64> = p.lb.iter().map(|v| bound(*v)).collect();
        let mut u: Vec<f64> = p.ub.iter().map(|v| bound(*v)).collect();
        l.extend(p.b_eq.iter());
        u.extend(p.b_eq.iter());
        l.extend(p.lo.iter().map(|v| bound(*v)));
        u.extend(p.hi.iter().map(|v| bound(*v)));
        (h, a, l, u)
    };
    let (h0, a0, l0, u0) = matrices(&recorded[0].0);
    let f0: Vec<f64> = recorded[0].0.f.iter().copied().collect();
    let mut solver =
        osqp::Problem::new(h0, &f0, a0, &l0, &u0, &osqp_settings).expect("OSQP's setup");
    let mut osqp_times = Vec::with_capacity(count);
    let mut osqp_differs = 0.0f64;
    let mut osqp_failed = 0usize;
    let mut osqp_unpolished = 0usize;
    let mut osqp_unpolished_differs = 0.0f64;
    for (p, _, s) in recorded {
        let (h, a, l, u) = matrices(p);
        let f: Vec<f64> = p.f.iter().copied().collect();
        let start = Instant::now();
        solver.update_P_A(h, a);
        solver.update_lin_cost(&f);
        solver.update_bounds(&l, &u);
        let status = solver.solve();
        let x = status.x().map(|x| x.to_vec());
        osqp_times.push(start.elapsed().as_secs_f64());
        let polished = status
            .solution()
            .is_some_and(|sol| matches!(sol.polish_status(), osqp::PolishStatus::Successful));
        match x {
            Some(x) if matches!(status, osqp::Status::Solved(_)) => {
                let differs = (0..N).fold(0.0f64, |m, k| m.max((x[k] - s.x[k]).abs()));
                if polished {
                    osqp_differs = osqp_differs.max(differs);
                } else {
                    osqp_unpolished += 1;
                    osqp_unpolished_differs = osqp_unpolished_differs.max(differs);
                }
            }
            _ => osqp_failed += 1,
        }
    }
    println!(
        "OSQP: {} of {count} solved, the polished optima at most {osqp_differs:.2e} from \
         trocar's; {osqp_unpolished} without a successful polish, at most \
         {osqp_unpolished_differs:.2e} from it",
        count - osqp_failed
    );

    println!("time per solve (warm-started; trocar's the least of five runs):");
    let (ours_median, ours_tail) = summary("trocar", &mut ours);
    let (first_median, _) = summary("1st run", &mut ours_first);
    let (primal_median, _) = summary("primal", &mut primal);
    let (daqp_median, _) = summary("DAQP", &mut theirs);
    let (osqp_median, _) = summary("OSQP", &mut osqp_times);
    println!(
        "trocar / DAQP {:.2}x, trocar / OSQP {:.3}x (medians); trocar's p99.9 {:.2}x its median; \
         the primal method alone / DAQP {:.2}x; trocar's first run of each solve / DAQP {:.2}x",
        ours_median / daqp_median,
        ours_median / osqp_median,
        ours_tail / ours_median,
        primal_median / daqp_median,
        first_median / daqp_median
    );
}
