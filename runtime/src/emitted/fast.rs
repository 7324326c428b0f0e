//! Fast, accurate `(sin x, cos x)`, with or without `std`: what [`Real::sin_cos`](super::Real::sin_cos) (the generated
//! code's trigonometry) uses.
//!
//! Both functions: `|x| ≤ π/4` goes straight to the kernels; otherwise a one-step Cody–Waite
//! reduction `x = n·π/2 + (y0 + y1)` (`n·P1` exact) whose cancellation test sends the rare
//! arguments near a multiple of π/2 to a careful reduction (π/2 in four parts, remainder as a
//! double-word by TwoSum); then **both** kernels (sharing `r²`), a branch-free quadrant select,
//! and the sign of `x` (`sin(−0) = −0`). Inline; the rare paths are `#[cold]`.
//!
//! - `f64`: fdlibm/musl minimax kernels (`|sin r/r − P| < 2⁻⁵⁸`, `|cos r − Q| < 2⁻⁵⁸`) with the
//!   tail `lo` folded in; musl's one-step reduction (`P1` of 33 bits) with its cancellation test,
//!   and a careful four-part TwoSum reduction for the rare arguments that cancel. Fast path
//!   `|x| ≤ 2²⁰`; beyond it, NaN and ±∞ go to [`libm`] (Payne–Hanek; NaN for NaN/±∞). Error:
//!   **at most 1 ulp from glibc's correctly-rounded-in-practice `sin`/`cos`** (tested over
//!   2·10⁷ random arguments up to 2²⁰, grids, neighbours of n·π/2 and every exponent; 3 % of
//!   results differ from glibc, all by exactly 1 ulp), i.e. < 2 ulp from the exact value by test;
//!   musl documents < 1 ulp for the same kernels and reduction.
//! - `f32`: pure single-precision arithmetic (so it stays fast on an FPU without `f64`, e.g.
//!   Cortex-M4F), Cephes minimax kernels with the reduction tail, `P1` of 12 bits (careful path:
//!   π/2 in 12+12+12+24 bits); fast path `|x| ≤ 4096`, beyond it [`libm`]'s `sinf`/`cosf`.
//!   Error: **< 1 ulp and ≤ 6e-8 absolute** — checked exhaustively on every `f32` in
//!   `[-4096, 4096]` against the exact value (max 0.849 ulp, 5.06e-8 absolute).
//!
//! `sin(−0) = −0`, `cos(±0) = 1`, NaN for NaN and ±∞. [`Real::sin_cos`](super::Real::sin_cos)
//! uses these functions with the `std` feature too: faster than std's (glibc's) `sin_cos` (see
//! BENCHMARKS.md), for at most 1 ulp of difference (`f64`). The numeric runtime (`nalgebra`'s
//! `RealField`) keeps std's.
// The kernels' coefficients are the published fdlibm/musl and Cephes minimax values, written to
// the digits of their sources so they can be checked against them; 2/π stays a literal beside
// its split parts for the same reason. `!(|x| <= LIMIT)` is meant: it sends NaN to the slow path.
#![allow(
    clippy::excessive_precision,
    clippy::approx_constant,
    clippy::neg_cmp_op_on_partial_ord
)]

use core::ops::{Add, Mul, Sub};

#[inline(always)]
fn two_sum64<T: Ops>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

#[inline(always)]
fn two_sum32(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `|x|` above which [`sin_cos_f64`] defers to `libm`.
pub const F64_FAST_LIMIT: f64 = 1048576.0;
/// `|x|` above which [`sin_cos_f32`] defers to `libm`.
pub const F32_FAST_LIMIT: f32 = 4096.0;

const FRAC_2_PI_64: f64 = 6.36619772367581382433e-01;
const TOINT_64: f64 = 1.5 / f64::EPSILON;
/// The sign bit of an `f64`.
const SIGN: u64 = 1 << 63;
/// The lanes' cancellation test: a reduced `|y0|` below `2⁻¹⁶ |x|` may have cancelled (it
/// holds whenever musl's exponent test of [`sin_cos_f64`] does).
const TWO_M16: f64 = 1.0 / 65536.0;

/// What the `f64` kernels and the one-step reduction are written against: `f64` itself, for
/// one argument; `sse2::Pair` (x86-64 with SSE2) and `avx2::Quad` (chosen at run time) for
/// two or four side by side in one register; `wide::f64x4` for the lane type `F64x4`. One
/// text of the arithmetic, so every path gives the same bits.
trait Ops: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    fn splat(x: f64) -> Self;
}

impl Ops for f64 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
}

/// A vector of `f64` lanes that runs [`sin_cos_f64`]'s main path on all its lanes at once
/// ([`main_path`]): `sse2::Pair`, `avx2::Quad`, `wide::f64x4`.
#[cfg(any(
    all(target_arch = "x86_64", target_feature = "sse2"),
    feature = "lanes"
))]
trait Vector: Ops {
    /// `(|x|, the sign bit of x)`.
    fn abs_and_sign(self) -> (Self, Self);
    /// Lanes where `!(self <= limit)` (NaN included) or `|y| < least`, as a bit mask.
    fn beyond_or_cancelled(self, limit: f64, y: Self, least: Self) -> i32;
    /// [`select64`] on every lane: `t`'s bits hold the quadrant, `sign` the sign of `x`.
    fn select(s: Self, c: Self, t: Self, sign: Self) -> (Self, Self);
}

/// [`sin_cos_f64`]'s main path on every lane of `x`: the one-step reduction, both kernels and
/// the select; the mask of lanes that need its rare paths instead (beyond
/// [`F64_FAST_LIMIT`], NaN, ±∞, or a reduction that may have cancelled, as in
/// [`sin_cos_f64_lanes`]).
#[cfg(any(
    all(target_arch = "x86_64", target_feature = "sse2"),
    feature = "lanes"
))]
#[inline(always)]
fn main_path<V: Vector>(x: V) -> (V, V, i32) {
    let (ax, sign) = x.abs_and_sign();
    let (y0, y1, t) = one_step64(ax);
    let slow = ax.beyond_or_cancelled(F64_FAST_LIMIT, y0, ax * V::splat(TWO_M16));
    let (s, c) = kernels64(y0, y1);
    let (s, c) = V::select(s, c, t, sign);
    (s, c, slow)
}

/// [`Ops`] and `+`, `−`, `×` for a vector type `$t(register)` from its intrinsics
/// (`sse2::Pair`, `avx2::Quad`). Used inside a module whose docs prove that the intrinsics'
/// target feature is present wherever the type is used; the intrinsics work on registers only.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
macro_rules! vector_ops {
    ($t:ident, $splat:ident, $add:ident, $sub:ident, $mul:ident) => {
        impl super::Ops for $t {
            #[inline(always)]
            fn splat(x: f64) -> Self {
                // SAFETY: the target feature is present (module docs); registers only.
                $t(unsafe { $splat(x) })
            }
        }
        impl core::ops::Add for $t {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                // SAFETY: the target feature is present (module docs); registers only.
                $t(unsafe { $add(self.0, o.0) })
            }
        }
        impl core::ops::Sub for $t {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                // SAFETY: the target feature is present (module docs); registers only.
                $t(unsafe { $sub(self.0, o.0) })
            }
        }
        impl core::ops::Mul for $t {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                // SAFETY: the target feature is present (module docs); registers only.
                $t(unsafe { $mul(self.0, o.0) })
            }
        }
    };
}
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
use vector_ops;

