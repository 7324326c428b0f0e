//! Lane types: four `f64` ([`F64x4`]) or eight `f32` ([`F32x8`]) configurations evaluated side
//! by side by generated code.
//!
//! The straight-line functions of a generated module are generic over [`Arith`], which these
//! types implement, so one call evaluates four or eight configurations with vector instructions
//! (the [`wide`](https://docs.rs/wide) crate's `f64x4` and `f32x8`: AVX where the target has it,
//! two SSE2 or NEON halves otherwise). **Each lane is bit for bit the scalar code's result** for
//! that lane's inputs:
//!
//! - `+ − × ÷`, `sqrt` are IEEE-754 operations, correctly rounded lane by lane as they are on one
//!   number; `abs` clears and `−x` flips the sign bit (so `−(+0) = −0`, as for `f64`: `wide`'s own
//!   negation computes `0 − x`, which gives `+0`, and is not used);
//! - `mul_add` is fused exactly where [`Real::mul_add`] is (the `std`
//!   feature and a target with FMA) and two operations elsewhere;
//! - `sin_cos` runs the main path of [`fast::sin_cos_f64`] / [`fast::sin_cos_f32`] on all lanes at
//!   once (`F64x4` on `wide::f64x4` itself, the same arithmetic text as the scalar function;
//!   `F32x8` through [`fast::sin_cos_f32_lanes`]); when a lane needs the careful reduction,
//!   `F64x4` recomputes its four lanes with the scalar function and `F32x8` recomputes its lanes
//!   side by side, each with the reduction the scalar function would choose (`F64x4` on its
//!   vector type is faster with AVX-512 than through arrays of four: BENCHMARKS.md, "`F64x4`'s
//!   sines and cosines on its vector type").
//!   `sin_cos_array` (a chain's joints at once) on `F64x4`, where the target has AVX2 or
//!   AVX-512, takes the joints four, then two at a time as sixteen or eight `f64` through
//!   [`fast::sin_cos_f64_lanes`], the scalar code's group kernel, and on `F32x8` two at a time
//!   as sixteen `f32` through [`fast::sin_cos_f32_lanes`] (see BENCHMARKS.md, "Slices of
//!   configurations written in place" and "`f32` joints in groups of eight").
//!
//! ```
//! use trocar::emitted::lanes::{F64x4, Lanes};
//! use trocar::Arith;
//!
//! // Any function generic over `Arith`, as generated code is.
//! fn f<T: Arith>(q: &[T; 2]) -> [T; 2] {
//!     let ([s0, s1], [c0, c1]) = T::sin_cos_array(q);
//!     [T::mul_add(s0, c1, c0 * s1), c0 * c1 - s0 * s1]
//! }
//!
//! let configs = [[0.1, 0.2], [0.3, -0.4], [1.5, 2.5], [-3.0, 0.0]];
//! let q: [F64x4; 2] = F64x4::gather(&configs);
//! let out = f(&q);
//! for (k, c) in configs.iter().enumerate() {
//!     assert_eq!(out.lane(k), f(c)); // bit for bit
//! }
//! ```
//!
//! [`for_each_f64x4`] and [`for_each_f32x8`] run such a function over a slice of any length (the
//! last group padded) into a slice of results.

use super::{fast, Arith, Real};
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

