//! A URDF-based description through the attribute: the Panda laparoscope's module has the joint
//! limits, the step function and the controller glue, and the runtime controller runs on it.
use trocar::control::{Controller, ControllerConfig, Damping, Method, NullSpaceObjective, Rcm};
use trocar::nalgebra::{SVector, Vector3};
use trocar_derive::constrained_robot;

#[constrained_robot(file = "../runtime/model/robots/panda-laparoscope.toml")]
pub struct Panda;

#[test]
fn compiles_and_runs() {
    let q = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
    let limits = Panda::JOINT_LIMITS;
    assert!(limits.iter().zip(&q).all(|(l, q)| l[0] < *q && *q < l[1]));
    let kin = panda::Kinematics::<f64>::nominal();
    let t = PandaJointTrig::<f64>::new(&q);
    let mut s = PandaStepKinematics::<f64>::zeroed();
    let trocar = [0.3, 0.0, 0.3];
    assert!(Panda::step_kinematics(
        &t,
        &trocar,
        &Panda::nominal_params(),
        &mut s
    ));
    let mut ctrl = Controller::<f64, 7, 7, 2, 4, 4, 4>::new(ControllerConfig {
        kp: 5.0,
        ko: 10.0,
        method: Method::Pinv,
        jb0i_damping: Some(Damping::Constant(0.0)),
        kr: 20.0,
        max_joint_speed: None,
    })
    .with_objective(NullSpaceObjective::JointLimits {
        gain: 10.0,
        lower: SVector::from_fn(|k, _| limits[k][0]),
        upper: SVector::from_fn(|k, _| limits[k][1]),
    });
    let (r, p) = panda::forward_kinematics(&q, &Panda::nominal_params());
    let reference = trocar::control::Reference {
        position: Vector3::from(p),
        rotation: trocar::nalgebra::Matrix3::from_data(trocar::nalgebra::ArrayStorage(r)),
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
    };
    let rcm = Rcm {
        trocar: Vector3::from(trocar),
        dv: SVector::<f64, 2>::zeros(),
    };
    let out = ctrl
        .step(&kin, &SVector::from(q), &reference, &rcm, 0.002)
        .expect("a regular configuration");
    assert!(out.qd.iter().all(|v| v.is_finite()));
}
