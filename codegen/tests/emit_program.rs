//! Rules of the program optimiser, one test each (named after the rule), op counts and the
//! interpreter against direct `f64` computation.

use trocar_codegen::evaluate::Compiled;
use trocar_codegen::ir::{Factor, Op, Program, Term};

fn prog() -> Program {
    Program::new(vec!["l_a".into(), "l_b".into(), "l_8".into()])
}

#[test]
fn hash_cons() {
    let mut p = prog();
    let s = p.sin(6);
    let c = p.cos(7);
    let a = p.mul(s, c);
    let b = p.mul(s, c);
    assert_eq!(a, b);
    assert_eq!(p.ops().len(), 3);
}

#[test]
fn commutative_order() {
    let mut p = prog();
    let s = p.sin(6);
    let c = p.cos(7);
    assert_eq!(p.mul(s, c), p.mul(c, s));
    assert_eq!(p.add(s, c), p.add(c, s));
}

#[test]
fn fold_constants() {
    let mut p = prog();
    let a = p.constant(1.5);
    let b = p.constant(2.0);
    let s = p.add(a, b);
    assert_eq!(p.as_const(s), Some(3.5));
    let m = p.mul(a, b);
    assert_eq!(p.as_const(m), Some(3.0));
    let d = p.div(a, b);
    assert_eq!(p.as_const(d), Some(0.75));
    let n = p.neg(a);
    assert_eq!(p.as_const(n), Some(-1.5));
    let four = p.constant(4.0);
    let r = p.sqrt(four);
    assert_eq!(p.as_const(r), Some(2.0));
}

#[test]
fn add_zero() {
    let mut p = prog();
    let x = p.sin(0);
    let z = p.constant(0.0);
    assert_eq!(p.add(x, z), x);
    assert_eq!(p.add(z, x), x);
    assert_eq!(p.sub(x, z), x);
    let n = p.sub(z, x);
    assert_eq!(p.op(n), &Op::Neg(x));
}

#[test]
fn mul_zero() {
    let mut p = prog();
    let x = p.sin(0);
    let z = p.constant(0.0);
    let m = p.mul(x, z);
    assert_eq!(p.as_const(m), Some(0.0));
    let d = p.div(z, x);
    assert_eq!(p.as_const(d), Some(0.0));
}

#[test]
fn mul_one() {
    let mut p = prog();
    let x = p.sin(0);
    let one = p.constant(1.0);
    let m1 = p.constant(-1.0);
    assert_eq!(p.mul(x, one), x);
    assert_eq!(p.div(x, one), x);
    let n = p.mul(m1, x);
    assert_eq!(p.op(n), &Op::Neg(x));
    let n2 = p.div(x, m1);
    assert_eq!(n, n2);
}

#[test]
fn neg_neg() {
    let mut p = prog();
    let x = p.sin(0);
    let n = p.neg(x);
    assert_eq!(p.neg(n), x);
}

#[test]
fn sign_out() {
    let mut p = prog();
    let x = p.sin(0);
    let y = p.cos(1);
    let nx = p.neg(x);
    let ny = p.neg(y);
    let xy = p.mul(x, y);
    let m = p.mul(nx, y);
    assert_eq!(p.op(m), &Op::Neg(xy));
    assert_eq!(p.mul(nx, ny), xy);
    let d = p.div(x, y);
    let d1 = p.div(nx, y);
    let d2 = p.div(x, ny);
    assert_eq!(p.op(d1), &Op::Neg(d));
    assert_eq!(d1, d2);
    let c = p.constant(-3.0);
    let cx = p.mul(c, x);
    let Op::Neg(inner) = *p.op(cx) else {
        panic!("expected a negation")
    };
    let Op::Mul(k, _) = *p.op(inner) else {
        panic!("expected a product")
    };
    assert_eq!(p.as_const(k), Some(3.0));
}

#[test]
fn add_neg() {
    let mut p = prog();
    let x = p.sin(0);
    let y = p.cos(1);
    let nx = p.neg(x);
    let ny = p.neg(y);
    let a = p.add(x, ny);
    assert_eq!(p.op(a), &Op::Sub(x, y));
    let b = p.add(nx, y);
    assert_eq!(p.op(b), &Op::Sub(y, x));
    assert_eq!(p.sub(x, ny), p.add(x, y));
    let s = p.sub(nx, y);
    let xy = p.add(x, y);
    assert_eq!(p.op(s), &Op::Neg(xy));
    let c = p.constant(-0.5);
    let e = p.add(x, c);
    let Op::Sub(l, r) = *p.op(e) else {
        panic!("expected a subtraction")
    };
    assert_eq!((l, p.as_const(r)), (x, Some(0.5)));
}