/// Two `f64` in one SSE2 register, for [`sin_cos_f64_lanes`] on x86-64 targets with SSE2
/// and without AVX2 (the default target; AVX without AVX2 too). There the compiler
/// vectorised the lanes' scalar paths only in part, and elementwise maps over eight lanes as
/// much as its settings (codegen units) let it; operations written on the register pair give
/// the same code under either setting, and faster (see BENCHMARKS.md, "Trigonometry on AVX2
/// and SSE2").
///
/// Every operation is one SSE2 intrinsic on registers: no memory is read or written through
/// a pointer. The intrinsics' only precondition is that the CPU has SSE2, and this module is
/// compiled only when the target enables the `sse2` feature (the hosted x86-64 targets do:
/// their ABI passes `f64` in SSE registers; a soft-float one such as `x86_64-unknown-none`
/// does not, and takes the scalar path), so each `unsafe` block below is sound.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod sse2 {
    use core::arch::x86_64::*;

    /// Lane 0 and lane 1 of an SSE2 register.
    #[derive(Clone, Copy)]
    pub(super) struct Pair(__m128d);

    use super::SIGN;

    impl Pair {
        #[inline(always)]
        pub(super) fn new(a: f64, b: f64) -> Self {
            // SAFETY: SSE2 is enabled (module cfg); registers only.
            Pair(unsafe { _mm_set_pd(b, a) })
        }

        #[inline(always)]
        pub(super) fn lanes(self) -> [f64; 2] {
            // SAFETY: SSE2 is enabled (module cfg); registers only.
            unsafe {
                [
                    _mm_cvtsd_f64(self.0),
                    _mm_cvtsd_f64(_mm_unpackhi_pd(self.0, self.0)),
                ]
            }
        }
    }

    impl super::Vector for Pair {
        #[inline(always)]
        fn abs_and_sign(self) -> (Self, Self) {
            // SAFETY: SSE2 is enabled (module cfg); registers only.
            unsafe {
                let s = _mm_set1_pd(-0.0);
                (Pair(_mm_andnot_pd(s, self.0)), Pair(_mm_and_pd(s, self.0)))
            }
        }

        #[inline(always)]
        fn beyond_or_cancelled(self, limit: f64, y: Self, least: Self) -> i32 {
            // SAFETY: SSE2 is enabled (module cfg); registers only.
            unsafe {
                let abs_y = _mm_andnot_pd(_mm_set1_pd(-0.0), y.0);
                _mm_movemask_pd(_mm_or_pd(
                    _mm_cmpnle_pd(self.0, _mm_set1_pd(limit)),
                    _mm_cmplt_pd(abs_y, least.0),
                ))
            }
        }

        #[inline(always)]
        fn select(s: Self, c: Self, t: Self, sign: Self) -> (Self, Self) {
            // SAFETY: SSE2 is enabled (module cfg); registers only.
            unsafe {
                let q = _mm_castpd_si128(t.0);
                let swap = _mm_castsi128_pd(_mm_sub_epi64(
                    _mm_setzero_si128(),
                    _mm_and_si128(q, _mm_set1_epi64x(1)),
                ));
                let sign_bit = _mm_castsi128_pd(_mm_set1_epi64x(SIGN as i64));
                let d = _mm_and_pd(_mm_xor_pd(s.0, c.0), swap);
                let flip = _mm_and_pd(_mm_castsi128_pd(_mm_slli_epi64(q, 62)), sign_bit);
                (
                    Pair(_mm_xor_pd(_mm_xor_pd(s.0, d), _mm_xor_pd(flip, sign.0))),
                    Pair(_mm_xor_pd(
                        _mm_xor_pd(c.0, d),
                        _mm_xor_pd(flip, _mm_and_pd(swap, sign_bit)),
                    )),
                )
            }
        }
    }

    super::vector_ops!(Pair, _mm_set1_pd, _mm_add_pd, _mm_sub_pd, _mm_mul_pd);
}

/// fdlibm `__kernel_sin(y0, y1, 1)` and `__kernel_cos(y0, y1)` on `|y0 + y1| ≤ π/4`:
/// `(sin, cos)` of the reduced argument.
#[inline(always)]
fn kernels64<T: Ops>(y0: T, y1: T) -> (T, T) {
    const S1: f64 = -1.66666666666666324348e-01;
    const S2: f64 = 8.33333333332248946124e-03;
    const S3: f64 = -1.98412698298579493134e-04;
    const S4: f64 = 2.75573137070700676789e-06;
    const S5: f64 = -2.50507602534068634195e-08;
    const S6: f64 = 1.58969099521155010221e-10;
    const C1: f64 = 4.16666666666666019037e-02;
    const C2: f64 = -1.38888888888741095749e-03;
    const C3: f64 = 2.48015872894767294178e-05;
    const C4: f64 = -2.75573143513906633035e-07;
    const C5: f64 = 2.08757232129817482790e-09;
    const C6: f64 = -1.13596475577881948265e-11;
    let k = T::splat;
    let z = y0 * y0;
    let w = z * z;
    let rs = k(S2) + z * (k(S3) + z * k(S4)) + z * w * (k(S5) + z * k(S6));
    let v = z * y0;
    let s = y0 - ((z * (k(0.5) * y1 - v * rs) - y1) - v * k(S1));
    let rc = z * (k(C1) + z * (k(C2) + z * k(C3))) + w * w * (k(C4) + z * (k(C5) + z * k(C6)));
    let hz = k(0.5) * z;
    let wc = k(1.0) - hz;
    let c = wc + (((k(1.0) - wc) - hz) + (z * rc - y0 * y1));
    (s, c)
}

/// The quadrant select on the kernels' `(s, c)` and the sign of `x` on the sine, on the bits:
/// quadrant bit 0 turns `(s, c)` into `(c, −s)`, bit 1 negates both.
#[inline(always)]
fn select64(s: f64, c: f64, quadrant: u64, sign: u64) -> (f64, f64) {
    let (s, c) = select_bits(s.to_bits(), c.to_bits(), quadrant, sign);
    (f64::from_bits(s), f64::from_bits(c))
}

/// The bits of one `f64` per lane: `u64` itself, and `wide::u64x4` for `F64x4`.
trait LaneBits:
    Copy
    + core::ops::BitAnd<Output = Self>
    + core::ops::BitXor<Output = Self>
    + core::ops::Shl<u64, Output = Self>
{
    fn splat(x: u64) -> Self;
    /// All ones where bit 0 is set, zero elsewhere.
    fn mask_of_bit_0(self) -> Self;
}

impl LaneBits for u64 {
    #[inline(always)]
    fn splat(x: u64) -> Self {
        x
    }
    #[inline(always)]
    fn mask_of_bit_0(self) -> Self {
        0u64.wrapping_sub(self & 1)
    }
}

#[cfg(feature = "lanes")]
impl LaneBits for wide::u64x4 {
    #[inline(always)]
    fn splat(x: u64) -> Self {
        wide::u64x4::splat(x)
    }
    #[inline(always)]
    fn mask_of_bit_0(self) -> Self {
        wide::u64x4::splat(0) - (self & wide::u64x4::splat(1))
    }
}

