//! Fused multiply-add chosen at run time: `f64` code built for the default x86-64 target, whose
//! instruction set has no FMA, running fused multiply-adds on a CPU that has them.
//!
//! Generated code writes every product that is added once as [`Real::mul_add`], which is one
//! FMA instruction only where the *build target* has FMA (`-C target-cpu=native`,
//! `x86-64-v3`). A crate built for the default target therefore runs two operations per
//! product even on a CPU with FMA. A module generated with the option `fma_at_run_time` (the
//! generator's `Builder::fma_at_run_time`, the command line's `--fma-at-run-time`) also has, for
//! each of its fused functions `name` and `name_trig`, an `f64` entry point `name_f64` and
//! `name_trig_f64` that asks [`path`] (one load of an answer kept after the first call) and then
//! either
//!
//! - runs the function on [`FusedF64`] inside a function compiled for AVX2 and FMA (every
//!   `mul_add` one fused instruction when optimised, the rest VEX-encoded); `name_trig_f64`,
//!   where the CPU also has AVX-512F and AVX-512VL ([`Path::Avx512`]), inside one compiled
//!   for those as well, with the same bits; or
//! - calls `name::<f64>`, exactly as without the option.
//!
//! Such a module needs Rust 1.89 or later (the AVX-512 target features became stable there).
//! The environment variable `TROCAR_FMA_PATH`, read once with the first detection, caps the
//! path: `plain` (always `name::<f64>`), `fma` (never the AVX-512 function); it never selects a
//! function the CPU cannot run.
//!
//! **The results then depend on the CPU** the code runs on, in their last bits: a fused
//! `x·a + b` is rounded once, the two operations twice. On a CPU with AVX2 and FMA they are bit
//! for bit those of the same module built with `-C target-feature=+fma` (or any `target-cpu`
//! with FMA); elsewhere bit for bit those of `name::<f64>`. Use `name::<f64>` itself where the
//! same binary must give the same bits everywhere; the lane types of `trocar::emitted::lanes` (feature
//! `lanes`) are bit for bit `name::<f64>`, not `name_f64`.
//!
//! What it gains is measured in BENCHMARKS.md ("FMA chosen at run time", "The fused functions
//! on AVX-512, given the sines and cosines"). Only optimised code gains: at opt-level 0 (a
//! debug build) `f64::mul_add` is not inlined into the `_fma` function, and every `mul_add` is
//! a call, slower than `pose_and_jacobian_trig::<f64>` itself.
//!
//! ```
//! use trocar::emitted::fma::FusedF64;
//! use trocar::Real;
//!
//! // `mul_add` of a `FusedF64` is always rounded once.
//! let (x, a, b) = (0.1, 10.0, -1.0);
//! let fused = FusedF64(x).mul_add(FusedF64(a), FusedF64(b)).0;
//! assert_eq!(fused, f64::mul_add(x, a, b));
//! assert_eq!(fused, 5.551115123125783e-17); // 0.1 · 10 − 1 before rounding
//! ```

use super::{fast, Real};
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// An `f64` whose [`Real::mul_add`] is always fused (one rounding), whatever the build target:
/// the scalar that a module's `_f64` entry points run on inside their AVX2 + FMA function
/// ([module docs](self)).
///
/// Everything else is `f64`'s: the same IEEE operations, the same [`Real::sin_cos`] (this
/// crate's kernels, which fuse nothing). Outside a function compiled with FMA, `mul_add` is a
/// correctly rounded software routine (`std`'s, or `libm`'s without `std`): right, but slow.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
#[repr(transparent)]
pub struct FusedF64(pub f64);

