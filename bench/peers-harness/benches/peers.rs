//! One criterion run: the peers' generated C, wrenfold's and SymForce's generated Rust, the harness's Rust f64 reference, Pinocchio on the
//! Panda (feature `pinocchio`), and trig floors.
//! Bench ids: `<case>/<implementation>`; `bench/peers_table.py` turns the medians into the table.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar_peers_harness::rust_peers::{RustPeer, Trig};
use trocar_peers_harness::{eval, floor_eight, floor_two, Case, Peer};

fn peers(c: &mut Criterion) {
    // The generic robots (oblique7, panda_rcm) at fixed inputs like dia10_like; their f64
    // reference is the numeric runtime built from the description (not timed as rust_reference).
    for case in [
        Case::Uni,
        Case::Bzy,
        Case::Bzx,
        Case::DiaZy,
        Case::Oblique7,
        Case::PandaRcm,
    ] {
        let mut g = c.benchmark_group(case.name());
        let (q, p) = case.inputs();
        let mut out = vec![0.0; case.out_len()];
        for peer in Peer::ALL {
            if case.is_generic() && peer == Peer::RustReference {
                continue;
            }
            g.bench_function(peer.name(), |b| {
                b.iter(|| {
                    eval(peer, case, black_box(&q), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        if trocar_peers_harness::PRESETS.contains(&case) {
            // The presets' generated code of 2026-11-23, frozen (`src/baseline`).
            let f = black_box(trocar_peers_harness::baseline_fn(case));
            g.bench_function("baseline", |b| {
                b.iter(|| {
                    f(black_box(&q), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        let mut num = trocar_peers_harness::numeric::Numeric::new(case, &p);
        g.bench_function("numeric", |b| {
            b.iter(|| {
                num.eval(black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            })
        });
        // wrenfold's and SymForce's Rust, called as ours: a function pointer chosen here.
        for peer in RustPeer::ALL {
            let f = black_box(peer.eval_fn(case));
            g.bench_function(peer.name(), |b| {
                b.iter(|| {
                    f(black_box(&q), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let f = black_box(peer.eval_trig_fn(case));
            let t = Trig::new(&q);
            g.bench_function(format!("{}_given_trig", peer.name()), |b| {
                b.iter(|| {
                    f(black_box(&t), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        #[cfg(feature = "ours")]
        {
            use trocar_peers_harness::ours;
            let f = black_box(ours::eval_fn(case));
            g.bench_function("ours_f64", |b| {
                b.iter(|| {
                    f(black_box(&q), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let trig = ours::Trig::new(case, &q);
            g.bench_function("ours_f64_given_trig", |b| {
                b.iter(|| {
                    ours::eval_trig(case, black_box(&trig), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let (q32, p32): (Vec<f32>, Vec<f32>) = (
                q.iter().map(|&x| x as f32).collect(),
                p.iter().map(|&x| x as f32).collect(),
            );
            let mut out32 = vec![0.0f32; case.out_len()];
            g.bench_function("ours_f32", |b| {
                b.iter(|| {
                    ours::eval(case, black_box(&q32), black_box(&p32), &mut out32);
                    black_box(&mut out32);
                })
            });
        }
        g.finish();
    }
}

/// The Panda cases: every implementation cycles through the same 16 configurations
/// ([`Case::configs`]), the index passed through `black_box`, so q changes on every call.
fn panda(c: &mut Criterion) {
    for case in [Case::Panda, Case::PandaI] {
        let mut g = c.benchmark_group(case.name());
        let qs = case.configs();
        assert_eq!(qs.len(), 16);
        let (_, p) = case.inputs();
        let mut out = vec![0.0; case.out_len()];
        for peer in Peer::ALL {
            let mut k = 0usize;
            g.bench_function(peer.name(), |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    eval(peer, case, &qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        if case == Case::PandaI {
            let mut num = trocar_peers_harness::numeric::Numeric::new(case, &p);
            let mut k = 0usize;
            g.bench_function("numeric", |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    num.eval(&qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        for peer in RustPeer::ALL {
            let f = black_box(peer.eval_fn(case));
            let mut k = 0usize;
            g.bench_function(peer.name(), |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    f(&qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let f = black_box(peer.eval_trig_fn(case));
            let trigs: Vec<Trig> = qs.iter().map(|q| Trig::new(q)).collect();
            let mut k = 0usize;
            g.bench_function(format!("{}_given_trig", peer.name()), |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    f(&trigs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
        }
        // The trigonometry floor: glibc sin + cos of the 7 joints, in C compiled like the peers.
        let mut k = 0usize;
        let mut o14 = [0.0; 14];
        g.bench_function("trig_c_glibc", |b| {
            b.iter(|| {
                k = black_box(k + 1) & 15;
                trocar_peers_harness::floor_seven(&qs[k], &mut o14);
                black_box(&mut o14);
            })
        });
        #[cfg(feature = "pinocchio")]
        {
            use trocar_peers_harness::pinocchio::{Pinocchio, Variant};
            // Model from the URDF once, outside the timed loop.
            let mut pin = Pinocchio::new(case);
            for v in Variant::ALL {
                let mut k = 0usize;
                g.bench_function(v.name(), |b| {
                    b.iter(|| {
                        k = black_box(k + 1) & 15;
                        pin.eval(v, &qs[k]);
                    })
                });
            }
        }
        #[cfg(feature = "ours")]
        {
            use trocar_peers_harness::ours;
            let mut k = 0usize;
            let f = black_box(ours::eval_fn(case));
            g.bench_function("ours_f64", |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    f(&qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let mut k = 0usize;
            g.bench_function("ours_trig", |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    black_box(ours::panda_trig::<f64>(&qs[k]));
                })
            });
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            let mut k = 0usize;
            g.bench_function("ours_f64_given_trig", |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    ours::eval_trig(case, &trigs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            });
            let qs32: Vec<Vec<f32>> = qs
                .iter()
                .map(|q| q.iter().map(|&x| x as f32).collect())
                .collect();
            let p32: Vec<f32> = p.iter().map(|&x| x as f32).collect();
            let mut out32 = vec![0.0f32; case.out_len()];
            let mut k = 0usize;
            g.bench_function("ours_f32", |b| {
                b.iter(|| {
                    k = black_box(k + 1) & 15;
                    ours::eval(case, &qs32[k], black_box(&p32), &mut out32);
                    black_box(&mut out32);
                })
            });
        }
        g.finish();
    }
}

fn trig(c: &mut Criterion) {
    let mut g = c.benchmark_group("trig");
    let q2 = [0.5f64, 0.3];
    let q8 = [0.0f64, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    g.bench_function("c_glibc_two_sincos", |b| {
        let mut o = [0.0; 4];
        b.iter(|| {
            floor_two(black_box(&q2), &mut o);
            black_box(&o);
        })
    });
    g.bench_function("c_glibc_eight_sincos", |b| {
        let mut o = [0.0; 16];
        b.iter(|| {
            floor_eight(black_box(&q8), &mut o);
            black_box(&o);
        })
    });
    g.bench_function("rust_std_two_sin_cos_f64", |b| {
        b.iter(|| {
            let q = black_box(q2);
            black_box([q[0].sin_cos(), q[1].sin_cos()])
        })
    });
    g.bench_function("trocar_real_two_sin_cos_f64", |b| {
        b.iter(|| {
            let q = black_box(q2);
            black_box([
                <f64 as trocar::Real>::sin_cos(q[0]),
                <f64 as trocar::Real>::sin_cos(q[1]),
            ])
        })
    });
    g.bench_function("libm_two_sin_cos_f64", |b| {
        b.iter(|| {
            let q = black_box(q2);
            black_box([
                (libm::sin(q[0]), libm::cos(q[0])),
                (libm::sin(q[1]), libm::cos(q[1])),
            ])
        })
    });
    g.bench_function("fast_two_sin_cos_f64", |b| {
        b.iter(|| {
            let q = black_box(q2);
            black_box([
                trocar::emitted::fast::sin_cos_f64(q[0]),
                trocar::emitted::fast::sin_cos_f64(q[1]),
            ])
        })
    });
    let q2f = [0.5f32, 0.3];
    g.bench_function("fast_two_sin_cos_f32", |b| {
        b.iter(|| {
            let q = black_box(q2f);
            black_box([
                trocar::emitted::fast::sin_cos_f32(q[0]),
                trocar::emitted::fast::sin_cos_f32(q[1]),
            ])
        })
    });
    g.bench_function("rust_std_two_sin_cos_f32", |b| {
        b.iter(|| {
            let q = black_box(q2f);
            black_box([q[0].sin_cos(), q[1].sin_cos()])
        })
    });
    g.bench_function("trocar_real_two_sin_cos_f32", |b| {
        b.iter(|| {
            let q = black_box(q2f);
            black_box([
                <f32 as trocar::Real>::sin_cos(q[0]),
                <f32 as trocar::Real>::sin_cos(q[1]),
            ])
        })
    });
    g.bench_function("libm_two_sin_cos_f32", |b| {
        b.iter(|| {
            let q = black_box(q2f);
            black_box([
                (libm::sinf(q[0]), libm::cosf(q[0])),
                (libm::sinf(q[1]), libm::cosf(q[1])),
            ])
        })
    });
    g.finish();
}

criterion_group!(benches, peers, panda, trig);
criterion_main!(benches);
