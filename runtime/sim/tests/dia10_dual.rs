//! The scene `dia10-dual` (`trocar_sim::scene::dual`): the reference arm and its mirror image on
//! one torso, each through its own port; the left tip holds still while the right one cuts. From
//! the trace (drift and tip errors from forward kinematics): both ports within 1e-4 m, the
//! holding tip within 1e-4 m of its start, the cutting tip within 1 mm of its path after 1 s,
//! and the torso moved (the arms' motion couples through it). The left arm starts as the mirror
//! image of the right one (its poses against conjugation of the right one's by the mirror; the
//! mirror itself is checked in `trocar-model`'s scene tests), the tips a few centimetres apart.

use nalgebra::{Matrix3, Vector3};
use trocar_sim::scene::dual::Dia10Dual;
use trocar_sim::scene::simulate;

#[test]
fn the_left_arm_starts_as_the_mirror_image_of_the_right_one() {
    let setup = Dia10Dual::new().unwrap();
    let m = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
    let [left, right] = [0, 1].map(|k| setup.kins[k].chain.forward_kinematics(&setup.q0[k]));
    assert!((left.translation - m * right.translation).norm() < 1e-12);
    assert!((left.rotation - m * right.rotation * m).norm() < 1e-12);
    for link in 1..=8 {
        let [l, r] = [0, 1].map(|k| setup.kins[k].chain.link_frame(link, &setup.q0[k]));
        assert!(
            (l.translation - m * r.translation).norm() < 1e-12,
            "link {link}"
        );
    }
    assert!((setup.rcms[0].trocar - m * setup.rcms[1].trocar).norm() < 1e-12);
    // A few centimetres apart, both arms along +y.
    let apart = (right.translation - left.translation).norm();
    assert!((0.02..0.06).contains(&apart), "tips {apart} m apart");
    assert!(right.translation.y > 1.0 && left.translation.y > 1.0);
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
