//! One LU for the core: nalgebra's fixed-size `LU` against the hand-written partial-pivoting
//! elimination the core used before (kept here, verbatim in substance, as the baseline), for the
//! sizes a control step factors (4×4, 6×6; f64): determinant, and determinant plus one solve.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::nalgebra::{Const, DimMin, SMatrix, SVector};

/// The former hand-written LU: factors in place, returns `det`, records pivots.
fn hand_lu<const D: usize>(a: &mut SMatrix<f64, D, D>, piv: &mut [usize; D]) -> f64 {
    let a = a.as_mut_slice();
    let n = D;
    let mut det = 1.0;
    for c in 0..n {
        let mut best = c;
        for r in c + 1..n {
            if a[c * n + r].abs() > a[c * n + best].abs() {
                best = r;
            }
        }
        let p = a[c * n + best];
        if p == 0.0 {
            return 0.0;
        }
        piv[c] = best;
        if best != c {
            for k in 0..n {
                a.swap(k * n + c, k * n + best);
            }
            det = -det;
        }
        det *= p;
        for r in c + 1..n {
            a[c * n + r] /= p;
        }
        for k in c + 1..n {
            let v = a[k * n + c];
            if v != 0.0 {
                for r in c + 1..n {
                    let l = a[c * n + r];
                    a[k * n + r] -= l * v;
                }
            }
        }
    }
    det
}

fn hand_solve<const D: usize>(
    f: &SMatrix<f64, D, D>,
    piv: &[usize; D],
    b: &SVector<f64, D>,
) -> SVector<f64, D> {
    let a = f.as_slice();
    let mut x = *b;
    for (c, &r) in piv.iter().enumerate() {
        x.swap_rows(c, r);
    }
    for c in 0..D {
        let xc = x[c];
        for r in c + 1..D {
            x[r] -= a[c * D + r] * xc;
        }
    }
    for c in (0..D).rev() {
        x[c] /= a[c * D + c];
        let xc = x[c];
        for r in 0..c {
            x[r] -= a[c * D + r] * xc;
        }
    }
    x
}

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
    g.bench_function("hand/det", |bch| {
        bch.iter(|| {
            let mut a = black_box(m);
            let mut p = [0; D];
            hand_lu(&mut a, &mut p)
        })
    });
    g.bench_function("nalgebra/det", |bch| {
        bch.iter(|| black_box(m).lu().determinant())
    });
    g.bench_function("hand/det+solve", |bch| {
        bch.iter(|| {
            let mut a = black_box(m);
            let mut p = [0; D];
            let d = hand_lu(&mut a, &mut p);
            (d, hand_solve(&a, &p, &black_box(b)))
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
