//! The scalar traits that generated code is written against, [`Real`] and [`Arith`].
//!
//! They are implemented for `f32` and `f64` (and, feature `lanes`, [`Arith`] for the lane types),
//! with `std` when the `std` feature is on and with [`libm`] otherwise, so generated code builds
//! in `#![no_std]` crates; `sin_cos` is this crate's own [`fast`] kernel in both builds.

use super::fast;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real scalar usable by generated kinematics (`f32` or `f64`).
///
/// Generated code calls these functions with fully qualified syntax
/// (`<T as ::trocar::emitted::Real>::sin_cos(x)`), so the names never clash with `nalgebra`'s
/// `RealField` methods in user code.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Default
    + core::fmt::Debug
    + 'static
{
    /// Additive identity.
    const ZERO: Self;
    /// Multiplicative identity.
    const ONE: Self;
    /// Converts a literal (rounded to nearest for `f32`).
    fn lit(x: f64) -> Self;
    /// Converts to `f64` (exact for both implementations).
    fn to_f64(self) -> f64;
    /// `(sin x, cos x)`.
    fn sin_cos(self) -> (Self, Self);
    /// `(sin x_k, cos x_k)` for every `k`: what generated code calls, once per control step, for
    /// all the joints it uses. Exactly [`Real::sin_cos`] of each element; `f64` on x86-64
    /// computes eight (AVX-512, AVX2) or two (SSE2 without AVX2) elements side by side, and a
    /// default-target build with `std` takes AVX2 at run time where the CPU has it
    /// ([`fast::sin_cos_f64_array`]).
    #[inline(always)]
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
        let mut s = [Self::ZERO; N];
        let mut c = [Self::ONE; N];
        for k in 0..N {
            (s[k], c[k]) = Self::sin_cos(x[k]);
        }
        (s, c)
    }
    /// `self · a + b`, fused into one instruction (one rounding) where the target has FMA and
    /// the `std` feature is on (`x86-64` with `-C target-feature=+fma` or a `target-cpu` that has
    /// it, `aarch64`); two operations (two roundings) otherwise. Generated code writes every
    /// product that is added once this way.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `true` unless NaN or infinite.
    fn is_finite(self) -> bool;
}

/// The part of [`Real`] that runs lane by lane: arithmetic, constants, `sin_cos`, `mul_add`,
/// `sqrt` and `abs`, with no comparison, branch or conversion to a single number.
///
/// Generated functions whose body is one straight-line program (forward kinematics, the
/// Jacobians, `pose_and_jacobians_trig`, the `Params` and `JointTrig` structs) are generic over
/// `T: Arith`, so they run on `f32` and `f64` and on the lane types of `lanes`
/// (feature `lanes`: four `f64` or eight `f32` configurations side by side, each lane bit for
/// bit the scalar code's result). Functions that branch on a value
/// (`manipulability`'s finiteness guard, the pivoting solves, the controller) stay `T: Real`.
///
/// Every [`Real`] is an `Arith` (a blanket implementation that calls the [`Real`] functions of
/// the same names), so `Arith` adds nothing to implement for a scalar type.
pub trait Arith:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Default
    + core::fmt::Debug
    + 'static
{
    /// Additive identity.
    const ZERO: Self;
    /// Multiplicative identity.
    const ONE: Self;
    /// Converts a literal (as [`Real::lit`]).
    fn lit(x: f64) -> Self;
    /// `(sin x, cos x)` (as [`Real::sin_cos`]).
    fn sin_cos(self) -> (Self, Self);
    /// `(sin x_k, cos x_k)` for every `k` (as [`Real::sin_cos_array`]).
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]);
    /// `self · a + b`, fused exactly where [`Real::mul_add`] is.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Square root (correctly rounded, as [`Real::sqrt`]).
    fn sqrt(self) -> Self;
    /// Absolute value (as [`Real::abs`]).
    fn abs(self) -> Self;
}

impl<T: Real> Arith for T {
    const ZERO: Self = <T as Real>::ZERO;
    const ONE: Self = <T as Real>::ONE;
    #[inline(always)]
    fn lit(x: f64) -> Self {
        <T as Real>::lit(x)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        <T as Real>::sin_cos(self)
    }
    #[inline(always)]
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
        <T as Real>::sin_cos_array(x)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        <T as Real>::mul_add(self, a, b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        <T as Real>::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        <T as Real>::abs(self)
    }
}

macro_rules! impl_real {
    ($t:ty, $fast:ident, $sqrt:ident, $fabs:ident $(, $array:ident)?) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            #[inline(always)]
            fn lit(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            /// [`fast`] with or without `std`: at most 1 ulp from glibc (`f64`), under 1 ulp
            /// from the exact value (`f32`), and faster than std's `sin_cos` (see BENCHMARKS.md).
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                fast::$fast(self)
            }
            $(
                #[inline(always)]
                fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
                    fast::$array(x)
                }
            )?
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                // The hardware instruction where there is one; std's `mul_add` elsewhere would
                // be a slow software routine, so two operations then.
                #[cfg(all(
                    feature = "std",
                    any(target_feature = "fma", target_arch = "aarch64")
                ))]
                {
                    <$t>::mul_add(self, a, b)
                }
                #[cfg(not(all(
                    feature = "std",
                    any(target_feature = "fma", target_arch = "aarch64")
                )))]
                {
                    self * a + b
                }
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::sqrt(self)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::$sqrt(self)
                }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                #[cfg(feature = "std")]
                {
                    <$t>::abs(self)
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::$fabs(self)
                }
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}

impl_real!(f64, sin_cos_f64, sqrt, fabs, sin_cos_f64_array);
impl_real!(f32, sin_cos_f32, sqrtf, fabsf, sin_cos_f32_array);

#[cfg(test)]
mod tests {
    use super::Real;

    #[test]
    fn f32_and_f64_agree_with_core_math() {
        for i in -50..50 {
            let x = i as f64 * 0.137;
            let (s, c) = <f64 as Real>::sin_cos(x);
            assert!((s - x.sin()).abs() < 1e-15 && (c - x.cos()).abs() < 1e-15);
            let (s, c) = <f32 as Real>::sin_cos(x as f32);
            assert!((s - (x as f32).sin()).abs() < 1e-6 && (c - (x as f32).cos()).abs() < 1e-6);
            assert_eq!(<f64 as Real>::sin_cos(x), super::fast::sin_cos_f64(x));
            assert_eq!(
                <f32 as Real>::sin_cos(x as f32),
                super::fast::sin_cos_f32(x as f32)
            );
        }
        assert_eq!(<f64 as Real>::sqrt(4.0), 2.0);
        assert_eq!(<f32 as Real>::abs(-2.5), 2.5);
        assert!(!<f64 as Real>::is_finite(f64::NAN));
    }
}
