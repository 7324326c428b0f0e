//! Cost of one control step (f64) for dia10_like (bidirectional zy): kinematics through the
//! `ConstrainedKinematics` trait plus the controller, for each inverse.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use trocar::constraint::Constraint;
use trocar::control::{
    ChainKinematics, ConstrainedKinematics, Controller, ControllerConfig, Damping, Method, Rcm,
    Reference,
};
use trocar::kinematics::Chain;
use trocar::nalgebra::{SVector, Vector2};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::Q0;

fn bench(c: &mut Criterion) {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let chain = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_chain::<8>()
        .unwrap();
    let numeric = ChainKinematics::thesis(chain, Constraint::<f64, 2>::thesis(6, 0.15).unwrap());
    bench_path(c, "numeric", &numeric, &chain);
}

fn bench_path(
    c: &mut Criterion,
    path: &str,
    kin: &impl ConstrainedKinematics<f64, 8, 6, 2, 4, 6>,
    chain: &Chain<f64, 8>,
) {
    let q = SVector::<f64, 8>::from(Q0);
    let (frames, g0) = (chain.link_frames(&q), chain.forward_kinematics(&q));
    let trocar = frames[5].translation + frames[5].rotation.column(1) * 0.15;
    let reference = Reference {
        position: g0.translation,
        rotation: g0.rotation,
        velocity: Default::default(),
        angular_velocity: Default::default(),
    };
    let rcm = Rcm {
        trocar,
        dv: Vector2::zeros(),
    };
    for (name, inverse) in [
        ("pinv", Method::Pinv),
        (
            "dls",
            Method::Dls(Damping::Variable {
                alpha0: 0.05,
                w0: 0.1,
            }),
        ),
        (
            "fi",
            Method::Fi {
                gamma_r: 5.0,
                gamma_l: 5.0,
            },
        ),
    ] {
        let mut ctrl = Controller::<f64, 8, 6, 2, 4, 6>::new(ControllerConfig {
            kp: 5.0,
            ko: 10.0,
            method: inverse,
            jb0i_damping: Some(Damping::Variable {
                alpha0: 0.05,
                w0: 0.01,
            }),
            kr: 20.0,
            max_joint_speed: None,
        });
        c.bench_function(&format!("control_step_dia10_zy_{path}_{name}"), |b| {
            b.iter(|| {
                ctrl.step(kin, black_box(&q), black_box(&reference), &rcm, 0.002)
                    .unwrap()
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
