//! Cost of one step of the scene `three-ports` (three Pandas, 21 joints, three couplings): each
//! arm's own QP step, the scene's QP over the 21 rates and its check of the distances over the
//! step (S5), warm-started as in the run. Timed at states of the run where the couplings act
//! (1.6 s: they are active from 1.3 s) and where none is near (0.2 s, the scene's QP not
//! solved), each from the controllers' and the scene's state at that step.

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};
use trocar::nalgebra::SVector;
use trocar_sim::scene::{ThreePorts, DT};

/// The scene and the joints at step `at`, reached by running the scene there.
fn at(at: usize) -> (ThreePorts, [SVector<f64, 7>; 3]) {
    let mut setup = ThreePorts::new(true).unwrap();
    let mut q = setup.q0;
    for step in 0..at {
        let o = setup.step(&q, step as f64 * DT).unwrap();
        for (qk, qd) in q.iter_mut().zip(o.qd) {
            *qk += qd * DT;
        }
    }
    (setup, q)
}

fn bench(c: &mut Criterion) {
    for (name, step) in [("coupled", 800usize), ("apart", 100)] {
        let (setup, q) = at(step);
        let t = step as f64 * DT;
        let active = setup.clone().step(&q, t).unwrap().coupling_active;
        assert_eq!(
            active,
            name == "coupled",
            "{name}: couplings active {active}"
        );
        c.bench_function(&format!("scene_step_three_ports_{name}"), |b| {
            b.iter_batched(
                || setup.clone(),
                |mut s| black_box(s.step(black_box(&q), t).unwrap()),
                BatchSize::SmallInput,
            )
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
