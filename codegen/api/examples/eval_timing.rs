//! Times the compiled evaluator on the Panda, one configuration and many (no Python):
//! `cargo run --release -p trocar-api --example eval_timing`.

use std::time::Instant;
use trocar_api::{Function, Robot};

fn main() -> Result<(), trocar_api::Error> {
    let robot = Robot::load("panda-laparoscope")?;
    let q = [0.1, -0.4, 0.2, -2.0, 0.1, 1.8, 0.7];
    let values: Vec<f64> = robot.params().iter().map(|p| p.1).collect();
    for f in [
        Function::PartialBodyJacobian,
        Function::ForwardKinematics,
        Function::ConstrainedJacobian,
    ] {
        let e = robot.evaluator(f)?;
        let c = robot.derive()?.compiled(f).expect("compiled");
        let mut out = vec![0.0; e.len()];
        let n: usize = std::env::var("EVAL_TIMING_CALLS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(200_000);
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let t = Instant::now();
            for _ in 0..n {
                e.eval_into(std::hint::black_box(&q), &values, &mut out)?;
            }
            best = best.min(t.elapsed().as_secs_f64() / n as f64);
        }
        let mut scratch = Vec::new();
        let mut raw = vec![0.0; c.outputs()];
        let mut best_raw = f64::INFINITY;
        for _ in 0..5 {
            let t = Instant::now();
            for _ in 0..n {
                c.eval_into(std::hint::black_box(&q), &values, &mut scratch, &mut raw);
            }
            best_raw = best_raw.min(t.elapsed().as_secs_f64() / n as f64);
        }
        println!("  compiled eval_into alone {:.1} ns", best_raw * 1e9);
        let qs: Vec<f64> = (0..10_000)
            .flat_map(|k| q.map(|x| x + 1e-4 * k as f64))
            .collect();
        let mut many = vec![0.0; 10_000 * e.len()];
        let mut best_many = f64::INFINITY;
        let repeats: usize = std::env::var("EVAL_TIMING_BATCHES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(5);
        for _ in 0..repeats {
            let t = Instant::now();
            e.eval_many(&qs, &values, &mut many)?;
            best_many = best_many.min(t.elapsed().as_secs_f64() / 10_000.0);
        }
        println!(
            "{f}: {} operations, {} registers; eval_into {:.1} ns, eval_many {:.1} ns per configuration",
            c.operations(),
            c.registers(),
            best * 1e9,
            best_many * 1e9
        );
    }
    // Several outputs in one program against the same outputs' own programs one after the other.
    let set = [
        Function::ConstrainedLinkKinematics,
        Function::PartialBodyJacobian,
    ];
    let fused = robot.fused_evaluator(&set)?;
    let mut out = vec![0.0; fused.len()];
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        for _ in 0..200_000 {
            fused.eval_into(std::hint::black_box(&q), &values, &mut out)?;
        }
        best = best.min(t.elapsed().as_secs_f64() / 200_000.0);
    }
    let qs: Vec<f64> = (0..10_000)
        .flat_map(|k| q.map(|x| x + 1e-4 * k as f64))
        .collect();
    let mut many = vec![0.0; 10_000 * fused.len()];
    let mut best_many = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        fused.eval_many(&qs, &values, &mut many)?;
        best_many = best_many.min(t.elapsed().as_secs_f64() / 10_000.0);
    }
    println!(
        "fk0i + jb0i: eval_many {:.1} ns per configuration",
        best_many * 1e9
    );
    let singles: Vec<_> = set
        .iter()
        .map(|&f| robot.evaluator(f))
        .collect::<Result<_, _>>()?;
    let mut best_singles = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        for _ in 0..200_000 {
            for e in &singles {
                e.eval_into(std::hint::black_box(&q), &values, &mut out[..e.len()])?;
            }
        }
        best_singles = best_singles.min(t.elapsed().as_secs_f64() / 200_000.0);
    }
    println!(
        "fk0i + jb0i: one program {:.1} ns ({} operations), their own programs {:.1} ns ({} operations)",
        best * 1e9,
        robot
            .derive()?
            .fuse(&set)
            .map_err(trocar_api::Error::Generation)?
            .compiled()
            .operations(),
        best_singles * 1e9,
        set.iter()
            .map(|&f| robot.derive().map(|g| g.compiled(f).map_or(0, |c| c.operations())))
            .sum::<Result<usize, _>>()?
    );
    Ok(())
}
