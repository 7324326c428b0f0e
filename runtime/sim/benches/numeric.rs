//! Numeric reference timings: the constrained Jacobian J^r (3.15) of each preset and the body
//! Jacobian J^B_0e of `dia10_like`, on the allocation-free typed API (and, for comparison, the
//! dynamic `NumericRobot` front end used by the CLI and verification).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::constraint::Constraint;
use trocar::kinematics::Chain;
use trocar::linalg::SquareDim;
use trocar::nalgebra::{Const, SMatrix, SVector};
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

const Q0: [f64; 8] = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];

fn robot(name: &str) -> NumericRobot<f64> {
    NumericRobot::from_description(&RobotDescription::preset(name).unwrap(), &[]).unwrap()
}

fn bench_jr<const R: usize, const M: usize>(c: &mut Criterion, name: &str)
where
    Const<R>: SquareDim,
{
    let robot = robot(name);
    let chain: Chain<f64, 8> = robot.to_chain().unwrap();
    let mut constraint: Constraint<f64, R> = robot.to_constraint().unwrap();
    let q = SVector::<f64, 8>::from(Q0);
    c.bench_function(&format!("jr/{name}/f64"), |b| {
        b.iter(|| -> SMatrix<f64, 6, M> {
            constraint.constrained_jacobian(black_box(&chain), black_box(&q))
        })
    });
    c.bench_function(&format!("jr+set_offset/{name}/f64"), |b| {
        b.iter(|| -> SMatrix<f64, 6, M> {
            constraint.set_offset(black_box(0.15)).unwrap();
            constraint.constrained_jacobian(black_box(&chain), black_box(&q))
        })
    });
    let chain32 = Chain::<f32, 8>::from_f64(&chain);
    let robot32 = NumericRobot::<f32>::from_description(robot.description(), &[]).unwrap();
    let constraint32: Constraint<f32, R> = robot32.to_constraint().unwrap();
    let q32 = q.map(|x| x as f32);
    c.bench_function(&format!("jr/{name}/f32"), |b| {
        b.iter(|| -> SMatrix<f32, 6, M> {
            constraint32.constrained_jacobian(black_box(&chain32), black_box(&q32))
        })
    });
    c.bench_function(&format!("jr/{name}/dynamic Robot"), |b| {
        b.iter(|| robot.constrained_jacobian(black_box(&Q0)).unwrap())
    });
}

fn numeric(c: &mut Criterion) {
    bench_jr::<1, 7>(c, "unidirectional");
    bench_jr::<2, 6>(c, "bidirectional-zy");
    bench_jr::<2, 6>(c, "bidirectional-zx");
    bench_jr::<2, 6>(c, "dia10_like_zy");
    let robot = robot("dia10_like_zy");
    let chain: Chain<f64, 8> = robot.to_chain().unwrap();
    let q = SVector::<f64, 8>::from(Q0);
    c.bench_function("jb0e/dia10_like/f64", |b| {
        b.iter(|| chain.body_jacobian(black_box(&q)))
    });
    let chain32 = Chain::<f32, 8>::from_f64(&chain);
    let q32 = q.map(|x| x as f32);
    c.bench_function("jb0e/dia10_like/f32", |b| {
        b.iter(|| chain32.body_jacobian(black_box(&q32)))
    });
    c.bench_function("jb0e/dia10_like/dynamic Robot", |b| {
        b.iter(|| robot.body_jacobian(black_box(&Q0)).unwrap())
    });
    c.bench_function("fk/dia10_like/f64", |b| {
        b.iter(|| chain.forward_kinematics(black_box(&q)))
    });
}

criterion_group!(benches, numeric);
criterion_main!(benches);