macro_rules! binary {
    ($($op:ident $f:ident $assign:ident $fa:ident $sym:tt),*) => {$(
        impl $op for FusedF64 {
            type Output = FusedF64;
            #[inline(always)]
            fn $f(self, o: FusedF64) -> FusedF64 {
                FusedF64(self.0 $sym o.0)
            }
        }
        impl $assign for FusedF64 {
            #[inline(always)]
            fn $fa(&mut self, o: FusedF64) {
                self.0 = self.0 $sym o.0;
            }
        }
    )*};
}
binary!(Add add AddAssign add_assign +, Sub sub SubAssign sub_assign -, Mul mul MulAssign mul_assign *);

impl Div for FusedF64 {
    type Output = FusedF64;
    #[inline(always)]
    fn div(self, o: FusedF64) -> FusedF64 {
        FusedF64(self.0 / o.0)
    }
}

impl Neg for FusedF64 {
    type Output = FusedF64;
    #[inline(always)]
    fn neg(self) -> FusedF64 {
        FusedF64(-self.0)
    }
}

impl Real for FusedF64 {
    const ZERO: Self = FusedF64(0.0);
    const ONE: Self = FusedF64(1.0);
    #[inline(always)]
    fn lit(x: f64) -> Self {
        FusedF64(x)
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self.0
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = fast::sin_cos_f64(self.0);
        (FusedF64(s), FusedF64(c))
    }
    #[inline(always)]
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
        let (s, c) = fast::sin_cos_f64_array_for_avx2(&x.map(|v| v.0));
        (s.map(FusedF64), c.map(FusedF64))
    }
    /// `self · a + b` rounded once.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        #[cfg(feature = "std")]
        {
            FusedF64(f64::mul_add(self.0, a.0, b.0))
        }
        #[cfg(not(feature = "std"))]
        {
            FusedF64(libm::fma(self.0, a.0, b.0))
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        FusedF64(<f64 as Real>::sqrt(self.0))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        FusedF64(<f64 as Real>::abs(self.0))
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        self.0.is_finite()
    }
}

impl FusedF64 {
    /// An array of `f64` (the joint values) seen as `FusedF64`, in place.
    #[inline(always)]
    pub fn array<const N: usize>(x: &[f64; N]) -> &[FusedF64; N] {
        // SAFETY: `FusedF64` is `#[repr(transparent)]` over `f64` (its size, alignment and valid
        // bit patterns), so `[FusedF64; N]` has the layout of `[f64; N]`; the shared borrow
        // lasts as long as `x`'s.
        unsafe { &*(x as *const [f64; N]).cast::<[FusedF64; N]>() }
    }

    /// A matrix `[[f64; R]; C]` (an output of a generated function) seen as `[[FusedF64; R];
    /// C]`, in place.
    #[inline(always)]
    pub fn matrix_mut<const R: usize, const C: usize>(
        x: &mut [[f64; R]; C],
    ) -> &mut [[FusedF64; R]; C] {
        // SAFETY: `FusedF64` is `#[repr(transparent)]` over `f64`, so it has `f64`'s size,
        // alignment and valid bit patterns; arrays lay out their elements contiguously by the
        // element's size, so `[[FusedF64; R]; C]` has the layout of `[[f64; R]; C]` and every
        // value of one is a value of the other. The result borrows `x` mutably for its lifetime,
        // so nothing else reads or writes the memory meanwhile.
        unsafe { &mut *(x as *mut [[f64; R]; C]).cast::<[[FusedF64; R]; C]>() }
    }

    /// An `f64` output seen as a `FusedF64`, in place.
    #[inline(always)]
    pub fn scalar_mut(x: &mut f64) -> &mut FusedF64 {
        // SAFETY: as in `matrix_mut`: `#[repr(transparent)]` over `f64`, borrowed mutably.
        unsafe { &mut *(x as *mut f64).cast::<FusedF64>() }
    }
}

