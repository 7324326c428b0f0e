//! Generated closed-form code against the numeric runtime, in one run (issue 3, "What must be
//! shown", last bullet): the constrained Jacobian J^r (3.15) of every preset, and for
//! `dia10_like_zy` the full set a controller needs per step (g_0e (2.21), J^B_0i (3.13), J^r).
//!
//! Per preset, one criterion group `jr/<preset>` with
//! - `numeric/f64`, `numeric/f32`: `Constraint::constrained_jacobian` on the allocation-free typed
//!   `Chain<T, N>` (nalgebra fixed-size matrices);
//! - `generated/f64`, `generated/f32`: the emitted generic `constrained_jacobian(&q, &p)` (its own
//!   `sin_cos` per joint included);
//! - `generated_trig/f64`, `generated_trig/f32`: `constrained_jacobian_trig(&trig, &p)` given a
//!   precomputed `JointTrig` (what a controller that shares one `JointTrig` per step pays per
//!   extra function).
//!
//! Every iteration takes the next of `CONFIGS` configurations (cycled by an index that goes
//! through `black_box`), and inputs and outputs pass through `black_box`, so nothing is
//! constant-folded or hoisted out of the loop. The cycling costs the same in every variant.
//!
//! `floor/write_6x6_f64` writes a dense `6 × 6` result of one multiplication per entry in the
//! same harness: the floor under any given-trig `J^r`.
//!
//! Ratios (numeric / generated) are computed from the medians of one run; see `BENCHMARKS.md`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::constraint::Constraint;
use trocar::kinematics::Chain;
use trocar::nalgebra::SVector;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_tests_generated as g;

/// Number of configurations cycled through (a power of two: the index is masked).
const CONFIGS: usize = 16;

/// Deterministic, well spread joint values in about [-1.5, 1.5] rad (a small LCG, no `rand`).
fn configs<const N: usize>() -> [[f64; N]; CONFIGS] {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    core::array::from_fn(|_| {
        core::array::from_fn(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            #[allow(clippy::cast_precision_loss)]
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            3.0 * u - 1.5
        })
    })
}

fn robot<T: trocar::nalgebra::RealField + Copy>(name: &str) -> NumericModel<T> {
    NumericModel::<T>::from_description(&RobotDescription::preset(name).unwrap(), &[]).unwrap()
}

/// Next index in `0..CONFIGS`, opaque to the optimiser.
#[inline(always)]
fn next(k: &mut usize) -> usize {
    *k = black_box(*k + 1) & (CONFIGS - 1);
    *k
}

macro_rules! bench_jr {
    ($c:expr, $m:ident, $preset:literal) => {{
        use g::$m as m;
        let mut group = $c.benchmark_group(concat!("jr/", $preset));
        let qs: [[f64; m::N]; CONFIGS] = configs();
        let qs32: [[f32; m::N]; CONFIGS] = qs.map(|q| q.map(|x| x as f32));

        // Numeric runtime (typed, allocation-free).
        let r64 = robot::<f64>($preset);
        let chain: Chain<f64, { m::N }> = r64.to_chain().unwrap();
        let constraint: Constraint<f64, { m::R }> = r64.to_constraint().unwrap();
        let nq: [SVector<f64, { m::N }>; CONFIGS] = qs.map(SVector::from);
        let r32 = robot::<f32>($preset);
        let chain32: Chain<f32, { m::N }> = r32.to_chain().unwrap();
        let constraint32: Constraint<f32, { m::R }> = r32.to_constraint().unwrap();
        let nq32: [SVector<f32, { m::N }>; CONFIGS] = qs32.map(SVector::from);

        // Generated.
        let p = m::Params::<f64>::nominal();
        let p32 = m::Params::<f32>::nominal();
        let trig: [m::JointTrig<f64>; CONFIGS] = qs.map(|q| m::JointTrig::new(&q));
        let trig32: [m::JointTrig<f32>; CONFIGS] = qs32.map(|q| m::JointTrig::new(&q));

        let mut k = 0;
        group.bench_function("numeric/f64", |b| {
            b.iter(|| {
                let q = &nq[next(&mut k)];
                black_box(
                    constraint.constrained_jacobian::<{ m::N }, { m::M }>(
                        black_box(&chain),
                        black_box(q),
                    ),
                )
            })
        });
        group.bench_function("generated/f64", |b| {
            b.iter(|| {
                let q = &qs[next(&mut k)];
                black_box(m::constrained_jacobian(black_box(q), black_box(&p)))
            })
        });
        group.bench_function("generated_trig/f64", |b| {
            b.iter(|| {
                let t = &trig[next(&mut k)];
                black_box(m::constrained_jacobian_trig(black_box(t), black_box(&p)))
            })
        });
        group.bench_function("numeric/f32", |b| {
            b.iter(|| {
                let q = &nq32[next(&mut k)];
                black_box(
                    constraint32.constrained_jacobian::<{ m::N }, { m::M }>(
                        black_box(&chain32),
                        black_box(q),
                    ),
                )
            })
        });
        group.bench_function("generated/f32", |b| {
            b.iter(|| {
                let q = &qs32[next(&mut k)];
                black_box(m::constrained_jacobian(black_box(q), black_box(&p32)))
            })
        });
        group.bench_function("generated_trig/f32", |b| {
            b.iter(|| {
                let t = &trig32[next(&mut k)];
                black_box(m::constrained_jacobian_trig(black_box(t), black_box(&p32)))
            })
        });
        group.finish();
    }};
}

