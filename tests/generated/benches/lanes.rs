//! Batch evaluation on lane types: the Panda's pose of `panda_link7` and its body Jacobian (the
//! fused `link_pose_and_jacobian` from `q`; BENCHMARKS.md, "Batch evaluation on SIMD lanes")
//! for `BATCH` configurations, in one criterion group whose ratios are read from one run
//! (throughput: one element is one configuration).
//!
//! - `scalar/f64`, `scalar/f32`: the generated code on one configuration at a time;
//! - `lanes/f64x4`, `lanes/f32x8`: the same code on `trocar::emitted::lanes::F64x4` / `F32x8`, inputs
//!   already in lanes and the results left in lanes (the kernel);
//! - `for_each/f64x4`, `for_each/f32x8`: `trocar::emitted::lanes::for_each_*` from a slice of
//!   configurations to one scalar result per configuration (the lanes gathered and scattered);
//! - `own/f64x4`, `own/f32x8`: the kernel on a lane type of plain arrays (`[f64; 4]` with every
//!   operation written lane by lane for the compiler to vectorise), the alternative to `wide`;
//! - `trig/*`: the joints' sines and cosines alone (`JointTrig::new`), scalar and on lanes: the
//!   part of the evaluation that the scalar code already computes on SIMD lanes (its seven
//!   joints side by side), so that batching configurations cannot make it cheaper per element.
//!
//! Before timing, every lane result is checked bit for bit against the scalar code, so a run
//! under other flags (`-C target-cpu=native`: FMA) checks that too. Inputs pass through
//! `black_box`, outputs are written to a buffer whose address goes through `black_box`.

use core::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use trocar::emitted::fast;
use trocar::emitted::lanes::{for_each_f32x8, for_each_f64x4, F32x8, F64x4, Lanes};
use trocar::{Arith, Real};
use trocar_tests_generated::panda_laparoscope as m;

/// Configurations per iteration (a multiple of 8).
const BATCH: usize = 64;

/// Deterministic joint values in about [-2.5, 2.5] rad (a small LCG).
fn configs() -> Vec<[f64; m::N]> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    (0..BATCH)
        .map(|_| {
            core::array::from_fn(|_| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                #[allow(clippy::cast_precision_loss)]
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                5.0 * u - 2.5
            })
        })
        .collect()
}

type Out<T> = (([[T; 3]; 3], [T; 3]), [[T; 6]; m::I]);

#[inline(always)]
fn pose_and_jb<T: Arith>(q: &[T; m::N], p: &m::Params<T>) -> Out<T> {
    let mut o = (([[T::ZERO; 3]; 3], [T::ZERO; 3]), [[T::ZERO; 6]; m::I]);
    m::link_pose_and_jacobian(q, p, &mut o.0, &mut o.1);
    o
}

/// A lane type of plain arrays, every operation lane by lane (what the compiler vectorises by
/// itself), with the same `sin_cos` kernels as `trocar::emitted::lanes`.
macro_rules! own_lanes {
    ($name:ident, $s:ty, $w:literal, $kernel:path) => {
        #[derive(Clone, Copy, Debug, Default)]
        #[repr(C, align(32))]
        struct $name([$s; $w]);

        impl $name {
            #[inline(always)]
            fn zip(self, b: Self, f: impl Fn($s, $s) -> $s) -> Self {
                Self(core::array::from_fn(|k| f(self.0[k], b.0[k])))
            }
        }
        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, b: Self) -> Self {
                self.zip(b, |x, y| x + y)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, b: Self) -> Self {
                self.zip(b, |x, y| x - y)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, b: Self) -> Self {
                self.zip(b, |x, y| x * y)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, b: Self) -> Self {
                self.zip(b, |x, y| x / y)
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Self(self.0.map(|x| -x))
            }
        }
        impl AddAssign for $name {
            #[inline(always)]
            fn add_assign(&mut self, b: Self) {
                *self = *self + b;
            }
        }
        impl SubAssign for $name {
            #[inline(always)]
            fn sub_assign(&mut self, b: Self) {
                *self = *self - b;
            }
        }
        impl MulAssign for $name {
            #[inline(always)]
            fn mul_assign(&mut self, b: Self) {
                *self = *self * b;
            }
        }
        impl Arith for $name {
            const ZERO: Self = Self([0.0; $w]);
            const ONE: Self = Self([1.0; $w]);
            #[inline(always)]
            fn lit(x: f64) -> Self {
                Self([<$s as Real>::lit(x); $w])
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                let (s, c) = $kernel(&self.0);
                (Self(s), Self(c))
            }
            #[inline(always)]
            fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
                let mut s = [Self::ZERO; N];
                let mut c = [Self::ONE; N];
                for k in 0..N {
                    (s[k], c[k]) = x[k].sin_cos();
                }
                (s, c)
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                Self(core::array::from_fn(|k| {
                    <$s as Real>::mul_add(self.0[k], a.0[k], b.0[k])
                }))
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                Self(self.0.map(<$s as Real>::sqrt))
            }
            #[inline(always)]
            fn abs(self) -> Self {
                Self(self.0.map(<$s as Real>::abs))
            }
        }
        impl Lanes for $name {
            type Lane = $s;
            const LANES: usize = $w;
            fn lane(&self, k: usize) -> $s {
                self.0[k]
            }
            fn zeroed() -> Self {
                Self::ZERO
            }
        }
    };
}

