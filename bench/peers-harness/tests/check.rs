//! The peers' C computes the right matrices: the harness's f64 reference is checked against the
//! thesis's closed forms (3.24), manipulability (3.41)/(3.42), the constraint itself and finite
//! differences; then every peer is checked against the reference. The Panda's reference (from the
//! URDF's numbers) is checked against finite differences, then Pinocchio (feature `pinocchio`),
//! the peers and trocar's generated code against it and against each other.
use trocar_peers_harness::reference::{self, Tf};
use trocar_peers_harness::{eval, Case, Peer, CASES, PRESETS};

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64) / ((1u64 << 53) as f64)
}

fn random_inputs(case: Case, seed: &mut u64) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut p) = case.inputs();
    for x in q.iter_mut() {
        *x = (lcg(seed) - 0.5) * 6.0;
    }
    if case == Case::DiaZy {
        p[0] = 0.05 + 0.25 * lcg(seed);
    } else {
        for x in p.iter_mut() {
            *x = 0.05 + 0.3 * lcg(seed);
        }
    }
    (q, p)
}

fn get(j: &[f64], r: usize, c: usize) -> f64 {
    j[6 * c + r]
}

#[test]
fn reference_unidirectional_is_3_24() {
    let mut seed = 1;
    for _ in 0..100 {
        let (q, p) = random_inputs(Case::Uni, &mut seed);
        let mut j = vec![0.0; 42];
        reference::eval(Case::Uni, &q, &p, &mut j);
        let (s7, c7, s8, c8) = (q[0].sin(), q[0].cos(), q[1].sin(), q[1].cos());
        let (la, lb, l8) = (p[0], p[1], p[2]);
        let a1 = -c8 * (l8 + lb * c7) / la;
        let a2 = -s8 * (l8 + lb * c7) / la;
        let a3 = -s8 * (la + lb + l8 * c7);
        let a4 = c8 * (la + lb + l8 * c7);
        let t = [
            [a1, c8 * s7, -s8, a3, -l8 * s7 * s8, -l8 * c8, 0.0],
            [lb * s7 / la, c7, 0.0, 0.0, 0.0, 0.0, 0.0],
            [a2, s7 * s8, c8, a4, l8 * c8 * s7, -l8 * s8, 0.0],
            [-s8 / la, 0.0, 0.0, c7 * c8, c8 * s7, -s8, 0.0],
            [0.0, 0.0, 0.0, -s7, c7, 0.0, 1.0],
            [c8 / la, 0.0, 0.0, c7 * s8, s7 * s8, c8, 0.0],
        ];
        for r in 0..6 {
            for c in 0..7 {
                assert!((get(&j, r, c) - t[r][c]).abs() < 1e-12, "({r},{c})");
            }
        }
    }
}

fn det6(j: &[f64]) -> f64 {
    let mut a = [[0.0; 6]; 6];
    for r in 0..6 {
        for c in 0..6 {
            a[r][c] = get(j, r, c);
        }
    }
    let mut det = 1.0;
    for k in 0..6 {
        let piv = (k..6)
            .max_by(|&x, &y| a[x][k].abs().total_cmp(&a[y][k].abs()))
            .unwrap();
        if piv != k {
            a.swap(piv, k);
            det = -det;
        }
        det *= a[k][k];
        for r in k + 1..6 {
            let f = a[r][k] / a[k][k];
            for c in k..6 {
                a[r][c] -= f * a[k][c];
            }
        }
    }
    det
}

#[test]
fn reference_bidirectional_manipulability_is_3_41_3_42() {
    let mut seed = 2;
    for _ in 0..100 {
        for case in [Case::Bzy, Case::Bzx] {
            let (q, p) = random_inputs(case, &mut seed);
            let mut j = vec![0.0; 36];
            reference::eval(case, &q, &p, &mut j);
            let t = if case == Case::Bzy {
                q[0].sin()
            } else {
                q[0].cos()
            };
            let want = p[1] * p[1] * t.abs() / (p[0] * p[0]);
            assert!(
                (det6(&j).abs() - want).abs() < 1e-10 * (1.0 + want),
                "{case:?}"
            );
        }
    }
}

