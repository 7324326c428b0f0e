//! The scalar trait that generated code is written against.
//!
//! Generated modules depend on this trait and nothing else from the runtime: it is the whole
//! "runtime surface" of emitted code. It is implemented for `f32` and `f64`, with `std` when the
//! `std` feature is on and with [`libm`] otherwise, so generated code builds in `#![no_std]` crates.

use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real scalar usable by generated kinematics (`f32` or `f64`).
///
/// Generated code calls these functions with fully qualified syntax
/// (`<T as ::trocar::Real>::sin_cos(x)`), so the names never clash with `nalgebra`'s
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
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `true` unless NaN or infinite.
    fn is_finite(self) -> bool;
}

macro_rules! impl_real {
    ($t:ty, $sin:ident, $cos:ident, $sqrt:ident, $fabs:ident) => {
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
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                #[cfg(feature = "std")]
                {
                    <$t>::sin_cos(self)
                }
                #[cfg(not(feature = "std"))]
                {
                    (libm::$sin(self), libm::$cos(self))
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

impl_real!(f64, sin, cos, sqrt, fabs);
impl_real!(f32, sinf, cosf, sqrtf, fabsf);

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
        }
        assert_eq!(<f64 as Real>::sqrt(4.0), 2.0);
        assert_eq!(<f32 as Real>::abs(-2.5), 2.5);
        assert!(!<f64 as Real>::is_finite(f64::NAN));
    }
}
