//! The Panda's `g_0i` and `J^B_0i` of `panda_link7` given the sines and cosines, written by hand
//! with the rows of the homogeneous transform as SSE2 pairs: a measurement of what the generator's
//! scalar straight-line code leaves on the table at the default x86-64 ISA, not a product
//! function.
//!
//! The walk is the one the generated `link_pose_and_jacobian_trig` does, from the tip to the
//! base: `S_7 = I`, `S_{k−1} = Trans(o_k) R_x(roll_k) R_z(q_k) S_k` with `S_k = g_k7`, and the
//! body-Jacobian column of joint `k` from `S_k`: `ω = R_kᵀ ẑ` (row 3 of `R`) and
//! `v = R_kᵀ (ẑ × p_k) = p_x · row 2 − p_y · row 1` (2.45). A row `(R_r1, R_r2 | R_r3, p_r)` is two
//! SSE2 registers, and `R_z(q)` mixes rows 1 and 2 lane by lane: a step costs eight packed
//! multiplications and four packed additions, with no shuffles. `R_x(±π/2)` only renames rows;
//! its signs are carried with the rows (`Row::neg`) and folded into the next addition's sign.
//! The first two steps, where the rows are still sparse, are written out.
//!
//! `tests/check.rs` checks it against the reference; BENCHMARKS.md ("Rows as SSE2 pairs") has the
//! measurement. The generated code now walks such chains the same way through
//! `trocar::emitted::paired_rows` (from the identity at the link, its first steps' zero pairs known but
//! not its constants); this kernel stays as the hand-written bound it is measured against.
#![cfg(target_arch = "x86_64")]

use core::arch::x86_64::{
    __m128d, _mm_add_pd, _mm_cvtsd_f64, _mm_mul_pd, _mm_set1_pd, _mm_set_pd, _mm_storeu_pd,
    _mm_sub_pd, _mm_unpackhi_pd, _mm_xor_pd,
};

// SAFETY (every `unsafe` block below): SSE2 is part of x86_64's baseline, so these intrinsics
// are available on every x86_64 target; they touch registers only, except `_mm_storeu_pd`, whose
// destination is a `&mut [f64; 2]` (16 valid, writable bytes; unaligned store).

#[derive(Clone, Copy)]
struct Pair(__m128d);

impl Pair {
    #[inline(always)]
    fn new(lo: f64, hi: f64) -> Pair {
        Pair(unsafe { _mm_set_pd(hi, lo) })
    }
    #[inline(always)]
    fn splat(x: f64) -> Pair {
        Pair(unsafe { _mm_set1_pd(x) })
    }
    #[inline(always)]
    fn mul(self, b: Pair) -> Pair {
        Pair(unsafe { _mm_mul_pd(self.0, b.0) })
    }
    #[inline(always)]
    fn add(self, b: Pair) -> Pair {
        Pair(unsafe { _mm_add_pd(self.0, b.0) })
    }
    #[inline(always)]
    fn sub(self, b: Pair) -> Pair {
        Pair(unsafe { _mm_sub_pd(self.0, b.0) })
    }
    #[inline(always)]
    fn neg(self) -> Pair {
        Pair(unsafe { _mm_xor_pd(self.0, _mm_set1_pd(-0.0)) })
    }
    /// Both lanes the high lane.
    #[inline(always)]
    fn hi_splat(self) -> Pair {
        Pair(unsafe { _mm_unpackhi_pd(self.0, self.0) })
    }
    #[inline(always)]
    fn lo(self) -> f64 {
        unsafe { _mm_cvtsd_f64(self.0) }
    }
    #[inline(always)]
    fn hi(self) -> f64 {
        self.hi_splat().lo()
    }
    #[inline(always)]
    fn store(self, dst: &mut [f64; 2]) {
        unsafe { _mm_storeu_pd(dst.as_mut_ptr(), self.0) }
    }
}

/// A row `(R_r1, R_r2 | R_r3, p_r)` as `(a, b)`; its value is `−(a, b)` where `neg`.
#[derive(Clone, Copy)]
struct Row {
    a: Pair,
    b: Pair,
    neg: bool,
}

impl Row {
    fn flipped(self) -> Row {
        Row {
            neg: !self.neg,
            ..self
        }
    }

    /// The row plus `o` in its `p` entry.
    #[inline(always)]
    fn offset(self, o: f64) -> Row {
        if o == 0.0 {
            return self;
        }
        let o = if self.neg { -o } else { o };
        Row {
            b: self.b.add(Pair::new(0.0, o)),
            ..self
        }
    }

    /// `(a, b)` with the sign applied.
    #[inline(always)]
    fn value(self) -> (Pair, Pair) {
        if self.neg {
            (self.a.neg(), self.b.neg())
        } else {
            (self.a, self.b)
        }
    }
}

/// Rows 1 and 2 of `R_z(q) S`: `c r₁ − s r₂` and `s r₁ + c r₂`, each kept with the sign of the
/// row it replaces (`σ₁ (c X₁ − σ₁σ₂ s X₂)`, `σ₂ (σ₁σ₂ s X₁ + c X₂)`).
#[inline(always)]
fn rotated(c: Pair, s: Pair, r1: Row, r2: Row) -> (Row, Row) {
    let lin = |x: Pair, y: Pair, u: Pair, v: Pair, minus: bool| {
        if minus {
            x.mul(y).sub(u.mul(v))
        } else {
            x.mul(y).add(u.mul(v))
        }
    };
    let same = r1.neg == r2.neg;
    let p1 = Row {
        a: lin(c, r1.a, s, r2.a, same),
        b: lin(c, r1.b, s, r2.b, same),
        neg: r1.neg,
    };
    let p2 = if same {
        Row {
            a: lin(s, r1.a, c, r2.a, false),
            b: lin(s, r1.b, c, r2.b, false),
            neg: r2.neg,
        }
    } else {
        Row {
            a: lin(c, r2.a, s, r1.a, true),
            b: lin(c, r2.b, s, r1.b, true),
            neg: r2.neg,
        }
    };
    (p1, p2)
}