/// Ad_{g_ri} Ad_{g_ie} maps the first columns of J^r back to F_r, where H V = 0 must hold.
#[test]
fn reference_first_columns_satisfy_the_constraint() {
    let mut seed = 3;
    for case in PRESETS {
        for _ in 0..50 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut j = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut j);
            let ncols = case.out_len() / 6 - 2;
            // V^B_0i = Ad_{g_ie} col; V^B_0r = Ad_{g_ri} V^B_0i with g_ri = (I, -(0, l_a, 0)).
            let wrist = if case == Case::Bzx { b'x' } else { b'y' };
            let g_ie = reference::mul(
                &reference::mul(
                    &reference::joint([0.0, p[0] + p[1], 0.0], b'z', q[0]),
                    &reference::joint([0.0; 3], wrist, q[1]),
                ),
                &Tf {
                    r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                    p: [0.0, p[2], 0.0],
                },
            );
            let g_ei = inv(&g_ie);
            let g_ir = Tf {
                r: g_ei.r.map(|_| [0.0; 3]),
                p: [0.0, p[0], 0.0],
            };
            let g_ir = Tf {
                r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                ..g_ir
            };
            for c in 0..ncols {
                let col: [f64; 6] = core::array::from_fn(|r| get(&j, r, c));
                let v0i = reference::ad_inv(&g_ei, col);
                let v0r = reference::ad_inv(&g_ir, v0i);
                assert!(v0r[0].abs() < 1e-12, "x_r");
                if case != Case::Uni {
                    assert!(v0r[2].abs() < 1e-12, "z_r");
                }
            }
        }
    }
}

fn inv(g: &Tf) -> Tf {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = g.r[j][i];
        }
    }
    let p = core::array::from_fn(|i| -(0..3).map(|k| r[i][k] * g.p[k]).sum::<f64>());
    Tf { r, p }
}

/// Body velocity (R^T p', (R^T R')^v) by central differences.
fn fd_body(f: impl Fn(f64) -> Tf) -> [f64; 6] {
    let h = 1e-6;
    let (a, b, g) = (f(h), f(-h), f(0.0));
    let mut out = [0.0; 6];
    let mut rd = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            rd[i][j] = (a.r[i][j] - b.r[i][j]) / (2.0 * h);
        }
    }
    for i in 0..3 {
        out[i] = (0..3)
            .map(|k| g.r[k][i] * (a.p[k] - b.p[k]) / (2.0 * h))
            .sum();
    }
    let w = |i: usize, j: usize| (0..3).map(|k| g.r[k][i] * rd[k][j]).sum::<f64>();
    out[3] = w(2, 1);
    out[4] = w(0, 2);
    out[5] = w(1, 0);
    out
}

#[test]
fn reference_dia_body_jacobians_match_finite_differences() {
    use reference::{joint, DIA_AXES_ZY, DIA_ORIGINS};
    let mut seed = 4;
    for _ in 0..20 {
        let (q, p) = random_inputs(Case::DiaZy, &mut seed);
        let mut out = vec![0.0; 84];
        reference::eval(Case::DiaZy, &q, &p, &mut out);
        let chain = |q: &[f64], n: usize| {
            let mut g = Tf {
                r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                p: [0.0; 3],
            };
            for k in 0..n {
                g = reference::mul(&g, &joint(DIA_ORIGINS[k], DIA_AXES_ZY[k], q[k]));
            }
            g
        };
        // FK
        let g = reference::dia_fk(&q);
        let g8 = reference::mul(
            &chain(&q, 8),
            &Tf {
                r: g.r.map(|_| [0.0; 3]),
                p: [0.0, 0.21, 0.0],
            },
        );
        for i in 0..3 {
            assert!((g.p[i] - g8.p[i]).abs() < 1e-12 && (out[9 + i] - g.p[i]).abs() < 1e-12);
        }
        // J^B_0i (6 joints)
        for k in 0..6 {
            let col = fd_body(|h| {
                let mut qq = q.clone();
                qq[k] += h;
                chain(&qq, 6)
            });
            for r in 0..6 {
                assert!(
                    (out[12 + 6 * k + r] - col[r]).abs() < 1e-7,
                    "jb0i ({r},{k})"
                );
            }
        }
        // J^B_0e2 columns of J^r (joints 7, 8) against the FK to the end effector
        for (k, c) in [(6usize, 4usize), (7, 5)] {
            let col = fd_body(|h| {
                let mut qq = q.clone();
                qq[k] += h;
                reference::dia_fk(&qq)
            });
            for r in 0..6 {
                assert!((out[48 + 6 * c + r] - col[r]).abs() < 1e-7, "jr ({r},{c})");
            }
        }
    }
}

