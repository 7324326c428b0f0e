//! One LU for the core: the core's `trocar::linalg::Lu` (nalgebra's fixed-size `LU`, its determinant kept,
//! solutions checked finite) against nalgebra's `LU` called directly, for the sizes a control step
//! factors (4×4, 6×6; f64): determinant, and determinant plus one solve. The two should agree to
//! within noise: the wrapper costs nothing.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::linalg::Lu;
use trocar::nalgebra::{Const, DimMin, SMatrix, SVector};

fn matrix<const D: usize>() -> SMatrix<f64, D, D> {
    SMatrix::from_fn(|r, c| ((r * 7 + c * 3) % 11) as f64 * 0.1 + if r == c { 1.5 } else { 0.0 })
}

fn bench_size<const D: usize>(c: &mut Criterion)
where
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    let m = matrix::<D>();
    let b = SVector::<f64, D>::from_fn(|r, _| r as f64 + 0.5);
    let mut g = c.benchmark_group(format!("lu{D}x{D}"));
    g.bench_function("core/det", |bch| {
        bch.iter(|| Lu::new(&black_box(m)).determinant())
    });
    g.bench_function("nalgebra/det", |bch| {
        bch.iter(|| black_box(m).lu().determinant())
    });
    g.bench_function("core/det+solve", |bch| {
        bch.iter(|| {
            let lu = Lu::new(&black_box(m));
            (lu.determinant(), lu.solve(&black_box(b)))
        })
    });
    g.bench_function("nalgebra/det+solve", |bch| {
        bch.iter(|| {
            let lu = black_box(m).lu();
            (lu.determinant(), lu.solve(&black_box(b)))
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench_size::<4>(c);
    bench_size::<6>(c);
}

criterion_group! {
    name = lu;
    config = Criterion::default().sample_size(60).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = benches
}
criterion_main!(lu);