/// Which function the `_f64` entry points of modules generated with `fma_at_run_time` take on
/// this CPU ([`path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
#[non_exhaustive]
pub enum Path {
    /// `name::<f64>` itself: no `std` (no detection), not x86-64, a build target that already
    /// has FMA (`name::<f64>` is fused there, with the same bits), or a CPU without AVX2 and FMA.
    Plain = 1,
    /// The function compiled for AVX2 and FMA.
    Fma = 2,
    /// As [`Path::Fma`], and the CPU also has AVX-512F and AVX-512VL: `name_trig_f64` (given the
    /// sines and cosines) takes the same program compiled for those too, with the same bits
    /// (every operation the same IEEE operation, every `mul_add` rounded once) and thirty-two
    /// vector registers instead of sixteen, faster given the sines and cosines (see
    /// BENCHMARKS.md, "The fused functions on AVX-512, given the sines and cosines"). The entry
    /// points from `q` keep the AVX2 + FMA function, faster there from `q`.
    Avx512 = 3,
}

/// The path of this CPU and build ([`Path`]): `std`'s CPU detection, capped by
/// `TROCAR_FMA_PATH` ([module docs](self)), made once and kept; after the first call, one load.
#[inline]
pub fn path() -> Path {
    #[cfg(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma")))]
    {
        use core::sync::atomic::Ordering;
        match ANSWER.load(Ordering::Relaxed) {
            1 => Path::Plain,
            2 => Path::Fma,
            3 => Path::Avx512,
            _ => detect(),
        }
    }
    #[cfg(not(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma"))))]
    {
        Path::Plain
    }
}

/// [`path`]'s kept answer: 0 before the first call, the answer's discriminant after.
#[cfg(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma")))]
static ANSWER: core::sync::atomic::AtomicU8 = core::sync::atomic::AtomicU8::new(0);

/// The first call of [`path`]: `std`'s detection under `TROCAR_FMA_PATH`'s cap, kept in
/// [`ANSWER`]. Out of line, so that [`path`] stays one load and a test where it is inlined (in
/// line, the environment's reading made it a call, more instructions per evaluation).
#[cfg(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma")))]
#[cold]
#[inline(never)]
fn detect() -> Path {
    let path = if !(std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma"))
    {
        Path::Plain
    } else if std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
    {
        Path::Avx512
    } else {
        Path::Fma
    };
    let path = path.min(cap(std::env::var("TROCAR_FMA_PATH").ok().as_deref()));
    ANSWER.store(path as u8, core::sync::atomic::Ordering::Relaxed);
    path
}

/// The highest path `TROCAR_FMA_PATH` allows: `plain`, `fma`, anything else (or unset) none lower
/// than [`Path::Avx512`].
#[cfg_attr(
    not(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma"))),
    allow(dead_code)
)]
fn cap(value: Option<&str>) -> Path {
    match value.map(str::trim) {
        Some(v) if v.eq_ignore_ascii_case("plain") => Path::Plain,
        Some(v) if v.eq_ignore_ascii_case("fma") => Path::Fma,
        _ => Path::Avx512,
    }
}