#[test]
fn peers_agree_with_the_reference() {
    let mut seed = 5;
    for case in CASES {
        for _ in 0..200 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for peer in [Peer::Casadi, Peer::CasadiCse, Peer::Sympy] {
                let mut got = vec![f64::NAN; case.out_len()];
                eval(peer, case, &q, &p, &mut got);
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (g - w).abs() <= 1e-12 * scale,
                        "{peer:?} {case:?} [{i}]: {g} vs {w}"
                    );
                }
            }
        }
    }
}

/// wrenfold's and SymForce's Rust, from the joint values and given the sines and cosines, against
/// the reference (and, with the feature `ours`, against trocar's generated code).
#[test]
fn rust_peers_agree_with_the_reference_and_ours() {
    use trocar_peers_harness::rust_peers::{RustPeer, Trig};
    let mut seed = 7;
    for case in CASES {
        for _ in 0..200 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            #[cfg(feature = "ours")]
            let ours = {
                let mut o = vec![f64::NAN; case.out_len()];
                trocar_peers_harness::ours::eval(case, &q, &p, &mut o);
                o
            };
            for peer in RustPeer::ALL {
                let mut got = vec![f64::NAN; case.out_len()];
                peer.eval_fn(case)(&q, &p, &mut got);
                let mut got_t = vec![f64::NAN; case.out_len()];
                peer.eval_trig_fn(case)(&Trig::new(&q), &p, &mut got_t);
                for i in 0..want.len() {
                    for (what, g) in [("q", got[i]), ("trig", got_t[i])] {
                        assert!(
                            (g - want[i]).abs() <= 1e-12 * scale,
                            "{peer:?} {what} {case:?} [{i}]: {g} vs {}",
                            want[i]
                        );
                        #[cfg(feature = "ours")]
                        assert!(
                            (g - ours[i]).abs() <= 1e-12 * scale,
                            "{peer:?} {what} {case:?} [{i}]: {g} vs ours {}",
                            ours[i]
                        );
                    }
                }
            }
        }
    }
}

/// The frozen baseline (2026-11-23's generated presets) still computes the presets' J^r.
#[test]
fn baseline_agrees_with_the_reference() {
    let mut seed = 8;
    for case in PRESETS {
        for _ in 0..200 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let mut got = vec![f64::NAN; case.out_len()];
            trocar_peers_harness::baseline_eval(case, &q, &p, &mut got);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                assert!(
                    (g - w).abs() <= 1e-12 * scale,
                    "baseline {case:?} [{i}]: {g} vs {w}"
                );
            }
        }
    }
}

#[test]
fn numeric_runtime_agrees_with_the_reference() {
    use trocar_peers_harness::numeric::Numeric;
    let mut seed = 6;
    for case in [Case::Uni, Case::Bzy, Case::Bzx, Case::DiaZy, Case::PandaI] {
        for _ in 0..100 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let mut got = vec![f64::NAN; case.out_len()];
            Numeric::new(case, &p).eval(&q, &p, &mut got);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                assert!(
                    (g - w).abs() <= 1e-12 * scale,
                    "numeric {case:?} [{i}]: {g} vs {w}"
                );
            }
        }
    }
}

