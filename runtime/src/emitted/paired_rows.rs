//! A homogeneous transform walked joint by joint with its rows as pairs, for generated code: the
//! pose `g_0i` and the body Jacobian `J^B_0i` (2.45) of a chain of right-angle joints.
//!
//! A chain fits when every joint up to link `i` turns about the `z` axis of its link frame and
//! the frame before it is reached by a constant head `Trans(o) · R_x(roll)` with `roll` one of
//! `0`, `+π/2`, `−π/2` (modified Denavit–Hartenberg with right-angle twists, as the Franka
//! Panda): `T_k = Trans(o_k) R_x(roll_k) R_z(q_k)`. Walking from link `i` towards the base,
//! `S_{k−1} = T_k S_k` with `S_k = g_ki` ([`Rows::first`], [`Rows::joint`]) gives every column
//! `Ad⁻¹_{g_ki} ξ_k` of `J^B_0i` on the way ([`Rows::column`]) and `g_0i` at the end
//! ([`Rows::pose`]).
//!
//! A row `(R_r1, R_r2 | R_r3, p_r)` of `S` is two [`Pair`]s. `R_z(q)` mixes rows 1 and 2 lane
//! by lane (four multiplications and two additions of pairs per row, no shuffles), `R_x(±π/2)`
//! only renames rows (their signs are carried with the rows and folded into the next addition
//! or subtraction), and `Trans(o)` adds to the `p` lanes. On x86-64 a `Pair<f64>` (or
//! `Pair<f32>`) is one SSE2 register: at the default target, where SSE2 is the widest unit,
//! the Panda's generated `link_pose_and_jacobian_trig` takes fewer instructions through this
//! walk than the same values written out as scalar expressions (see BENCHMARKS.md, "Rows as
//! SSE2 pairs").
//!
//! Every operation is one IEEE operation per lane, so a [`Pair`] of lane types gives, lane by
//! lane, the bits of the scalar walk.

use super::Arith;
use core::ops::{Add, Mul, Neg, Sub};

/// Two values side by side, `[lo, hi]`. For `f64` and `f32` on x86-64 (with SSE2, as every
/// x86-64 target but the soft-float ones) every operation is one SSE2 instruction on both;
/// otherwise one operation of `T` on each.
#[derive(Clone, Copy, Debug)]
pub struct Pair<T>([T; 2]);

/// `op` of `a` and `b` as one SSE2 instruction, where `T` is `f64` or `f32` and the target has
/// SSE2; `None` otherwise. The type tests compare constant `TypeId`s, which the compiler folds.
#[inline(always)]
#[allow(unused_variables)] // `a`, `b` and `op` go unused without SSE2
fn on_sse2<T: Arith>(a: &Pair<T>, b: &Pair<T>, op: Op) -> Option<Pair<T>> {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use core::any::Any;
        let (a, b) = (a as &dyn Any, b as &dyn Any);
        if let (Some(x), Some(y)) = (a.downcast_ref::<Pair<f64>>(), b.downcast_ref()) {
            let r = sse2::f64_op(*x, *y, op);
            return (&r as &dyn Any).downcast_ref::<Pair<T>>().copied();
        }
        if let (Some(x), Some(y)) = (a.downcast_ref::<Pair<f32>>(), b.downcast_ref()) {
            let r = sse2::f32_op(*x, *y, op);
            return (&r as &dyn Any).downcast_ref::<Pair<T>>().copied();
        }
    }
    #[allow(unreachable_code)]
    None
}

/// An operation of [`Pair`] (`Neg` and `HiSplat` read only the first operand).
#[derive(Clone, Copy)]
enum Op {
    Add,
    Sub,
    Mul,
    Neg,
    HiSplat,
}

