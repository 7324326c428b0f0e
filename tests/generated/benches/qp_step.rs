//! The QP control step (`Method::Qp`, f64) on the Panda laparoscope's generated kinematics:
//! `n = 7` joint rates, 4 task rows, 2 trocar rows, 14 joint bounds and the two-sided
//! insertion-depth row, warm-started from the previous step's active set.
//!
//! - `qp_step/panda_generated` (criterion): one step at a fixed state, as `panda_step/generated`
//!   of `control_step.rs` measures the DLS step.
//! - `qp_step/scenario` (timed step by step): the steps of the scenario
//!   `panda-laparoscope-limits` (12 s at 2 ms, 6,001 steps: withdrawal to the insertion limit,
//!   roll into joint 7's speed and position limits and back), run again and again from its start
//!   until 10⁵ steps are timed, each with `Instant` around `Controller::step` alone (the
//!   reference and the Euler update outside the timed region). Each step runs five times from
//!   the same state (a copy of the controller before it): `single` is the first run's time, as a
//!   control loop on this machine sees it, the operating system's interruptions included; `own`
//!   the least of the five, the step's own cost. Between two steps of the scenario one more
//!   step is timed, always the same (the fixed state above, from a copy): `fixed` is what the
//!   machine does to identical work, the floor of `single`'s spread. Prints the median, the
//!   99th and 99.9th percentiles and the maximum of each, and how many steps changed the
//!   working set. The timer's own cost (two `Instant::now`, ~40 ns here) is included.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::time::Instant;
use trocar::control::{ConstrainedKinematics, Controller, HardLimits, NullSpaceObjective, Rcm};
use trocar::nalgebra::{SVector, Vector3};
use trocar_model::description::RobotDescription;
use trocar_sim::simulation::{
    panda_limits_reference, Method, Scenario, ScenarioConfig, PANDA_DEPTH_LIMITS, PANDA_Q0,
};
use trocar_tests_generated::control::PandaLaparoscope;

type Ctrl = Controller<f64, 7, 7, 2, 4, 4, 4>;

/// The controller of the scenario: its configuration, the joint-limit objective and the URDF's
/// limits with the scenario's depth bounds.
fn controller() -> (Ctrl, ScenarioConfig) {
    let config = ScenarioConfig::new(Scenario::PandaLimits)
        .with_method(Method::Qp)
        .with_drift_correction(true);
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    let lower = SVector::from_fn(|k, _| d.joints[k].limits.unwrap()[0]);
    let upper = SVector::from_fn(|k, _| d.joints[k].limits.unwrap()[1]);
    let speed = SVector::from_fn(|k, _| d.joints[k].speed_limit.unwrap());
    let ctrl = Ctrl::new(config.controller_config())
        .with_objective(NullSpaceObjective::JointLimits {
            gain: config.null_space_gain,
            lower,
            upper,
        })
        .with_limits(
            HardLimits::none()
                .with_joint_limits(lower, upper)
                .with_speed_limits(speed)
                .with_depth(PANDA_DEPTH_LIMITS[0], PANDA_DEPTH_LIMITS[1]),
        );
    (ctrl, config)
}