#[cfg(feature = "ours")]
#[test]
fn ours_agree_with_the_reference_f64_and_f32() {
    use trocar_peers_harness::ours;
    let mut seed = 8;
    for case in CASES {
        for _ in 0..200 {
            let (q, p) = random_inputs(case, &mut seed);
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let mut got = vec![f64::NAN; case.out_len()];
            ours::eval(case, &q, &p, &mut got);
            let mut got_t = vec![f64::NAN; case.out_len()];
            ours::eval_trig(case, &ours::Trig::new(case, &q), &p, &mut got_t);
            let (q32, p32): (Vec<f32>, Vec<f32>) = (
                q.iter().map(|&x| x as f32).collect(),
                p.iter().map(|&x| x as f32).collect(),
            );
            let mut got32 = vec![f32::NAN; case.out_len()];
            ours::eval(case, &q32, &p32, &mut got32);
            for i in 0..want.len() {
                assert!(
                    (got[i] - want[i]).abs() <= 1e-12 * scale,
                    "ours f64 {case:?} [{i}]"
                );
                assert!(
                    (got_t[i] - want[i]).abs() <= 1e-12 * scale,
                    "ours trig {case:?} [{i}]"
                );
                assert!(
                    (got32[i] as f64 - want[i]).abs() <= 2e-5 * scale,
                    "ours f32 {case:?} [{i}]"
                );
            }
        }
    }
}

/// The Panda cases written in place in the generated functions' own layout (the timing
/// drivers' `ours_f64_in_place`, `ours_f64_given_trig_in_place`) hold the reference's values:
/// `(R, p)` and the column-major Jacobian read as the flat buffer's R, p, J.
#[cfg(feature = "ours")]
#[test]
fn ours_in_place_agree_with_the_reference() {
    use trocar_peers_harness::ours;
    let mut seed = 9;
    for case in [Case::Panda, Case::PandaI] {
        for (q, p) in panda_inputs(case, &mut seed, 200) {
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let mut a = ours::PandaOut::<f64>::default();
            ours::eval_panda_in_place(case, &q, &p, &mut a);
            let mut b = ours::PandaOut::<f64>::default();
            ours::eval_trig_panda_in_place(case, &ours::Trig::new(case, &q), &p, &mut b);
            for o in [&a, &b] {
                let flat: Vec<f64> =
                    o.g.0
                        .iter()
                        .flatten()
                        .chain(&o.g.1)
                        .chain(o.jb.iter().flatten())
                        .copied()
                        .collect();
                assert_eq!(flat.len(), want.len());
                for (i, (x, w)) in flat.iter().zip(&want).enumerate() {
                    assert!((x - w).abs() <= 1e-12 * scale, "{case:?} [{i}]");
                }
            }
        }
    }
}

/// The hand-written kernel with rows as SSE2 pairs (`paired_rows`) holds the reference's values
/// of `panda_link7`'s pose and body Jacobian.
#[cfg(target_arch = "x86_64")]
#[test]
fn paired_rows_agree_with_the_reference() {
    let case = Case::PandaI;
    let mut seed = 10;
    for (q, p) in panda_inputs(case, &mut seed, 500) {
        let mut want = vec![0.0; case.out_len()];
        reference::eval(case, &q, &p, &mut want);
        let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let s: [f64; 7] = std::array::from_fn(|k| q[k].sin());
        let c: [f64; 7] = std::array::from_fn(|k| q[k].cos());
        let mut g = ([[f64::NAN; 3]; 3], [f64::NAN; 3]);
        let mut jb = [[f64::NAN; 6]; 7];
        trocar_peers_harness::paired_rows::panda_link7(&s, &c, &mut g, &mut jb);
        let flat: Vec<f64> =
            g.0.iter()
                .flatten()
                .chain(&g.1)
                .chain(jb.iter().flatten())
                .copied()
                .collect();
        for (i, (x, w)) in flat.iter().zip(&want).enumerate() {
            assert!((x - w).abs() <= 1e-13 * scale, "[{i}] {x} vs {w} at {q:?}");
        }
    }
}

