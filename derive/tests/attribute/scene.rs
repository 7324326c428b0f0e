//! A scene through the attribute: the shipped `dia10-dual` (by name) and `three-ports` (by
//! file) get their modules beside the structs, and the scene's step runs on them: the ports
//! hold, the torso is one joint.
use trocar::control::{ControllerConfig, Method, QpWeights};
use trocar::se3::Se3;
use trocar_derive::constrained_robot;

#[constrained_robot(scene = "dia10-dual")]
pub struct Dual;

#[constrained_robot(
    scene = "../runtime/model/scenes/three-ports.toml",
    module = "ports",
    real = "f32"
)]
pub struct ThreePorts;

#[test]
fn compiles_and_runs() {
    let config = ControllerConfig {
        kp: 10.0,
        ko: 10.0,
        method: Method::Qp(QpWeights::with_kappa(0.01)),
        jb0i_damping: None,
        kr: 10.0,
        max_joint_speed: None,
    };
    let kins = dual::kinematics::<f64>();
    let mut scene = dual::scene::<f64>();
    let mut arms = [dual::ArmController::<f64>::new(config); dual::A];
    let mut q = dual::q0::<f64>();
    let starts = [0, 1].map(|k| {
        use trocar::control::ConstrainedKinematics;
        kins[k].g_0e(&q[k]).expect("the start")
    });
    let references = starts.map(|g: Se3<f64>| trocar::control::Reference {
        position: g.translation,
        rotation: g.rotation,
        velocity: trocar::nalgebra::Vector3::zeros(),
        angular_velocity: trocar::nalgebra::Vector3::zeros(),
    });
    for _ in 0..10 {
        let out = dual::step(&mut scene, &mut arms, &kins, &q, &references, 0.002).expect("a step");
        for (qk, qd) in q.iter_mut().zip(out.qd.iter()) {
            *qk += qd * 0.002;
        }
        assert_eq!(out.qd[0][0], out.qd[1][0]);
    }
    // The structs carry the scenes' modules; they are unit values of their own.
    let (Dual, ThreePorts) = (Dual, ThreePorts);
    assert_eq!(dual::SCENE_JOINTS, 15);
    assert_eq!(ports::ARMS, ["left", "right", "endoscope"]);
    let _: [trocar::control::scene::Coupling<f32>; 3] = ports::couplings();
}