own_lanes!(Own64, f64, 4, fast::sin_cos_f64_lanes::<4>);
own_lanes!(Own32, f32, 8, fast::sin_cos_f32_lanes::<8>);

/// The lanes of `configs` in groups of `W` (`gather(group)` of each).
fn groups<L, S: Copy, const W: usize>(
    configs: &[[S; m::N]],
    gather: impl Fn(&[[S; m::N]; W]) -> [L; m::N],
) -> Vec<[L; m::N]> {
    configs
        .chunks_exact(W)
        .map(|c| gather(&core::array::from_fn(|k| c[k])))
        .collect()
}

/// Every lane of `lanes` (results of the groups in order) equal bit for bit to `scalar`.
fn assert_lanes<L: Lanes>(lanes: &[L], scalar: &[L::Lane], what: &str)
where
    L::Lane: core::fmt::Debug,
{
    let w = L::LANES;
    for (i, s) in scalar.iter().enumerate() {
        let l = lanes[i / w].lane(i % w);
        assert_eq!(
            format!("{l:?}"),
            format!("{s:?}"),
            "{what}: configuration {i}"
        );
    }
}

fn lanes(c: &mut Criterion) {
    let qs = configs();
    let qs32: Vec<[f32; m::N]> = qs.iter().map(|q| q.map(|x| x as f32)).collect();
    let (p, p32) = (m::Params::<f64>::nominal(), m::Params::<f32>::nominal());
    let (pl, pl32) = (m::Params::<F64x4>::nominal(), m::Params::<F32x8>::nominal());
    let (po, po32) = (m::Params::<Own64>::nominal(), m::Params::<Own32>::nominal());
    let q4 = groups::<F64x4, f64, 4>(&qs, F64x4::gather);
    let q8 = groups::<F32x8, f32, 8>(&qs32, F32x8::gather);
    let qo4 = groups::<Own64, f64, 4>(&qs, |g| {
        core::array::from_fn(|j| Own64(core::array::from_fn(|k| g[k][j])))
    });
    let qo8 = groups::<Own32, f32, 8>(&qs32, |g| {
        core::array::from_fn(|j| Own32(core::array::from_fn(|k| g[k][j])))
    });

    let mut out: Vec<Out<f64>> = qs.iter().map(|q| pose_and_jb(q, &p)).collect();
    let mut out32: Vec<Out<f32>> = qs32.iter().map(|q| pose_and_jb(q, &p32)).collect();
    let mut out4: Vec<Out<F64x4>> = q4.iter().map(|q| pose_and_jb(q, &pl)).collect();
    let mut out8: Vec<Out<F32x8>> = q8.iter().map(|q| pose_and_jb(q, &pl32)).collect();
    let mut outo4: Vec<Out<Own64>> = qo4.iter().map(|q| pose_and_jb(q, &po)).collect();
    let mut outo8: Vec<Out<Own32>> = qo8.iter().map(|q| pose_and_jb(q, &po32)).collect();
    // Checked once here, under this build's flags.
    assert_lanes(&out4, &out, "f64x4");
    assert_lanes(&out8, &out32, "f32x8");
    assert_lanes(&outo4, &out, "own f64x4");
    assert_lanes(&outo8, &out32, "own f32x8");
    let mut each = out.clone();
    for_each_f64x4(
        &qs,
        |q, o: &mut Out<F64x4>| m::link_pose_and_jacobian(q, &pl, &mut o.0, &mut o.1),
        &mut each,
    );
    assert_eq!(format!("{each:?}"), format!("{out:?}"));

    let mut g = c.benchmark_group("lanes/panda_pose_jb");
    g.throughput(Throughput::Elements(BATCH as u64));
    macro_rules! run {
        ($name:literal, $inputs:expr, $outs:expr, $p:expr) => {
            g.bench_function($name, |b| {
                b.iter(|| {
                    for (q, o) in black_box(&$inputs).iter().zip($outs.iter_mut()) {
                        m::link_pose_and_jacobian(q, $p, &mut o.0, &mut o.1);
                    }
                    black_box(&mut $outs);
                })
            });
        };
    }
    run!("scalar/f64", qs, out, &p);
    run!("lanes/f64x4", q4, out4, &pl);
    run!("own/f64x4", qo4, outo4, &po);
    run!("scalar/f32", qs32, out32, &p32);
    run!("lanes/f32x8", q8, out8, &pl32);
    run!("own/f32x8", qo8, outo8, &po32);
    // The Panda's ready pose, a joint at π/2 in every configuration: the sines and cosines'
    // rare path (the careful reduction) in every group.
    let ready = [
        0.0,
        -FRAC_PI_4,
        0.0,
        -3.0 * FRAC_PI_4,
        0.0,
        FRAC_PI_2,
        FRAC_PI_4,
    ];
    let rs = vec![ready; BATCH];
    let rs32: Vec<[f32; m::N]> = rs.iter().map(|q| q.map(|x| x as f32)).collect();
    let r4 = groups::<F64x4, f64, 4>(&rs, F64x4::gather);
    let r8 = groups::<F32x8, f32, 8>(&rs32, F32x8::gather);
    let mut rout: Vec<Out<f64>> = rs.iter().map(|q| pose_and_jb(q, &p)).collect();
    let mut rout32: Vec<Out<f32>> = rs32.iter().map(|q| pose_and_jb(q, &p32)).collect();
    let mut rout4: Vec<Out<F64x4>> = r4.iter().map(|q| pose_and_jb(q, &pl)).collect();
    let mut rout8: Vec<Out<F32x8>> = r8.iter().map(|q| pose_and_jb(q, &pl32)).collect();
    assert_lanes(&rout4, &rout, "ready f64x4");
    assert_lanes(&rout8, &rout32, "ready f32x8");
    run!("ready/scalar/f64", rs, rout, &p);
    run!("ready/lanes/f64x4", r4, rout4, &pl);
    run!("ready/scalar/f32", rs32, rout32, &p32);
    run!("ready/lanes/f32x8", r8, rout8, &pl32);
    g.bench_function("for_each/f64x4", |b| {
        b.iter(|| {
            for_each_f64x4(
                black_box(&qs),
                |q, o: &mut Out<F64x4>| m::link_pose_and_jacobian(q, &pl, &mut o.0, &mut o.1),
                &mut each,
            );
            black_box(&mut each);
        })
    });
    macro_rules! trig {
        ($name:literal, $inputs:expr) => {
            let mut touts: Vec<_> = $inputs.iter().map(m::JointTrig::new).collect();
            g.bench_function($name, |b| {
                b.iter(|| {
                    for (q, o) in black_box(&$inputs).iter().zip(touts.iter_mut()) {
                        *o = m::JointTrig::new(q);
                    }
                    black_box(&mut touts);
                })
            });
        };
    }
    trig!("trig/f64", qs);
    trig!("trig/f64x4", q4);
    trig!("trig/f32", qs32);
    trig!("trig/f32x8", q8);
    let mut each32 = out32.clone();
    for_each_f32x8(
        &qs32,
        |q, o: &mut Out<F32x8>| m::link_pose_and_jacobian(q, &pl32, &mut o.0, &mut o.1),
        &mut each32,
    );
    assert_eq!(format!("{each32:?}"), format!("{out32:?}"));
    g.bench_function("for_each/f32x8", |b| {
        b.iter(|| {
            for_each_f32x8(
                black_box(&qs32),
                |q, o: &mut Out<F32x8>| m::link_pose_and_jacobian(q, &pl32, &mut o.0, &mut o.1),
                &mut each32,
            );
            black_box(&mut each32);
        })
    });
    g.finish();
}

criterion_group!(benches, lanes);
criterion_main!(benches);