/// The step cases written with the pose in place (`ours_f64_in_place`,
/// `ours_f64_given_trig_in_place` of the step cases) and every fused case through the `_f64`
/// entry points of the `fma_at_run_time` modules (`ours_f64_fma`, `ours_f64_given_trig_fma`)
/// hold the reference's values.
#[cfg(feature = "ours")]
#[test]
fn ours_in_place_and_fma_agree_with_the_reference() {
    use trocar_peers_harness::ours;
    let mut seed = 10;
    for case in [Case::PandaI, Case::DiaZy, Case::Oblique7, Case::PandaRcm] {
        let inputs: Vec<(Vec<f64>, Vec<f64>)> = if case.is_panda() {
            panda_inputs(case, &mut seed, 200)
        } else {
            (0..200).map(|_| random_inputs(case, &mut seed)).collect()
        };
        for (q, p) in inputs {
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let mut results = Vec::new();
            let flat = |o: &ours::PandaOut<f64>, out: &[f64]| -> Vec<f64> {
                let pose = o.g.0.iter().flatten().chain(&o.g.1).copied();
                if case.is_panda() {
                    pose.chain(o.jb.iter().flatten().copied()).collect()
                } else {
                    pose.chain(out[12..].iter().copied()).collect()
                }
            };
            if !case.is_panda() {
                let (mut o, mut out) = (ours::PandaOut::default(), vec![f64::NAN; want.len()]);
                ours::eval_step_in_place(case, &q, &p, &mut o.g, &mut out);
                results.push(("in place", flat(&o, &out)));
                let (mut o, mut out) = (ours::PandaOut::default(), vec![f64::NAN; want.len()]);
                ours::eval_trig_step_in_place(
                    case,
                    &ours::Trig::new(case, &q),
                    &p,
                    &mut o.g,
                    &mut out,
                );
                results.push(("in place, given trig", flat(&o, &out)));
            }
            let (mut o, mut out) = (ours::PandaOut::default(), vec![f64::NAN; want.len()]);
            ours::eval_fma(case, &q, &p, &mut out, &mut o);
            results.push(("fma", flat(&o, &out)));
            let (mut o, mut out) = (ours::PandaOut::default(), vec![f64::NAN; want.len()]);
            ours::eval_trig_fma(case, &ours::TrigFma::new(&q), &p, &mut out, &mut o);
            results.push(("fma, given trig", flat(&o, &out)));
            for (what, got) in results {
                assert_eq!(got.len(), want.len());
                for (i, (x, w)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (x - w).abs() <= 1e-12 * scale,
                        "{what} {case:?} [{i}]: {x} vs {w}"
                    );
                }
            }
        }
    }
}

/// The CasADi functions need no `iw` or `w` scratch, which is why `eval` passes null for both;
/// the Panda's need `w`, at most `CASADI_W` doubles, which `eval` passes.
#[test]
fn casadi_functions_need_no_work_arrays() {
    for peer in [Peer::Casadi, Peer::CasadiCse] {
        for case in CASES {
            let [n_arg, n_res, n_iw, n_w] = trocar_peers_harness::casadi_work_sizes(peer, case);
            if case.is_panda() {
                assert_eq!(n_iw, 0, "{peer:?} {case:?}");
                assert!(
                    n_w as usize <= trocar_peers_harness::CASADI_W,
                    "{peer:?} {case:?}: sz_w {n_w}"
                );
            } else {
                assert_eq!((n_iw, n_w), (0, 0), "{peer:?} {case:?}");
            }
            assert_eq!(n_arg, 2, "{peer:?} {case:?}");
            assert!((1..=3).contains(&n_res), "{peer:?} {case:?}");
        }
    }
}

/// The Panda's configurations: random in ±3 rad, and the benchmark's 16 (within the limits).
fn panda_inputs(case: Case, seed: &mut u64, n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let (_, p) = case.inputs();
    let mut v: Vec<(Vec<f64>, Vec<f64>)> =
        case.configs().into_iter().map(|q| (q, p.clone())).collect();
    v.extend((0..n).map(|_| random_inputs(case, seed)));
    v
}

#[test]
fn reference_panda_matches_finite_differences_and_the_urdf() {
    let mut seed = 9;
    for case in [Case::Panda, Case::PandaI] {
        for (q, p) in panda_inputs(case, &mut seed, 20) {
            let mut out = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut out);
            let flange = case == Case::Panda;
            // The pose is the product of the URDF's joint transforms (and panda_joint8's offset).
            let (g, _) = reference::panda(&q, flange);
            for j in 0..3 {
                for i in 0..3 {
                    assert_eq!(out[3 * j + i], g.r[i][j]);
                }
            }
            // The columns of J are the body velocities of the pose per joint.
            for k in 0..7 {
                let col = fd_body(|h| {
                    let mut qq = q.clone();
                    qq[k] += h;
                    reference::panda(&qq, flange).0
                });
                for r in 0..6 {
                    assert!(
                        (out[12 + 6 * k + r] - col[r]).abs() < 1e-7,
                        "{case:?} J ({r},{k})"
                    );
                }
            }
            // panda_link8 = panda_link7 · (I, (0, 0, 0.107)).
            if flange {
                let (g7, _) = reference::panda(&q, false);
                for i in 0..3 {
                    let want = g7.p[i] + g7.r[i][2] * reference::PANDA_FLANGE[2];
                    assert!((out[9 + i] - want).abs() < 1e-15);
                }
            }
        }
    }
}

