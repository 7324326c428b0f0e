//! With `CPUTIME=1` it prints instead the median thread-CPU time per evaluation (ns).
//! Driver for `valgrind --tool=callgrind --toggle-collect='*measured_loop*'`:
//! `cg_driver IMPL CASE N` evaluates one function N times inside `measured_loop`, so the collected
//! instruction count divided by N is instructions per evaluation (the loop's own ~5 instructions
//! per iteration included; `cg_driver noop - N` measures them).
//! IMPL: casadi | casadi_cse | sympy | rust_reference | numeric | baseline (presets) | ours_f64 |
//! ours_f64_given_trig | ours_f64_in_place | ours_f64_given_trig_in_place (the pose in place) |
//! ours_f64_fma | ours_f64_given_trig_fma (the fused cases' `_f64` entry points of the
//! `fma_at_run_time` modules) |
//! ours_f32 (feature `ours`) | wrenfold | symforce | wrenfold_given_trig | symforce_given_trig |
//! wrenfold_fed_trocar_sin_cos | symforce_fed_trocar_sin_cos (Panda cases, feature `ours`) |
//! paired_rows_given_trig (`panda_i`, feature `ours`: the hand-written kernel of `paired_rows`) | pinocchio | pinocchio_fk (feature `pinocchio`, Panda cases) |
//! ours_trig | trig_c_glibc (Panda cases: the 7 joints' trigonometry alone) | noop |
//! trig_c_glibc | trig_std_f64 | trig_fast_f64 | trig_std_f32 | trig_fast_f32 | trig_libm_f64 |
//! trig_libm_f32. CASE: uni | bzy | bzx | dia_zy | panda | panda_i | -.
//! The Panda cases cycle through `Case::configs` (16 configurations, the index through
//! `black_box`), as the criterion bench does.
use std::hint::black_box;
use trocar_peers_harness::rust_peers::{RustPeer, Trig};
use trocar_peers_harness::{eval, floor_two, Case, Peer};

/// `wrenfold` | `symforce` (from q) | `wrenfold_given_trig` | `symforce_given_trig`.
fn rust_peer(name: &str) -> Option<(RustPeer, bool)> {
    match name.strip_suffix("_given_trig") {
        Some(base) => RustPeer::from_name(base).map(|p| (p, true)),
        None => RustPeer::from_name(name).map(|p| (p, false)),
    }
}

#[repr(C)]
struct Timespec {
    sec: i64,
    nsec: i64,
}
extern "C" {
    fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
}
const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

