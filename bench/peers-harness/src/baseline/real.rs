//! The runtime surface of the frozen baseline: `trocar::Real` for `f64` and its `sin_cos`
//! kernel as they were at commit f680db9 (2026-11-23), copied verbatim (the `f32` half left
//! out). Frozen so that later changes to the runtime do not move the baseline.
#![allow(dead_code, clippy::all)]

/// The part of `trocar::Real` the baseline modules call, for `f64` only.
pub trait Real: Copy {
    /// Additive identity.
    const ZERO: Self;
    /// Multiplicative identity.
    const ONE: Self;
    /// `(sin x_k, cos x_k)` of every element.
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]);
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn sin_cos_array<const N: usize>(x: &[Self; N]) -> ([Self; N], [Self; N]) {
        fast::sin_cos_f64_array(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
}

#[allow(
    clippy::excessive_precision,
    clippy::approx_constant,
    clippy::neg_cmp_op_on_partial_ord
)]
pub mod fast {
    #[inline(always)]
    fn two_sum64(a: f64, b: f64) -> (f64, f64) {
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

    const FRAC_2_PI_64: f64 = 6.36619772367581382433e-01;
    const TOINT_64: f64 = 1.5 / f64::EPSILON;

    /// fdlibm `__kernel_sin(y0, y1, 1)` and `__kernel_cos(y0, y1)` on `|y0 + y1| ≤ π/4`, then the
    /// quadrant select and the sign of `x`.
    #[inline(always)]
    fn finish64(y0: f64, y1: f64, quadrant: u32, sign: u64) -> (f64, f64) {
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
        let z = y0 * y0;
        let w = z * z;
        let rs = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
        let v = z * y0;
        let s = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * S1);
        let rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
        let hz = 0.5 * z;
        let wc = 1.0 - hz;
        let c = wc + (((1.0 - wc) - hz) + (z * rc - y0 * y1));
        let (s, c) = if quadrant & 1 == 0 { (s, c) } else { (c, -s) };
        let (s, c) = if quadrant & 2 == 0 { (s, c) } else { (-s, -c) };
        (f64::from_bits(s.to_bits() ^ sign), c)
    }

    /// The careful reduction: π/2 in four parts (three of 33 bits, `n·P_k` exact for `n < 2²⁰`),
    /// remainder carried as a double-word by TwoSum. Used when the one-step reduction of
    /// [`sin_cos_f64`] cancels (x within ~2⁻¹⁶ relative of a multiple of π/2), and beyond
    /// [`F64_FAST_LIMIT`] (and for NaN, ±∞) it defers to `libm`.
    #[cold]
    #[inline(never)]
    fn careful64(x: f64) -> (f64, f64) {
        const P1: f64 = 1.57079632673412561417e+00;
        const P2: f64 = 6.07710050630396597660e-11;
        const P3: f64 = 2.02226624871116645580e-21;
        const P4: f64 = 8.47842766036889956997e-32;
        let sign = x.to_bits() & (1u64 << 63);
        let ax = f64::from_bits(x.to_bits() & !(1u64 << 63));
        if !(ax <= F64_FAST_LIMIT) {
            return (libm::sin(x), libm::cos(x));
        }
        let t = ax * FRAC_2_PI_64 + TOINT_64;
        let quadrant = t.to_bits() as u32;
        let fnum = t - TOINT_64;
        let r1 = ax - fnum * P1; // exact (Sterbenz)
        let (r2, e1) = two_sum64(r1, -(fnum * P2));
        let (hi, e2) = two_sum64(r2, -(fnum * P3));
        let lo = (e1 + e2) - fnum * P4;
        let y0 = hi + lo;
        let y1 = (hi - y0) + lo;
        finish64(y0, y1, quadrant, sign)
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
        let (y0, y1, quadrant) = one_step64(ax);
        let ex = (ax.to_bits() >> 52) as i64;
        let ey = ((y0.to_bits() >> 52) & 0x7ff) as i64;
        if ex - ey > 16 {
            return careful64(x);
        }
        finish64(y0, y1, quadrant, sign)
    }