#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod sse2 {
    //! `Pair<f64>` and `Pair<f32>` through SSE2.
    //!
    //! SAFETY (every `unsafe` block): the module is compiled only where the target has SSE2
    //! (its `cfg`), so the intrinsics may be called. `_mm_loadu_pd` reads the 16 bytes of the
    //! `[f64; 2]` inside a `Pair<f64>` (a shared borrow, valid for reads); `_mm_storeu_pd` and
    //! `_mm_storeu_ps` write 16 bytes of an array of that size, local or borrowed `&mut`
    //! (valid for writes); all are the unaligned forms, so no alignment is assumed. Every other
    //! intrinsic touches registers only.
    use super::{Op, Pair};
    use core::arch::x86_64::{
        __m128, __m128d, _mm_add_pd, _mm_add_ps, _mm_loadu_pd, _mm_mul_pd, _mm_mul_ps, _mm_set1_pd,
        _mm_set1_ps, _mm_setr_ps, _mm_shuffle_ps, _mm_storeu_pd, _mm_storeu_ps, _mm_sub_pd,
        _mm_sub_ps, _mm_unpackhi_pd, _mm_xor_pd, _mm_xor_ps,
    };

    #[inline(always)]
    fn load(p: &Pair<f64>) -> __m128d {
        // SAFETY: see the module.
        unsafe { _mm_loadu_pd(p.0.as_ptr()) }
    }

    /// `op` of two `Pair<f64>`.
    #[inline(always)]
    pub(super) fn f64_op(a: Pair<f64>, b: Pair<f64>, op: Op) -> Pair<f64> {
        let (x, y) = (load(&a), load(&b));
        // SAFETY: see the module.
        let r = unsafe {
            match op {
                Op::Add => _mm_add_pd(x, y),
                Op::Sub => _mm_sub_pd(x, y),
                Op::Mul => _mm_mul_pd(x, y),
                Op::Neg => _mm_xor_pd(x, _mm_set1_pd(-0.0)),
                Op::HiSplat => _mm_unpackhi_pd(x, x),
            }
        };
        let mut out = [0.0; 2];
        // SAFETY: see the module.
        unsafe { _mm_storeu_pd(out.as_mut_ptr(), r) };
        Pair(out)
    }

    /// `dst = a`, one store of both lanes.
    #[inline(always)]
    pub(super) fn store(a: Pair<f64>, dst: &mut [f64; 2]) {
        // SAFETY: see the module; `dst` is 16 bytes valid for writes.
        unsafe { _mm_storeu_pd(dst.as_mut_ptr(), load(&a)) }
    }

    #[inline(always)]
    fn load32(p: &Pair<f32>) -> __m128 {
        // SAFETY: see the module.
        unsafe { _mm_setr_ps(p.0[0], p.0[1], 0.0, 0.0) }
    }

    /// `op` of two `Pair<f32>`, in the low two of four lanes.
    #[inline(always)]
    pub(super) fn f32_op(a: Pair<f32>, b: Pair<f32>, op: Op) -> Pair<f32> {
        let (x, y) = (load32(&a), load32(&b));
        // SAFETY: see the module.
        let r = unsafe {
            match op {
                Op::Add => _mm_add_ps(x, y),
                Op::Sub => _mm_sub_ps(x, y),
                Op::Mul => _mm_mul_ps(x, y),
                Op::Neg => _mm_xor_ps(x, _mm_set1_ps(-0.0)),
                Op::HiSplat => _mm_shuffle_ps::<0b01_01_01_01>(x, x),
            }
        };
        let mut out = [0.0f32; 4];
        // SAFETY: see the module.
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), r) };
        Pair([out[0], out[1]])
    }
}

impl<T: Arith> Pair<T> {
    /// `[lo, hi]`.
    #[inline(always)]
    pub fn new(lo: T, hi: T) -> Self {
        Pair([lo, hi])
    }

    /// `[x, x]`.
    #[inline(always)]
    pub fn splat(x: T) -> Self {
        Pair([x, x])
    }

    /// The low lane.
    #[inline(always)]
    pub fn lo(self) -> T {
        self.0[0]
    }

    /// The high lane.
    #[inline(always)]
    pub fn hi(self) -> T {
        self.0[1]
    }

    /// `[hi, hi]`.
    #[inline(always)]
    pub fn hi_splat(self) -> Self {
        if let Some(r) = on_sse2(&self, &self, Op::HiSplat) {
            return r;
        }
        Pair([self.0[1], self.0[1]])
    }