macro_rules! lane_type {
    (
        $(#[$doc:meta])*
        $name:ident, $wide:ident, $scalar:ty, $w:literal, $bits:ty, $kernel:path, $array:path
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Default, PartialEq)]
        #[repr(transparent)]
        pub struct $name(wide::$wide);

        impl $name {
            /// Number of lanes.
            pub const LANES: usize = $w;

            /// Every lane `x`.
            #[inline(always)]
            #[must_use]
            pub fn splat(x: $scalar) -> Self {
                Self(wide::$wide::new([x; $w]))
            }

            /// The lanes from an array (lane `k` is `a[k]`).
            #[inline(always)]
            #[must_use]
            pub fn from_array(a: [$scalar; $w]) -> Self {
                Self(wide::$wide::new(a))
            }

            /// The lanes as an array.
            #[inline(always)]
            #[must_use]
            pub fn to_array(self) -> [$scalar; $w] {
                self.0.to_array()
            }

            /// Lane `k` (`k < LANES`).
            #[inline(always)]
            #[must_use]
            pub fn get(self, k: usize) -> $scalar {
                self.0.as_array_ref()[k]
            }

            /// Configurations to lanes: `configs[k][j]` becomes lane `k` of element `j`.
            #[inline(always)]
            #[must_use]
            pub fn gather<const N: usize>(configs: &[[$scalar; N]; $w]) -> [Self; N] {
                core::array::from_fn(|j| Self::from_array(core::array::from_fn(|k| configs[k][j])))
            }

            /// Each lane by itself: `f` of the lanes' elements.
            #[cfg(not(all(
                target_feature = "sse2",
                any(target_arch = "x86", target_arch = "x86_64")
            )))]
            #[inline(always)]
            fn map(self, f: impl Fn($scalar) -> $scalar) -> Self {
                let a = self.to_array();
                Self::from_array(core::array::from_fn(|k| f(a[k])))
            }
        }

        impl From<[$scalar; $w]> for $name {
            #[inline(always)]
            fn from(a: [$scalar; $w]) -> Self {
                Self::from_array(a)
            }
        }

        impl From<$name> for [$scalar; $w] {
            #[inline(always)]
            fn from(x: $name) -> Self {
                x.to_array()
            }
        }

        impl core::fmt::Debug for $name {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(f, "{}({:?})", stringify!($name), self.to_array())
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, b: Self) -> Self {
                Self(self.0 + b.0)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, b: Self) -> Self {
                Self(self.0 - b.0)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, b: Self) -> Self {
                Self(self.0 * b.0)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, b: Self) -> Self {
                Self(self.0 / b.0)
            }
        }
        impl Neg for $name {
            type Output = Self;
            /// The sign bit flipped, as `-x` on one number (`-(+0) = -0`).
            #[inline(always)]
            fn neg(self) -> Self {
                Self(self.0 ^ wide::$wide::new([-0.0; $w]))
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
            const ZERO: Self = Self(wide::$wide::new([0.0; $w]));
            const ONE: Self = Self(wide::$wide::new([1.0; $w]));
            #[inline(always)]
            fn lit(x: f64) -> Self {
                Self::splat(<$scalar as Real>::lit(x))
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                let (s, c) = $kernel(self.0);
                (Self(s), Self(c))
            }
            #[inline(always)]
            fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
                $array(x)
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                // Fused exactly where `Real::mul_add` of one number is: with `std` on a target
                // with FMA. `wide`'s `mul_add` is then the fused instruction on x86 (it is fused
                // there iff the target has `fma`); elsewhere (aarch64) each lane goes through
                // the scalar fused operation.
                #[cfg(all(
                    feature = "std",
                    target_feature = "fma",
                    any(target_arch = "x86", target_arch = "x86_64")
                ))]
                {
                    Self(self.0.mul_add(a.0, b.0))
                }
                #[cfg(all(
                    feature = "std",
                    any(target_feature = "fma", target_arch = "aarch64"),
                    not(any(target_arch = "x86", target_arch = "x86_64"))
                ))]
                {
                    let (x, a, b) = (self.to_array(), a.to_array(), b.to_array());
                    Self::from_array(core::array::from_fn(|k| {
                        <$scalar as Real>::mul_add(x[k], a[k], b[k])
                    }))
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
                // The SSE2/AVX square root is IEEE-754's, correctly rounded like the scalar one;
                // elsewhere lane by lane through the scalar function.
                #[cfg(all(
                    target_feature = "sse2",
                    any(target_arch = "x86", target_arch = "x86_64")
                ))]
                {
                    Self(self.0.sqrt())
                }
                #[cfg(not(all(
                    target_feature = "sse2",
                    any(target_arch = "x86", target_arch = "x86_64")
                )))]
                {
                    self.map(<$scalar as Real>::sqrt)
                }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                Self(self.0 & wide::$wide::new([<$scalar>::from_bits(<$bits>::MAX >> 1); $w]))
            }
        }

        impl Lanes for $name {
            type Lane = $scalar;
            const LANES: usize = $w;
            #[inline(always)]
            fn lane(&self, k: usize) -> $scalar {
                self.get(k)
            }
            #[inline(always)]
            fn zeroed() -> Self {
                <Self as Arith>::ZERO
            }
            #[inline(always)]
            fn write_lanes<S: Slots<$scalar> + ?Sized>(&self, slots: &mut S) {
                let a = self.to_array();
                for (k, x) in a.into_iter().enumerate() {
                    *slots.slot(k) = x;
                }
            }
            /// Blocks of four elements transposed: lane `k`'s four values stored together.
            #[inline(always)]
            fn write_array_lanes<const N: usize, S: Slots<[$scalar; N]> + ?Sized>(
                a: &[Self; N],
                slots: &mut S,
            ) {
                let mut j = 0;
                while j + 4 <= N {
                    let b = [
                        a[j].to_array(),
                        a[j + 1].to_array(),
                        a[j + 2].to_array(),
                        a[j + 3].to_array(),
                    ];
                    for k in 0..$w {
                        let four = [b[0][k], b[1][k], b[2][k], b[3][k]];
                        slots.slot(k)[j..j + 4].copy_from_slice(&four);
                    }
                    j += 4;
                }
                while j < N {
                    for (k, x) in a[j].to_array().into_iter().enumerate() {
                        slots.slot(k)[j] = x;
                    }
                    j += 1;
                }
            }
        }
    };
}