#[test]
fn sub_self() {
    let mut p = prog();
    let x = p.sin(0);
    let d = p.sub(x, x);
    assert_eq!(p.as_const(d), Some(0.0));
}

#[test]
fn div_pow2() {
    let mut p = prog();
    let x = p.sin(0);
    let two = p.constant(2.0);
    let three = p.constant(3.0);
    let h = p.div(x, two);
    let Op::Mul(k, y) = *p.op(h) else {
        panic!("expected a product")
    };
    assert_eq!((p.as_const(k), y), (Some(0.5), x));
    let t = p.div(x, three);
    assert_eq!(p.op(t), &Op::Div(x, three));
}

#[test]
fn const_assoc() {
    let mut p = prog();
    let x = p.sin(0);
    let a = p.constant(2.0);
    let b = p.constant(3.0);
    let bx = p.mul(b, x);
    let abx = p.mul(a, bx);
    let Op::Mul(k, y) = *p.op(abx) else {
        panic!("expected a product")
    };
    assert_eq!((p.as_const(k), y), (Some(6.0), x));
}

#[test]
fn one_inverse() {
    let mut p = prog();
    let a = p.power(Factor::Param(0), -1);
    let b = p.power(Factor::Param(0), -2);
    let Op::Mul(x, y) = *p.op(b) else {
        panic!("expected a product")
    };
    assert_eq!((x, y), (a, a));
    p.set_outputs(vec![a, b]);
    assert_eq!(p.op_counts().div, 1);
}

#[test]
fn monomial_prefix() {
    // s7 c8 l_8 and 2 s7 c8 l_8 share the product s7·c8·l_8 (coefficient multiplied last).
    let mut p = prog();
    let t1 = Term::new(
        1.0,
        [
            (Factor::Sin(6), 1),
            (Factor::Cos(7), 1),
            (Factor::Param(2), 1),
        ],
    );
    let t2 = Term::new(
        2.0,
        [
            (Factor::Param(2), 1),
            (Factor::Sin(6), 1),
            (Factor::Cos(7), 1),
        ],
    );
    let a = p.monomial(&t1);
    let b = p.monomial(&t2);
    let Op::Mul(_, inner) = *p.op(b) else {
        panic!("expected a product")
    };
    assert_eq!(inner, a);
}

#[test]
fn horner() {
    // α1 of (3.24): −c8 l8 / la − lb c7 c8 / la = −c8 (l8 + lb c7) / la: 2 mul + 1 div + 1 add
    // once factored, against 5 mul expanded.
    let mut p = prog();
    let terms = [
        Term::new(
            -1.0,
            [
                (Factor::Cos(7), 1),
                (Factor::Param(2), 1),
                (Factor::Param(0), -1),
            ],
        ),
        Term::new(
            -1.0,
            [
                (Factor::Cos(6), 1),
                (Factor::Cos(7), 1),
                (Factor::Param(1), 1),
                (Factor::Param(0), -1),
            ],
        ),
    ];
    let v = p.sum_of_monomials(&terms);
    p.set_outputs(vec![v]);
    let c = p.op_counts();
    assert_eq!((c.add, c.mul, c.div, c.neg, c.trig), (1, 3, 1, 1, 2), "{c}");
    let q: [f64; 8] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.4, -1.1];
    let params: [f64; 3] = [0.15, 0.18, 0.21];
    let direct = -q[7].cos() * (params[2] + params[1] * q[6].cos()) / params[0];
    assert!((Compiled::new(&p, q.len()).eval(&q, &params)[0] - direct).abs() < 1e-14);
}

#[test]
fn sign_normalise() {
    let mut p = prog();
    let terms = [
        Term::new(-2.0, [(Factor::Sin(0), 1)]),
        Term::new(-2.0, [(Factor::Cos(1), 1)]),
    ];
    let v = p.sum_of_monomials(&terms);
    // −(2 · (s1 + c2)): one mul, one add, one neg.
    p.set_outputs(vec![v]);
    let c = p.op_counts();
    assert_eq!((c.add, c.mul, c.neg), (1, 1, 1), "{c}");
}