    /// Writes `[lo, hi]` into `dst`.
    #[inline(always)]
    pub fn store(self, dst: &mut [T; 2]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
        {
            use core::any::Any;
            let pair = (&self as &dyn Any).downcast_ref::<Pair<f64>>();
            let out = (dst as &mut dyn Any).downcast_mut::<[f64; 2]>();
            if let (Some(&pair), Some(out)) = (pair, out) {
                return sse2::store(pair, out);
            }
        }
        *dst = self.0;
    }
}

/// The constant rotation `R_x(roll)` of a joint's head `Trans(o) · R_x(roll)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Roll {
    /// `R_x(0)`: none.
    Zero,
    /// `R_x(+π/2)`: `(x, y, z) ↦ (x, −z, y)`.
    Quarter,
    /// `R_x(−π/2)`: `(x, y, z) ↦ (x, z, −y)`.
    MinusQuarter,
}

/// One row `(R_r1, R_r2 | R_r3, p_r)` of `S` as `(a, b)`; the row is `−(a, b)` where `neg`.
/// `a_zero` and `b_zero` mark pairs known to be zero (near the walk's start), whose products
/// are then not computed; like `neg`, they are constants once the walk is inlined.
#[derive(Clone, Copy, Debug)]
struct Row<T> {
    a: Pair<T>,
    b: Pair<T>,
    neg: bool,
    a_zero: bool,
    b_zero: bool,
}

impl<T: Arith> Row<T> {
    #[inline(always)]
    fn flipped(self) -> Self {
        Row {
            neg: !self.neg,
            ..self
        }
    }

    /// The row with `o` added to its `p` entry (nothing when `o` is 0).
    #[inline(always)]
    fn offset(self, o: f64) -> Self {
        if o == 0.0 {
            return self;
        }
        let o = Pair::new(T::ZERO, T::lit(if self.neg { -o } else { o }));
        Row {
            b: if self.b_zero { o } else { self.b.add(o) },
            b_zero: false,
            ..self
        }
    }

    /// `(a, b)` with the row's sign applied.
    #[inline(always)]
    fn value(self) -> (Pair<T>, Pair<T>) {
        let signed = |x: Pair<T>, zero: bool| if self.neg && !zero { x.neg() } else { x };
        (signed(self.a, self.a_zero), signed(self.b, self.b_zero))
    }
}

/// `x·y + u·v`, or `x·y − u·v` where `minus`, with `y` or `v` known to be zero where
/// `y_zero`, `v_zero`; whether the result is known to be zero.
#[inline(always)]
fn lin<T: Arith>(
    x: Pair<T>,
    (y, y_zero): (Pair<T>, bool),
    u: Pair<T>,
    (v, v_zero): (Pair<T>, bool),
    minus: bool,
) -> (Pair<T>, bool) {
    match (y_zero, v_zero) {
        (true, true) => (y, true),
        (true, false) if minus => (u.mul(v).neg(), false),
        (true, false) => (u.mul(v), false),
        (false, true) => (x.mul(y), false),
        (false, false) if minus => (x.mul(y).sub(u.mul(v)), false),
        (false, false) => (x.mul(y).add(u.mul(v)), false),
    }
}

/// `x·y + u·v` (or `−` where `minus`) of two rows' `a` and `b` pairs: one row of the result.
#[inline(always)]
fn lin_row<T: Arith>(
    x: Pair<T>,
    r: Row<T>,
    u: Pair<T>,
    w: Row<T>,
    minus: bool,
    neg: bool,
) -> Row<T> {
    let (a, a_zero) = lin(x, (r.a, r.a_zero), u, (w.a, w.a_zero), minus);
    let (b, b_zero) = lin(x, (r.b, r.b_zero), u, (w.b, w.b_zero), minus);
    Row {
        a,
        b,
        neg,
        a_zero,
        b_zero,
    }
}