/// `sin_cos` of each element.
#[inline(always)]
fn each<L: Arith, const N: usize>(x: &[L; N]) -> ([L; N], [L; N]) {
    let mut s = [L::ZERO; N];
    let mut c = [L::ONE; N];
    for k in 0..N {
        (s[k], c[k]) = x[k].sin_cos();
    }
    (s, c)
}

/// The elements' sines and cosines, two at a time as sixteen `f32` through
/// [`fast::sin_cos_f32_lanes`], an odd last element alone.
#[inline(always)]
fn sin_cos_array_f32x8<const N: usize>(x: &[F32x8; N]) -> ([F32x8; N], [F32x8; N]) {
    let mut s = [F32x8::ZERO; N];
    let mut c = [F32x8::ONE; N];
    let mut k = 0;
    while k + 2 <= N {
        group_f32x8::<N, 2, 16>(x, k, &mut s, &mut c);
        k += 2;
    }
    if k < N {
        (s[k], c[k]) = x[k].sin_cos();
    }
    (s, c)
}

/// Elements `k..k + G` of `x` as `M = 8 G` `f32` through [`fast::sin_cos_f32_lanes`] into `s`,
/// `c` (lane `l` of element `k + j` at `8 j + l`).
#[inline(always)]
fn group_f32x8<const N: usize, const G: usize, const M: usize>(
    x: &[F32x8; N],
    k: usize,
    s: &mut [F32x8; N],
    c: &mut [F32x8; N],
) {
    const { assert!(M == 8 * G) };
    let all: [f32; M] = core::array::from_fn(|l| x[k + l / 8].0.as_array_ref()[l % 8]);
    let (se, ce) = fast::sin_cos_f32_lanes::<M>(&all);
    for j in 0..G {
        s[k + j] = F32x8::from_array(core::array::from_fn(|l| se[8 * j + l]));
        c[k + j] = F32x8::from_array(core::array::from_fn(|l| ce[8 * j + l]));
    }
}

/// The elements' sines and cosines, where the target has AVX2 or AVX-512 four elements at a
/// time as sixteen `f64`, then two at a time as eight, through [`fast::sin_cos_f64_lanes`] (the
/// scalar code's group kernel, bit for bit [`fast::sin_cos_f64`] of each lane), an odd last
/// element on its vector type; each element on its vector type elsewhere.
#[inline(always)]
fn sin_cos_array_f64x4<const N: usize>(x: &[F64x4; N]) -> ([F64x4; N], [F64x4; N]) {
    if fast::F64_LANES != 8 {
        return each(x);
    }
    let mut s = [F64x4::ZERO; N];
    let mut c = [F64x4::ONE; N];
    let mut k = 0;
    while k + 4 <= N {
        group_f64x4::<N, 4, 16>(x, k, &mut s, &mut c);
        k += 4;
    }
    while k + 2 <= N {
        group_f64x4::<N, 2, 8>(x, k, &mut s, &mut c);
        k += 2;
    }
    if k < N {
        (s[k], c[k]) = x[k].sin_cos();
    }
    (s, c)
}

/// Elements `k..k + G` of `x` as `M = 4 G` `f64` through [`fast::sin_cos_f64_lanes`] into `s`,
/// `c` (lane `l` of element `k + j` at `4 j + l`).
#[inline(always)]
fn group_f64x4<const N: usize, const G: usize, const M: usize>(
    x: &[F64x4; N],
    k: usize,
    s: &mut [F64x4; N],
    c: &mut [F64x4; N],
) {
    const { assert!(M == 4 * G) };
    let all: [f64; M] = core::array::from_fn(|l| x[k + l / 4].0.as_array_ref()[l % 4]);
    let (se, ce) = fast::sin_cos_f64_lanes::<M>(&all);
    for j in 0..G {
        s[k + j] = F64x4::from_array(core::array::from_fn(|l| se[4 * j + l]));
        c[k + j] = F64x4::from_array(core::array::from_fn(|l| ce[4 * j + l]));
    }
}

/// [`fast::sin_cos_f32_lanes`] of the eight lanes.
#[inline(always)]
fn sin_cos_f32x8(x: wide::f32x8) -> (wide::f32x8, wide::f32x8) {
    let (s, c) = fast::sin_cos_f32_lanes::<8>(&x.to_array());
    (wide::f32x8::new(s), wide::f32x8::new(c))
}