/// [`select64`] on the bits of `s`, `c`, the quadrant and the sign, lane by lane.
#[inline(always)]
fn select_bits<B: LaneBits>(sb: B, cb: B, quadrant: B, sign: B) -> (B, B) {
    let swap = quadrant.mask_of_bit_0();
    let d = (sb ^ cb) & swap;
    let flip = (quadrant << 62) & B::splat(SIGN);
    (
        sb ^ d ^ flip ^ sign,
        cb ^ d ^ flip ^ (swap & B::splat(SIGN)),
    )
}

/// [`kernels64`] and [`select64`]: `(sin x, cos x)` from `x = n·π/2 + (y0 + y1)` with
/// `quadrant = n mod 2⁶⁴` and `sign` the sign bit of `x`.
#[inline(always)]
fn finish64(y0: f64, y1: f64, quadrant: u64, sign: u64) -> (f64, f64) {
    let (s, c) = kernels64(y0, y1);
    select64(s, c, quadrant, sign)
}

/// The careful reduction: π/2 in four parts (three of 33 bits, `n·P_k` exact for `n < 2²⁰`),
/// remainder carried as a double-word by TwoSum. Used when the one-step reduction of
/// [`sin_cos_f64`] cancels (x within ~2⁻¹⁶ relative of a multiple of π/2), and beyond
/// [`F64_FAST_LIMIT`] (and for NaN, ±∞) it defers to `libm`.
#[cold]
#[inline(never)]
fn careful64(x: f64) -> (f64, f64) {
    let sign = x.to_bits() & (1u64 << 63);
    let ax = f64::from_bits(x.to_bits() & !(1u64 << 63));
    if !(ax <= F64_FAST_LIMIT) {
        return (libm::sin(x), libm::cos(x));
    }
    let (y0, y1, t) = careful_reduction64(ax);
    finish64(y0, y1, t.to_bits(), sign)
}

/// [`careful64`]'s reduction of `ax = |x| ≤ F64_FAST_LIMIT`: `(y0, y1, t)` with
/// `ax = n·π/2 + (y0 + y1)` and `t`'s bits holding `n mod 2⁶⁴`, as [`one_step64`]; for one
/// argument, and lane by lane in [`careful_reductions64`] (which the compiler vectorises,
/// compiled for AVX2 in the AVX2 groups' rare path).
#[inline(always)]
fn careful_reduction64<T: Ops>(ax: T) -> (T, T, T) {
    const P1: f64 = 1.57079632673412561417e+00;
    const P2: f64 = 6.07710050630396597660e-11;
    const P3: f64 = 2.02226624871116645580e-21;
    const P4: f64 = 8.47842766036889956997e-32;
    let k = T::splat;
    let t = ax * k(FRAC_2_PI_64) + k(TOINT_64);
    let fnum = t - k(TOINT_64);
    // `r1` is exact (Sterbenz). `0 − a` is `−a` for every `a ≠ 0`; for `a = +0` (`n = 0`) TwoSum
    // still gives the same sum and error.
    let r1 = ax - fnum * k(P1);
    let (r2, e1) = two_sum64(r1, k(0.0) - fnum * k(P2));
    let (hi, e2) = two_sum64(r2, k(0.0) - fnum * k(P3));
    let lo = (e1 + e2) - fnum * k(P4);
    let y0 = hi + lo;
    let y1 = (hi - y0) + lo;
    (y0, y1, t)
}

/// `(sin x, cos x)` for `f64`, < 1 ulp (see the [module docs](self)).
///
/// One-step Cody–Waite reduction as in musl's `__rem_pio2` (`P1` of 33 bits, `n·P1` exact,
/// `P1T = π/2 − P1`), with musl's cancellation test sending the rare arguments near a
/// multiple of π/2 to the careful reduction; branch-free otherwise (`|x| ≤ π/4` included).
#[inline(always)]
pub fn sin_cos_f64(x: f64) -> (f64, f64) {
    let sign = x.to_bits() & (1u64 << 63);
    let ax = f64::from_bits(x.to_bits() & !(1u64 << 63));
    if ax <= core::f64::consts::FRAC_PI_4 {
        return finish64(ax, 0.0, 0, sign);
    }
    if !(ax <= F64_FAST_LIMIT) {
        return careful64(x);
    }
    let (y0, y1, t) = one_step64(ax);
    if cancelled64(ax, y0) {
        return careful64(x);
    }
    finish64(y0, y1, t.to_bits(), sign)
}

/// musl's one-step Cody–Waite reduction of `ax = |x| ≤ F64_FAST_LIMIT`:
/// `ax = n·π/2 + (y0 + y1)` with `P1` of 33 bits (`n·P1` exact) and `P1T = π/2 − P1`;
/// returns `(y0, y1, t)`, `t`'s bits holding `n mod 2⁶⁴`. Its result cancels when `x` is near
/// a multiple of π/2, which the callers test.
#[inline(always)]
fn one_step64<T: Ops>(ax: T) -> (T, T, T) {
    const P1: f64 = 1.57079632673412561417e+00;
    const P1T: f64 = 6.07710050650619224932e-11;
    let t = ax * T::splat(FRAC_2_PI_64) + T::splat(TOINT_64);
    let fnum = t - T::splat(TOINT_64);
    let r = ax - fnum * T::splat(P1); // exact
    let w = fnum * T::splat(P1T);
    let y0 = r - w;
    (y0, (r - y0) - w, t)
}

/// `wide::f64x4` for the lane type `F64x4` (feature `lanes`): its four lanes go through the
/// same arithmetic as every other path, on the vector type itself.
#[cfg(feature = "lanes")]
impl Ops for wide::f64x4 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        wide::f64x4::splat(x)
    }
}

/// The select on the lanes' bits (`wide::u64x4`), through the scalar [`select64`]'s
/// [`select_bits`].
#[cfg(feature = "lanes")]
impl Vector for wide::f64x4 {
    #[inline(always)]
    fn abs_and_sign(self) -> (Self, Self) {
        let bits: wide::u64x4 = bytemuck::cast(self);
        (
            bytemuck::cast(bits & wide::u64x4::splat(!SIGN)),
            bytemuck::cast(bits & wide::u64x4::splat(SIGN)),
        )
    }
    #[inline(always)]
    fn beyond_or_cancelled(self, limit: f64, y: Self, least: Self) -> i32 {
        use wide::{CmpLe, CmpLt};
        ((!self.cmp_le(Self::splat(limit))) | y.abs().cmp_lt(least)).move_mask()
    }
    #[inline(always)]
    fn select(s: Self, c: Self, t: Self, sign: Self) -> (Self, Self) {
        use bytemuck::cast;
        let (s, c) = select_bits::<wide::u64x4>(cast(s), cast(c), cast(t), cast(sign));
        (cast(s), cast(c))
    }
}

/// [`sin_cos_f64`] of each lane of a `wide::f64x4`, bit for bit, computed on the vector
/// ([`main_path`]); if a lane needs more, every lane through [`sin_cos_f64`]. Of four lanes,
/// at the default target, recomputing only the lanes that need it (in line or out of line)
/// made the Panda at its ready pose slower, and the careful reduction on all four
/// ([`careful_lanes64`]) made it faster there but random configurations slower (see
/// BENCHMARKS.md).
#[cfg(feature = "lanes")]
#[inline(always)]
pub(crate) fn sin_cos_f64x4(x: wide::f64x4) -> (wide::f64x4, wide::f64x4) {
    let (s, c, slow) = main_path(x);
    if slow != 0 {
        let x = x.to_array();
        let r: [(f64, f64); 4] = core::array::from_fn(|k| sin_cos_f64(x[k]));
        return (
            wide::f64x4::new(core::array::from_fn(|k| r[k].0)),
            wide::f64x4::new(core::array::from_fn(|k| r[k].1)),
        );
    }
    (s, c)
}

