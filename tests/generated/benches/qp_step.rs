//! The QP control step (`Inverse::Qp`, f64) on the Panda laparoscope's generated kinematics:
//! `n = 7` joint rates, 4 task rows, 2 trocar rows, 14 joint bounds and the two-sided
//! insertion-depth row, warm-started from the previous step's active set.
//!
//! - `qp_step/panda_generated` (criterion): one step at a fixed state, as `panda_step/generated`
//!   of `control_step.rs` measures the DLS step.
//! - `qp_step/scenario` (timed step by step): the steps of the scenario
//!   `panda-laparoscope-limits` (12 s at 2 ms, 6,001 steps: withdrawal to the insertion limit,
//!   roll into joint 7's speed and position limits and back), run again and again from its start
//!   until 10⁵ steps are timed, each with `Instant` around `Controller::step` alone (the
//!   reference and the Euler update outside the timed region). Prints the median, the 99th and
//!   99.9th percentiles and the maximum. The timer's own cost (two `Instant::now`, ~40 ns here)
//!   is included.

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

    // 10⁵ steps of the scenario, each timed.
    let total = 100_000usize;
    let steps = (config.duration / config.dt).round() as usize + 1;
    let mut times = Vec::with_capacity(total);
    let mut iterations = 0usize;
    let mut most_iterations = 0usize;
    while times.len() < total {
        let (mut ctrl, _) = controller();
        let mut q = q0;
        for k in 0..steps {
            if times.len() == total {
                break;
            }
            let reference = panda_limits_reference(k as f64 * config.dt, &g0);
            let start = Instant::now();
            let out = ctrl
                .step(black_box(&kin), black_box(&q), &reference, &rcm, config.dt)
                .unwrap();
            let elapsed = start.elapsed();
            times.push(elapsed.as_nanos() as u64);
            let report = out.qp.unwrap();
            iterations += report.iterations;
            most_iterations = most_iterations.max(report.iterations);
            q += out.qd * config.dt;
        }
    }
    times.sort_unstable();
    println!(
        "qp_step/scenario: {} steps of panda-laparoscope-limits: median {} ns, p99 {} ns, \
         p99.9 {} ns ({:.2}x the median), max {} ns; working-set changes {:.3} per step on \
         average, at most {}",
        times.len(),
        percentile(&times, 0.5),
        percentile(&times, 0.99),
        percentile(&times, 0.999),
        percentile(&times, 0.999) as f64 / percentile(&times, 0.5) as f64,
        times[times.len() - 1],
        iterations as f64 / times.len() as f64,
        most_iterations
    );
}

criterion_group!(benches, qp_step);
criterion_main!(benches);
