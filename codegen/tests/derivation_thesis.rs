//! The thesis's printed constrained Jacobians (3.24), (3.28), (3.29) and manipulabilities
//! (3.40)–(3.42) against the derivation, **symbolically**: every printed matrix is transcribed by
//! hand below (from `docs/reference-robots.md` and the thesis text) and parsed into the canonical normal form;
//! equality is `==` of normal forms, i.e. identity modulo `s² + c² = 1`.
//! The findings are those of `docs/ERRATA.md`.

mod derivation_support;

use derivation_support::*;
use trocar_codegen::derivation::{derive, ConstrainedDerivation, Derivation, NullSpaceBasis};
use trocar_codegen::symbolic::{Matrix, Poly};

fn parse(t: &str) -> Poly {
    Poly::parse(t, &["la", "lb", "l8"]).unwrap_or_else(|e| panic!("{t}: {e}"))
}

fn matrix(rows: &[&[&str]]) -> Matrix {
    Matrix::from_fn(rows.len(), rows[0].len(), |i, j| parse(rows[i][j]))
}

fn derived(name: &str) -> (Derivation, ConstrainedDerivation) {
    let d = derive(&preset(name)).unwrap();
    assert_eq!(d.params, PRESET_PARAMS);
    let c = d.constraint.clone().unwrap();
    (d, c)
}

/// Entries `(row, col)` (1-based) where two matrices differ.
fn differing(a: &Matrix, b: &Matrix) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    for i in 0..a.rows() {
        for j in 0..a.cols() {
            if a.get(i, j) != b.get(i, j) {
                v.push((i + 1, j + 1));
            }
        }
    }
    v
}

const A1: &str = "-c8*(l8 + lb*c7)/la";
const A2: &str = "-s8*(l8 + lb*c7)/la";

/// (3.24) as printed (presets' geometry: `docs/reference-robots.md`).
fn printed_3_24() -> Matrix {
    matrix(&[
        &[
            A1,
            "c8*s7",
            "-s8",
            "-s8*(la + lb + l8*c7)",
            "-l8*s7*s8",
            "-l8*c8",
            "0",
        ],
        &["lb*s7/la", "c7", "0", "0", "0", "0", "0"],
        &[
            A2,
            "s7*s8",
            "c8",
            "c8*(la + lb + l8*c7)",
            "l8*c8*s7",
            "-l8*s8",
            "0",
        ],
        &["-s8/la", "0", "0", "c7*c8", "c8*s7", "-s8", "0"],
        &["0", "0", "0", "-s7", "c7", "0", "1"],
        &["c8/la", "0", "0", "c7*s8", "s7*s8", "c8", "0"],
    ])
}

/// (3.28) with entry (3, 4) given: printed `l8*c7*c8`, corrected `l8*s7*c8`.
fn thesis_3_28(entry_3_4: &str) -> Matrix {
    let a3 = "s8*(lb + l8*c7)/la";
    let a4 = "-c8*(lb + l8*c7)/la";
    matrix(&[
        &[A1, "c8*s7", a3, "-l8*s7*s8", "-l8*c8", "0"],
        &["lb*s7/la", "c7", "0", "0", "0", "0"],
        &[A2, "s7*s8", a4, entry_3_4, "-l8*s8", "0"],
        &["-s8/la", "0", "-c7*c8/la", "c8*s7", "-s8", "0"],
        &["0", "0", "s7/la", "c7", "0", "1"],
        &["c8/la", "0", "-c7*s8/la", "s7*s8", "c8", "0"],
    ])
}

/// (3.29) as printed in the thesis (text extraction; `α1` read as `(l8 + lb c7)/la`,
/// entry (6, 1) `c8la` read as `c8/la`).
fn printed_3_29() -> Matrix {
    let a1 = "(l8 + lb*c7)/la";
    let a2 = "s8*(lb + l8*c7)/la";
    let a3 = "-c8*(lb + l8*c7)/la";
    matrix(&[
        &[a1, "s7", "0", "0", "-l8", "0"],
        &["lb*c8*s7/la", "c7*c8", a2, "-l8*s7*s8", "0", "-l8*s8"],
        &["lb*c7*s8/la", "c7*s8", a3, "l8*c8*s7", "0", "l8*c8"],
        &["0", "0", "-c7/la", "s7", "0", "1"],
        &["-s8/la", "0", "c8*s7/la", "c7*c8", "-s8", "0"],
        &["c8/la", "0", "s7*s8/la", "c7*s8", "c8", "0"],
    ])
}