fn percentile(sorted: &[u64], p: f64) -> u64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn qp_step(c: &mut Criterion) {
    let kin = PandaLaparoscope::<f64>::nominal();
    let (mut ctrl, config) = controller();
    let q0 = SVector::<f64, 7>::from(PANDA_Q0);
    let s = ConstrainedKinematics::<f64, 7, 7, 2, 4, 4, 4>::evaluate(&kin, &q0, 0.25).unwrap();
    let g0 = s.g_0e;
    let trocar = s.g_0i.transform_point(&Vector3::new(0.0, 0.0, 0.25));
    let rcm = Rcm {
        trocar,
        dv: SVector::<f64, 2>::zeros(),
    };

    // One step at a fixed state (t = 1.5 s of the reference, joints a little off q0).
    let q = q0 + SVector::<f64, 7>::from_element(0.01);
    let reference = panda_limits_reference(1.5, &g0);
    let (q_fixed, reference_fixed) = (q, reference);
    let out = ctrl.step(&kin, &q, &reference, &rcm, config.dt).unwrap();
    assert!(out.qp.is_some());
    c.bench_function("qp_step/panda_generated", |b| {
        b.iter(|| {
            ctrl.step(
                black_box(&kin),
                black_box(&q),
                black_box(&reference),
                black_box(&rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });

    // The state of the fixed step, for `fixed` below.
    let fixed_state = ctrl;

    // 10⁵ steps of the scenario, each timed: once as it runs (`single`, what a control loop on
    // this machine sees, interruptions of the operating system included), and as the least of
    // `REPEAT` runs of the same step from the same state (`own`: the controller is `Copy`, so
    // each run starts from a copy of the state before the step and gives the same rates).
    const REPEAT: usize = 5;
    let total = 100_000usize;
    let steps = (config.duration / config.dt).round() as usize + 1;
    let mut single = Vec::with_capacity(total);
    let mut own = Vec::with_capacity(total);
    let mut fixed = Vec::with_capacity(total);
    let mut by_iterations = [0usize; 4];
    let mut most_iterations = 0usize;
    let mut worst_own: (u64, usize, usize) = (0, 0, 0);
    while single.len() < total {
        let (mut ctrl, _) = controller();
        let mut q = q0;
        for k in 0..steps {
            if single.len() == total {
                break;
            }
            let reference = panda_limits_reference(k as f64 * config.dt, &g0);
            let before = ctrl;
            let mut least = u64::MAX;
            let mut out = None;
            for r in 0..REPEAT {
                let mut c = before;
                let start = Instant::now();
                let o = c
                    .step(black_box(&kin), black_box(&q), &reference, &rcm, config.dt)
                    .unwrap();
                let elapsed = start.elapsed().as_nanos() as u64;
                if r == 0 {
                    single.push(elapsed);
                }
                least = least.min(elapsed);
                ctrl = c;
                out = Some(o);
            }
            own.push(least);
            // The same work every time: the machine's own spread.
            let mut c = fixed_state;
            let start = Instant::now();
            black_box(
                c.step(
                    black_box(&kin),
                    black_box(&q_fixed),
                    &reference_fixed,
                    &rcm,
                    config.dt,
                )
                .unwrap(),
            );
            fixed.push(start.elapsed().as_nanos() as u64);
            let out = out.unwrap();
            let report = out.qp.unwrap();
            by_iterations[report.iterations.min(3)] += 1;
            most_iterations = most_iterations.max(report.iterations);
            if least > worst_own.0 {
                worst_own = (least, k, report.iterations);
            }
            q += out.qd * config.dt;
        }
    }
    for (name, times) in [
        ("single", &mut single),
        ("own", &mut own),
        ("fixed", &mut fixed),
    ] {
        times.sort_unstable();
        println!(
            "qp_step/scenario/{name}: {} steps of panda-laparoscope-limits: median {} ns, p99 {} ns, \
             p99.9 {} ns ({:.2}x the median), max {} ns",
            times.len(),
            percentile(times, 0.5),
            percentile(times, 0.99),
            percentile(times, 0.999),
            percentile(times, 0.999) as f64 / percentile(times, 0.5) as f64,
            times[times.len() - 1],
        );
    }
    println!(
        "qp_step/scenario: working-set changes per step: 0: {}, 1: {}, 2: {}, 3 or more: {} \
         (at most {most_iterations}); largest own time {} ns at step {} ({} changes)",
        by_iterations[0],
        by_iterations[1],
        by_iterations[2],
        by_iterations[3],
        worst_own.0,
        worst_own.1,
        worst_own.2
    );
}

criterion_group!(benches, qp_step);
criterion_main!(benches);