lane_type!(
    /// Four `f64` lanes (`wide::f64x4`: one AVX register, or two SSE2/NEON ones).
    F64x4, f64x4, f64, 4, u64, fast::sin_cos_f64x4, sin_cos_array_f64x4
);
lane_type!(
    /// Eight `f32` lanes (`wide::f32x8`: one AVX register, or two SSE2/NEON ones).
    F32x8, f32x8, f32, 8, u32, sin_cos_f32x8, sin_cos_array_f32x8
);

/// A value made of lane types (a lane type, arrays and tuples of them: what generated functions
/// return) and the same value for one lane.
pub trait Lanes {
    /// The value of one lane (`f64` for [`F64x4`], `[f64; 3]` for `[F64x4; 3]`, ...).
    type Lane;
    /// Number of lanes.
    const LANES: usize;
    /// The value of lane `k` (`k < LANES`).
    fn lane(&self, k: usize) -> Self::Lane;
    /// The value whose every lane is all zeros (what [`for_each_f64x4`] and [`for_each_f32x8`]
    /// start their value in lanes from; arrays of any length have one, unlike `Default`).
    fn zeroed() -> Self
    where
        Self: Sized;
    /// Every lane into its slot: `*slots.slot(k) = self.lane(k)` for `k < LANES` (what
    /// [`for_each_f64x4`] and [`for_each_f32x8`] write their results with). The lane types,
    /// their arrays and tuples write element by element in place, without building each lane's
    /// value and moving it, blocks of four array elements transposed; this provided version
    /// builds each lane's value.
    #[inline(always)]
    fn write_lanes<S: Slots<Self::Lane> + ?Sized>(&self, slots: &mut S) {
        for k in 0..Self::LANES {
            *slots.slot(k) = self.lane(k);
        }
    }
    /// [`write_lanes`](Lanes::write_lanes) of an array of values: what `[Self; N]` writes with,
    /// so that a lane type can write several elements of an array together. Element by element
    /// unless a lane type does better. Not meant to be called directly.
    #[doc(hidden)]
    #[inline(always)]
    fn write_array_lanes<const N: usize, S: Slots<[Self::Lane; N]> + ?Sized>(
        a: &[Self; N],
        slots: &mut S,
    ) where
        Self: Sized,
    {
        for (j, x) in a.iter().enumerate() {
            x.write_lanes(&mut Part::new(slots, move |t: &mut [Self::Lane; N]| {
                &mut t[j]
            }));
        }
    }
}

/// Where the lanes of a value go, one slot per lane (see [`Lanes::write_lanes`]).
pub trait Slots<T> {
    /// The slot of lane `k` (`k < LANES` of the value written).
    fn slot(&mut self, k: usize) -> &mut T;
}

/// Lane `k` into element `k`.
impl<T, const W: usize> Slots<T> for [T; W] {
    #[inline(always)]
    fn slot(&mut self, k: usize) -> &mut T {
        &mut self[k]
    }
}

/// Lane `k` into element `k` (panics if the slice is shorter than the value's lanes).
impl<T> Slots<T> for [T] {
    #[inline(always)]
    fn slot(&mut self, k: usize) -> &mut T {
        &mut self[k]
    }
}

/// One part of every slot of `S` (an element of an array, a field of a tuple): the slots of a
/// value's part, so that a nested value writes its lanes part by part.
struct Part<'a, S: ?Sized, T, F> {
    slots: &'a mut S,
    part: F,
    whole: PhantomData<fn(&mut T)>,
}

impl<'a, S: ?Sized, T, F> Part<'a, S, T, F> {
    #[inline(always)]
    fn new<U>(slots: &'a mut S, part: F) -> Self
    where
        S: Slots<T>,
        F: Fn(&mut T) -> &mut U,
    {
        Self {
            slots,
            part,
            whole: PhantomData,
        }
    }
}

impl<T, U, S: Slots<T> + ?Sized, F: Fn(&mut T) -> &mut U> Slots<U> for Part<'_, S, T, F> {
    #[inline(always)]
    fn slot(&mut self, k: usize) -> &mut U {
        (self.part)(self.slots.slot(k))
    }
}

impl<L: Lanes, const N: usize> Lanes for [L; N] {
    type Lane = [L::Lane; N];
    const LANES: usize = L::LANES;
    #[inline(always)]
    fn lane(&self, k: usize) -> Self::Lane {
        core::array::from_fn(|j| self[j].lane(k))
    }
    #[inline(always)]
    fn zeroed() -> Self {
        core::array::from_fn(|_| L::zeroed())
    }
    #[inline(always)]
    fn write_lanes<S: Slots<Self::Lane> + ?Sized>(&self, slots: &mut S) {
        L::write_array_lanes(self, slots);
    }
}