fn thread_cpu_ns() -> f64 {
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: valid pointer; Linux x86_64 timespec layout.
    unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.sec as f64 * 1e9 + ts.nsec as f64
}

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut()) {
    if std::env::var_os("CPUTIME").is_some() {
        // Thread CPU time instead of callgrind: median over 31 runs of n evaluations, in ns per
        // evaluation. Counts only the time this thread was on a core, so it holds up on a
        // loaded machine where wall-clock (criterion) medians do not.
        for _ in 0..n {
            f();
        }
        let mut v: Vec<f64> = (0..31)
            .map(|_| {
                let t0 = thread_cpu_ns();
                for _ in 0..n {
                    f();
                }
                (thread_cpu_ns() - t0) / n as f64
            })
            .collect();
        v.sort_by(f64::total_cmp);
        println!("{:.2}", v[15]);
        return;
    }
    for _ in 0..n {
        f();
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: cg_driver IMPL CASE N");
        std::process::exit(2);
    }
    let n: usize = args[3].parse().expect("N");
    let q2 = [0.5f64, 0.3];
    let q2f = [0.5f32, 0.3];
    if let Some(case) = Case::from_name(&args[2]).filter(|c| c.is_panda()) {
        return panda(&args[1], case, n);
    }
    match args[1].as_str() {
        "noop" => measured_loop(n, &mut || {
            black_box(black_box(&q2));
        }),
        "trig_c_glibc" => {
            let mut o = [0.0; 4];
            measured_loop(n, &mut || {
                floor_two(black_box(&q2), &mut o);
                black_box(&o);
            })
        }
        "trig_std_f64" => measured_loop(n, &mut || {
            let q = black_box(q2);
            black_box([q[0].sin_cos(), q[1].sin_cos()]);
        }),
        "trig_fast_f64" => measured_loop(n, &mut || {
            let q = black_box(q2);
            black_box([
                trocar::emitted::fast::sin_cos_f64(q[0]),
                trocar::emitted::fast::sin_cos_f64(q[1]),
            ]);
        }),
        "trig_libm_f64" => measured_loop(n, &mut || {
            let q = black_box(q2);
            black_box([
                (libm::sin(q[0]), libm::cos(q[0])),
                (libm::sin(q[1]), libm::cos(q[1])),
            ]);
        }),
        "trig_std_f32" => measured_loop(n, &mut || {
            let q = black_box(q2f);
            black_box([q[0].sin_cos(), q[1].sin_cos()]);
        }),
        "trig_fast_f32" => measured_loop(n, &mut || {
            let q = black_box(q2f);
            black_box([
                trocar::emitted::fast::sin_cos_f32(q[0]),
                trocar::emitted::fast::sin_cos_f32(q[1]),
            ]);
        }),
        "trig_libm_f32" => measured_loop(n, &mut || {
            let q = black_box(q2f);
            black_box([
                (libm::sinf(q[0]), libm::cosf(q[0])),
                (libm::sinf(q[1]), libm::cosf(q[1])),
            ]);
        }),
        "numeric" => {
            let case =
                Case::from_name(&args[2]).unwrap_or_else(|| panic!("unknown CASE {}", args[2]));
            let (q, p) = case.inputs();
            let mut num = trocar_peers_harness::numeric::Numeric::new(case, &p);
            let mut out = vec![0.0; case.out_len()];
            measured_loop(n, &mut || {
                num.eval(black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            });
        }
        "baseline" => {
            let case =
                Case::from_name(&args[2]).unwrap_or_else(|| panic!("unknown CASE {}", args[2]));
            let (q, p) = case.inputs();
            let mut out = vec![0.0; case.out_len()];
            let f = black_box(trocar_peers_harness::baseline_fn(case));
            measured_loop(n, &mut || {
                f(black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            });
        }
        #[cfg(feature = "ours")]
        "ours_f64"
        | "ours_f64_given_trig"
        | "ours_f32"
        | "ours_f64_in_place"
        | "ours_f64_given_trig_in_place"
        | "ours_f64_fma"
        | "ours_f64_given_trig_fma" => {
            use trocar_peers_harness::ours;
            let case =
                Case::from_name(&args[2]).unwrap_or_else(|| panic!("unknown CASE {}", args[2]));
            let (q, p) = case.inputs();
            let mut out = vec![0.0; case.out_len()];
            match args[1].as_str() {
                "ours_f64" => {
                    let f = black_box(ours::eval_fn(case));
                    measured_loop(n, &mut || {
                        f(black_box(&q), black_box(&p), &mut out);
                        black_box(&mut out);
                    })
                }
                "ours_f64_given_trig" => {
                    let t = ours::Trig::new(case, &q);
                    measured_loop(n, &mut || {
                        ours::eval_trig(case, black_box(&t), black_box(&p), &mut out);
                        black_box(&mut out);
                    })
                }
                "ours_f64_in_place" => {
                    let mut o = ours::PandaOut::<f64>::default();
                    measured_loop(n, &mut || {
                        ours::eval_step_in_place(
                            case,
                            black_box(&q),
                            black_box(&p),
                            &mut o.g,
                            &mut out,
                        );
                        black_box(&mut out);
                        black_box(&mut o);
                    })
                }
                "ours_f64_given_trig_in_place" => {
                    let t = ours::Trig::new(case, &q);
                    let mut o = ours::PandaOut::<f64>::default();
                    measured_loop(n, &mut || {
                        ours::eval_trig_step_in_place(
                            case,
                            black_box(&t),
                            black_box(&p),
                            &mut o.g,
                            &mut out,
                        );
                        black_box(&mut out);
                        black_box(&mut o);
                    })
                }
                "ours_f64_fma" => {
                    let mut o = ours::PandaOut::<f64>::default();
                    measured_loop(n, &mut || {
                        ours::eval_fma(case, black_box(&q), black_box(&p), &mut out, &mut o);
                        black_box(&mut out);
                        black_box(&mut o);
                    })
                }
                "ours_f64_given_trig_fma" => {
                    let t = ours::TrigFma::new(&q);
                    let mut o = ours::PandaOut::<f64>::default();
                    measured_loop(n, &mut || {
                        ours::eval_trig_fma(case, black_box(&t), black_box(&p), &mut out, &mut o);
                        black_box(&mut out);
                        black_box(&mut o);
                    })
                }
                _ => {
                    let (q32, p32): (Vec<f32>, Vec<f32>) = (
                        q.iter().map(|&x| x as f32).collect(),
                        p.iter().map(|&x| x as f32).collect(),
                    );
                    let mut out32 = vec![0.0f32; case.out_len()];
                    measured_loop(n, &mut || {
                        ours::eval(case, black_box(&q32), black_box(&p32), &mut out32);
                        black_box(&mut out32);
                    })
                }
            }
        }
        name if rust_peer(name).is_some() => {
            let (peer, given_trig) = rust_peer(name).unwrap();
            let case =
                Case::from_name(&args[2]).unwrap_or_else(|| panic!("unknown CASE {}", args[2]));
            let (q, p) = case.inputs();
            let mut out = vec![0.0; case.out_len()];
            if given_trig {
                let f = black_box(peer.eval_trig_fn(case));
                let t = Trig::new(&q);
                measured_loop(n, &mut || {
                    f(black_box(&t), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            } else {
                let f = black_box(peer.eval_fn(case));
                measured_loop(n, &mut || {
                    f(black_box(&q), black_box(&p), &mut out);
                    black_box(&mut out);
                })
            }
        }
        name => {
            let peer = Peer::from_name(name).unwrap_or_else(|| panic!("unknown IMPL {name}"));
            let case =
                Case::from_name(&args[2]).unwrap_or_else(|| panic!("unknown CASE {}", args[2]));
            let (q, p) = case.inputs();
            let mut out = vec![0.0; case.out_len()];
            measured_loop(n, &mut || {
                eval(peer, case, black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            });
        }
    }
}

/// The Panda cases: every implementation cycles through the 16 configurations of `Case::configs`.
fn panda(name: &str, case: Case, n: usize) {
    let qs = case.configs();
    let (_, p) = case.inputs();
    let mut out = vec![0.0; case.out_len()];
    let mut k = 0usize;
    match name {
        "numeric" => {
            let mut num = trocar_peers_harness::numeric::Numeric::new(case, &p);
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                num.eval(&qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            });
        }
        #[cfg(feature = "pinocchio")]
        "pinocchio" | "pinocchio_fk" => {
            use trocar_peers_harness::pinocchio::{Pinocchio, Variant};
            let v = Variant::from_name(name).unwrap();
            let mut pin = Pinocchio::new(case);
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                pin.eval(v, &qs[k]);
            });
        }
        #[cfg(feature = "ours")]
        "ours_f64" => {
            let f = black_box(trocar_peers_harness::ours::eval_fn(case));
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                f(&qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f64_in_place" => {
            use trocar_peers_harness::ours;
            let mut o = ours::PandaOut::<f64>::default();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                ours::eval_panda_in_place(case, &qs[k], black_box(&p), &mut o);
                black_box(&mut o);
            })
        }
        #[cfg(feature = "ours")]
        "paired_rows_given_trig" if case == Case::PandaI => {
            use trocar_peers_harness::paired_rows;
            let trigs: Vec<([f64; 7], [f64; 7])> =
                qs.iter().map(|q| paired_rows::std_sin_cos(q)).collect();
            let mut o = trocar_peers_harness::ours::PandaOut::<f64>::default();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                let (s, c) = &trigs[k];
                paired_rows::panda_link7(s, c, &mut o.g, &mut o.jb);
                black_box(&mut o);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f64_given_trig_in_place" => {
            use trocar_peers_harness::ours;
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                ours::eval_trig_panda_in_place(case, &trigs[k], black_box(&p), &mut o);
                black_box(&mut o);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f64_fma" => {
            use trocar_peers_harness::ours;
            let mut o = ours::PandaOut::<f64>::default();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                ours::eval_fma(case, &qs[k], black_box(&p), &mut out, &mut o);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f64_given_trig_fma" => {
            use trocar_peers_harness::ours;
            let trigs: Vec<ours::TrigFma> = qs.iter().map(|q| ours::TrigFma::new(q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                ours::eval_trig_fma(case, &trigs[k], black_box(&p), &mut out, &mut o);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f64_given_trig" => {
            use trocar_peers_harness::ours;
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                ours::eval_trig(case, &trigs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        #[cfg(feature = "ours")]
        "ours_f32" => {
            let qs32: Vec<Vec<f32>> = qs
                .iter()
                .map(|q| q.iter().map(|&x| x as f32).collect())
                .collect();
            let p32: Vec<f32> = p.iter().map(|&x| x as f32).collect();
            let mut out32 = vec![0.0f32; case.out_len()];
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                trocar_peers_harness::ours::eval(case, &qs32[k], black_box(&p32), &mut out32);
                black_box(&mut out32);
            })
        }
        "noop" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            black_box(&qs[k]);
        }),
        "trig_c_glibc" => {
            let mut o14 = [0.0; 14];
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                trocar_peers_harness::floor_seven(&qs[k], &mut o14);
                black_box(&mut o14);
            })
        }
        #[cfg(feature = "ours")]
        "ours_trig" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            black_box(trocar_peers_harness::ours::panda_trig::<f64>(&qs[k]));
        }),
        name if rust_peer(name).is_some() => {
            let (peer, given_trig) = rust_peer(name).unwrap();
            if given_trig {
                let f = black_box(peer.eval_trig_fn(case));
                let trigs: Vec<Trig> = qs.iter().map(|q| Trig::new(q)).collect();
                measured_loop(n, &mut || {
                    k = black_box(k + 1) & 15;
                    f(&trigs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            } else {
                let f = black_box(peer.eval_fn(case));
                measured_loop(n, &mut || {
                    k = black_box(k + 1) & 15;
                    f(&qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            }
        }
        // The Rust peers' `eval_trig` fed trocar's `JointTrig::new` (our `sin_cos_array`) inside
        // the loop: the three kernels given the same sines and cosines.
        #[cfg(feature = "ours")]
        name if name
            .strip_suffix("_fed_trocar_sin_cos")
            .and_then(RustPeer::from_name)
            .is_some() =>
        {
            let peer = name
                .strip_suffix("_fed_trocar_sin_cos")
                .and_then(RustPeer::from_name)
                .unwrap();
            let f = black_box(peer.eval_trig_fn(case));
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                let jt = trocar_peers_harness::ours::panda_trig::<f64>(&qs[k]);
                let mut t = Trig {
                    s: [0.0; 8],
                    c: [0.0; 8],
                };
                t.s[..7].copy_from_slice(&jt.sin);
                t.c[..7].copy_from_slice(&jt.cos);
                f(&t, black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        name => {
            let peer =
                Peer::from_name(name).unwrap_or_else(|| panic!("unknown IMPL {name} for {case:?}"));
            measured_loop(n, &mut || {
                k = black_box(k + 1) & 15;
                eval(peer, case, &qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            });
        }
    }
}
