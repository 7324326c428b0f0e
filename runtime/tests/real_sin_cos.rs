//! `trocar::emitted::fast::{sin_cos_f64, sin_cos_f32}` (what `Real::sin_cos` uses) against std.
//!
//! f64: at most 1 ulp from std (glibc, itself < 1 ulp from the exact value). f32: < 1 ulp and
//! ≤ 6e-8 absolute from the exact value (std's f64 `sin_cos`, exact to far below an f32 ulp);
//! measured exhaustively on [-4096, 4096]: 0.849 ulp, 5.06e-8.
//! The exhaustive f32 check and a 10⁷-sample f64 check are `#[ignore]`d (run with
//! `cargo test --release -p trocar --test real_sin_cos -- --ignored`).
use trocar::emitted::fast::{sin_cos_f32, sin_cos_f64, F32_FAST_LIMIT, F64_FAST_LIMIT};

fn ord64(x: f64) -> i64 {
    let b = x.to_bits() as i64;
    if b < 0 {
        i64::MIN - b
    } else {
        b
    }
}

/// Distance in ulps between two finite f64 values.
fn ulps64(a: f64, b: f64) -> u64 {
    ord64(a).abs_diff(ord64(b))
}

/// Error of an f32 result against an f64 "exact" value, in f32 ulps of the exact value.
fn ulps32(got: f32, exact: f64) -> f64 {
    let e = (exact as f32).abs();
    let ulp = if e == 0.0 || e < f32::MIN_POSITIVE {
        f32::from_bits(1) as f64
    } else {
        // ulp of the binade of |exact| (the smaller one at a power of two)
        let exp = e.to_bits() >> 23;
        f32::from_bits((exp.max(24) - 23) << 23) as f64
    };
    (got as f64 - exact).abs() / ulp
}

fn check64(x: f64, max_ulps: &mut u64) {
    let (s, c) = sin_cos_f64(x);
    let (ws, wc) = x.sin_cos();
    if x.is_nan() || x.is_infinite() {
        assert!(s.is_nan() && c.is_nan(), "{x}: ({s}, {c})");
        return;
    }
    let (us, uc) = (ulps64(s, ws), ulps64(c, wc));
    assert!(
        us <= 1 && uc <= 1,
        "x = {x:e} ({:#x}): sin {s:e} vs {ws:e} ({us} ulp), cos {c:e} vs {wc:e} ({uc} ulp)",
        x.to_bits()
    );
    *max_ulps = (*max_ulps).max(us).max(uc);
}