/// Pinocchio's LOCAL frame Jacobian and placement of panda_link8 (case `panda`) and panda_link7
/// (`panda_i`), both routes (placement left by computeFrameJacobian in data.iMf[0], and
/// forwardKinematics + updateFramePlacement), against the reference.
#[cfg(feature = "pinocchio")]
#[test]
fn pinocchio_agrees_with_the_reference() {
    use trocar_peers_harness::pinocchio::{Pinocchio, Variant};
    let mut seed = 10;
    for case in [Case::Panda, Case::PandaI] {
        let mut pin = Pinocchio::new(case);
        for (q, p) in panda_inputs(case, &mut seed, 100) {
            let mut want = vec![0.0; case.out_len()];
            reference::eval(case, &q, &p, &mut want);
            for v in Variant::ALL {
                pin.eval(v, &q);
                let mut got = vec![f64::NAN; case.out_len()];
                pin.read(v, &mut got);
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (g - w).abs() <= 1e-12,
                        "pinocchio {v:?} {case:?} [{i}]: {g} vs {w}"
                    );
                }
            }
        }
    }
}

/// trocar's generated g_0i + J^B_0i of panda-laparoscope against Pinocchio's panda_link7 (the
/// same frame), and the bench's panda_link8 module against Pinocchio's panda_link8; and
/// panda-laparoscope's against Pinocchio's panda_link8 moved by panda_joint8's fixed offset
/// (J^B_08 = Ad_{g_78}^{-1} J^B_07, g_08 = g_07 g_78).
#[cfg(all(feature = "pinocchio", feature = "ours"))]
#[test]
fn ours_agree_with_pinocchio() {
    use trocar_peers_harness::ours;
    use trocar_peers_harness::pinocchio::{Pinocchio, Variant};
    let mut seed = 11;
    let mut pin8 = Pinocchio::new(Case::Panda);
    for case in [Case::Panda, Case::PandaI] {
        let mut pin = Pinocchio::new(case);
        for (q, p) in panda_inputs(case, &mut seed, 100) {
            let mut ours = vec![f64::NAN; case.out_len()];
            ours::eval(case, &q, &p, &mut ours);
            let mut theirs = vec![f64::NAN; case.out_len()];
            pin.eval(Variant::FrameJacobian, &q);
            pin.read(Variant::FrameJacobian, &mut theirs);
            for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "ours vs pinocchio {case:?} [{i}]: {a} vs {b}"
                );
            }
            if case == Case::PandaI {
                let mut flange = vec![f64::NAN; 54];
                pin8.eval(Variant::FrameJacobian, &q);
                pin8.read(Variant::FrameJacobian, &mut flange);
                let d = reference::PANDA_FLANGE[2];
                for i in 0..3 {
                    let p8 = ours[9 + i] + ours[6 + i] * d;
                    assert!((p8 - flange[9 + i]).abs() <= 1e-12);
                    for j in 0..3 {
                        assert!((ours[3 * j + i] - flange[3 * j + i]).abs() <= 1e-12);
                    }
                }
                for k in 0..7 {
                    let c: [f64; 6] = core::array::from_fn(|r| ours[12 + 6 * k + r]);
                    let g78 = Tf {
                        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                        p: [0.0, 0.0, d],
                    };
                    let c8 = reference::ad_inv(&g78, c);
                    for r in 0..6 {
                        let b = flange[12 + 6 * k + r];
                        assert!(
                            (c8[r] - b).abs() <= 1e-12,
                            "F_i moved to panda_link8 ({r},{k}): {} vs {b}",
                            c8[r]
                        );
                    }
                }
            }
        }
    }
}
