//! What the slowest steps of the scene `three-ports` solved: ten runs of its 4 s (2·10⁴ steps) on
//! the Panda laparoscope's generated kinematics, each step timed as the least of five runs from
//! the same state (as `cargo bench --bench scene_step` times `own`), with the iterations of each
//! QP the scene's step solved (0: answered in the range space; a second QP: the distances'
//! correction (S5)) and of each arm's own QP step. Prints the median, p99 and p99.9, the 60
//! slowest steps, and the steps grouped by what they solved.
//!
//! ```text
//! cargo run --release -p trocar-tests-generated --example scene_tail
//! ```
use std::time::Instant;
use trocar::qp::{ActiveSet, Problem, Solution};
use trocar_sim::scene::{ThreePorts, DT, DURATION};
use trocar_tests_generated::control::PandaLaparoscope;

fn main() {
    let generated = [PandaLaparoscope::<f64>::nominal(); 3];
    let steps = (DURATION / DT).round() as usize;
    let mut rows = Vec::new();
    for round in 0..10 {
        let mut setup = ThreePorts::new(true).unwrap();
        let mut q = setup.q0;
        for step in 0..steps {
            let t = step as f64 * DT;
            let references = setup.references(&q, t).unwrap();
            let before = setup.clone();
            let mut least = u64::MAX;
            let mut info = (0usize, Vec::new(), [0usize; 3], [false; 3]);
            let mut out = None;
            for _ in 0..5 {
                let mut s = before.clone();
                let mut qps = Vec::new();
                let start = Instant::now();
                let o = s
                    .scene
                    .step_observed::<_, 3, 7, 7, 2, 4, 4, 4, 6, _>(
                        &mut s.arms,
                        std::hint::black_box(&generated),
                        &q,
                        &references,
                        &s.rcms,
                        &s.bases,
                        &[],
                        DT,
                        |_: &Problem<f64, 21, 6, 6>,
                         _: &ActiveSet<21, 6>,
                         sol: &Solution<f64, 21, 6, 6>| {
                            qps.push(sol.iterations)
                        },
                    )
                    .unwrap();
                let e = start.elapsed().as_nanos() as u64;
                if e < least {
                    least = e;
                    let arm_iters =
                        std::array::from_fn(|k| o.arms[k].qp.map_or(0, |r| r.iterations));
                    let resolved =
                        std::array::from_fn(|k| o.arms[k].qp.is_some_and(|r| r.resolved));
                    info = (qps.len(), qps, arm_iters, resolved);
                }
                setup = s;
                out = Some(o);
            }
            let out = out.unwrap();
            rows.push((least, round, step, out.coupling_active, info));
            for (qk, qd) in q.iter_mut().zip(&out.qd) {
                *qk += qd * DT;
            }
        }
    }
    let mut times: Vec<u64> = rows.iter().map(|r| r.0).collect();
    times.sort_unstable();
    // The percentiles as `cargo bench --bench scene_step` takes them (the nearest rank).
    let at = |p: f64| times[((times.len() - 1) as f64 * p).round() as usize];
    println!(
        "median {} p99 {} p99.9 {} (the next rank up {})",
        at(0.5),
        at(0.99),
        at(0.999),
        times[((times.len() - 1) as f64 * 0.999).round() as usize + 1]
    );
    rows.sort_by_key(|r| std::cmp::Reverse(r.0));
    for r in rows.iter().take(60) {
        println!(
            "{:>7} round {} step {:>4} active {} qps {:?} arms {:?} resolved {:?}",
            r.0, r.1, r.2, r.3, r.4 .1, r.4 .2, r.4 .3
        );
    }
    // The typical: histogram of scene-QP counts and arm iterations among all.
    let mut by_kind = std::collections::BTreeMap::new();
    for r in &rows {
        let key = (r.4 .0, r.4 .2.iter().sum::<usize>());
        by_kind.entry(key).or_insert_with(Vec::new).push(r.0);
    }
    for (k, mut v) in by_kind {
        v.sort_unstable();
        println!(
            "scene qps {} arm iterations {:>2}: {:>5} steps, median {:>6}, max {:>6}",
            k.0,
            k.1,
            v.len(),
            v[v.len() / 2],
            v[v.len() - 1]
        );
    }
}