/// Lanes of the side-by-side kernel [`sin_cos_f64_lanes`] for [`sin_cos_f64_array`]: eight
/// where the target has AVX2 (two registers) or AVX-512 (one), two on other x86-64 targets
/// with SSE2 (two `f64` in one SSE2 register), none (one element at a time) elsewhere. With
/// AVX2, seven joints as one group of eight are faster than a group of four then a padded one
/// (see BENCHMARKS.md, "Trigonometry on AVX2 and SSE2").
pub const F64_LANES: usize = if cfg!(any(target_feature = "avx512f", target_feature = "avx2")) {
    8
} else if cfg!(all(target_arch = "x86_64", target_feature = "sse2")) {
    2
} else {
    1
};

/// Whether [`sin_cos_f64_lanes`] computes its lanes two at a time on `sse2::Pair` rather
/// than as one scalar path per lane: on x86-64 with SSE2 and without AVX2. With AVX2 or
/// AVX-512 the compiler vectorises the scalar paths whole.
const PAIRS: bool = F64_LANES == 2;

/// [`sin_cos_f64`] of every element, bit for bit. With eight [`F64_LANES`] the elements go
/// through [`sin_cos_f64_lanes`] in groups of eight, the last group padded (by repeating its
/// last element) when three or more are left (one or two left go alone through
/// [`sin_cos_f64`]); with two, arrays of two or more elements go through
/// [`sin_cos_f64_lanes`] in pairs (one element alone through [`sin_cos_f64`]).
///
/// With `std`, on an x86-64 target without AVX2 (the default target) running on a CPU that
/// has it, arrays of three to eight elements go as one group of eight on AVX2, chosen at run
/// time (std's detection, cached): the same operations, none fused, so the same bits, faster
/// than the SSE2 pairs (see BENCHMARKS.md, "AVX2 chosen at run time"). Longer arrays, and
/// builds without `std`, keep the pairs.
#[inline(always)]
pub fn sin_cos_f64_array<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
    let mut s = [0.0; N];
    let mut c = [0.0; N];
    let mut k = 0;
    if PAIRS && N >= 2 {
        #[cfg(all(
            feature = "std",
            target_arch = "x86_64",
            target_feature = "sse2",
            not(target_feature = "avx2")
        ))]
        if let Some((s, c)) = avx2::groups(x) {
            // Each element read alone (8-byte loads): the caller's own loads of two
            // neighbours at once would span two of `eight`'s stores, a failed
            // store-to-load forwarding.
            // SAFETY: `s[k]`, `c[k]` are valid, aligned `f64` of local arrays.
            let read = |a: &[f64; N], k: usize| unsafe { core::ptr::read_volatile(&a[k]) };
            return (
                core::array::from_fn(|k| read(&s, k)),
                core::array::from_fn(|k| read(&c, k)),
            );
        }
        return sin_cos_f64_lanes(x);
    }
    if F64_LANES == 8 {
        // A group of two or fewer goes one element at a time: padding two joints out to a
        // group of eight (the presets' `J^r` needs `q7`, `q8` only) made the compiler build
        // the vector through the stack, a failed store-to-load forwarding, and took the call
        // out of line (the presets' `J^r` from `q` about twice as slow).
        while k + 3 <= N {
            k += group::<N, 8>(x, k, &mut s, &mut c);
        }
    }
    while k < N {
        (s[k], c[k]) = sin_cos_f64(x[k]);
        k += 1;
    }
    (s, c)
}

/// [`sin_cos_f64_array`] for a caller compiled for AVX2 and FMA at run time (the `_fma`
/// functions of `fma_at_run_time` modules, through [`FusedF64`](super::fma::FusedF64)), bit for bit
/// the same: the AVX2 groups' results returned as they are, without the element-by-element
/// reads that spare SSE2 callers a failed store-to-load forwarding. Such a caller does not
/// need them, and they cost it (see BENCHMARKS.md, "FMA chosen at run time").
#[inline(always)]
pub(crate) fn sin_cos_f64_array_for_avx2<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
    #[cfg(all(
        feature = "std",
        target_arch = "x86_64",
        target_feature = "sse2",
        not(target_feature = "avx2")
    ))]
    if PAIRS {
        if let Some(r) = avx2::groups(x) {
            return r;
        }
    }
    sin_cos_f64_array(x)
}

/// Groups of eight compiled for AVX2, for x86-64 builds whose target lacks it; chosen at run
/// time by [`sin_cos_f64_array`].
///
/// The main path's eight lanes are two `Quad`s: four `f64` in one AVX register, one AVX
/// intrinsic per operation, the same arithmetic as every other path ([`kernels64`],
/// [`one_step64`]). The compiler's own vectorisation of [`sin_cos_f64_lanes`] in such a
/// function built its vectors through the stack, a failed store-to-load forwarding that made
/// the Panda's seven joints slower than the SSE2 pairs. The rare path
/// (`careful`) is the compiler's vectorisation of [`careful_reductions64`], stack traffic
/// and all: it runs only for arguments near a multiple of π/2, and one pass there cost less
/// than the two `Quad` passes it replaced (BENCHMARKS.md, "Where the two paths meet").
///
/// Soundness: the `unsafe` blocks below are AVX or AVX2 intrinsics on registers (no memory is
/// read or written through a pointer), whose one precondition is that the CPU has AVX2; the
/// transmute of `Quad::lanes`, sound for any bits (its own comment); and the calls of the
/// two functions compiled for AVX2, `eight` (from `groups`, only after std's detection has
/// confirmed AVX2 at run time) and `careful` (from `eight` alone). `Quad` and its operations
/// are private to this module and used only inside `eight`.
#[cfg(all(
    feature = "std",
    target_arch = "x86_64",
    target_feature = "sse2",
    not(target_feature = "avx2")
))]
mod avx2 {
    use core::arch::x86_64::*;

    use super::{careful_reductions64, main_path, Vector, SIGN};

    /// `x` (three to eight elements) as one group of eight on AVX2, padded with its last
    /// element, where the CPU (and the operating system) supports AVX2 (std's detection,
    /// cached); `None` for other lengths or without AVX2.
    #[inline(always)]
    pub(super) fn groups<const N: usize>(x: &[f64; N]) -> Option<([f64; N], [f64; N])> {
        if !(3..=8).contains(&N) || !std::arch::is_x86_feature_detected!("avx2") {
            return None;
        }
        let e = |l: usize| x[l.min(N - 1)];
        // SAFETY: `eight` only needs the CPU to have AVX2, which std's detection has just
        // confirmed (it also checks that the operating system saves the YMM registers).
        Some(unsafe { eight::<N>(e(0), e(1), e(2), e(3), e(4), e(5), e(6), e(7)) })
    }