    /// musl's one-step Cody–Waite reduction of `ax = |x| ≤ F64_FAST_LIMIT`:
    /// `ax = n·π/2 + (y0 + y1)` with `P1` of 33 bits (`n·P1` exact) and `P1T = π/2 − P1`;
    /// returns `(y0, y1, n mod 2³²)`. Its result cancels when `x` is near a multiple of π/2,
    /// which the callers test.
    #[inline(always)]
    fn one_step64(ax: f64) -> (f64, f64, u32) {
        const P1: f64 = 1.57079632673412561417e+00;
        const P1T: f64 = 6.07710050650619224932e-11;
        let t = ax * FRAC_2_PI_64 + TOINT_64;
        let quadrant = t.to_bits() as u32;
        let fnum = t - TOINT_64;
        let r = ax - fnum * P1; // exact
        let w = fnum * P1T;
        let y0 = r - w;
        (y0, (r - y0) - w, quadrant)
    }

    /// [`sin_cos_f64`] of every element, bit for bit. Where the target has AVX2, four elements
    /// at a time go through [`sin_cos_f64_x4`] (measured: eight joints in 28 ns instead of 45,
    /// four in 14 instead of 26), and the rest one by one; without AVX2 (where the four-wide
    /// kernel measured no faster) every element goes through [`sin_cos_f64`].
    #[inline(always)]
    pub fn sin_cos_f64_array<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
        let mut s = [0.0; N];
        let mut c = [0.0; N];
        #[allow(unused_mut)]
        let mut k = 0;
        #[cfg(target_feature = "avx2")]
        while k + 4 <= N {
            let (s4, c4) = sin_cos_f64_x4(&[x[k], x[k + 1], x[k + 2], x[k + 3]]);
            s[k..k + 4].copy_from_slice(&s4);
            c[k..k + 4].copy_from_slice(&c4);
            k += 4;
        }
        for j in k..N {
            (s[j], c[j]) = sin_cos_f64(x[j]);
        }
        (s, c)
    }

    /// [`sin_cos_f64`] of four elements, bit for bit, computed side by side: the main path of
    /// [`sin_cos_f64`] (one-step reduction, both kernels, quadrant select) runs branch-free on
    /// all four, so the compiler can put them in one AVX2 register. If any element needs more
    /// (beyond [`F64_FAST_LIMIT`], NaN, ±∞, or a reduction that may have cancelled:
    /// `|y0| < 2⁻¹⁶ |x|`, which holds whenever musl's exponent test of [`sin_cos_f64`] does),
    /// all four are recomputed by [`sin_cos_f64`].
    #[inline(always)]
    pub fn sin_cos_f64_x4(x: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
        const TWO_M16: f64 = 1.0 / 65536.0;
        const ABS: u64 = !(1u64 << 63);
        let mut s = [0.0; 4];
        let mut c = [0.0; 4];
        let mut slow = false;
        for k in 0..4 {
            let sign = x[k].to_bits() & !ABS;
            let ax = f64::from_bits(x[k].to_bits() & ABS);
            // |x| ≤ π/4 goes to the kernels unreduced, as in sin_cos_f64, by a select.
            let (y0, y1, quadrant) = one_step64(ax);
            let small = ax <= core::f64::consts::FRAC_PI_4;
            let (y0, y1, quadrant) = if small {
                (ax, 0.0, 0)
            } else {
                (y0, y1, quadrant)
            };
            slow |= !(ax <= F64_FAST_LIMIT) | (f64::from_bits(y0.to_bits() & ABS) < ax * TWO_M16);
            (s[k], c[k]) = finish64(y0, y1, quadrant, sign);
        }
        if slow {
            for k in 0..4 {
                (s[k], c[k]) = sin_cos_f64(x[k]);
            }
        }
        (s, c)
    }
}