fn constrained_jacobian(c: &mut Criterion) {
    bench_jr!(c, unidirectional, "unidirectional");
    bench_jr!(c, bidirectional_zy, "bidirectional-zy");
    bench_jr!(c, bidirectional_zx, "bidirectional-zx");
    bench_jr!(c, dia10_like_zy, "dia10_like_zy");
    bench_jr!(c, dia10_like_zx, "dia10_like_zx");
}

/// The full set per control step for `dia10_like_zy`: g_0e, J^B_0i and J^r.
fn full_set(c: &mut Criterion) {
    use g::dia10_like_zy as m;
    let mut group = c.benchmark_group("full/dia10_like_zy");
    let qs: [[f64; m::N]; CONFIGS] = configs();
    let r64 = robot::<f64>("dia10_like_zy");
    let chain: Chain<f64, { m::N }> = r64.to_chain().unwrap();
    let constraint: Constraint<f64, { m::R }> = r64.to_constraint().unwrap();
    let nq: [SVector<f64, { m::N }>; CONFIGS] = qs.map(SVector::from);
    let p = m::Params::<f64>::nominal();
    let trig: [m::JointTrig<f64>; CONFIGS] = qs.map(|q| m::JointTrig::new(&q));

    let mut k = 0;
    group.bench_function("numeric/f64", |b| {
        b.iter(|| {
            let q = black_box(&nq[next(&mut k)]);
            let chain = black_box(&chain);
            let g0e = chain.forward_kinematics(q);
            let jb0i = chain.partial_body_jacobian::<{ m::I }>(q);
            let jr = constraint.constrained_jacobian::<{ m::N }, { m::M }>(chain, q);
            black_box((g0e, jb0i, jr))
        })
    });
    group.bench_function("generated/f64", |b| {
        b.iter(|| {
            let q = black_box(&qs[next(&mut k)]);
            let p = black_box(&p);
            let t = m::JointTrig::new(q);
            let g0e = m::forward_kinematics_trig(&t, p);
            let jb0i = m::partial_body_jacobian_trig(&t, p);
            let jr = m::constrained_jacobian_trig(&t, p);
            black_box((g0e, jb0i, jr))
        })
    });
    group.bench_function("generated_trig/f64", |b| {
        b.iter(|| {
            let t = black_box(&trig[next(&mut k)]);
            let p = black_box(&p);
            let g0e = m::forward_kinematics_trig(t, p);
            let jb0i = m::partial_body_jacobian_trig(t, p);
            let jr = m::constrained_jacobian_trig(t, p);
            black_box((g0e, jb0i, jr))
        })
    });
    group.finish();
}

/// The floor under any dense `6 × 6` result in this harness: the same cycling and `black_box`
/// as `generated_trig/f64`, and a result whose 36 entries are each one multiplication of two
/// `JointTrig` values (no division, no shared subexpression). What a given-trig `J^r` costs
/// above this is its arithmetic.
fn store_floor(c: &mut Criterion) {
    use g::bidirectional_zy as m;
    let qs: [[f64; m::N]; CONFIGS] = configs();
    let trig: [m::JointTrig<f64>; CONFIGS] = qs.map(|q| m::JointTrig::new(&q));
    let mut k = 0;
    c.bench_function("floor/write_6x6_f64", |b| {
        b.iter(|| {
            let t = black_box(&trig[next(&mut k)]);
            let out: [[f64; 6]; 6] = core::array::from_fn(|col| {
                core::array::from_fn(|row| t.sin[(col + row) % 8] * t.cos[(3 * col + row) % 8])
            });
            black_box(out)
        })
    });
}

criterion_group!(benches, constrained_jacobian, full_set, store_floor);
criterion_main!(benches);
