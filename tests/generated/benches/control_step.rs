//! One full constrained control step (f64, DLS on `J^r_0e` and `J^B_0i`, drift correction on) on
//! `dia10_like_zy`, with the generated closed forms and with the numeric runtime, in one run.
//! Issue 7's target: a full constrained control step ≤ 1 µs median.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::constraint::Constraint;
use trocar::control::{ChainKinematics, ConstrainedKinematics, Controller, Rcm, Reference};
use trocar::nalgebra::{SVector, Vector3};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::{Method, Scenario, ScenarioConfig, L_A0, Q0};
use trocar_tests_generated::control::GeneratedKinematics;

fn bench_step<Kin: ConstrainedKinematics<f64, 8, 6, 2, 4, 6>>(
    c: &mut Criterion,
    name: &str,
    kin: &Kin,
    reference: &Reference<f64>,
    rcm: &Rcm<f64, 2>,
    config: &ScenarioConfig,
) {
    let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(config.controller_config());
    // A configuration off q0 so that the errors are not zero.
    let q = SVector::<f64, 8>::from(Q0) + SVector::<f64, 8>::from_element(0.01);
    c.bench_function(name, |b| {
        b.iter(|| {
            ctrl.step(
                black_box(kin),
                black_box(&q),
                black_box(reference),
                black_box(rcm),
                black_box(config.dt),
            )
            .unwrap()
        })
    });
}

fn control_step(c: &mut Criterion) {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let numeric = ChainKinematics::thesis(
        NumericModel::<f64>::from_description(&d, &[])
            .unwrap()
            .to_chain::<8>()
            .unwrap(),
        Constraint::<f64, 2>::thesis(6, L_A0).unwrap(),
    );
    let generated = GeneratedKinematics::<f64>::nominal();
    let config = ScenarioConfig::new(Scenario::S2)
        .with_method(Method::Dls)
        .with_drift_correction(true);
    let q0 = SVector::<f64, 8>::from(Q0);
    let g_0e0 = numeric.chain.forward_kinematics(&q0);
    let axis7 = numeric
        .chain
        .link_frame(7, &q0)
        .rotation
        .column(2)
        .into_owned();
    let g_0i0 = numeric.chain.link_frame(6, &q0);
    let reference = config.scenario.reference(1.0, config.dt, &g_0e0, &axis7);
    let rcm = Rcm {
        trocar: g_0i0.translation + g_0i0.rotation.column(1) * L_A0 + Vector3::new(1e-4, 0.0, 0.0),
        dv: SVector::<f64, 2>::new(0.001, -0.001),
    };
    bench_step(
        c,
        "control_step/generated",
        &generated,
        &reference,
        &rcm,
        &config,
    );
    bench_step(
        c,
        "control_step/numeric",
        &numeric,
        &reference,
        &rcm,
        &config,
    );
    // The kinematics alone.
    let l_a = L_A0 + 0.001;
    let q = q0 + SVector::<f64, 8>::from_element(0.01);
    c.bench_function("evaluate/generated", |b| {
        b.iter(|| black_box(&generated).evaluate(black_box(&q), black_box(l_a)))
    });
    c.bench_function("evaluate/numeric", |b| {
        b.iter(|| {
            ConstrainedKinematics::<f64, 8, 6, 2, 4, 6>::evaluate(
                black_box(&numeric),
                black_box(&q),
                black_box(l_a),
            )
        })
    });
}

criterion_group!(benches, control_step);
criterion_main!(benches);