macro_rules! tuple_lanes {
    ($($t:ident $i:tt),+) => {
        impl<$($t: Lanes),+> Lanes for ($($t,)+) {
            type Lane = ($($t::Lane,)+);
            const LANES: usize = <tuple_lanes!(@first $($t)+)>::LANES;
            #[inline(always)]
            fn lane(&self, k: usize) -> Self::Lane {
                ($(self.$i.lane(k),)+)
            }
            #[inline(always)]
            fn zeroed() -> Self {
                ($($t::zeroed(),)+)
            }
            #[inline(always)]
            fn write_lanes<S: Slots<Self::Lane> + ?Sized>(&self, slots: &mut S) {
                $(self.$i.write_lanes(&mut Part::new(slots, |t: &mut Self::Lane| &mut t.$i));)+
            }
        }
    };
    (@first $a:ident $($rest:ident)*) => { $a };
}

tuple_lanes!(A 0, B 1);
tuple_lanes!(A 0, B 1, C 2);
tuple_lanes!(A 0, B 1, C 2, D 3);

macro_rules! for_each {
    ($(#[$doc:meta])* $fn:ident, $lanes:ident, $scalar:ty, $w:literal) => {
        $(#[$doc])*
        pub fn $fn<const N: usize, R: Lanes>(
            configs: &[[$scalar; N]],
            mut f: impl FnMut(&[$lanes; N], &mut R),
            out: &mut [R::Lane],
        ) {
            assert_eq!(
                configs.len(),
                out.len(),
                "{}: {} configurations and {} results",
                stringify!($fn),
                configs.len(),
                out.len()
            );
            // One value in lanes, kept from group to group: `f` writes into it and its lanes are
            // written out in place, nothing built, returned or moved per group.
            let mut r = R::zeroed();
            let mut groups = out.chunks_exact_mut($w);
            let mut start = 0;
            for slots in &mut groups {
                let group: &[[$scalar; N]; $w] = configs[start..start + $w]
                    .try_into()
                    .expect("a group of the chunk's length");
                let slots: &mut [R::Lane; $w] =
                    slots.try_into().expect("a chunk of the group's length");
                f(&$lanes::gather(group), &mut r);
                r.write_lanes(slots);
                start += $w;
            }
            let rest = groups.into_remainder();
            if let Some(last) = configs[start..].last() {
                // The spare lanes of the last group repeat its last configuration.
                let group: [[$scalar; N]; $w] =
                    core::array::from_fn(|k| *configs.get(start + k).unwrap_or(last));
                f(&$lanes::gather(&group), &mut r);
                for (k, slot) in rest.iter_mut().enumerate() {
                    *slot = r.lane(k);
                }
            }
        }
    };
}

for_each!(
    /// `f` of every configuration, four at a time on [`F64x4`] lanes, into `out`: `out[i]` becomes
    /// the value for `configs[i]`, bit for bit what `f` of that configuration alone on `f64` gives
    /// when `f` is a generated function (generic over [`Arith`]).
    ///
    /// `f` writes a group's results into a value in lanes, `r`, as the generated functions with
    /// output arguments do (`|q, o: &mut ([F64x4; 3], [F64x4; 3])| arm::g(q, &p, &mut o.0, &mut
    /// o.1)`: the closure's second argument needs its type); a function that returns its value is
    /// called as `|q, r| *r = g(q)`. `r` starts as [`Lanes::zeroed`] and is kept from group to
    /// group, so it holds the previous group's values when `f` is called: `f` must write all of
    /// it (the generated functions do). The last group is padded with its last configuration.
    /// Whole groups' results are written in place ([`Lanes::write_lanes`]), the last partial
    /// group's lane by lane.
    ///
    /// # Panics
    ///
    /// If `out` and `configs` differ in length.
    ///
    /// ```
    /// use trocar::emitted::lanes::for_each_f64x4;
    /// use trocar::Arith;
    ///
    /// fn norm2<T: Arith>(q: &[T; 3]) -> T {
    ///     T::mul_add(q[0], q[0], T::mul_add(q[1], q[1], q[2] * q[2]))
    /// }
    /// let configs = vec![[1.0, 2.0, 2.0]; 5];
    /// let mut out = vec![0.0; 5];
    /// for_each_f64x4(&configs, |q, r| *r = norm2(q), &mut out);
    /// assert_eq!(out, vec![9.0; 5]);
    /// ```
    for_each_f64x4, F64x4, f64, 4
);
for_each!(
    /// `f` of every configuration, eight at a time on [`F32x8`] lanes, into `out` (see
    /// [`for_each_f64x4`]).
    ///
    /// # Panics
    ///
    /// If `out` and `configs` differ in length.
    for_each_f32x8, F32x8, f32, 8
);

#[cfg(test)]
mod tests {
    use super::fast::{sin_cos_f32, sin_cos_f64};
    use super::*;

    /// splitmix64: reproducible pseudo-random bits.
    struct Bits(u64);
    impl Bits {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
    }

    /// Arguments of every kind: edges, then uniform in ±8, in ±2¹⁰, any bit pattern (all
    /// exponents, NaN, ±∞, subnormals), and neighbours of multiples of π/2 (where the reduction
    /// cancels).
    fn f64_samples(n: usize) -> Vec<f64> {
        let mut r = Bits(7);
        let mut v = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            core::f64::consts::FRAC_PI_4,
            -core::f64::consts::FRAC_PI_4,
            fast::F64_FAST_LIMIT,
            -fast::F64_FAST_LIMIT,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        // In blocks of one kind, so that most groups of lanes take the side-by-side path (one
        // argument that needs the careful reduction sends its lane, or on `F64x4`'s own vector
        // its four lanes, to the scalar function).
        for i in 0..n {
            let u = (r.next() >> 11) as f64 / (1u64 << 53) as f64;
            v.push(match 4 * i / n {
                0 => 16.0 * u - 8.0,
                1 => 2048.0 * u - 1024.0,
                2 => f64::from_bits(r.next()),
                _ => {
                    let k = (r.next() % 2000) as f64 - 1000.0;
                    let x = k * core::f64::consts::FRAC_PI_2;
                    f64::from_bits(x.to_bits().wrapping_add(r.next() % 9).wrapping_sub(4))
                }
            });
        }
        v
    }

    fn same64(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// A scalar operation of up to three operands.
    type Op64 = fn(f64, f64, f64) -> f64;
    /// A scalar operation of up to three operands.
    type Op32 = fn(f32, f32, f32) -> f32;

    fn same32(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn f64_lanes_sin_cos_is_the_scalar_one_bit_for_bit() {
        let v = f64_samples(40_000);
        for (i, w) in v.chunks_exact(4).enumerate() {
            let x = F64x4::from_array([w[0], w[1], w[2], w[3]]);
            let (s, c) = x.sin_cos();
            for (k, &xk) in w.iter().enumerate() {
                let (s1, c1) = sin_cos_f64(xk);
                assert!(
                    same64(s.get(k), s1) && same64(c.get(k), c1),
                    "group {i}, x = {xk:e}"
                );
            }
        }
    }

    /// `sin_cos_array` of one to nine elements (pairs as groups of eight where the target has
    /// AVX2 or AVX-512, an odd last one on its vector type), each lane [`sin_cos_f64`]'s bits.
    #[test]
    fn f64_lanes_sin_cos_array_is_the_scalar_one_bit_for_bit() {
        fn check<const N: usize>(v: &[f64]) {
            for (i, w) in v.chunks_exact(4 * N).enumerate() {
                let x: [F64x4; N] = core::array::from_fn(|j| {
                    F64x4::from_array(core::array::from_fn(|k| w[4 * j + k]))
                });
                let (s, c) = F64x4::sin_cos_array(&x);
                for j in 0..N {
                    for k in 0..4 {
                        let (s1, c1) = sin_cos_f64(w[4 * j + k]);
                        assert!(
                            same64(s[j].get(k), s1) && same64(c[j].get(k), c1),
                            "N = {N}, group {i}, element {j}, lane {k}, x = {:e}",
                            w[4 * j + k]
                        );
                    }
                }
            }
        }
        let v = f64_samples(20_160);
        check::<1>(&v);
        check::<2>(&v);
        check::<3>(&v);
        check::<7>(&v);
        check::<9>(&v);
    }

    /// `F32x8::sin_cos_array` of one to nine elements (pairs as sixteen `f32`, an odd last one
    /// alone), each lane [`sin_cos_f32`]'s bits.
    #[test]
    fn f32_lanes_sin_cos_array_is_the_scalar_one_bit_for_bit() {
        fn check<const N: usize>(v: &[f32]) {
            for (i, w) in v.chunks_exact(8 * N).enumerate() {
                let x: [F32x8; N] = core::array::from_fn(|j| {
                    F32x8::from_array(core::array::from_fn(|k| w[8 * j + k]))
                });
                let (s, c) = F32x8::sin_cos_array(&x);
                for j in 0..N {
                    for k in 0..8 {
                        let (s1, c1) = sin_cos_f32(w[8 * j + k]);
                        assert!(
                            same32(s[j].get(k), s1) && same32(c[j].get(k), c1),
                            "N = {N}, group {i}, element {j}, lane {k}, x = {:e}",
                            w[8 * j + k]
                        );
                    }
                }
            }
        }
        let v: Vec<f32> = f64_samples(40_320).iter().map(|&x| x as f32).collect();
        check::<1>(&v);
        check::<2>(&v);
        check::<3>(&v);
        check::<7>(&v);
        check::<9>(&v);
    }

    #[test]
    fn f32_lanes_sin_cos_is_the_scalar_one_bit_for_bit() {
        let mut v: Vec<f32> = f64_samples(40_000).iter().map(|&x| x as f32).collect();
        let mut r = Bits(11);
        v.extend((0..40_000).map(|_| f32::from_bits(r.next() as u32)));
        // Every f32 around π/4 (the kernels' own range ends there) and around the fast limit.
        for base in [core::f32::consts::FRAC_PI_4, fast::F32_FAST_LIMIT] {
            for d in -64i32..64 {
                v.push(f32::from_bits((base.to_bits() as i32 + d) as u32));
                v.push(-f32::from_bits((base.to_bits() as i32 + d) as u32));
            }
        }
        v.truncate(v.len() / 8 * 8);
        for (i, w) in v.chunks_exact(8).enumerate() {
            let x = F32x8::from_array(core::array::from_fn(|k| w[k]));
            let (s, c) = x.sin_cos();
            for (k, &xk) in w.iter().enumerate() {
                let (s1, c1) = sin_cos_f32(xk);
                assert!(
                    same32(s.get(k), s1) && same32(c.get(k), c1),
                    "group {i}, x = {xk:e}"
                );
            }
        }
    }

    #[test]
    fn lane_arithmetic_is_the_scalar_arithmetic_bit_for_bit() {
        let v = f64_samples(8_000);
        let at = |i: usize| v[i % v.len()];
        for i in 0..v.len() {
            let a: [f64; 4] = core::array::from_fn(|k| at(i + k));
            let b: [f64; 4] = core::array::from_fn(|k| at(3 * i + 5 * k + 1));
            let c: [f64; 4] = core::array::from_fn(|k| at(7 * i + k + 2));
            let (x, y, z) = (F64x4::from(a), F64x4::from(b), F64x4::from(c));
            let ops: [(F64x4, Op64); 8] = [
                (x + y, |a, b, _| a + b),
                (x - y, |a, b, _| a - b),
                (x * y, |a, b, _| a * b),
                (x / y, |a, b, _| a / b),
                (-x, |a, _, _| -a),
                (Arith::abs(x), |a, _, _| <f64 as Real>::abs(a)),
                (Arith::sqrt(x), |a, _, _| <f64 as Real>::sqrt(a)),
                (Arith::mul_add(x, y, z), <f64 as Real>::mul_add),
            ];
            for (j, (lanes, f)) in ops.iter().enumerate() {
                for k in 0..4 {
                    assert!(same64(lanes.get(k), f(a[k], b[k], c[k])), "op {j}");
                }
            }
            let (a32, b32, c32) = (
                a.map(|x| x as f32),
                b.map(|x| x as f32),
                c.map(|x| x as f32),
            );
            let w = |p: [f32; 4], q: [f32; 4]| {
                F32x8::from_array(core::array::from_fn(
                    |k| if k < 4 { p[k] } else { q[k - 4] },
                ))
            };
            let (x, y, z) = (w(a32, c32), w(b32, a32), w(c32, b32));
            let s = |l: F32x8| l.to_array();
            let pairs: [([f32; 8], Op32); 8] = [
                (s(x + y), |a, b, _| a + b),
                (s(x - y), |a, b, _| a - b),
                (s(x * y), |a, b, _| a * b),
                (s(x / y), |a, b, _| a / b),
                (s(-x), |a, _, _| -a),
                (s(Arith::abs(x)), |a, _, _| <f32 as Real>::abs(a)),
                (s(Arith::sqrt(x)), |a, _, _| <f32 as Real>::sqrt(a)),
                (s(Arith::mul_add(x, y, z)), <f32 as Real>::mul_add),
            ];
            let (xa, ya, za) = (x.to_array(), y.to_array(), z.to_array());
            for (j, (lanes, f)) in pairs.iter().enumerate() {
                for k in 0..8 {
                    assert!(same32(lanes[k], f(xa[k], ya[k], za[k])), "f32 op {j}");
                }
            }
        }
        assert_eq!(<F64x4 as Arith>::lit(0.1).to_array(), [0.1; 4]);
        assert_eq!(<F32x8 as Arith>::lit(0.1).to_array(), [0.1f32; 8]);
        assert_eq!((-F64x4::ZERO).get(2).to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn lanes_of_nested_values_and_the_slice_driver() {
        let configs: Vec<[f64; 2]> = (0..11).map(|i| [i as f64 * 0.3, 1.0 - i as f64]).collect();
        fn f<T: Arith>(q: &[T; 2]) -> ([T; 2], T) {
            let (s, c) = T::sin_cos_array(q);
            ([s[0] * c[1], c[0]], T::mul_add(s[1], s[1], c[1] * c[1]))
        }
        // Lengths 0..=11 cover no group, whole groups, and every size of a padded last group.
        for n in 0..=configs.len() {
            let c = &configs[..n];
            let mut out = vec![([f64::NAN; 2], f64::NAN); n];
            for_each_f64x4(c, |q, r| *r = f(q), &mut out);
            for (i, v) in out.iter().enumerate() {
                let w = f(&c[i]);
                assert!(
                    same64(v.0[0], w.0[0]) && same64(v.0[1], w.0[1]) && same64(v.1, w.1),
                    "f64x4, {n} configurations, result {i}"
                );
            }
            let c32: Vec<[f32; 2]> = c.iter().map(|c| c.map(|x| x as f32)).collect();
            let mut out = vec![([f32::NAN; 2], f32::NAN); n];
            for_each_f32x8(&c32, |q, r| *r = f(q), &mut out);
            for (i, v) in out.iter().enumerate() {
                let w = f(&c32[i]);
                assert!(
                    same32(v.0[0], w.0[0]) && same32(v.0[1], w.0[1]) && same32(v.1, w.1),
                    "f32x8, {n} configurations, result {i}"
                );
            }
        }
    }

    #[test]
    fn write_lanes_is_lane_by_lane() {
        let x = [F64x4::from_array([1.0, 2.0, 3.0, 4.0]), F64x4::splat(-0.0)];
        let v = (x, [x, x], F64x4::from_array([5.0, 6.0, 7.0, 8.0]));
        let mut slots = [([0.5; 2], [[0.5; 2]; 2], 0.5); 4];
        v.write_lanes(&mut slots);
        for (k, s) in slots.iter().enumerate() {
            assert_eq!(format!("{s:?}"), format!("{:?}", v.lane(k)), "lane {k}");
        }
    }

    /// Arrays of 1, 4, 5, 8 and 9 elements (no block of four, whole blocks, blocks and a rest)
    /// nested in tuples and arrays, on both lane types: `write_lanes` (and `for_each` through
    /// it) lane by lane what `lane` gives.
    #[test]
    fn write_lanes_transposes_blocks_of_four() {
        type V<L> = ([L; 1], [L; 4], ([L; 5], [[L; 8]; 2]), [L; 9]);
        fn value<L: Lanes + Copy>(mut next: impl FnMut() -> L) -> V<L> {
            let mut a = <V<L> as Lanes>::zeroed();
            a.0 = core::array::from_fn(|_| next());
            a.1 = core::array::from_fn(|_| next());
            a.2 .0 = core::array::from_fn(|_| next());
            a.2 .1 = core::array::from_fn(|_| core::array::from_fn(|_| next()));
            a.3 = core::array::from_fn(|_| next());
            a
        }
        let mut x = 0.0;
        let v64 = value(|| {
            x += 1.0;
            F64x4::from_array(core::array::from_fn(|k| x + 0.25 * k as f64))
        });
        let mut slots = [<V<F64x4> as Lanes>::zeroed().lane(0); 4];
        v64.write_lanes(&mut slots);
        for (k, s) in slots.iter().enumerate() {
            assert_eq!(
                format!("{s:?}"),
                format!("{:?}", v64.lane(k)),
                "f64x4 lane {k}"
            );
        }
        let mut x = 0.0;
        let v32 = value(|| {
            x += 1.0;
            F32x8::from_array(core::array::from_fn(|k| x + 0.125 * k as f32))
        });
        let mut slots = vec![<V<F32x8> as Lanes>::zeroed().lane(0); 8];
        v32.write_lanes(&mut slots[..]);
        for (k, s) in slots.iter().enumerate() {
            assert_eq!(
                format!("{s:?}"),
                format!("{:?}", v32.lane(k)),
                "f32x8 lane {k}"
            );
        }
        // The same through `for_each`, whole groups and a partial last one.
        let configs: Vec<[f32; 1]> = (0..11).map(|i| [i as f32]).collect();
        let f = |q: &[F32x8; 1], r: &mut V<F32x8>| {
            let mut n = 0.0;
            *r = value(|| {
                n += 1.0;
                q[0] * F32x8::splat(n)
            });
        };
        let mut out = vec![<V<F32x8> as Lanes>::zeroed().lane(0); configs.len()];
        for_each_f32x8(&configs, f, &mut out);
        for (i, c) in configs.iter().enumerate() {
            let mut r = <V<F32x8> as Lanes>::zeroed();
            f(&[F32x8::splat(c[0])], &mut r);
            assert_eq!(
                format!("{:?}", out[i]),
                format!("{:?}", r.lane(0)),
                "result {i}"
            );
        }
    }

    #[test]
    #[should_panic(expected = "3 configurations and 2 results")]
    fn for_each_wants_one_result_per_configuration() {
        let mut out = [0.0; 2];
        for_each_f64x4(&[[0.0]; 3], |q: &[F64x4; 1], r| *r = q[0], &mut out);
    }
}
