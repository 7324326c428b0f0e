//! What a control loop calls does not allocate: a counting global allocator around the typed API.

use trocar::constraint::Constraint;
use trocar::kinematics::Chain;
use trocar::nalgebra::{SMatrix, SVector};
use trocar_counting_allocator::{allocations_during as allocations, Counting};
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn control_loop_calls_do_not_allocate() {
    let d = RobotDescription::preset("dia10_like_zy").unwrap();
    let robot = NumericRobot::<f64>::from_description(&d, &[]).unwrap();
    let chain: Chain<f64, 8> = robot.to_chain().unwrap();
    let mut c: Constraint<f64, 2> = robot.to_constraint().unwrap();
    let q = SVector::<f64, 8>::from([0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3]);
    let mut sink = 0.0;
    let n = allocations(|| {
        for k in 0..10 {
            c.set_offset(0.1 + 0.01 * k as f64).unwrap();
            let (jr, jc): (SMatrix<f64, 6, 6>, _) = c.constrained_jacobians(&chain, &q);
            let jb = chain.body_jacobian(&q);
            let js = chain.spatial_jacobian(&q);
            let jb0i = chain.partial_body_jacobian::<6>(&q);
            let (j1, j2) = chain.body_jacobian_split::<6, 2>(&q);
            let v = c.link_velocity(&SVector::<f64, 4>::repeat(0.1), &SVector::zeros());
            let th: SVector<f64, 6> = c
                .joint_rates_before_constraint::<8, 6>(&chain, &q, &v)
                .unwrap();
            let w = trocar::manipulability::manipulability(&jr);
            let fd = trocar::finite_diff::body_jacobian(&chain, &q, 1e-6);
            sink += jr[0] + jc[0] + jb[0] + js[0] + jb0i[0] + j1[0] + j2[0] + th[0] + w + fd[0];
            sink += chain.forward_kinematics(&q).translation.x;
        }
    });
    assert!(sink.is_finite());
    assert_eq!(n, 0, "{n} allocations in the control-loop API");
    // The counter works: the dynamic front end does allocate.
    assert!(allocations(|| drop(robot.body_jacobian(&[0.0; 8]).unwrap())) > 0);
}