#[test]
fn one_trig() {
    let mut p = prog();
    let s = p.sin(3);
    let c = p.cos(3);
    let c2 = p.cos(5);
    let a = p.mul(s, c);
    let b = p.add(a, c2);
    p.set_outputs(vec![b]);
    assert_eq!(p.trig_joints(), vec![3, 5]);
    assert_eq!(p.op_counts().trig, 2);
}

#[test]
fn dead_code() {
    let mut p = prog();
    let s = p.sin(3);
    let c = p.cos(4);
    let _unused = p.mul(s, c);
    let used = p.add(s, c);
    p.set_outputs(vec![used]);
    let counts = p.op_counts();
    assert_eq!((counts.add, counts.mul, counts.trig), (1, 0, 2));
    assert_eq!(p.live_len(), 3);
}

/// The interpreter agrees with direct evaluation of (3.24)'s α3 = −s8 (la + lb + l8 c7) and a
/// shared-subexpression matrix at many configurations.
#[test]
fn interpreter_matches_direct_f64() {
    let mut p = prog();
    let alpha3 = [
        Term::new(-1.0, [(Factor::Sin(7), 1), (Factor::Param(0), 1)]),
        Term::new(-1.0, [(Factor::Sin(7), 1), (Factor::Param(1), 1)]),
        Term::new(
            -1.0,
            [
                (Factor::Sin(7), 1),
                (Factor::Param(2), 1),
                (Factor::Cos(6), 1),
            ],
        ),
    ];
    let entry = [
        Term::new(0.5, [(Factor::Sin(6), 1), (Factor::Cos(7), 2)]),
        Term::new(-3.0, [(Factor::Joint(2), 1)]),
        Term::new(0.25, []),
    ];
    let a = p.sum_of_monomials(&alpha3);
    let b = p.sum_of_monomials(&entry);
    let r = p.mul(a, b);
    let sq = p.mul(r, r);
    let w = p.sqrt(sq);
    p.set_outputs(vec![a, b, w]);
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0
    };
    let compiled = Compiled::new(&p, 8);
    for _ in 0..1000 {
        let q: Vec<f64> = (0..8).map(|_| rnd()).collect();
        let l = [rnd().abs() + 0.1, rnd(), rnd()];
        let got = compiled.eval(&q, &l);
        let da = -q[7].sin() * (l[0] + l[1] + l[2] * q[6].cos());
        let db = 0.5 * q[6].sin() * q[7].cos().powi(2) - 3.0 * q[2] + 0.25;
        let dw = (da * db).abs();
        for (g, d) in got.iter().zip([da, db, dw]) {
            assert!((g - d).abs() <= 1e-12 * (1.0 + d.abs()), "{g} vs {d}");
        }
    }
}

/// `Program::import`: another program's live values built into this one share what both compute
/// (rule `hash_cons`) and evaluate to the same numbers; its dead values are not built.
#[test]
fn import_shares_common_values() {
    let mut a = prog();
    let s = a.sin(0);
    let la = a.param(0);
    let dead = a.cos(3);
    let _ = a.mul(dead, la);
    let x = a.mul(s, la);
    let one = a.constant(1.0);
    let y = a.add(x, one);
    a.set_outputs(vec![y, x]);

    let mut b = prog();
    let c = b.cos(1);
    let la = b.param(0);
    let s = b.sin(0);
    let shared = b.mul(la, s);
    let before = b.ops().len();
    let outs = b.import(&a);
    assert_eq!(outs[1], shared);
    // sin q0, l_a and their product exist already: only 1 and the sum are new.
    assert_eq!(b.ops().len(), before + 2);
    assert!(!b.ops().contains(&Op::Cos(3)));
    b.set_outputs(vec![outs[0], outs[1], c]);
    let q = [0.3, -0.2, 0.0, 0.9];
    let params = [0.15, 0.18, 0.21];
    let got = Compiled::new(&b, q.len()).eval(&q, &params);
    let want = Compiled::new(&a, q.len()).eval(&q, &params);
    assert_eq!(&got[..2], &want[..]);
    assert!((want[1] - 0.3f64.sin() * 0.15).abs() < 1e-16);
}