/// The derived (3.29) for the zx geometry of `docs/reference-robots.md` (published in `docs/ERRATA.md`).
fn derived_3_29() -> Matrix {
    matrix(&[
        &[
            "-(l8*c8 + lb*c7)/la",
            "s7",
            "l8*s7*s8/la",
            "l8*c7*s8",
            "-l8*c8",
            "0",
        ],
        &["lb*s7*c8/la", "c7*c8", "-lb*s8/la", "0", "0", "0"],
        &[
            "-lb*s7*s8/la",
            "-c7*s8",
            "-(l8*c7 + lb*c8)/la",
            "l8*s7",
            "0",
            "l8",
        ],
        &["0", "0", "-c7/la", "s7", "0", "1"],
        &["s8/la", "0", "c8*s7/la", "c7*c8", "s8", "0"],
        &["c8/la", "0", "-s7*s8/la", "-c7*s8", "c8", "0"],
    ])
}

#[test]
fn unidirectional_equals_printed_3_24() {
    let (_, c) = derived("unidirectional");
    assert_eq!(c.basis, NullSpaceBasis::Unidirectional);
    assert_eq!((c.r, c.m), (1, 7));
    assert_eq!(c.jr, printed_3_24());
}

#[test]
fn lambda_is_3_22_and_3_26() {
    let (_, c) = derived("unidirectional");
    assert_eq!(c.lambda, matrix(&[&["1", "0", "0", "0", "0", "-la"]]));
    let (_, c) = derived("bidirectional-zy");
    assert_eq!(
        c.lambda,
        matrix(&[
            &["1", "0", "0", "0", "0", "-la"],
            &["0", "0", "1", "la", "0", "0"]
        ])
    );
    assert!(c.lambda.mul(&c.lambda_sharp).is_zero());
    assert_eq!(c.lambda.mul(&c.lambda_pinv), Matrix::identity(2));
}

#[test]
fn bidirectional_zy_equals_3_28_after_the_misprint_correction() {
    let (_, c) = derived("bidirectional-zy");
    assert_eq!(c.basis, NullSpaceBasis::Bidirectional);
    assert_eq!(c.jr, thesis_3_28("l8*s7*c8"));
    // The printed entry (3, 4) `l8 c7 c8` is not equal, and it is the only difference.
    let printed = thesis_3_28("l8*c7*c8");
    assert_ne!(c.jr, printed);
    assert_eq!(differing(&c.jr, &printed), vec![(3, 4)]);
}

#[test]
fn bidirectional_zx_is_derived_and_printed_3_29_is_not_equal() {
    let (_, c) = derived("bidirectional-zx");
    assert_eq!(c.jr, derived_3_29());
    let printed = printed_3_29();
    assert_ne!(c.jr, printed);
    // 16 of the 36 printed entries differ from the derivation.
    let diff = differing(&c.jr, &printed);
    assert_eq!(
        diff,
        vec![
            (1, 1),
            (1, 3),
            (1, 4),
            (1, 5),
            (2, 3),
            (2, 4),
            (2, 6),
            (3, 1),
            (3, 2),
            (3, 3),
            (3, 4),
            (3, 6),
            (5, 1),
            (5, 5),
            (6, 3),
            (6, 4)
        ]
    );
    // The printed last column has a θ8-dependent linear part (0, −l8 s8, l8 c8): impossible for
    // the last joint of a rigid chain, whose body twist is constant.
    let last: Vec<Poly> = (0..6).map(|i| printed.get(i, 5).clone()).collect();
    assert!(last.iter().any(|p| p.joints().contains(&7)));
    let derived_last: Vec<Poly> = (0..6).map(|i| c.jr.get(i, 5).clone()).collect();
    assert!(derived_last.iter().all(|p| p.joints().is_empty()));
}

#[test]
fn manipulability_zy_is_3_42() {
    let (_, c) = derived("bidirectional-zy");
    // (3.42) w = lb² |s7| / la²  ⇔  w² = lb⁴ s7² / la⁴
    assert_eq!(
        c.manipulability.as_ref().unwrap().squared,
        parse("lb^4*s7^2/la^4")
    );
    match &c.manipulability.as_ref().unwrap().form {
        trocar_codegen::derivation::ManipulabilityForm::AbsDet(d) => {
            assert_eq!(d.mul(d), parse("lb^4*s7^2/la^4"));
        }
        other => panic!("square J^r expected, got {other:?}"),
    }
}