    /// [`super::sin_cos_f64_lanes`] of eight elements, bit for bit (no operation is fused),
    /// compiled for AVX2. The arguments come one by one, in registers.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[allow(clippy::too_many_arguments)]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn eight<const N: usize>(
        x0: f64,
        x1: f64,
        x2: f64,
        x3: f64,
        x4: f64,
        x5: f64,
        x6: f64,
        x7: f64,
    ) -> ([f64; N], [f64; N]) {
        let (s0, c0, slow0) = main_path(Quad::new(x0, x1, x2, x3));
        let (s1, c1, slow1) = main_path(Quad::new(x4, x5, x6, x7));
        if (slow0 | slow1) != 0 {
            // Given `x` alone: with the main path's results passed as well, the compiler
            // tested after both kernels instead of before, and the Panda's pose and body
            // Jacobian from `q` was slower.
            let x = [x0, x1, x2, x3, x4, x5, x6, x7];
            // SAFETY: this function's own precondition (AVX2).
            return unsafe { careful::<N>(&x) };
        }
        let (s0, c0, s1, c1) = (s0.lanes(), c0.lanes(), s1.lanes(), c1.lanes());
        (
            core::array::from_fn(|k| if k < 4 { s0[k] } else { s1[k - 4] }),
            core::array::from_fn(|k| if k < 4 { c0[k] } else { c1[k - 4] }),
        )
    }

    /// The rare path of [`eight`], out of line, compiled for AVX2 like it, from the eight
    /// arguments alone (given the main path's results as well, the compiler tested after
    /// `eight`'s kernels, and the Panda's pose and body Jacobian from `q` was slower):
    /// [`careful_reductions64`] on the eight lanes, which the compiler vectorises
    /// for AVX2 here (both reductions of every lane, the careful one where
    /// [`super::cancelled64`] sends [`super::sin_cos_f64`] to it, both kernels once; lanes
    /// beyond [`super::F64_FAST_LIMIT`], NaN and ±∞ one at a time through
    /// [`super::sin_cos_f64`]) (BENCHMARKS.md, "Where the two paths meet").
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cold]
    #[inline(never)]
    #[target_feature(enable = "avx2")]
    unsafe fn careful<const N: usize>(x: &[f64; 8]) -> ([f64; N], [f64; N]) {
        let (s, c) = careful_reductions64(x);
        (
            core::array::from_fn(|k| s[k]),
            core::array::from_fn(|k| c[k]),
        )
    }

    /// Four `f64` in one AVX register (lane 0 first).
    #[derive(Clone, Copy)]
    struct Quad(__m256d);

    impl Quad {
        #[inline(always)]
        fn new(a: f64, b: f64, c: f64, d: f64) -> Self {
            // SAFETY: AVX2 (module docs); registers only.
            Quad(unsafe { _mm256_set_pd(d, c, b, a) })
        }

        #[inline(always)]
        fn lanes(self) -> [f64; 4] {
            // SAFETY: four `f64` in 32 bytes, lane 0 at the lowest address; every bit
            // pattern is an `f64`.
            unsafe { core::mem::transmute::<__m256d, [f64; 4]>(self.0) }
        }
    }

    impl Vector for Quad {
        #[inline(always)]
        fn abs_and_sign(self) -> (Self, Self) {
            // SAFETY: AVX2 (module docs); registers only.
            unsafe {
                let s = _mm256_set1_pd(-0.0);
                (
                    Quad(_mm256_andnot_pd(s, self.0)),
                    Quad(_mm256_and_pd(s, self.0)),
                )
            }
        }

        #[inline(always)]
        fn beyond_or_cancelled(self, limit: f64, y: Self, least: Self) -> i32 {
            // SAFETY: AVX2 (module docs); registers only.
            unsafe {
                let abs_y = _mm256_andnot_pd(_mm256_set1_pd(-0.0), y.0);
                _mm256_movemask_pd(_mm256_or_pd(
                    _mm256_cmp_pd::<_CMP_NLE_UQ>(self.0, _mm256_set1_pd(limit)),
                    _mm256_cmp_pd::<_CMP_LT_OQ>(abs_y, least.0),
                ))
            }
        }

        #[inline(always)]
        fn select(s: Self, c: Self, t: Self, sign: Self) -> (Self, Self) {
            // SAFETY: AVX2 (module docs); registers only.
            unsafe {
                let q = _mm256_castpd_si256(t.0);
                let swap = _mm256_castsi256_pd(_mm256_sub_epi64(
                    _mm256_setzero_si256(),
                    _mm256_and_si256(q, _mm256_set1_epi64x(1)),
                ));
                let sign_bit = _mm256_castsi256_pd(_mm256_set1_epi64x(SIGN as i64));
                let d = _mm256_and_pd(_mm256_xor_pd(s.0, c.0), swap);
                let flip = _mm256_and_pd(_mm256_castsi256_pd(_mm256_slli_epi64::<62>(q)), sign_bit);
                (
                    Quad(_mm256_xor_pd(
                        _mm256_xor_pd(s.0, d),
                        _mm256_xor_pd(flip, sign.0),
                    )),
                    Quad(_mm256_xor_pd(
                        _mm256_xor_pd(c.0, d),
                        _mm256_xor_pd(flip, _mm256_and_pd(swap, sign_bit)),
                    )),
                )
            }
        }
    }

    super::vector_ops!(
        Quad,
        _mm256_set1_pd,
        _mm256_add_pd,
        _mm256_sub_pd,
        _mm256_mul_pd
    );
}

/// Elements `k..` (at most `W` of them) of `x` through [`sin_cos_f64_lanes`] into `s`, `c`;
/// returns how many.
#[inline(always)]
fn group<const N: usize, const W: usize>(
    x: &[f64; N],
    k: usize,
    s: &mut [f64; N],
    c: &mut [f64; N],
) -> usize {
    let m = W.min(N - k);
    // The spare lanes repeat the last element (zeros written into a copy made the compiler
    // build the vector through memory, a store-to-load forwarding stall: several times slower
    // in one AVX-512 group).
    let xs: [f64; W] = core::array::from_fn(|l| x[k + l.min(m - 1)]);
    let (sw, cw) = each_lane::<W>(&xs);
    // Element by element: `copy_from_slice` here sent the results through memory too
    // (several times slower, AVX-512).
    #[allow(clippy::manual_memcpy)]
    for l in 0..m {
        s[k + l] = sw[l];
        c[k + l] = cw[l];
    }
    m
}

/// [`sin_cos_f64`] of four elements: [`sin_cos_f64_lanes`] with `W = 4`.
#[inline(always)]
pub fn sin_cos_f64_x4(x: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
    sin_cos_f64_lanes::<4>(x)
}

/// [`sin_cos_f64`] of `W` elements, bit for bit, computed side by side: the main path of
/// [`sin_cos_f64`] (one-step reduction, both kernels, quadrant select) runs branch-free on
/// all of them, so the compiler can put them in vector registers. If any element needs more
/// (beyond [`F64_FAST_LIMIT`], NaN, ±∞, or a reduction that may have cancelled:
/// `|y0| < 2⁻¹⁶ |x|`, which holds whenever musl's exponent test of [`sin_cos_f64`] does),
/// the elements that [`sin_cos_f64`] sends to its careful reduction take it: where the
/// compiler vectorises the lanes, every lane is computed again from `x` with the reduction
/// [`sin_cos_f64`] would choose; on SSE2's pairs those elements alone go through
/// [`sin_cos_f64`], the others are kept. `|x| ≤ π/4` needs no select: the reduction then
/// gives `n = 0` and exactly `(|x|, 0)`, the arguments [`sin_cos_f64`] hands to the kernels
/// unreduced.
#[inline(always)]
pub fn sin_cos_f64_lanes<const W: usize>(x: &[f64; W]) -> ([f64; W], [f64; W]) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    if PAIRS {
        return pairs(x);
    }
    each_lane(x)
}

