//! Interleaved minimum time: `interleave CASE ROUNDS N IMPL...` runs N evaluations of each IMPL in
//! turn, ROUNDS times over, and prints for each IMPL the minimum over the rounds of the mean
//! wall-clock time per evaluation (ns). On a shared machine a slow period then hits every IMPL
//! alike instead of one contiguous block, and the minimum is the least disturbed round.
//!
//! CASE: any case of the harness (`panda`, `panda_i`: the 16 configurations of `Case::configs`,
//! cycled as `cg_driver` does; the other cases have one configuration, evaluated every time).
//! IMPL: ours_f64 | ours_f64_split (`JointTrig::new`, then the fused `_trig` function) |
//! ours_f64_in_place | ours_f64_given_trig_in_place (writing the pose into the generated
//! functions' own `(R, p)` in place, without the copy into the flat buffer; the Panda cases
//! their `[[f64; 6]; 7]` too, the step cases their Jacobians into the flat buffer) |
//! ours_f64_given_trig | ours_f64_fma | ours_f64_given_trig_fma (the fused cases through the
//! `_f64` entry points of the modules generated with `fma_at_run_time`, FMA chosen at run time;
//! the Panda in place) | wrenfold | symforce | wrenfold_given_trig |
//! symforce_given_trig | paired_rows_given_trig (`panda_i` only: the hand-written kernel of
//! `paired_rows`, given the sines and cosines) | ours_trig (our `JointTrig::new` alone) | the C peers `casadi`,
//! `casadi_cse`, `sympy` (and `rust_reference`), each through the harness's `eval`. Needs the
//! feature `ours`.
use std::hint::black_box;
use std::time::Instant;
use trocar_peers_harness::ours;
use trocar_peers_harness::paired_rows;
use trocar_peers_harness::rust_peers::{RustPeer, Trig};
use trocar_peers_harness::{Case, Peer};

/// One implementation's evaluation of configuration `k` (0..16), writing into its own buffer.
type Eval = Box<dyn FnMut(usize)>;