#[test]
fn manipulability_zx_is_3_41() {
    let (_, c) = derived("bidirectional-zx");
    // (3.41) w = lb² |c7| / la²  ⇔  w² = lb⁴ c7² / la⁴
    assert_eq!(
        c.manipulability.as_ref().unwrap().squared,
        parse("lb^4*c7^2/la^4")
    );
}

#[test]
fn manipulability_unidirectional_against_3_40() {
    let (_, c) = derived("unidirectional");
    let w2 = &c.manipulability.as_ref().unwrap().squared;
    // Derived: w² = lb² (s7² (la + lb)² + 2) / la².
    assert_eq!(*w2, parse("lb^2*(s7^2*(la + lb)^2 + 2)/la^2"));
    // The extracted (3.40) reads "wr = l2 b sin (θ7) 2(la + lb)2 + 2 l2 a": with the radical
    // lost in extraction, w = sqrt(lb² (sin²θ7 (la + lb)² + 2) / la²) — equal to the derivation.
    // The reading without a radical, w = lb² (sin²θ7 (la + lb)² + 2)/la², is not.
    let no_radical = parse("lb^2*(s7^2*(la + lb)^2 + 2)/la^2");
    assert_ne!(*w2, no_radical.mul(&no_radical));
}

#[test]
fn dia10_like_jr_depends_only_on_joints_7_and_8() {
    for zx in [false, true] {
        let d = derive(&dia10_like(zx)).unwrap();
        let c = d.constraint.as_ref().unwrap();
        assert_eq!(c.jr.joints().into_iter().collect::<Vec<_>>(), vec![6, 7]);
        assert_eq!(c.body_jacobian_i.joints().into_iter().max(), Some(5));
        // dia10_like: lb = 0.33 − la, l8 = 0.21; the presets' closed forms with those values.
        let w2 = &c.manipulability.as_ref().unwrap().squared;
        let expected = if zx {
            Poly::parse("(33/100 - la)^4*c7^2/la^4", &["la"]).unwrap()
        } else {
            Poly::parse("(33/100 - la)^4*s7^2/la^4", &["la"]).unwrap()
        };
        assert_eq!(*w2, expected);
    }
}

#[test]
fn decimal_geometry_stays_exact() {
    // 0.194, 1.037, 0.38, 0.39, 0.33, 0.21 are read as exact decimals (97/500, ...): no long
    // binary-fraction coefficients appear anywhere in dia10_like. The full-chain `g_0e` of ten
    // joints is kept partly as shared subexpressions; written out it is the canonical form.
    let d = derive(&dia10_like(false)).unwrap();
    let fk = d.fk_e.as_ref().unwrap();
    let pos: Vec<Poly> = fk
        .pos
        .entries()
        .iter()
        .map(|e| e.expanded(20_000).expect("g_0e of dia10_like writes out"))
        .collect();
    let digits = pos.iter().map(Poly::max_coefficient_digits).max().unwrap();
    assert!(digits <= 8, "{digits}");
    // x coordinate of the end effector contains exactly 0.194 c1 = 97/500 c1
    let term = Poly::parse("97/500*c1", &[]).unwrap();
    assert!(pos[0].terms().contains(&term.terms()[0]));
}

/// The quantities the thesis prints for its robots (`J^r` (3.24), (3.28), (3.29), `Λ#`, `Λ†`,
/// `J_c` and the manipulability (3.40)–(3.42)) stay in expanded canonical form (no shared
/// subexpression): that is what the comparisons with the printed equations above rely on.
#[test]
fn the_thesis_quantities_stay_canonical() {
    let mut robots: Vec<(String, Derivation)> =
        ["unidirectional", "bidirectional-zy", "bidirectional-zx"]
            .iter()
            .map(|n| (n.to_string(), derived(n).0))
            .collect();
    robots.push(("dia10_like zy".into(), derive(&dia10_like(false)).unwrap()));
    robots.push(("dia10_like zx".into(), derive(&dia10_like(true)).unwrap()));
    for (name, d) in &robots {
        let c = d.constraint.as_ref().unwrap();
        for (what, m) in [
            ("J^r", &c.jr),
            ("J_c", &c.jc),
            ("Λ#", &c.lambda_sharp),
            ("Λ†", &c.lambda_pinv),
        ] {
            assert!(
                !m.entries().iter().any(Poly::has_nodes),
                "{name}: {what} has shared subexpressions"
            );
        }
        assert!(
            c.manipulability.is_some(),
            "{name}: no closed-form manipulability"
        );
    }
}
