//! `trocar::qp` on the controller's problem — 7 joint rates, 2 trocar rows, the 14 box bounds
//! and one two-sided general row (the insertion depth): 16 inequality bounds — against
//! Clarabel 0.11 on the same problems in the same run.
//!
//! A sequence of 256 control steps: each step's data are the previous step's moved a little
//! (`perturb`, up to 0.01), as between two control periods. `trocar/warm` solves each step from
//! the previous step's active set (what the controller does); `trocar/cold` from the empty one;
//! `clarabel` builds and solves each step with its default settings (an interior-point method
//! has no warm start). Each iteration of a benchmark solves one step, cycling through the
//! sequence. The `c2` group is the same with two general rows (the property tests' shape).

#[path = "../tests/qp_common/mod.rs"]
mod qp_common;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use qp_common::*;
use trocar::qp::{solve, ActiveSet, Problem, Settings, Status};

const STEPS: usize = 256;

/// The sequence of steps, each with the previous step's active set.
fn sequence<const C: usize>() -> Vec<(Problem<f64, 7, 2, C>, ActiveSet<7, C>)> {
    let mut r = rng(2024);
    let shape = Shape {
        kappa: 0.05,
        j_rows: 6,
        task: 1.5,
        feasible_eq: true,
        b_scale: 0.0,
    };
    let mut p: Problem<f64, 7, 2, C> = random_problem(&mut r, &shape);
    let settings = Settings::default();
    let mut warm = solve(&p, &ActiveSet::EMPTY, &settings).active;
    let mut out = Vec::with_capacity(STEPS);
    let mut k = 0u64;
    while out.len() < STEPS {
        k += 1;
        let q = perturb(&p, k, 0.01);
        let s = solve(&q, &warm, &settings);
        if s.status != Status::Optimal {
            // A step the perturbation made infeasible: start again from a fresh problem.
            p = random_problem(&mut r, &shape);
            warm = solve(&p, &ActiveSet::EMPTY, &settings).active;
            continue;
        }
        out.push((q, warm));
        warm = s.active;
        p = q;
    }
    out
}

fn bench_shape<const C: usize>(c: &mut Criterion, name: &str) {
    let steps = sequence::<C>();
    let settings = Settings::default();
    let iters: Vec<usize> = steps
        .iter()
        .map(|(p, w)| solve(p, w, &settings).iterations)
        .collect();
    let cold: Vec<usize> = steps
        .iter()
        .map(|(p, _)| solve(p, &ActiveSet::EMPTY, &settings).iterations)
        .collect();
    let active: usize = steps.iter().map(|(_, w)| w.len()).sum();
    eprintln!(
        "{name}: {STEPS} steps, mean active rows {:.2}, iterations warm: mean {:.3}, max {}; \
         cold: mean {:.2}, max {}",
        active as f64 / STEPS as f64,
        iters.iter().sum::<usize>() as f64 / STEPS as f64,
        iters.iter().max().unwrap_or(&0),
        cold.iter().sum::<usize>() as f64 / STEPS as f64,
        cold.iter().max().unwrap_or(&0)
    );
    let data: Vec<ClarabelData> = steps.iter().map(|(p, _)| clarabel_data(p)).collect();
    let mut g = c.benchmark_group(name);
    let mut k = 0;
    g.bench_function("trocar/warm", |b| {
        b.iter(|| {
            k = (k + 1) % STEPS;
            let (p, w) = &steps[k];
            solve(black_box(p), black_box(w), &settings)
        })
    });
    g.bench_function("trocar/cold", |b| {
        b.iter(|| {
            k = (k + 1) % STEPS;
            solve(black_box(&steps[k].0), &ActiveSet::EMPTY, &settings)
        })
    });
    g.bench_function("clarabel", |b| {
        b.iter(|| {
            k = (k + 1) % STEPS;
            clarabel_solve(black_box(&data[k]), clarabel_settings(false))
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench_shape::<1>(c, "qp7x2x16");
    bench_shape::<2>(c, "qp7x2x18_c2");
}

criterion_group! {
    name = qp;
    config = Criterion::default().sample_size(60).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(3));
    targets = benches
}
criterion_main!(qp);
