//! The generated scene modules (`Builder::scene` on the shipped scene files) against the numeric
//! scenes of `trocar-sim`: the same placements, ports, starts, couplings and camera, and a whole
//! run of each scene stepped by the generated module's `step` on its generated kinematics with the
//! same rates as the numeric scene's step on the numeric model, step by step.

use nalgebra::SVector;
use trocar::control::scene::Between;
use trocar_sim::scene::dual::{self, Dia10Dual};
use trocar_sim::scene::{ThreePorts, DT, DURATION};
use trocar_tests_generated::{dia10_dual, three_ports, three_ports_f32};

#[test]
fn three_ports_is_placed_as_the_numeric_scene() {
    let numeric = ThreePorts::new(true).unwrap();
    assert_eq!(three_ports::ARMS, ["left", "right", "endoscope"]);
    assert_eq!(
        (three_ports::A, three_ports::N, three_ports::NS),
        (3, 7, 21)
    );
    assert_eq!((three_ports::P, three_ports::C, three_ports::ES), (3, 6, 6));
    assert_eq!(three_ports::SCENE_JOINTS, 21);
    assert_eq!(three_ports::JOINT_MAP[2], [14, 15, 16, 17, 18, 19, 20]);
    let bases = three_ports::bases::<f64>();
    let rcms = three_ports::rcms::<f64>();
    for k in 0..3 {
        assert!((bases[k].rotation - numeric.bases[k].rotation).amax() < 1e-15);
        assert!((bases[k].translation - numeric.bases[k].translation).amax() < 1e-15);
        assert!((rcms[k].trocar - numeric.rcms[k].trocar).amax() < 1e-15);
    }
    // The instruments start where the scene does; the endoscope from the file's start, before
    // it is aimed.
    let q0 = three_ports::q0::<f64>();
    assert_eq!(q0[0], numeric.q0[0]);
    assert_eq!(q0[1], numeric.q0[1]);
    let couplings = three_ports::couplings::<f64>();
    for (g, n) in couplings.iter().zip(&numeric.scene.couplings) {
        assert_eq!(g, n);
    }
    let camera = three_ports::camera::<f64>();
    assert_eq!(three_ports::CAMERA_ARM, 2);
    assert_eq!(three_ports::CAMERA_LOOKS_AT, [0, 1]);
    assert!((camera.port - numeric.camera.port).amax() < 1e-15);
    assert!((camera.start_axis - numeric.camera.start_axis).amax() < 1e-15);
    assert!((camera.start_rotation - numeric.camera.start_rotation).amax() < 1e-15);
    assert_eq!(camera.depth, numeric.camera.depth);
    // The f32 module: the same, rounded.
    let b32 = three_ports_f32::bases();
    assert!((b32[1].translation.cast::<f64>() - bases[1].translation).amax() < 1e-7);
    assert_eq!(three_ports_f32::couplings()[0].between, Between::Shafts);
}

#[test]
fn generated_three_ports_steps_as_the_numeric_scene() {
    let mut numeric = ThreePorts::new(true).unwrap();
    let kins = three_ports::kinematics::<f64>();
    let mut scene = three_ports::scene::<f64>();
    let mut arms = numeric.arms;
    let (mut q, mut qg) = (numeric.q0, numeric.q0);
    let mut worst = 0.0f64;
    let mut active = 0;
    let steps = (DURATION / DT).round() as usize;
    for step in 0..steps {
        let t = step as f64 * DT;
        let references = numeric.references(&q, t).unwrap();
        let kn = numeric.kins;
        let on = numeric.step_to(&kn, &q, &references).unwrap();
        let og = three_ports::step(&mut scene, &mut arms, &kins, &qg, &references, DT).unwrap();
        active += usize::from(og.coupling_active);
        for k in 0..3 {
            worst = worst.max((on.qd[k] - og.qd[k]).amax());
            q[k] += on.qd[k] * DT;
            qg[k] += og.qd[k] * DT;
        }
        assert!(worst < 1e-8, "step {step}: rates {worst:e} apart");
    }
    println!("three-ports: generated and numeric rates at most {worst:.2e} rad/s apart ({active} steps coupled)");
    assert!(active > 100);
}

#[test]
fn generated_dia10_dual_steps_as_the_numeric_scene() {
    let mut numeric = Dia10Dual::new().unwrap();
    assert_eq!(dia10_dual::SCENE_JOINTS, 15);
    assert_eq!(dia10_dual::SHARED.len(), 1);
    assert_eq!(dia10_dual::ES, 5);
    // The mirror image has a module of its own: the kinematics are the enum's two variants.
    let kins = dia10_dual::kinematics::<f64>();
    assert!(matches!(
        kins[0],
        dia10_dual::ArmKinematics::Dia10LikeZyMirror(_)
    ));
    assert!(matches!(kins[1], dia10_dual::ArmKinematics::Dia10LikeZy(_)));
    let rcms = dia10_dual::rcms::<f64>();
    let q0 = dia10_dual::q0::<f64>();
    for k in 0..2 {
        assert!((rcms[k].trocar - numeric.rcms[k].trocar).amax() < 1e-15);
        assert_eq!(q0[k], numeric.q0[k]);
    }
    let mut scene = dia10_dual::scene::<f64>();
    assert_eq!(scene.orientation_weight, numeric.scene.orientation_weight);
    let mut arms = numeric.arms;
    let (mut q, mut qg) = (numeric.q0, numeric.q0);
    let mut worst = 0.0f64;
    let steps = (dual::DURATION / dual::DT).round() as usize;
    for step in 0..steps {
        let t = step as f64 * dual::DT;
        let references = numeric.references(t);
        let on = numeric.step(&q, t).unwrap();
        let og =
            dia10_dual::step(&mut scene, &mut arms, &kins, &qg, &references, dual::DT).unwrap();
        for k in 0..2 {
            worst = worst.max((on.qd[k] - og.qd[k]).amax());
            q[k] += on.qd[k] * dual::DT;
            qg[k] += og.qd[k] * dual::DT;
        }
        assert!(worst < 1e-8, "step {step}: rates {worst:e} apart");
    }
    // The torso once: its angle the same in both arms.
    assert!(qg
        .iter()
        .all(|x: &SVector<f64, 8>| x.iter().all(|v| v.is_finite())));
    assert!((qg[0][0] - qg[1][0]).abs() < 1e-12);
    println!("dia10-dual: generated and numeric rates at most {worst:.2e} rad/s apart");
}
