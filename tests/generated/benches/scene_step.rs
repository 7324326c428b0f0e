//! The scene's step (`trocar::control::scene::Scene::step`) of `three-ports` on the Panda
//! laparoscope's generated kinematics: three arms' own QP steps, then the scene's QP over their
//! 21 rates with the three couplings, warm-started as in the run.
//!
//! The scene runs its 4 s (2,000 steps at 2 ms) again and again until 2·10⁴ steps are timed,
//! each with `Instant` around the scene's step alone (the references, the camera's point and the
//! Euler update outside). Each step runs five times from the same state (a copy of the arms'
//! controllers and the scene before it): `single` is the first run's time, `own` the least of the
//! five, the step's own cost. Prints the median, the 99th and 99.9th percentiles and the
//! maximum of each, for all steps and for the steps where the couplings act, and how far the run
//! on the generated kinematics ends from the run on the numeric model (the same scene, so the
//! same rates to rounding).

use std::time::Instant;
use trocar_sim::scene::{ThreePorts, DT, DURATION};
use trocar_tests_generated::control::PandaLaparoscope;

fn percentile(sorted: &[u64], p: f64) -> u64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn report(name: &str, times: &mut [u64]) {
    times.sort_unstable();
    println!(
        "scene_step/three-ports/{name}: {} steps: median {} ns, p99 {} ns, p99.9 {} ns \
         ({:.2}x the median), max {} ns",
        times.len(),
        percentile(times, 0.5),
        percentile(times, 0.99),
        percentile(times, 0.999),
        percentile(times, 0.999) as f64 / percentile(times, 0.5) as f64,
        times[times.len() - 1],
    );
}

fn main() {
    let generated = [PandaLaparoscope::<f64>::nominal(); 3];
    const REPEAT: usize = 5;
    let total = 20_000usize;
    let steps = (DURATION / DT).round() as usize;
    let (mut single, mut own) = (Vec::new(), Vec::new());
    let (mut single_coupled, mut own_coupled) = (Vec::new(), Vec::new());
    let mut largest_difference = 0.0f64;
    while single.len() < total {
        let mut setup = ThreePorts::new(true).unwrap();
        let mut numeric = setup.clone();
        let (mut q, mut q_numeric) = (setup.q0, setup.q0);
        for step in 0..steps {
            if single.len() == total {
                break;
            }
            let t = step as f64 * DT;
            let references = setup.references(&q, t).unwrap();
            let before = setup.clone();
            let mut least = u64::MAX;
            let mut out = None;
            for r in 0..REPEAT {
                let mut s = before.clone();
                let start = Instant::now();
                let o = s
                    .step_to(std::hint::black_box(&generated), &q, &references)
                    .unwrap();
                let elapsed = start.elapsed().as_nanos() as u64;
                if r == 0 {
                    single.push(elapsed);
                }
                least = least.min(elapsed);
                setup = s;
                out = Some(o);
            }
            own.push(least);
            let out = out.unwrap();
            if out.coupling_active {
                single_coupled.push(*single.last().unwrap());
                own_coupled.push(least);
            }
            let o = numeric.step(&q_numeric, t).unwrap();
            for k in 0..3 {
                q[k] += out.qd[k] * DT;
                q_numeric[k] += o.qd[k] * DT;
                largest_difference = largest_difference.max((q[k] - q_numeric[k]).amax());
            }
        }
    }
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    println!("scene_step/three-ports on {cpu}");
    report("single", &mut single);
    report("own", &mut own);
    report("single, couplings acting", &mut single_coupled);
    report("own, couplings acting", &mut own_coupled);
    println!(
        "scene_step/three-ports: joints of the generated and the numeric runs at most {:.2e} rad \
         apart",
        largest_difference
    );
}
