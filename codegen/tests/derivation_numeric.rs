//! Numeric cross-check of every derived matrix against the independent `f64` implementation in
//! `derivation_support` (4×4 products, series exponential, 6×6 adjoints), at random
//! configurations and parameter values, to 1e-12 relative.

mod derivation_support;

use derivation_support::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use trocar_codegen::derivation::{derive, DerivationErrorKind, ManipulabilityForm, NullSpaceBasis};
use trocar_codegen::symbolic::Env;
use trocar_model::description::{JointKind, RobotDescription, Rotation, Wrist};

const TOL: f64 = 1e-12;

fn assert_close(what: &str, got: &[Vec<f64>], want: &[Vec<f64>]) {
    let err = max_abs_diff(got, want);
    let scale = norm(want).max(1.0);
    assert!(
        err <= TOL * scale,
        "{what}: error {err:e} (scale {scale})\n got {got:?}\nwant {want:?}"
    );
}

fn transpose(a: &[Vec<f64>]) -> Vec<Vec<f64>> {
    (0..a[0].len())
        .map(|j| a.iter().map(|r| r[j]).collect())
        .collect()
}

/// Gauss–Jordan inverse with partial pivoting.
fn inverse(a: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = a.len();
    let mut m: Vec<Vec<f64>> = a
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let mut row = r.clone();
            row.extend((0..n).map(|j| if i == j { 1.0 } else { 0.0 }));
            row
        })
        .collect();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
            .unwrap();
        m.swap(c, p);
        let d = m[c][c];
        for x in m[c].iter_mut() {
            *x /= d;
        }
        for r in 0..n {
            if r != c {
                let f = m[r][c];
                let pivot = m[c].clone();
                for (x, y) in m[r].iter_mut().zip(pivot) {
                    *x -= f * y;
                }
            }
        }
    }
    m.into_iter().map(|r| r[n..].to_vec()).collect()
}

fn det(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    let mut m = a.to_vec();
    let mut d = 1.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
            .unwrap();
        if p != c {
            m.swap(c, p);
            d = -d;
        }
        d *= m[c][c];
        if m[c][c] == 0.0 {
            return 0.0;
        }
        for r in c + 1..n {
            let f = m[r][c] / m[c][c];
            let pivot = m[c].clone();
            for (x, y) in m[r].iter_mut().zip(pivot) {
                *x -= f * y;
            }
        }
    }
    d
}

fn rank(a: &[Vec<f64>]) -> usize {
    // rank via Gram matrix determinant of columns
    let at = transpose(a);
    let g = mat_mul(&at, a);
    let mut rnk = 0;
    let n = g.len();
    let mut m = g;
    let mut row = 0;
    for c in 0..n {
        let Some(p) = (row..n).find(|&r| m[r][c].abs() > 1e-9) else {
            continue;
        };
        m.swap(row, p);
        for r in 0..n {
            if r != row {
                let f = m[r][c] / m[row][c];
                let pivot = m[row].clone();
                for (x, y) in m[r].iter_mut().zip(pivot) {
                    *x -= f * y;
                }
            }
        }
        row += 1;
        rnk += 1;
    }
    rnk
}