/// [`sin_cos_f64_lanes`] as one scalar path per lane, which the compiler vectorises where
/// the target has AVX2 or AVX-512.
#[inline(always)]
fn each_lane<const W: usize>(x: &[f64; W]) -> ([f64; W], [f64; W]) {
    const ABS: u64 = !SIGN;
    let mut s = [0.0; W];
    let mut c = [0.0; W];
    let mut slow = false;
    for k in 0..W {
        let sign = x[k].to_bits() & !ABS;
        let ax = f64::from_bits(x[k].to_bits() & ABS);
        let (y0, y1, t) = one_step64(ax);
        slow |= lane_needs_care64(ax, y0);
        (s[k], c[k]) = finish64(y0, y1, t.to_bits(), sign);
    }
    if slow {
        // Every lane again from `x` alone, the careful reduction where it is needed (given
        // this path's `s`, `c` too, the compiler tested after the kernels, and the Panda's
        // evaluation was slower); out of line beyond eight lanes, in line up to eight (see
        // `sin_cos_f32_lanes`).
        if W <= 8 {
            return careful_reductions64(x);
        }
        // Assigned, not returned: see `sin_cos_f32_lanes`.
        (s, c) = careful_lanes64(x);
    }
    (s, c)
}

/// [`sin_cos_f64_lanes`] on [`sse2::Pair`]s: lanes `2i, 2i + 1` in pair `i` (an odd last lane
/// paired with itself), the one-step reduction, both kernels and the select on each pair;
/// a lane that needs more through [`sin_cos_f64`] ([`redo_lanes64`]).
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[inline(always)]
fn pairs<const W: usize>(x: &[f64; W]) -> ([f64; W], [f64; W]) {
    let mut s = [0.0; W];
    let mut c = [0.0; W];
    let n = W.div_ceil(2);
    // The first four pairs written out, so that their independent chains interleave (as a
    // loop the compiler kept it rolled, one pair after another, and slower).
    let mut slow = 0;
    if n > 0 {
        slow |= one_pair(x, 0, &mut s, &mut c);
    }
    if n > 1 {
        slow |= one_pair(x, 1, &mut s, &mut c);
    }
    if n > 2 {
        slow |= one_pair(x, 2, &mut s, &mut c);
    }
    if n > 3 {
        slow |= one_pair(x, 3, &mut s, &mut c);
    }
    for i in 4..n {
        slow |= one_pair(x, i, &mut s, &mut c);
    }
    if slow != 0 {
        return redo_lanes64(x, s, c);
    }
    (s, c)
}

/// Pair `i` of [`pairs`] into `s`, `c`; nonzero if a lane needs [`sin_cos_f64`]'s rare paths.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[inline(always)]
fn one_pair<const W: usize>(x: &[f64; W], i: usize, s: &mut [f64; W], c: &mut [f64; W]) -> i32 {
    let (sp, cp, slow) = main_path(sse2::Pair::new(x[2 * i], x[(2 * i + 1).min(W - 1)]));
    let (sp, cp) = (sp.lanes(), cp.lanes());
    for l in 0..2.min(W - 2 * i) {
        s[2 * i + l] = sp[l];
        c[2 * i + l] = cp[l];
    }
    slow
}

/// [`sin_cos_f64_lanes`]' test of one lane: beyond [`F64_FAST_LIMIT`] (NaN and ±∞
/// included), or a reduction `y0` of `ax = |x|` that may have cancelled (`|y0| < 2⁻¹⁶ |x|`,
/// which holds whenever musl's exponent test of [`sin_cos_f64`] does). The vector types'
/// `beyond_or_cancelled` is the same test.
#[inline(always)]
fn lane_needs_care64(ax: f64, y0: f64) -> bool {
    !(ax <= F64_FAST_LIMIT) | (f64::from_bits(y0.to_bits() & !SIGN) < ax * TWO_M16)
}

/// [`lane_needs_care64`] of `x`, its reduction computed again.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[inline(always)]
fn needs_care64(x: f64) -> bool {
    let ax = f64::from_bits(x.to_bits() & !SIGN);
    lane_needs_care64(ax, one_step64(ax).0)
}

/// musl's exponent test of [`sin_cos_f64`]: the one-step reduction `y0` of `ax = |x|` lost
/// more than 16 bits (false for `|x| ≤ π/4`, whose reduction is `ax` itself).
#[inline(always)]
fn cancelled64(ax: f64, y0: f64) -> bool {
    let ex = (ax.to_bits() >> 52) as i64;
    let ey = ((y0.to_bits() >> 52) & 0x7ff) as i64;
    ex - ey > 16
}

/// The rare path of the SSE2 pairs, out of line: the lanes that fail [`lane_needs_care64`]
/// recomputed by [`sin_cos_f64`], the others kept, being its bits already. One argument
/// near a multiple of π/2 (a joint at ±π/2, common in robots' home poses) costs one careful
/// reduction, not a whole group recomputed one element at a time, nor
/// [`careful_lanes64`]'s one per lane, which code built for the default target runs one
/// after the other (from the AVX2 groups chosen at run time, the Panda at its ready pose was
/// slower that way).
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[cold]
#[inline(never)]
fn redo_lanes64<const W: usize>(
    x: &[f64; W],
    mut s: [f64; W],
    mut c: [f64; W],
) -> ([f64; W], [f64; W]) {
    for k in 0..W {
        if needs_care64(x[k]) {
            (s[k], c[k]) = sin_cos_f64(x[k]);
        }
    }
    (s, c)
}

/// The rare path of the compiler-vectorised groups beyond eight lanes, out of line:
/// [`careful_reductions64`].
#[cold]
#[inline(never)]
fn careful_lanes64<const W: usize>(x: &[f64; W]) -> ([f64; W], [f64; W]) {
    careful_reductions64(x)
}

/// The rare path of the compiler-vectorised groups (in line up to eight lanes, out of line
/// beyond through [`careful_lanes64`]), from `x` alone and branch-free on all `W` lanes so
/// that the compiler vectorises it too: both reductions of every lane, the careful one taken
/// where [`cancelled64`] sends [`sin_cos_f64`] to [`careful64`], then both kernels and the
/// select once (each lane [`sin_cos_f64`]'s bits); then lanes beyond [`F64_FAST_LIMIT`] (NaN,
/// ±∞) one at a time through [`sin_cos_f64`] (`libm`). Four configurations of the Panda at
/// its ready pose (`q6 = π/2`) on `F64x4` cost one vector pass instead of four scalar careful
/// reductions (BENCHMARKS.md, "The careful reduction on all lanes").
#[inline(always)]
fn careful_reductions64<const W: usize>(x: &[f64; W]) -> ([f64; W], [f64; W]) {
    let mut s = [0.0; W];
    let mut c = [0.0; W];
    let mut beyond = false;
    for k in 0..W {
        let sign = x[k].to_bits() & SIGN;
        let ax = f64::from_bits(x[k].to_bits() & !SIGN);
        beyond |= !(ax <= F64_FAST_LIMIT);
        let one_step = one_step64(ax);
        let careful = careful_reduction64(ax);
        let (y0, y1, t) = if cancelled64(ax, one_step.0) {
            careful
        } else {
            one_step
        };
        (s[k], c[k]) = finish64(y0, y1, t.to_bits(), sign);
    }
    if beyond {
        for k in 0..W {
            if !(f64::from_bits(x[k].to_bits() & !SIGN) <= F64_FAST_LIMIT) {
                (s[k], c[k]) = sin_cos_f64(x[k]);
            }
        }
    }
    (s, c)
}

