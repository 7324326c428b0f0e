//! The scene `dia10-dual` (`trocar_sim::scene::dual`): the reference arm and its mirror image on
//! one torso, each through its own port; the left tip holds still while the right one cuts. From
//! the trace (drift and tip errors from forward kinematics): both ports within 1e-4 m, the
//! holding tip within 1e-4 m of its start, the cutting tip within 1 mm of its path after 1 s,
//! and the torso moved (the arms' motion couples through it). The mirrored chain is the mirror
//! image of the reference arm's (against conjugation of its poses by the mirror), and the tips
//! start a few centimetres apart.

use nalgebra::{Matrix3, SVector, Vector3};
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_sim::scene::dual::{mirrored, Q_DUAL};
use trocar_sim::scene::simulate;

#[test]
fn the_left_arm_is_the_mirror_image_of_the_right_one() {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let chain = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_chain::<8>()
        .unwrap();
    let mirror = mirrored(&chain);
    let m = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
    let conjugate = |g: &Se3<f64>| Se3::new(m * g.rotation * m, m * g.translation);
    for k in 0..50 {
        let q = SVector::<f64, 8>::from_fn(|i, _| ((k * 8 + i) as f64 * 0.77).sin() * 1.5);
        let mut q_neg = q;
        q_neg[0] = -q[0];
        // The mirrored chain at q is the mirror image of the reference arm at (−θ₁, θ₂, …).
        let expected = conjugate(&chain.forward_kinematics(&q_neg));
        let got = mirror.forward_kinematics(&q);
        assert!((got.translation - expected.translation).norm() < 1e-12);
        assert!((got.rotation - expected.rotation).norm() < 1e-12);
        assert!((got.rotation.determinant() - 1.0).abs() < 1e-12);
        for link in 1..=8 {
            let e = conjugate(&chain.link_frame(link, &q_neg));
            let g = mirror.link_frame(link, &q);
            assert!(
                (g.translation - e.translation).norm() < 1e-12,
                "link {link}"
            );
        }
    }
    // At the start the tips are mirror images a few centimetres apart, both arms along +y.
    let q0 = SVector::<f64, 8>::from(Q_DUAL);
    let (right, left) = (
        chain.forward_kinematics(&q0).translation,
        mirror.forward_kinematics(&q0).translation,
    );
    assert!((left - Vector3::new(-right.x, right.y, right.z)).norm() < 1e-12);
    let apart = (right - left).norm();
    assert!((0.02..0.06).contains(&apart), "tips {apart} m apart");
    assert!(right.y > 1.0 && left.y > 1.0);
}

#[test]
fn dia10_dual_holds_both_ports_and_both_tasks() {
    let trace = simulate("dia10-dual", true, |_| {}).unwrap();
    let col = |name: &str| trace.column(name).unwrap_or_else(|| panic!("{name}"));
    let max = |v: Vec<f64>| v.into_iter().fold(0.0, f64::max);
    let t = col("t");
    let after = |name: &str, from: f64| {
        max(col(name)
            .into_iter()
            .zip(&t)
            .filter(|(_, t)| **t >= from)
            .map(|(v, _)| v)
            .collect())
    };
    let (left_drift, right_drift) = (max(col("left.rcm_drift")), max(col("right.rcm_drift")));
    let holding = max(col("left.ep_norm"));
    let cutting = after("right.ep_norm", 1.0);
    let torso = max(col("qd1").into_iter().map(f64::abs).collect());
    println!(
        "drift {left_drift:.2e} / {right_drift:.2e} m, holding tip {holding:.2e} m, cutting tip \
         after 1 s {cutting:.2e} m, torso up to {torso:.3} rad/s"
    );
    assert!(left_drift <= 1e-4 && right_drift <= 1e-4);
    assert!(holding <= 1e-4, "the holding tip moved {holding} m");
    assert!(cutting <= 1e-3, "the cutting tip's error {cutting} m");
    assert!(torso > 1e-3, "the torso did not move");
    assert_eq!(trace.columns.len(), 1 + 15 + 15 + 4 + 1);
}