/// `S = g_ki` of a walk from link `i` towards the base, three rows of two [`Pair`]s each.
#[derive(Clone, Copy, Debug)]
pub struct Rows<T> {
    rows: [Row<T>; 3],
}

impl<T: Arith> Rows<T> {
    /// `S = Trans(o) R_x(roll) R_z(q)`: the walk's first joint, from the identity at link `i`
    /// (`sin`, `cos` of that joint's value).
    #[inline(always)]
    pub fn first(sin: T, cos: T, roll: Roll, o: [f64; 3]) -> Self {
        let z = Pair::splat(T::ZERO);
        // R_z(q): (c, −s, 0 | 0), (s, c, 0 | 0), (0, 0, 1 | 0).
        let r1 = Row {
            a: Pair::new(cos, -sin),
            b: z,
            neg: false,
            a_zero: false,
            b_zero: true,
        };
        let r2 = Row {
            a: Pair::new(sin, cos),
            ..r1
        };
        let r3 = Row {
            a: z,
            b: Pair::new(T::ONE, T::ZERO),
            neg: false,
            a_zero: true,
            b_zero: false,
        };
        Self::head([r1, r2, r3], roll, o)
    }

    /// `S ← Trans(o) R_x(roll) R_z(q) S`: one joint further towards the base.
    #[inline(always)]
    pub fn joint(self, sin: T, cos: T, roll: Roll, o: [f64; 3]) -> Self {
        let [r1, r2, r3] = self.rows;
        let (c, s) = (Pair::splat(cos), Pair::splat(sin));
        // c r₁ − s r₂ = σ₁ (c X₁ − σ₁σ₂ s X₂), kept with r₁'s sign; s r₁ + c r₂ =
        // σ₂ (σ₁σ₂ s X₁ + c X₂), kept with r₂'s sign.
        let same = r1.neg == r2.neg;
        let p1 = lin_row(c, r1, s, r2, same, r1.neg);
        let p2 = if same {
            lin_row(s, r1, c, r2, false, r2.neg)
        } else {
            lin_row(c, r2, s, r1, true, r2.neg)
        };
        Self::head([p1, p2, r3], roll, o)
    }

    /// `Trans(o) R_x(roll)` applied to rows `p`.
    #[inline(always)]
    fn head(p: [Row<T>; 3], roll: Roll, o: [f64; 3]) -> Self {
        let [p1, p2, p3] = p;
        let [r1, r2, r3] = match roll {
            Roll::Zero => [p1, p2, p3],
            Roll::Quarter => [p1, p3.flipped(), p2],
            Roll::MinusQuarter => [p1, p3, p2.flipped()],
        };
        Rows {
            rows: [r1.offset(o[0]), r2.offset(o[1]), r3.offset(o[2])],
        }
    }

    /// The body-Jacobian column `Ad⁻¹_{g_ki} (0, ẑ)` (2.45) of the joint about the `z` axis of
    /// the frame `S` starts from: `(v, ω)` with `ω = Rᵀ ẑ` (row 3 of `R`) and
    /// `v = Rᵀ (ẑ × p) = p_x · (row 2) − p_y · (row 1)`.
    #[inline(always)]
    pub fn column(&self, col: &mut [T; 6]) {
        let [x1, x2, x3] = self.rows;
        let (p1, p2) = (x1.b.hi_splat(), x2.b.hi_splat());
        // σ₁σ₂ (X₁.p X₂ − X₂.p X₁); a zero `b` has a zero `p`.
        let ((first, pf), (second, ps)) = if x1.neg == x2.neg {
            ((x1, p1), (x2, p2))
        } else {
            ((x2, p2), (x1, p1))
        };
        // pf · second − ps · first, the terms with a zero `p` or a zero pair left out.
        let term =
            |p: Pair<T>, p_zero: bool, x: Pair<T>, x_zero: bool| (p.mul(x), p_zero || x_zero);
        let diff =
            |(l, l_zero): (Pair<T>, bool), (r, r_zero): (Pair<T>, bool)| match (l_zero, r_zero) {
                (true, true) => Pair::splat(T::ZERO),
                (true, false) => r.neg(),
                (false, true) => l,
                (false, false) => l.sub(r),
            };
        let va = diff(
            term(pf, first.b_zero, second.a, second.a_zero),
            term(ps, second.b_zero, first.a, first.a_zero),
        );
        let vb = diff(
            term(pf, first.b_zero, second.b, second.b_zero),
            term(ps, second.b_zero, first.b, first.b_zero),
        );
        let (wa, wb) = x3.value();
        let (v, w) = col.split_at_mut(3);
        if let (Ok(v), Ok(w)) = (
            <&mut [T; 2]>::try_from(&mut v[..2]),
            <&mut [T; 2]>::try_from(&mut w[..2]),
        ) {
            va.store(v);
            wa.store(w);
        }
        col[2] = vb.lo();
        col[5] = wb.lo();
    }