fn check32(x: f32, worst: &mut (f64, f64)) {
    let (s, c) = sin_cos_f32(x);
    let (ws, wc) = (x as f64).sin_cos();
    if x.is_nan() || x.is_infinite() {
        assert!(s.is_nan() && c.is_nan(), "{x}: ({s}, {c})");
        return;
    }
    let (us, uc) = (ulps32(s, ws), ulps32(c, wc));
    let abs = ((s as f64 - ws).abs()).max((c as f64 - wc).abs());
    assert!(
        us < 1.0 && uc < 1.0 && abs <= 6e-8,
        "x = {x:e}: sin {s:e} vs {ws:e} ({us} ulp), cos {c:e} vs {wc:e} ({uc} ulp)"
    );
    worst.0 = worst.0.max(us).max(uc);
    worst.1 = worst.1.max(abs);
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every element of `(s, c)` bit for bit `sin_cos_f64` of the same element of `x` (`what` names
/// the path in the message).
fn assert_scalar_bits64(what: &str, x: &[f64], s: &[f64], c: &[f64]) {
    for (k, &xk) in x.iter().enumerate() {
        let (ws, wc) = sin_cos_f64(xk);
        assert_eq!(
            (s[k].to_bits(), c[k].to_bits()),
            (ws.to_bits(), wc.to_bits()),
            "{what}, element {k} of {}, x = {xk:e}",
            x.len()
        );
    }
}

/// [`assert_scalar_bits64`] for `f32` and `sin_cos_f32`.
fn assert_scalar_bits32(what: &str, x: &[f32], s: &[f32], c: &[f32]) {
    for (k, &xk) in x.iter().enumerate() {
        let (ws, wc) = sin_cos_f32(xk);
        assert_eq!(
            (s[k].to_bits(), c[k].to_bits()),
            (ws.to_bits(), wc.to_bits()),
            "{what}, element {k} of {}, x = {xk:e}",
            x.len()
        );
    }
}

const SPECIAL64: [f64; 14] = [
    0.0,
    -0.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MIN_POSITIVE,
    -f64::MIN_POSITIVE,
    5e-324,
    -5e-324,
    1e-300,
    f64::MAX,
    f64::MIN,
    F64_FAST_LIMIT,
    // far beyond the fast path (libm's Payne–Hanek reduction)
    1.0e22,
];

#[test]
fn f64_special_values() {
    let mut m = 0;
    for x in SPECIAL64 {
        check64(x, &mut m);
    }
    assert_eq!(sin_cos_f64(0.0).0.to_bits(), 0.0f64.to_bits());
    assert_eq!(
        sin_cos_f64(-0.0).0.to_bits(),
        (-0.0f64).to_bits(),
        "sin(-0) = -0"
    );
    assert_eq!(sin_cos_f64(-0.0).1, 1.0);
    assert_eq!(sin_cos_f64(5e-324), (5e-324, 1.0));
    let (s, c) = sin_cos_f64(f64::NAN);
    assert!(s.is_nan() && c.is_nan());
}

#[test]
fn f64_dense_grid_and_multiples_of_half_pi() {
    let mut m = 0;
    for i in -200_000..=200_000 {
        check64(i as f64 * 1e-4, &mut m); // [-20, 20]
    }
    // next to n pi/2, where the reduction cancels
    for n in (0..2_000_000i64).step_by(7) {
        let x = n as f64 * core::f64::consts::FRAC_PI_2;
        if x > F64_FAST_LIMIT * 1.01 {
            break;
        }
        for k in -2i64..=2 {
            let y = f64::from_bits((x.to_bits() as i64 + k) as u64);
            check64(y, &mut m);
            check64(-y, &mut m);
        }
    }
}

#[test]
fn f64_random_arguments_all_magnitudes() {
    let mut m = 0;
    let mut r = Lcg(7);
    for _ in 0..300_000 {
        check64((r.unit() - 0.5) * 2.0 * F64_FAST_LIMIT, &mut m); // fast path
        check64((r.unit() - 0.5) * 8.0, &mut m); // joint angles
        let x = f64::from_bits(r.next()); // any value, every exponent
        check64(x, &mut m);
    }
}

#[test]
#[ignore = "slow: 10^7 samples; run with --release -- --ignored"]
fn f64_ten_million_random_fast_path() {
    let mut m = 0;
    let mut r = Lcg(11);
    let mut diff = 0u64;
    for _ in 0..10_000_000 {
        let x = (r.unit() - 0.5) * 2.0 * F64_FAST_LIMIT;
        let (s, c) = sin_cos_f64(x);
        let (ws, wc) = x.sin_cos();
        diff += (s != ws) as u64 + (c != wc) as u64;
        check64(x, &mut m);
    }
    eprintln!("f64: max {m} ulp from std; {diff} of 2e7 results differ from std");
}

#[test]
fn f32_special_values() {
    let mut w = (0.0, 0.0);
    for x in [
        0.0f32,
        -0.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MIN_POSITIVE,
        1e-45,
        -1e-45,
        f32::MAX,
        f32::MIN,
        F32_FAST_LIMIT,
        1e10,
    ] {
        check32(x, &mut w);
    }
    assert_eq!(
        sin_cos_f32(-0.0).0.to_bits(),
        (-0.0f32).to_bits(),
        "sin(-0) = -0"
    );
    assert_eq!(sin_cos_f32(0.0), (0.0, 1.0));
}

#[test]
fn f32_grid_random_and_all_magnitudes() {
    let mut w = (0.0, 0.0);
    for i in -2_000_000..=2_000_000 {
        check32(i as f32 * 1e-5, &mut w); // [-20, 20]
    }
    let mut r = Lcg(3);
    for _ in 0..1_000_000 {
        check32(
            ((r.unit() - 0.5) * 2.0 * F32_FAST_LIMIT as f64) as f32,
            &mut w,
        );
        check32(f32::from_bits(r.next() as u32), &mut w);
    }
    eprintln!("f32 sampled: max {:.3} ulp, max abs {:e}", w.0, w.1);
}

/// Every `f32` within 2¹⁶ ulps of `n·π/2` for the multiples a robot's joints reach (n ≤ 8) and a
/// few large ones (the last window ends below `F32_FAST_LIMIT`): the arguments whose one-step
/// reduction cancels, where the exponent test chooses between the one-step and the careful
/// reduction. Each against the exact value, and the group kernel on eight and sixteen lanes of
/// them against the scalar function, bit for bit (the lanes' own trigger must flag every
/// argument that the exponent test sends to the careful reduction). Taking the one-step
/// reduction up to 20 bits of cancellation instead of 12 fails here (1.45 ulp at
/// `x = 1.5707945`).
#[test]
fn f32_every_argument_near_multiples_of_half_pi() {
    use trocar::emitted::fast::sin_cos_f32_lanes;
    fn lanes_equal_scalar<const W: usize>(x: &[f32; W]) {
        let (s, c) = sin_cos_f32_lanes(x);
        assert_scalar_bits32("lanes", x, &s, &c);
    }
    let mut w = (0.0, 0.0);
    for n in (1..=8).chain([100, 1000, 2590]) {
        let centre = (n as f64 * core::f64::consts::FRAC_PI_2) as f32;
        let b = centre.to_bits() as i64;
        let xs: Vec<f32> = (-(1i64 << 16)..=(1 << 16))
            .flat_map(|d| {
                let x = f32::from_bits((b + d) as u32);
                [x, -x]
            })
            .collect();
        assert!(xs.iter().all(|x| x.abs() <= F32_FAST_LIMIT));
        for &x in &xs {
            check32(x, &mut w);
        }
        for g in xs.chunks_exact(16) {
            lanes_equal_scalar::<16>(g.try_into().unwrap());
            lanes_equal_scalar::<8>(g[..8].try_into().unwrap());
        }
    }
    eprintln!("f32 near n·π/2: max {:.3} ulp, max abs {:e}", w.0, w.1);
}

#[test]
#[ignore = "slow: every f32 in [-4096, 4096]; run with --release -- --ignored"]
fn f32_exhaustive_fast_path() {
    let mut w = (0.0, 0.0);
    let top = F32_FAST_LIMIT.to_bits();
    for b in 0..=top {
        let x = f32::from_bits(b);
        check32(x, &mut w);
        check32(-x, &mut w);
    }
    eprintln!(
        "f32 exhaustive |x| <= {F32_FAST_LIMIT}: max {:.3} ulp, max abs {:e}",
        w.0, w.1
    );
}

/// `sin_cos_f64_lanes` (eight, four and two lanes) and `sin_cos_f64_array` (what generated code
/// calls through `Real::sin_cos_array`; of three to eight elements, on AVX2 quads chosen at run
/// time where a default-target build runs on a CPU with AVX2) are `sin_cos_f64` of each element,
/// bit for bit: random arguments, the neighbours of π/4 and of multiples of π/2 (where the
/// careful reduction takes over), huge arguments, NaN and ±∞, in arrays that mix them.
#[test]
fn array_version_equals_the_scalar_one_bit_for_bit() {
    use trocar::emitted::fast::{sin_cos_f64_array, sin_cos_f64_lanes, sin_cos_f64_x4};
    use trocar::Real;
    let mut special = Vec::new();
    for k in 0..2000i64 {
        let m = k as f64 * core::f64::consts::FRAC_PI_2;
        special.push(m);
        special.push(-m);
        let mut a = m;
        let mut b = m;
        for _ in 0..3 {
            a = f64::from_bits(a.to_bits() + 1);
            b = f64::from_bits(b.to_bits().saturating_sub(1));
            special.extend([a, b, -a, -b]);
        }
    }
    let mut p = core::f64::consts::FRAC_PI_4;
    let mut m = p;
    for _ in 0..64 {
        p = f64::from_bits(p.to_bits() + 1);
        m = f64::from_bits(m.to_bits() - 1);
        special.extend([p, m, -p, -m]);
    }
    special.extend([
        0.0,
        -0.0,
        f64::MIN_POSITIVE / 4.0,
        1e-300,
        F64_FAST_LIMIT,
        F64_FAST_LIMIT * 1.5,
        1e300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ]);
    let mut seed = 7u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        seed
    };
    let mut checked = 0usize;
    for round in 0..40_000 {
        let mut x = [0.0f64; 8];
        for v in x.iter_mut() {
            let r = next();
            *v = if round % 4 == 0 {
                special[(r >> 20) as usize % special.len()]
            } else {
                ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 40.0
            };
        }
        let (s, c) = sin_cos_f64_array(&x);
        let (s2, c2) = <f64 as Real>::sin_cos_array(&x);
        let (lo_s, lo_c) = sin_cos_f64_x4(&[x[0], x[1], x[2], x[3]]);
        let (hi_s, hi_c) = sin_cos_f64_x4(&[x[4], x[5], x[6], x[7]]);
        let (s4, c4) = ([lo_s, hi_s].concat(), [lo_c, hi_c].concat());
        let (s5, c5) = sin_cos_f64_array(&[x[0], x[1], x[2], x[3], x[4]]);
        // Two go one at a time, three as a padded group: both sides of the boundary.
        let (s2e, c2e) = sin_cos_f64_array(&[x[0], x[1]]);
        let (s3e, c3e) = sin_cos_f64_array(&[x[0], x[1], x[2]]);
        let (s4e, c4e) = sin_cos_f64_array(&[x[0], x[1], x[2], x[3]]);
        let (s6, c6) = sin_cos_f64_array(&[x[0], x[1], x[2], x[3], x[4], x[5]]);
        let (s7, c7) = sin_cos_f64_array(&[x[0], x[1], x[2], x[3], x[4], x[5], x[6]]);
        let (s8, c8) = sin_cos_f64_lanes(&x);
        // Two lanes (SSE2, the default x86-64 target's `sin_cos_f64_array`), pair by pair.
        let pairs: Vec<([f64; 2], [f64; 2])> = x
            .chunks(2)
            .map(|p| sin_cos_f64_lanes::<2>(&[p[0], p[1]]))
            .collect();
        for k in 0..8 {
            let (ss, cc) = sin_cos_f64(x[k]);
            let want = (ss.to_bits(), cc.to_bits());
            let (ps, pc) = pairs[k / 2];
            assert_eq!((ps[k % 2].to_bits(), pc[k % 2].to_bits()), want, "pairs");
            assert_eq!((s[k].to_bits(), c[k].to_bits()), want, "x = {:e}", x[k]);
            assert_eq!((s2[k].to_bits(), c2[k].to_bits()), want);
            assert_eq!(
                (s4[k].to_bits(), c4[k].to_bits()),
                want,
                "x4, x = {:e}",
                x[k]
            );
            if k < 5 {
                assert_eq!((s5[k].to_bits(), c5[k].to_bits()), want);
            }
            if k < 2 {
                assert_eq!((s2e[k].to_bits(), c2e[k].to_bits()), want, "two");
            }
            if k < 3 {
                assert_eq!((s3e[k].to_bits(), c3e[k].to_bits()), want, "three");
            }
            if k < 4 {
                assert_eq!((s4e[k].to_bits(), c4e[k].to_bits()), want, "four");
            }
            if k < 6 {
                assert_eq!((s6[k].to_bits(), c6[k].to_bits()), want, "six");
            }
            if k < 7 {
                assert_eq!((s7[k].to_bits(), c7[k].to_bits()), want);
            }
            assert_eq!(
                (s8[k].to_bits(), c8[k].to_bits()),
                want,
                "x8, x = {:e}",
                x[k]
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 320_000);
    // f32 goes element by element through Real::sin_cos.
    let xf = [0.5f32, -2.0, 1e-30, 3000.0];
    let (s, c) = <f32 as Real>::sin_cos_array(&xf);
    for k in 0..4 {
        assert_eq!((s[k], c[k]), sin_cos_f32(xf[k]));
    }
}

/// Arguments with `|x| ≤ π/4`, which `sin_cos_f64` hands to its kernels unreduced, take the
/// lanes' reduction unchanged (`n = 0`, `(|x|, 0)`): bit for bit the same, at every magnitude
/// from subnormal to π/4 and at π/4's neighbours.
#[test]
fn small_arguments_need_no_reduction_in_lanes() {
    use trocar::emitted::fast::sin_cos_f64_lanes;
    let mut seed = 11u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        seed
    };
    let quarter = core::f64::consts::FRAC_PI_4;
    for _ in 0..50_000 {
        let x: [f64; 8] = core::array::from_fn(|_| {
            let r = next();
            // A uniform fraction of π/4 scaled by 2^-e, e in 0..1100 (down to subnormals), signed.
            let frac = (r >> 11) as f64 / (1u64 << 53) as f64;
            let e = (r % 1100) as i32;
            let v = quarter * frac * 2f64.powi(-e);
            if r & 1 == 0 {
                v
            } else {
                -v
            }
        });
        let (s, c) = sin_cos_f64_lanes::<8>(&x);
        assert_scalar_bits64("eight lanes", &x, &s, &c);
    }
    let mut q = quarter;
    for _ in 0..1000 {
        let (s, c) = sin_cos_f64_lanes::<2>(&[q, -q]);
        assert_scalar_bits64("two lanes", &[q, -q], &s, &c);
        q = f64::from_bits(q.to_bits() - 1);
    }
}

/// `sin_cos_f64_lanes` of every width from 0 to 11 and of 16 (odd widths pair their last lane
/// with itself where the lanes are SSE2 pairs; beyond eight lanes the pairs go on in a loop, and
/// the rare path is out of line), bit for bit the scalar `sin_cos_f64`, with one lane in eleven
/// sent to the careful path (that lane left on the side-by-side path's value fails it) and, in
/// some groups, one at or beyond the fast limit, NaN or ±∞.
#[test]
fn lanes_of_every_width_equal_the_scalar_one() {
    use trocar::emitted::fast::sin_cos_f64_lanes;
    fn check<const W: usize>(x: [f64; W]) {
        let (s, c) = sin_cos_f64_lanes::<W>(&x);
        assert_scalar_bits64("lanes", &x, &s, &c);
    }
    let mut seed = 11u64;
    for round in 0..2_000 {
        let mut x = [0.0f64; 11];
        for (k, v) in x.iter_mut().enumerate() {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            *v = if round % 11 == k {
                // a neighbour of a multiple of π/2: the careful reduction
                f64::from_bits(
                    ((round % 50 + 1) as f64 * core::f64::consts::FRAC_PI_2).to_bits() + 1,
                )
            } else if round % 13 == k {
                // at and beyond the fast limit, NaN, ±∞: `libm`, one lane at a time
                let limit = trocar::emitted::fast::F64_FAST_LIMIT;
                [
                    limit,
                    f64::from_bits(limit.to_bits() + 1),
                    -1.5 * limit,
                    f64::NAN,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ][(round / 13) % 6]
            } else {
                ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 50.0
            };
        }
        check::<0>([]);
        check::<1>([x[0]]);
        check::<2>([x[0], x[1]]);
        check::<3>([x[0], x[1], x[2]]);
        check::<4>([x[0], x[1], x[2], x[3]]);
        check::<5>([x[0], x[1], x[2], x[3], x[4]]);
        check::<6>(core::array::from_fn(|k| x[k]));
        check::<7>(core::array::from_fn(|k| x[k]));
        check::<8>(core::array::from_fn(|k| x[k]));
        check::<9>(core::array::from_fn(|k| x[k]));
        check::<10>(core::array::from_fn(|k| x[k]));
        check::<11>(x);
        check::<16>(core::array::from_fn(|k| x[k % 11]));
    }
}

/// Arguments whose one-step reduction cancels by 12 to 19 bits near `n·π/2` (n ≤ 8): the band
/// where the lanes' trigger (`|y0| < 2⁻¹⁶ |x|`) flags a lane and musl's exponent test (more than
/// 16 bits) may or may not send it to the careful reduction. Every lane of `sin_cos_f64_lanes`
/// (eight and sixteen lanes, and `sin_cos_f64_array` of seven) bit for bit `sin_cos_f64`.
/// In this band both reductions are accurate far below an ulp (the one-step one to about
/// `n·2⁻⁸⁶`), so which one a lane takes does not show in these results: a rare path that took
/// the careful reduction for every flagged lane passes this test too. It guards the lanes'
/// results where their rare path starts, not the choice of reduction.
#[test]
fn f64_lanes_where_the_trigger_and_the_exponent_test_differ() {
    use trocar::emitted::fast::{sin_cos_f64_array, sin_cos_f64_lanes};
    let mut r = Lcg(29);
    let mut xs = Vec::new();
    for n in 1..=8 {
        let centre = n as f64 * core::f64::consts::FRAC_PI_2;
        for bits in 12..20 {
            for _ in 0..250 {
                // |y| in [2^-bits, 2^(1-bits)) of |x|, either side
                let y = centre * (1.0 + r.unit()) * 2f64.powi(-bits);
                xs.push(if r.next() & 1 == 0 {
                    centre + y
                } else {
                    centre - y
                });
            }
        }
    }
    for g in xs.chunks_exact(16) {
        let x16: [f64; 16] = g.try_into().unwrap();
        let (s, c) = sin_cos_f64_lanes(&x16);
        assert_scalar_bits64("lanes", &x16, &s, &c);
        let x8: [f64; 8] = g[..8].try_into().unwrap();
        let (s, c) = sin_cos_f64_lanes(&x8);
        assert_scalar_bits64("lanes", &x8, &s, &c);
        let x7: [f64; 7] = g[8..15].try_into().unwrap();
        let (s, c) = sin_cos_f64_array(&x7);
        assert_scalar_bits64("array", &x7, &s, &c);
    }
}

/// `sin_cos_f32_array` (what generated `f32` code calls through `Real::sin_cos_array`: groups of
/// eight, the last padded, where the target has vector registers for `f32`) and
/// `sin_cos_f32_lanes` (the group kernel; `F32x8` runs it on sixteen lanes, where its rare path
/// is out of line) of lengths 1–11, 16, 17 and 19, bit for bit the scalar `sin_cos_f32`: random
/// and special arguments, with some groups holding an argument that needs the careful reduction
/// (that lane left on the side-by-side path's value fails it).
#[test]
fn f32_arrays_of_every_length_equal_the_scalar_one() {
    use trocar::emitted::fast::{sin_cos_f32_array, sin_cos_f32_lanes};
    fn check<const N: usize>(x: &[f32]) {
        let x: [f32; N] = core::array::from_fn(|k| x[k]);
        for (what, (s, c)) in [
            ("array", sin_cos_f32_array(&x)),
            ("lanes", sin_cos_f32_lanes(&x)),
        ] {
            assert_scalar_bits32(what, &x, &s, &c);
        }
    }
    let specials = [
        0.0f32,
        -0.0,
        f32::NAN,
        f32::INFINITY,
        -1e-45,
        f32::MAX,
        F32_FAST_LIMIT,
        1e10,
        core::f32::consts::FRAC_PI_2,
        -3.0 * core::f32::consts::FRAC_PI_2,
    ];
    let mut r = Lcg(19);
    for round in 0..3_000 {
        let x: Vec<f32> = (0..19)
            .map(|k| {
                if round % 3 == 0 && k == round % 19 {
                    specials[(r.next() % specials.len() as u64) as usize]
                } else if round % 3 == 1 {
                    f32::from_bits(r.next() as u32)
                } else {
                    ((r.unit() - 0.5) * 20.0) as f32
                }
            })
            .collect();
        check::<1>(&x);
        check::<2>(&x);
        check::<3>(&x);
        check::<4>(&x);
        check::<5>(&x);
        check::<6>(&x);
        check::<7>(&x);
        check::<8>(&x);
        check::<9>(&x);
        check::<10>(&x);
        check::<11>(&x);
        check::<16>(&x);
        check::<17>(&x);
        check::<19>(&x);
    }
}

/// Seven joints, one of them at a multiple of π/2 (a joint at ±π/2, as in a robot's home pose)
/// among ordinary ones, at every position: `sin_cos_f64_array` and `sin_cos_f32_array` (one
/// group of eight: on AVX2 chosen at run time or on SSE2 pairs at the default target, compiled
/// for AVX2 or AVX-512 otherwise) bit for bit the scalar functions. Only that lane takes the
/// careful reduction; left on the group's value, it fails this test.
#[test]
fn one_joint_at_a_multiple_of_half_pi_among_seven() {
    use core::f64::consts::FRAC_PI_2;
    use trocar::emitted::fast::{sin_cos_f32_array, sin_cos_f64_array};
    let mut r = Lcg(7);
    for round in 0..700 {
        let mut x: [f64; 7] = core::array::from_fn(|_| (r.unit() - 0.5) * 5.0);
        x[round % 7] = [1.0, -1.0, 2.0, 3.0, -3.0][round % 5] * FRAC_PI_2;
        let (s, c) = sin_cos_f64_array(&x);
        let x32 = x.map(|v| v as f32);
        let (s32, c32) = sin_cos_f32_array(&x32);
        assert_scalar_bits64("f64 array", &x, &s, &c);
        assert_scalar_bits32("f32 array", &x32, &s32, &c32);
    }
}