/// Checks every derived matrix of `desc` at `samples` random configurations.
fn cross_check(desc: &RobotDescription, samples: usize, seed: u64) {
    let d = derive(desc).unwrap_or_else(|e| panic!("{}: {e}", desc.name));
    let mut rng = StdRng::seed_from_u64(seed);
    let n = desc.joints.len();
    for _ in 0..samples {
        let q: Vec<f64> = (0..n).map(|_| rng.gen_range(-3.0..3.0)).collect();
        let values: Vec<f64> = d.params.iter().map(|_| rng.gen_range(0.1..0.4)).collect();
        let named: Vec<(&str, f64)> = d
            .params
            .iter()
            .map(|s| s.as_str())
            .zip(values.iter().copied())
            .collect();
        let env = Env {
            q: &q,
            params: &values,
        };
        let num = Numeric::new(desc, &q, &named);

        let g_0e = m4_vec(&num.fk(n, true));
        let jb_0e = num.body_jacobian(n, true);
        if let Some(fk) = &d.fk_e {
            assert_close("g_0e", &fk.homogeneous().eval(&env), &g_0e);
        }
        if let Some(jb) = &d.body_jacobian_e {
            assert_close("J^B_0e", &jb.eval(&env), &jb_0e);
        }

        let Some(c) = &d.constraint else { continue };
        let cd = desc.constraint.as_ref().unwrap();
        let i = c.link;
        assert_close(
            "g_0i",
            &c.fk_i.homogeneous().eval(&env),
            &m4_vec(&num.fk(i, false)),
        );
        assert_close(
            "J^B_0i",
            &c.body_jacobian_i.eval(&env),
            &num.body_jacobian(i, false),
        );
        // the factorisation g_0e = g_0i g_ie, evaluated numerically from the derived factors
        let g0i = c.fk_i.homogeneous().eval(&env);
        let gie = c.g_ie.homogeneous().eval(&env);
        assert_close("g_0i g_ie", &mat_mul(&g0i, &gie), &g_0e);

        // Λ = H Ad_{g_ri}, numerically
        let g_ir = origin_matrix(&cd.origin, &named);
        let h: Vec<Vec<f64>> = cd.h.iter().map(|r| r.to_vec()).collect();
        let lambda = mat_mul(&h, &m6_vec(&adjoint(&m4_inv(&g_ir))));
        assert_close("Λ", &c.lambda.eval(&env), &lambda);

        // Λ#: the thesis bases transcribed here; a derived basis checked by its properties.
        let la = g_ir[1][3];
        let lambda_sharp = match cd.wrist {
            Some(Wrist::Unidirectional) => {
                let mut b = vec![vec![0.0; 5]; 6];
                for (k, row) in b.iter_mut().take(5).enumerate() {
                    row[k] = 1.0;
                }
                b[5][0] = 1.0 / la;
                b
            }
            Some(_) => {
                let mut b = vec![vec![0.0; 4]; 6];
                b[0][0] = 1.0;
                b[5][0] = 1.0 / la;
                b[1][1] = 1.0;
                b[2][2] = 1.0;
                b[3][2] = -1.0 / la;
                b[4][3] = 1.0;
                b
            }
            None => {
                assert_eq!(c.basis, NullSpaceBasis::Computed);
                let b = c.lambda_sharp.eval(&env);
                let prod = mat_mul(&lambda, &b);
                assert!(prod.iter().flatten().all(|x| x.abs() < 1e-12), "Λ Λ# ≠ 0");
                assert_eq!(rank(&b), 6 - c.r);
                b
            }
        };
        assert_close("Λ#", &c.lambda_sharp.eval(&env), &lambda_sharp);

        // J^r = [Ad_{g_ei} Λ# | J^B_0e2] (3.15)
        let mut g_ie = m4_identity();
        for t in &num.t[i..] {
            g_ie = m4_mul(&g_ie, t);
        }
        g_ie = m4_mul(&g_ie, &num.ee);
        let ad_ei = m6_vec(&adjoint(&m4_inv(&g_ie)));
        let left = mat_mul(&ad_ei, &lambda_sharp);
        let jb = num.body_jacobian(n, true);
        let jr: Vec<Vec<f64>> = (0..6)
            .map(|r| {
                let mut row = left[r].clone();
                row.extend_from_slice(&jb[r][i..]);
                row
            })
            .collect();
        assert_close("J^r", &c.jr.eval(&env), &jr);

        // J_c = Ad_{g_ei} Λᵀ (Λ Λᵀ)⁻¹ (3.33)
        let lt = transpose(&lambda);
        let pinv = mat_mul(&lt, &inverse(&mat_mul(&lambda, &lt)));
        assert_close("Λ†", &c.lambda_pinv.eval(&env), &pinv);
        assert_close("J_c", &c.jc.eval(&env), &mat_mul(&ad_ei, &pinv));

        // manipulability² = det(J^r J^rᵀ)
        let w2 = det(&mat_mul(&jr, &transpose(&jr)));
        if c.manipulability.is_none() {
            continue;
        }
        let got = c.manipulability.as_ref().unwrap().squared.eval(&env);
        assert!(
            (got - w2).abs() <= 1e-10 * w2.abs().max(1.0),
            "w²: {got} vs {w2}"
        );
        if let ManipulabilityForm::AbsDet(p) = &c.manipulability.as_ref().unwrap().form {
            let dj = det(&jr);
            assert!((p.eval(&env) - dj).abs() <= 1e-10 * dj.abs().max(1.0));
        }
    }
}

#[test]
fn presets_match_numeric_kinematics() {
    for (k, name) in ["unidirectional", "bidirectional-zy", "bidirectional-zx"]
        .iter()
        .enumerate()
    {
        cross_check(&preset(name), 50, 10 + k as u64);
    }
}

#[test]
fn dia10_like_matches_numeric_kinematics() {
    cross_check(&dia10_like(false), 30, 20);
    cross_check(&dia10_like(true), 30, 21);
}

#[test]
fn derived_basis_on_a_preset_geometry() {
    // Same geometry as bidirectional-zy, no wrist preset: derived basis Λ# = Ad_{g_ir} N.
    let mut d = preset("bidirectional-zy");
    d.constraint.as_mut().unwrap().wrist = None;
    cross_check(&d, 30, 30);
    let der = derive(&d).unwrap();
    assert_eq!(der.constraint.unwrap().basis, NullSpaceBasis::Computed);
}