const FRAC_2_PI_32: f32 = 0.636_619_75;
const TOINT_32: f32 = 1.5 / f32::EPSILON;

/// Cephes `sinf`/`cosf` minimax kernels on `|y0 + y1| ≤ π/4` with the tail `y1`, then the
/// quadrant select and the sign of `x`.
#[inline(always)]
fn finish32(y0: f32, y1: f32, quadrant: u32, sign: u32) -> (f32, f32) {
    const S1: f32 = -1.666_665_5e-1;
    const S2: f32 = 8.332_161e-3;
    const S3: f32 = -1.951_529_6e-4;
    const C1: f32 = 4.166_664_6e-2;
    const C2: f32 = -1.388_731_6e-3;
    const C3: f32 = 2.443_315_7e-5;
    let z = y0 * y0;
    // sin(y0 + y1) ~ y0 + y0 z S(z) + y1 (1 - z/2)
    let s = y0 + (y0 * z * (S1 + z * (S2 + z * S3)) + y1 * (1.0 - 0.5 * z));
    // cos(y0 + y1) ~ 1 - z/2 + z^2 C(z) - y0 y1
    let hz = 0.5 * z;
    let wc = 1.0 - hz;
    let c = wc + (((1.0 - wc) - hz) + (z * z * (C1 + z * (C2 + z * C3)) - y0 * y1));
    let (s, c) = if quadrant & 1 == 0 { (s, c) } else { (c, -s) };
    let (s, c) = if quadrant & 2 == 0 { (s, c) } else { (-s, -c) };
    (f32::from_bits(s.to_bits() ^ sign), c)
}

/// Careful reduction for `f32`: π/2 = P1 + P2 + P3 + P4, the first three of 12 bits
/// (`n·P_k` exact for `n < 2¹²`), remainder as a double-word by TwoSum; beyond
/// [`F32_FAST_LIMIT`] (and NaN, ±∞) `libm`'s `sinf`/`cosf`.
#[cold]
#[inline(never)]
fn careful32(x: f32) -> (f32, f32) {
    let sign = x.to_bits() & (1u32 << 31);
    let ax = f32::from_bits(x.to_bits() & !(1u32 << 31));
    if !(ax <= F32_FAST_LIMIT) {
        return (libm::sinf(x), libm::cosf(x));
    }
    let (y0, y1, t) = careful_reduction32(ax);
    finish32(y0, y1, t.to_bits(), sign)
}

/// [`careful32`]'s reduction of `ax = |x| ≤ F32_FAST_LIMIT`: `(y0, y1, t)` as
/// [`reduce32`]; for one argument, and for the lanes of [`careful_reductions32`] side by side.
#[inline(always)]
fn careful_reduction32(ax: f32) -> (f32, f32, f32) {
    const P1: f32 = 1.570_800_8; // 0x1.922p0
    const P2: f32 = -4.453_584_6e-6; // -0x1.2aep-18
    const P3: f32 = -8.706_138e-10; // -0x1.deap-31
    const P4: f32 = 6.223_372e-14; // 0x1.184698p-44
    let t = ax * FRAC_2_PI_32 + TOINT_32;
    let fnum = t - TOINT_32;
    let r1 = ax - fnum * P1;
    let (r2, e1) = two_sum32(r1, -(fnum * P2));
    let (hi, e2) = two_sum32(r2, -(fnum * P3));
    let lo = (e1 + e2) - fnum * P4;
    let y0 = hi + lo;
    let y1 = (hi - y0) + lo;
    (y0, y1, t)
}

/// The one-step reduction of `ax = |x|` (`P1` of 12 bits, `n·P1` exact, `P1T = π/2 − P1`):
/// `(y0, y1, t)` with `x = n·π/2 + (y0 + y1)` and `n mod 2³²` the bits of `t`.
#[inline(always)]
fn reduce32(ax: f32) -> (f32, f32, f32) {
    const P1: f32 = 1.570_800_8; // 0x1.922p0
    const P1T: f32 = -4.454_455e-6; // pi/2 - P1, rounded
    let t = ax * FRAC_2_PI_32 + TOINT_32;
    let fnum = t - TOINT_32;
    let r = ax - fnum * P1; // exact
    let w = fnum * P1T;
    let y0 = r - w;
    (y0, (r - y0) - w, t)
}

/// `(sin x, cos x)` for `f32`, < 1 ulp, single-precision arithmetic only (see the
/// [module docs](self)). One-step reduction (`P1` of 12 bits, `P1T = π/2 − P1`); arguments
/// whose reduction cancels by more than 12 bits take the careful path.
#[inline(always)]
pub fn sin_cos_f32(x: f32) -> (f32, f32) {
    let sign = x.to_bits() & (1u32 << 31);
    let ax = f32::from_bits(x.to_bits() & !(1u32 << 31));
    if ax <= core::f32::consts::FRAC_PI_4 {
        return finish32(ax, 0.0, 0, sign);
    }
    if !(ax <= F32_FAST_LIMIT) {
        return careful32(x);
    }
    let (y0, y1, t) = reduce32(ax);
    let quadrant = t.to_bits();
    if cancelled32(ax, y0) {
        return careful32(x);
    }
    finish32(y0, y1, quadrant, sign)
}

/// Lanes of the side-by-side kernel [`sin_cos_f32_lanes`] for [`sin_cos_f32_array`]: eight on
/// x86-64 (two SSE2 registers of four `f32` at the default target, one AVX register with
/// AVX2 or AVX-512), none (one element at a time) elsewhere, where the lanes would run one
/// after the other (or are unmeasured: aarch64's NEON). The Panda's seven joints at the
/// default target take about half the instructions of one at a time (see BENCHMARKS.md,
/// "`f32` joints in groups of eight").
pub const F32_LANES: usize = if cfg!(all(target_arch = "x86_64", target_feature = "sse2")) {
    8
} else {
    1
};

/// [`sin_cos_f32`] of every element, bit for bit. With eight [`F32_LANES`] the elements go
/// through [`sin_cos_f32_lanes`] in groups of eight, the last group padded (by repeating its
/// last element) when three or more are left (one or two left go alone through
/// [`sin_cos_f32`]).
#[inline(always)]
pub fn sin_cos_f32_array<const N: usize>(x: &[f32; N]) -> ([f32; N], [f32; N]) {
    let mut s = [0.0; N];
    let mut c = [0.0; N];
    let mut k = 0;
    if F32_LANES == 8 {
        while k + 3 <= N {
            let m = (N - k).min(8);
            // The spare lanes repeat the last element (see `group` for `f64`).
            let xs: [f32; 8] = core::array::from_fn(|l| x[k + l.min(m - 1)]);
            let (sw, cw) = sin_cos_f32_lanes::<8>(&xs);
            #[allow(clippy::manual_memcpy)]
            for l in 0..m {
                s[k + l] = sw[l];
                c[k + l] = cw[l];
            }
            k += m;
        }
    }
    while k < N {
        (s[k], c[k]) = sin_cos_f32(x[k]);
        k += 1;
    }
    (s, c)
}