    /// `S` as `(R, p)`, `R` column-major (`r[col][row]`).
    #[inline(always)]
    pub fn pose(&self, g: &mut ([[T; 3]; 3], [T; 3])) {
        for (i, r) in self.rows.iter().enumerate() {
            let (a, b) = r.value();
            g.0[0][i] = a.lo();
            g.0[1][i] = a.hi();
            g.0[2][i] = b.lo();
            g.1[i] = b.hi();
        }
    }
}

/// Lane by lane `a + b`.
impl<T: Arith> Add for Pair<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        if let Some(r) = on_sse2(&self, &b, Op::Add) {
            return r;
        }
        Pair([self.0[0] + b.0[0], self.0[1] + b.0[1]])
    }
}

/// Lane by lane `a - b`.
impl<T: Arith> Sub for Pair<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        if let Some(r) = on_sse2(&self, &b, Op::Sub) {
            return r;
        }
        Pair([self.0[0] - b.0[0], self.0[1] - b.0[1]])
    }
}

/// Lane by lane `a * b`.
impl<T: Arith> Mul for Pair<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        if let Some(r) = on_sse2(&self, &b, Op::Mul) {
            return r;
        }
        Pair([self.0[0] * b.0[0], self.0[1] * b.0[1]])
    }
}

/// Lane by lane `−a` (the sign bits flipped).
impl<T: Arith> Neg for Pair<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        if let Some(r) = on_sse2(&self, &self, Op::Neg) {
            return r;
        }
        Pair([-self.0[0], -self.0[1]])
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // index arithmetic of 4 × 4 matrices
mod tests {
    use super::*;

    type M4 = [[f64; 4]; 4];

    fn mul(a: &M4, b: &M4) -> M4 {
        let mut c = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        c
    }