/// dia10_like and the thesis presets derive with the end effector's pose and body Jacobian
/// expanded; the sizes of the derived expressions are printed. How long the derivation takes is
/// measured by `cargo bench -p trocar-codegen --bench derivation`.
#[test]
fn presets_derive_with_expanded_pose_and_body_jacobian() {
    let cases = [
        ("dia10_like_zy", dia10_like(false)),
        ("dia10_like_zx", dia10_like(true)),
        ("unidirectional", preset("unidirectional")),
        ("bidirectional-zy", preset("bidirectional-zy")),
        ("bidirectional-zx", preset("bidirectional-zx")),
    ];
    for (name, desc) in cases {
        let d = derive(&desc).unwrap();
        assert!(d.fk_e.is_some() && d.body_jacobian_e.is_some(), "{name}");
        let sizes: Vec<String> = d
            .sizes()
            .iter()
            .map(|(n, r, c, t)| format!("{n} {r}x{c}: {t}"))
            .collect();
        println!("{name}: terms: {}", sizes.join(", "));
    }
}

#[test]
fn random_chain_with_prismatic_screw_and_three_row_h() {
    let desc = random_chain(7);
    let d = derive(&desc).unwrap();
    println!(
        "random chain: sizes {:?}; fk_e expanded: {}, manipulability closed form: {}",
        d.sizes(),
        d.fk_e.is_some(),
        d.constraint.as_ref().unwrap().manipulability.is_some()
    );
    let c = d.constraint.as_ref().unwrap();
    assert_eq!((c.r, c.m), (3, 6));
    assert!(d.joint_is_linear[3]);
    cross_check(&desc, 10, 40);
}

#[test]
fn non_identity_r_ir_on_the_presets_geometry() {
    let mut d = preset("unidirectional");
    let c = d.constraint.as_mut().unwrap();
    c.wrist = None;
    c.origin.rotation = Rotation::Rpy([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
    c.h = vec![HX, HZ];
    cross_check(&d, 20, 50);
    // Exact permutation matrix thanks to the "snap unit" rule: J^r stays small.
    let der = derive(&d).unwrap();
    assert!(der.constraint.unwrap().jr.total_terms() < 80);
}

#[test]
fn validation_errors_are_results() {
    // n − r < 6
    let mut d = preset("bidirectional-zy");
    d.joints.pop();
    d.joints.pop();
    let e = derive(&d).unwrap_err();
    assert_eq!(e.kind, DerivationErrorKind::TooFewJoints);
    // constrained link out of range
    let mut d = preset("unidirectional");
    d.constraint.as_mut().unwrap().link = 9;
    assert_eq!(derive(&d).unwrap_err().field, "constraint.link");
    // dependent rows of H
    let mut d = preset("bidirectional-zy");
    d.constraint.as_mut().unwrap().h = vec![HX, HX];
    assert_eq!(derive(&d).unwrap_err().field, "constraint.h");
    // non-unit axis
    let mut d = preset("unidirectional");
    d.joints[0].kind = JointKind::Revolute {
        axis: [0.0, 0.0, 2.0],
    };
    assert_eq!(derive(&d).unwrap_err().field, "joints[0].axis");
    // unknown parameter
    let mut d = preset("unidirectional");
    d.joints[6].origin.xyz[1] = par(&[(1.0, "nope")]);
    assert!(derive(&d).unwrap_err().message.contains("nope"));
    // wrist preset that does not fit the geometry (F_r off the y axis)
    let mut d = preset("bidirectional-zx");
    d.constraint.as_mut().unwrap().origin.xyz[0] = num(0.1);
    assert_eq!(
        derive(&d).unwrap_err().kind,
        DerivationErrorKind::WristMismatch
    );
    // wrist preset with the wrong number of rows
    let mut d = preset("unidirectional");
    d.constraint.as_mut().unwrap().wrist = Some(Wrist::Zy);
    assert_eq!(
        derive(&d).unwrap_err().kind,
        DerivationErrorKind::WristMismatch
    );
    // not finite
    let mut d = preset("unidirectional");
    d.end_effector.origin.xyz[0] = num(f64::NAN);
    assert_eq!(derive(&d).unwrap_err().kind, DerivationErrorKind::Invalid);
}

#[test]
fn no_constraint_gives_fk_and_body_jacobian_only() {
    let mut d = preset("unidirectional");
    d.constraint = None;
    let der = derive(&d).unwrap();
    assert!(der.constraint.is_none());
    cross_check(&d, 10, 60);
}

/// Oblique axes: the derivation's own expanded forms (`g_0i`, `J^B_0i`, `g_ie`, `J^r`, and
/// without a constraint `g_0e`, `J^B_0e`) in the turned frames turned back, against the numeric
/// kinematics; the constrained link's joint and the last one are oblique.
#[test]
fn oblique_frames_match_numeric_kinematics() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/api/tests/data/");
    let constrained =
        RobotDescription::from_toml_file(format!("{data}dia10_oblique.toml")).unwrap();
    let d = derive(&constrained).unwrap();
    assert!(d.frame_turns[5].is_some() && d.frame_turns[7].is_some());
    assert!(
        d.fk_e.is_some() && d.body_jacobian_e.is_some(),
        "expanded forms derived"
    );
    cross_check(&constrained, 40, 3);
    let mut free = constrained.clone();
    free.constraint = None;
    free.task = None;
    cross_check(&free, 40, 4);
}