/// [`sin_cos_f32`] of `W` elements, bit for bit, computed side by side: the main path of
/// [`sin_cos_f32`] (one-step reduction, both kernels, quadrant select) runs branch-free on
/// all of them, so the compiler can put them in vector registers. If any element needs more
/// (beyond [`F32_FAST_LIMIT`], NaN, ±∞, or a reduction that may have cancelled:
/// `|y0| < 2⁻¹² |x|`, which holds whenever the exponent test of [`sin_cos_f32`] does), every
/// lane is computed again from `x`, side by side, with the reduction [`sin_cos_f32`] would
/// choose (the careful one where it sends the element to it). For `|x| ≤ π/4` the reduction
/// gives `n = 0` and exactly `(|x|, +0)`, the arguments [`sin_cos_f32`] hands to the kernels
/// unreduced.
#[inline(always)]
pub fn sin_cos_f32_lanes<const W: usize>(x: &[f32; W]) -> ([f32; W], [f32; W]) {
    const ABS: u32 = !(1u32 << 31);
    let mut s = [0.0; W];
    let mut c = [0.0; W];
    let mut slow = false;
    for k in 0..W {
        let sign = x[k].to_bits() & !ABS;
        let ax = f32::from_bits(x[k].to_bits() & ABS);
        let (y0, y1, t) = reduce32(ax);
        let quadrant = t.to_bits();
        slow |= lane_needs_care32(ax, y0);
        (s[k], c[k]) = finish32(y0, y1, quadrant, sign);
    }
    if slow {
        // Every lane again from `x` alone, the careful reduction where it is needed (see
        // `sin_cos_f64_lanes`). Beyond eight lanes out of line: in line, `F32x8`'s sixteen
        // lanes were slower (BENCHMARKS.md, "Only the lanes that need it"); up to eight in
        // line: out of line, the scalar Panda's evaluation was slower in `f32` and `f64` on
        // random configurations (BENCHMARKS.md, "The careful reduction on all lanes", its
        // first form).
        if W <= 8 {
            return careful_reductions32(x);
        }
        // Assigned to `s`, `c`, not returned: `return careful_lanes32(x)` made the call write
        // into the result's place, so the main path stored its results there too and read
        // them back (the two paths met in memory; on Zen 4 the reload of each 64-byte
        // result waited on its store, and `F32x8`'s evaluation was slower, BENCHMARKS.md,
        // "Where the two paths meet").
        (s, c) = careful_lanes32(x);
    }
    (s, c)
}

/// [`sin_cos_f32`]'s exponent test: the one-step reduction `y0` of `ax = |x|` lost more
/// than 12 bits (false for `|x| ≤ π/4`, whose reduction is `ax` itself).
///
/// Why 12: [`reduce32`]'s `y0 + y1` differs from `|x| − n·π/2` only through `P1T` (within
/// 2⁻⁴² of π/2 − P1) and the rounding of `n·P1T` (at most `n·2⁻⁴¹`), less than `n·2⁻⁴⁰` in
/// all. Passing the test means `|y0| > 2⁻¹³ |x| ≥ 2⁻¹³ (n − ½)·π/2`, so the reduced argument
/// is off by less than `0.16 · 2⁻²⁴` of itself: at most 0.16 ulp more in the result. Every
/// `f32` with `|x| ≤ 4096` checked against the exact value (`f32_exhaustive_fast_path`)
/// gives the same worst case as with the careful reduction from 8 bits on (0.849 ulp); at
/// 20 bits that check fails (1.45 ulp at `x = 1.5707945`, `y ≈ 2⁻¹⁹`). The lanes' trigger
/// (`|y0| < 2⁻¹² |x|`) then flags a joint sampled uniformly in [−2.5, 2.5] rad about once
/// in 3,000 samples, not once in 200 as at 8 bits, where a sixteen-lane `F32x8` group took
/// its rare path in one call of 13.
#[inline(always)]
fn cancelled32(ax: f32, y0: f32) -> bool {
    let ex = (ax.to_bits() >> 23) as i32;
    let ey = ((y0.to_bits() >> 23) & 0xff) as i32;
    ex - ey > 12
}

/// The rare path of [`sin_cos_f32_lanes`] beyond eight lanes, out of line:
/// [`careful_reductions32`].
#[cold]
#[inline(never)]
fn careful_lanes32<const W: usize>(x: &[f32; W]) -> ([f32; W], [f32; W]) {
    careful_reductions32(x)
}

/// The rare path of [`sin_cos_f32_lanes`] (in line up to eight lanes, out of line beyond
/// through [`careful_lanes32`]), from `x` alone and branch-free on all `W` lanes so that the
/// compiler vectorises it too: both reductions of every lane, the careful one taken where
/// [`cancelled32`] sends [`sin_cos_f32`] to [`careful32`], then both kernels and the select
/// once (each lane [`sin_cos_f32`]'s bits); then lanes beyond [`F32_FAST_LIMIT`] (NaN, ±∞)
/// one at a time through [`sin_cos_f32`] (`libm`). `F32x8` with a joint at ±π/2 in every
/// configuration (eight lanes of a group of sixteen) costs one vector pass instead of eight
/// scalar careful reductions (BENCHMARKS.md, "The careful reduction on all lanes").
#[inline(always)]
fn careful_reductions32<const W: usize>(x: &[f32; W]) -> ([f32; W], [f32; W]) {
    const SIGN32: u32 = 1 << 31;
    let mut s = [0.0; W];
    let mut c = [0.0; W];
    let mut beyond = false;
    for k in 0..W {
        let sign = x[k].to_bits() & SIGN32;
        let ax = f32::from_bits(x[k].to_bits() & !SIGN32);
        beyond |= !(ax <= F32_FAST_LIMIT);
        let one_step = reduce32(ax);
        let careful = careful_reduction32(ax);
        let (y0, y1, t) = if cancelled32(ax, one_step.0) {
            careful
        } else {
            one_step
        };
        (s[k], c[k]) = finish32(y0, y1, t.to_bits(), sign);
    }
    if beyond {
        for k in 0..W {
            if !(f32::from_bits(x[k].to_bits() & !SIGN32) <= F32_FAST_LIMIT) {
                (s[k], c[k]) = sin_cos_f32(x[k]);
            }
        }
    }
    (s, c)
}

/// [`sin_cos_f32_lanes`]' test of one lane: beyond [`F32_FAST_LIMIT`] (NaN and ±∞ included),
/// or a reduction `y0` of `|x|` that may have cancelled (`|y0| < 2⁻¹² |x|`, which holds
/// whenever [`cancelled32`] does).
#[inline(always)]
fn lane_needs_care32(ax: f32, y0: f32) -> bool {
    const TWO_M12: f32 = 1.0 / 4096.0;
    !(ax <= F32_FAST_LIMIT) | (f32::from_bits(y0.to_bits() & !(1u32 << 31)) < ax * TWO_M12)
}
