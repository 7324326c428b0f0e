//! The control step allocates nothing: a counting global allocator (this test binary only).

use trocar::constraint::Constraint;
use trocar::control::{
    ChainKinematics, ConstrainedKinematics, Controller, ControllerConfig, Damping, Method, Rcm,
    Reference,
};
use trocar::kinematics::Chain;
use trocar::nalgebra::{SVector, Vector2, Vector3};
use trocar_counting_allocator::{allocations_during, Counting};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::simulation::Q0;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn control_step_allocates_nothing() {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let model = NumericModel::<f64>::from_description(&d, &[]).unwrap();
    let chain = model.to_chain::<8>().unwrap();
    let numeric = ChainKinematics::thesis(chain, Constraint::<f64, 2>::thesis(6, 0.15).unwrap());
    // The constraint as the description states it (wrist preset, `g_ir` from `[constraint]`).
    let described = ChainKinematics::thesis(chain, model.to_constraint::<2>().unwrap());
    // The counter sees an allocation on this thread.
    assert_eq!(
        allocations_during(|| drop(std::hint::black_box(vec![1u8; 16]))),
        1
    );
    // Each call counts the allocations of its own 9000 steps (after its setup).
    assert_eq!(run(&numeric, &chain), 9000);
    assert_eq!(run(&described, &chain), 9000);
}

/// 3000 steps with each inverse; asserts no allocation and returns the number of steps.
fn run(kin: &impl ConstrainedKinematics<f64, 8, 6, 2, 4, 6>, chain: &Chain<f64, 8>) -> usize {
    let q0 = SVector::<f64, 8>::from(Q0);
    let (frames, g0) = (chain.link_frames(&q0), chain.forward_kinematics(&q0));
    let trocar = frames[5].translation + frames[5].rotation.column(1) * 0.15;
    let inverses = [
        Method::Pinv,
        Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 0.1,
        }),
        Method::Fi {
            gamma_r: 5.0,
            gamma_l: 5.0,
        },
    ];
    let mut steps = 0;
    let mut allocations = 0;
    for inverse in inverses {
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
        let mut q = q0;
        allocations += allocations_during(|| {
            for k in 0..3000 {
                let t = k as f64 * 0.002;
                let reference = Reference {
                    position: g0.translation + Vector3::new(0.01 * t.sin(), 0.0, 0.0),
                    rotation: g0.rotation,
                    velocity: Vector3::new(0.01 * t.cos(), 0.0, 0.0),
                    angular_velocity: Vector3::zeros(),
                };
                let rcm = Rcm {
                    trocar,
                    dv: Vector2::new(0.001, 0.0),
                };
                let out = ctrl.step(kin, &q, &reference, &rcm, 0.002).unwrap();
                q += out.qd * 0.002;
                steps += 1;
            }
        });
    }
    assert_eq!(allocations, 0, "{allocations} allocations in {steps} steps");
    steps
}