/// `S ← Trans(o) R_x(roll) R_z(q) S`, `roll` 0, `+π/2` (1) or `−π/2` (−1).
#[inline(always)]
fn step(sin: f64, cos: f64, rows: [Row; 3], roll: i8, o: [f64; 3]) -> [Row; 3] {
    let (p1, p2) = rotated(Pair::splat(cos), Pair::splat(sin), rows[0], rows[1]);
    let p3 = rows[2];
    let [r1, r2, r3] = match roll {
        0 => [p1, p2, p3],
        1 => [p1, p3.flipped(), p2],
        _ => [p1, p3, p2.flipped()],
    };
    [r1.offset(o[0]), r2.offset(o[1]), r3.offset(o[2])]
}

/// The body-Jacobian column of a joint about `ẑ` of `S = g_k7` (2.45): `v = p_x · row 2 −
/// p_y · row 1` (`σ₁σ₂ (X₁.p X₂ − X₂.p X₁)`), `ω` = row 3.
#[inline(always)]
fn column(rows: &[Row; 3], col: &mut [f64; 6]) {
    let [x1, x2, x3] = *rows;
    let (p1, p2) = (x1.b.hi_splat(), x2.b.hi_splat());
    let (va, vb) = if x1.neg == x2.neg {
        (
            p1.mul(x2.a).sub(p2.mul(x1.a)),
            p1.mul(x2.b).sub(p2.mul(x1.b)),
        )
    } else {
        (
            p2.mul(x1.a).sub(p1.mul(x2.a)),
            p2.mul(x1.b).sub(p1.mul(x2.b)),
        )
    };
    let (wa, wb) = x3.value();
    let (v, w) = col.split_at_mut(3);
    va.store((&mut v[..2]).try_into().expect("two"));
    v[2] = vb.lo();
    wa.store((&mut w[..2]).try_into().expect("two"));
    w[2] = wb.lo();
}

/// `g_0i = (R column-major, p)` and `J^B_0i` (column-major `6 × 7`) of the Panda's `panda_link7`
/// from the seven joints' sines and cosines.
#[inline(always)]
pub fn panda_link7(
    s: &[f64; 7],
    c: &[f64; 7],
    g: &mut ([[f64; 3]; 3], [f64; 3]),
    jb: &mut [[f64; 6]; 7],
) {
    // S_6 = Trans(0.088, 0, 0) R_x(π/2) R_z(q_7): rows (c₇, −s₇, 0 | 0.088), (0, 0, −1 | 0),
    // (s₇, c₇, 0 | 0).
    jb[6] = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    jb[5] = [0.0, 0.0, -0.088, s[6], c[6], 0.0];
    // S_5 = R_x(π/2) R_z(q_6) S_6.
    let cs7 = Pair::new(c[6], -s[6]);
    let (s6, c6) = (s[5], c[5]);
    let mut rows = [
        Row {
            a: Pair::splat(c6).mul(cs7),
            b: Pair::new(s6, 0.088 * c6),
            neg: false,
        },
        Row {
            a: Pair::new(-s[6], -c[6]),
            b: Pair::new(0.0, 0.0),
            neg: false,
        },
        Row {
            a: Pair::splat(s6).mul(cs7),
            b: Pair::new(-c6, 0.088 * s6),
            neg: false,
        },
    ];
    let x = 0.088 * c6;
    jb[4] = [-(x * s[6]), -(x * c[6]), 0.0, s6 * c[6], -(s6 * s[6]), -c6];
    // Joints 5 to 2: the step, then the column of the joint before.
    rows = step(s[4], c[4], rows, -1, [-0.0825, 0.384, 0.0]);
    column(&rows, &mut jb[3]);
    rows = step(s[3], c[3], rows, 1, [0.0825, 0.0, 0.0]);
    column(&rows, &mut jb[2]);
    rows = step(s[2], c[2], rows, 1, [0.0, -0.316, 0.0]);
    column(&rows, &mut jb[1]);
    rows = step(s[1], c[1], rows, -1, [0.0, 0.0, 0.0]);
    column(&rows, &mut jb[0]);
    rows = step(s[0], c[0], rows, 0, [0.0, 0.0, 0.333]);
    for (i, r) in rows.iter().enumerate() {
        let (a, b) = r.value();
        g.0[0][i] = a.lo();
        g.0[1][i] = a.hi();
        g.0[2][i] = b.lo();
        g.1[i] = b.hi();
    }
}

/// The first seven joints' `(sin, cos)` as `std` computes them, as the peers are given them
/// ([`crate::rust_peers::Trig`]): the inputs of [`panda_link7`] in the bench drivers.
pub fn std_sin_cos(q: &[f64]) -> ([f64; 7], [f64; 7]) {
    let t = crate::rust_peers::Trig::new(q);
    let first = |x: &[f64; 8]| core::array::from_fn(|k| x[k]);
    (first(&t.s), first(&t.c))
}