/// Whether the `_f64` entry points of modules generated with `fma_at_run_time` take their
/// AVX2 + FMA function (or, given the sines and cosines, the AVX-512 one): `true` on an x86-64
/// CPU with AVX2 and FMA, in a build with `std` whose target lacks FMA. `false` without `std`
/// (no detection), on other architectures, and where the target already has FMA
/// (`name::<f64>` is fused there, with the same bits). [`path`] tells which.
#[inline]
pub fn available() -> bool {
    path() >= Path::Fma
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `mul_add` is rounded once: `0.1 · 10 − 1` keeps the product's rounding error, which two
    /// operations lose; and it is `std`'s fused value bit for bit over a spread of operands.
    #[test]
    fn mul_add_is_rounded_once() {
        let two_roundings = 0.1f64 * 10.0 - 1.0;
        assert_eq!(two_roundings, 0.0);
        let once = FusedF64(0.1).mul_add(FusedF64(10.0), FusedF64(-1.0)).0;
        assert_eq!(once, 5.551115123125783e-17);
        let mut x = 0.377_f64;
        for _ in 0..1000 {
            x = (x * 3.7 + 0.31).fract() * 7.0 - 3.5;
            let (a, b) = (x * 1.3 - 0.2, -x * 0.7 + 0.9);
            let got = FusedF64(x).mul_add(FusedF64(a), FusedF64(b)).0;
            assert_eq!(got.to_bits(), libm::fma(x, a, b).to_bits(), "{x} {a} {b}");
        }
    }

    /// Everything but `mul_add` is `f64`'s own, bit for bit.
    #[test]
    fn the_rest_is_f64() {
        let xs = [0.3, -2.5, 1e-300, 7.0e5, -0.0, 3.0];
        for &x in &xs {
            let f = FusedF64(x);
            let (s, c) = f.sin_cos();
            assert_eq!((s.0, c.0), <f64 as Real>::sin_cos(x));
            assert_eq!(f.sqrt().0.to_bits(), <f64 as Real>::sqrt(x).to_bits());
            assert_eq!((-f).0.to_bits(), (-x).to_bits());
            assert_eq!((f / FusedF64(3.0)).0, x / 3.0);
        }
        let (s, c) = FusedF64::sin_cos_array(&xs.map(FusedF64));
        let (s64, c64) = <f64 as Real>::sin_cos_array(&xs);
        assert_eq!(s.map(|v| v.0.to_bits()), s64.map(f64::to_bits));
        assert_eq!(c.map(|v| v.0.to_bits()), c64.map(f64::to_bits));
    }

    /// The in-place views read and write the `f64` storage.
    #[test]
    fn views_write_in_place() {
        let q = [0.5, -1.0, 2.0];
        assert_eq!(FusedF64::array(&q).map(|v| v.0), q);
        let mut m = [[0.0f64; 2]; 3];
        FusedF64::matrix_mut(&mut m)[2][1] = FusedF64(4.5);
        assert_eq!(m[2][1], 4.5);
        let mut s = 1.0f64;
        *FusedF64::scalar_mut(&mut s) = FusedF64(-2.0);
        assert_eq!(s, -2.0);
    }

    /// The path, and [`available`] with it, agree with the CPU and the build (under
    /// `TROCAR_FMA_PATH`'s cap), and AVX-512 comes only with AVX2 and FMA. With `TROCAR_EXPECT_FMA_PATH` set (`plain`, `fma`, `avx512`; CI sets
    /// it from the CPU's flags), the path must be that one, so that a run states which
    /// functions the fused-program tests compared.
    #[test]
    fn the_path_follows_the_cpu() {
        #[cfg(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma")))]
        {
            let fma = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma");
            let avx512 = std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl");
            let detected = match (fma, avx512) {
                (false, _) => Path::Plain,
                (true, false) => Path::Fma,
                (true, true) => Path::Avx512,
            };
            let expected = detected.min(cap(std::env::var("TROCAR_FMA_PATH").ok().as_deref()));
            assert_eq!(path(), expected);
            assert_eq!(path(), expected, "the kept answer");
            assert_eq!(available(), expected != Path::Plain);
        }
        #[cfg(not(all(feature = "std", target_arch = "x86_64", not(target_feature = "fma"))))]
        {
            assert_eq!(path(), Path::Plain);
            assert!(!available());
        }
        #[cfg(feature = "std")]
        if let Ok(want) = std::env::var("TROCAR_EXPECT_FMA_PATH") {
            assert_eq!(
                format!("{:?}", path()).to_lowercase(),
                want.trim().to_lowercase()
            );
        }
    }

    /// `TROCAR_FMA_PATH`'s values.
    #[test]
    fn the_cap_reads_its_values() {
        assert_eq!(cap(None), Path::Avx512);
        assert_eq!(cap(Some("plain")), Path::Plain);
        assert_eq!(cap(Some(" FMA ")), Path::Fma);
        assert_eq!(cap(Some("avx512")), Path::Avx512);
        assert_eq!(cap(Some("anything")), Path::Avx512);
    }
}