fn implementation(name: &str, case: Case) -> Eval {
    // Sixteen entries for every case (the Panda's are distinct; the others repeat their one).
    let qs = case.configs();
    let qs: Vec<Vec<f64>> = (0..16).map(|k| qs[k % qs.len()].clone()).collect();
    let (_, p) = case.inputs();
    let mut out = vec![0.0; case.out_len()];
    match name {
        "ours_f64" => {
            let f = black_box(ours::eval_fn(case));
            Box::new(move |k| {
                f(&qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        "ours_f64_split" => {
            let f = black_box(ours::split_fn(case));
            Box::new(move |k| {
                f(&qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        "ours_f64_in_place" if case.is_panda() => {
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_panda_in_place(case, &qs[k], black_box(&p), &mut o);
                black_box(&mut o);
            })
        }
        "ours_f64_given_trig_in_place" if case.is_panda() => {
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_trig_panda_in_place(case, &trigs[k], black_box(&p), &mut o);
                black_box(&mut o);
            })
        }
        "ours_f64_in_place" => {
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_step_in_place(case, &qs[k], black_box(&p), &mut o.g, &mut out);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        "ours_f64_given_trig_in_place" => {
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_trig_step_in_place(case, &trigs[k], black_box(&p), &mut o.g, &mut out);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        "ours_f64_given_trig" => {
            let trigs: Vec<ours::Trig<f64>> = qs.iter().map(|q| ours::Trig::new(case, q)).collect();
            Box::new(move |k| {
                ours::eval_trig(case, &trigs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        "ours_f64_fma" if case.is_panda() => {
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_fma(case, &qs[k], black_box(&p), &mut [], &mut o);
                black_box(&mut o);
            })
        }
        "ours_f64_given_trig_fma" if case.is_panda() => {
            let trigs: Vec<ours::TrigFma> = qs.iter().map(|q| ours::TrigFma::new(q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_trig_fma(case, &trigs[k], black_box(&p), &mut [], &mut o);
                black_box(&mut o);
            })
        }
        "ours_f64_fma" => {
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_fma(case, &qs[k], black_box(&p), &mut out, &mut o);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        "ours_f64_given_trig_fma" => {
            let trigs: Vec<ours::TrigFma> = qs.iter().map(|q| ours::TrigFma::new(q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                ours::eval_trig_fma(case, &trigs[k], black_box(&p), &mut out, &mut o);
                black_box(&mut out);
                black_box(&mut o);
            })
        }
        "paired_rows_given_trig" if case == Case::PandaI => {
            // The peers' sines and cosines (`std`), as for `symforce_given_trig`.
            let trigs: Vec<([f64; 7], [f64; 7])> =
                qs.iter().map(|q| paired_rows::std_sin_cos(q)).collect();
            let mut o = ours::PandaOut::<f64>::default();
            Box::new(move |k| {
                let (s, c) = &trigs[k];
                paired_rows::panda_link7(s, c, &mut o.g, &mut o.jb);
                black_box(&mut o);
            })
        }
        "ours_trig" => Box::new(move |k| {
            black_box(ours::panda_trig::<f64>(&qs[k]));
        }),
        _ if Peer::from_name(name).is_some() => {
            let peer = Peer::from_name(name).expect("checked");
            Box::new(move |k| {
                trocar_peers_harness::eval(peer, case, &qs[k], black_box(&p), &mut out);
                black_box(&mut out);
            })
        }
        _ => {
            let (peer, given_trig) = match name.strip_suffix("_given_trig") {
                Some(base) => (RustPeer::from_name(base), true),
                None => (RustPeer::from_name(name), false),
            };
            let peer = peer.unwrap_or_else(|| panic!("unknown IMPL {name}"));
            if given_trig {
                let f = black_box(peer.eval_trig_fn(case));
                let trigs: Vec<Trig> = qs.iter().map(|q| Trig::new(q)).collect();
                Box::new(move |k| {
                    f(&trigs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            } else {
                let f = black_box(peer.eval_fn(case));
                Box::new(move |k| {
                    f(&qs[k], black_box(&p), &mut out);
                    black_box(&mut out);
                })
            }
        }
    }
}

#[inline(never)]
fn measured_loop(n: usize, f: &mut Eval) -> f64 {
    let mut k = 0usize;
    let t0 = Instant::now();
    for _ in 0..n {
        k = black_box(k + 1) & 15;
        f(k);
    }
    t0.elapsed().as_nanos() as f64 / n as f64
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!("usage: interleave CASE ROUNDS N IMPL...");
        std::process::exit(2);
    }
    let case = Case::from_name(&args[1]).unwrap_or_else(|| panic!("unknown CASE {}", args[1]));
    let rounds: usize = args[2].parse().expect("ROUNDS");
    let n: usize = args[3].parse().expect("N");
    let names = &args[4..];
    // TROCAR_PEERS_PAD=BYTES: an allocation of that size kept before each IMPL's own, which
    // moves every IMPL's data on the heap (to tell layout effects, such as 4K aliasing between
    // an IMPL's output stores and its input loads, from the code's own cost).
    let pad: usize = std::env::var("TROCAR_PEERS_PAD")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let mut pads = Vec::new();
    let mut impls: Vec<Eval> = names
        .iter()
        .map(|s| {
            pads.push(vec![0u8; pad]);
            implementation(s, case)
        })
        .collect();
    let mut best = vec![f64::INFINITY; impls.len()];
    // One warm-up round, not counted.
    for f in &mut impls {
        measured_loop(n, f);
    }
    for _ in 0..rounds {
        for (f, b) in impls.iter_mut().zip(&mut best) {
            *b = b.min(measured_loop(n, f));
        }
    }
    for (name, b) in names.iter().zip(&best) {
        println!("{name} {b:.2}");
    }
    drop(pads);
}