    /// `Trans(o) R_x(roll) R_z(q)` as a 4 × 4 matrix.
    fn joint(q: f64, roll: Roll, o: [f64; 3]) -> M4 {
        let (s, c) = q.sin_cos();
        let rz = [
            [c, -s, 0.0, 0.0],
            [s, c, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let (sa, ca) = match roll {
            Roll::Zero => (0.0, 1.0),
            Roll::Quarter => (1.0, 0.0),
            Roll::MinusQuarter => (-1.0, 0.0),
        };
        let rx = [
            [1.0, 0.0, 0.0, o[0]],
            [0.0, ca, -sa, o[1]],
            [0.0, sa, ca, o[2]],
            [0.0, 0.0, 0.0, 1.0],
        ];
        mul(&rx, &rz)
    }

    /// A chain with every roll and sign combination: the walk's poses and columns against
    /// 4 × 4 products and `Ad⁻¹_g (0, ẑ)` written from `g` directly.
    #[test]
    fn walk_matches_matrix_products() {
        let rolls = [
            Roll::Quarter,
            Roll::MinusQuarter,
            Roll::Zero,
            Roll::Quarter,
            Roll::Quarter,
            Roll::MinusQuarter,
            Roll::MinusQuarter,
        ];
        let offsets = [
            [0.0, 0.0, 0.333],
            [0.1, 0.0, 0.0],
            [0.0, -0.316, 0.2],
            [0.0825, 0.0, 0.0],
            [-0.0825, 0.384, 0.0],
            [0.0, 0.0, 0.0],
            [0.088, 0.0, -0.05],
        ];
        let mut seed = 7u64;
        for _ in 0..200 {
            let q: Vec<f64> = (0..7)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 7.0
                })
                .collect();
            let n = q.len();
            let mut rows =
                Rows::<f64>::first(q[n - 1].sin(), q[n - 1].cos(), rolls[n - 1], offsets[n - 1]);
            let mut g: M4 = joint(q[n - 1], rolls[n - 1], offsets[n - 1]);
            for k in (0..n - 1).rev() {
                // Column of joint k + 1 from S = g_{k+1, i}.
                let mut col = [0.0; 6];
                rows.column(&mut col);
                let (r, p) = (|i: usize, j: usize| g[i][j], [g[0][3], g[1][3], g[2][3]]);
                // v = Rᵀ (ẑ × p) = Rᵀ (−p_y, p_x, 0), ω = Rᵀ ẑ.
                for j in 0..3 {
                    let v = r(0, j) * -p[1] + r(1, j) * p[0];
                    assert!((col[j] - v).abs() < 1e-14, "v[{j}]");
                    assert!((col[3 + j] - r(2, j)).abs() < 1e-15, "ω[{j}]");
                }
                rows = rows.joint(q[k].sin(), q[k].cos(), rolls[k], offsets[k]);
                g = mul(&joint(q[k], rolls[k], offsets[k]), &g);
            }
            let mut pose = ([[f64::NAN; 3]; 3], [f64::NAN; 3]);
            rows.pose(&mut pose);
            for i in 0..3 {
                for j in 0..3 {
                    assert!((pose.0[j][i] - g[i][j]).abs() < 1e-14, "R[{i}][{j}]");
                }
                assert!((pose.1[i] - g[i][3]).abs() < 1e-14, "p[{i}]");
            }
        }
    }

    /// `Pair<f64>` and `Pair<f32>` (SSE2 on x86-64) against the same operations on plain
    /// numbers, bit for bit.
    #[test]
    fn pair_operations_are_lane_operations() {
        let xs = [1.5f64, -0.0, 3.25e-300, -7.0e10, 0.1, f64::INFINITY];
        for &a in &xs {
            for &b in &xs {
                let (p, r) = (Pair::new(a, b), Pair::new(b, a));
                let bits = |x: Pair<f64>| [x.lo().to_bits(), x.hi().to_bits()];
                assert_eq!(bits(p.add(r)), [(a + b).to_bits(), (b + a).to_bits()]);
                assert_eq!(bits(p.sub(r)), [(a - b).to_bits(), (b - a).to_bits()]);
                assert_eq!(bits(p.mul(r)), [(a * b).to_bits(), (b * a).to_bits()]);
                assert_eq!(bits(p.neg()), [(-a).to_bits(), (-b).to_bits()]);
                assert_eq!(bits(p.hi_splat()), [b.to_bits(), b.to_bits()]);
                let (a32, b32) = (a as f32, b as f32);
                let (p, r) = (Pair::new(a32, b32), Pair::new(b32, a32));
                let bits = |x: Pair<f32>| [x.lo().to_bits(), x.hi().to_bits()];
                assert_eq!(
                    bits(p.add(r)),
                    [(a32 + b32).to_bits(), (b32 + a32).to_bits()]
                );
                assert_eq!(
                    bits(p.sub(r)),
                    [(a32 - b32).to_bits(), (b32 - a32).to_bits()]
                );
                assert_eq!(
                    bits(p.mul(r)),
                    [(a32 * b32).to_bits(), (b32 * a32).to_bits()]
                );
                assert_eq!(bits(p.neg()), [(-a32).to_bits(), (-b32).to_bits()]);
                assert_eq!(bits(p.hi_splat()), [b32.to_bits(), b32.to_bits()]);
                let mut dst = [0.0f32; 2];
                p.store(&mut dst);
                assert_eq!(dst.map(f32::to_bits), [a32.to_bits(), b32.to_bits()]);
            }
        }
    }
}
