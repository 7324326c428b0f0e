//! A control step does not allocate: a counting global allocator sees zero allocations on this
//! thread across many steps (and the count is checked to work by allocating once on purpose).

use trocar_counting_allocator::{allocations_during, Counting};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn control_step_does_not_allocate() {
    use trocar::control::Reference;
    use trocar::nalgebra::{Matrix3, Vector3};
    use trocar_panda::{control_step, controller, panda, Q0};
    let params = panda::Params::nominal();
    let (r, p) = panda::forward_kinematics(&Q0, &params);
    let (ri, pi) = panda::forward_kinematics_i(&Q0, &params);
    // The trocar 0.107 + 0.25 m along z of link 7's frame.
    let trocar = [0, 1, 2].map(|k| pi[k] + 0.357 * ri[2][k]);
    let reference = Reference {
        position: Vector3::from(p) + Vector3::new(0.005, 0.0, 0.0),
        rotation: Matrix3::from_data(trocar::nalgebra::ArrayStorage(r)),
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
    };
    let mut ctrl = controller();

    // The counter works.
    let n = allocations_during(|| {
        std::hint::black_box(Box::new(1u64));
    });
    assert_eq!(n, 1);

    let mut q = Q0;
    let mut steps = 0;
    let n = allocations_during(|| {
        for _ in 0..500 {
            let out = control_step(&mut ctrl, &q, &reference, &trocar, 0.002).unwrap();
            for (qk, v) in q.iter_mut().zip(out.qd.iter()) {
                *qk += 0.002 * v;
            }
            steps += 1;
        }
    });
    assert_eq!(steps, 500);
    assert_eq!(n, 0, "the control step allocated");

    // The QP step, from the same start, the tip pulled toward the trocar past l_max so that
    // limits become active and the warm start changes.
    let mut ctrl = trocar_panda::qp_controller();
    let z = Vector3::new(r[2][0], r[2][1], r[2][2]);
    let pulled = Reference {
        position: Vector3::from(p) - z * 0.08,
        ..reference
    };
    let mut q = Q0;
    let mut active = 0;
    let n = allocations_during(|| {
        for _ in 0..500 {
            let out = control_step(&mut ctrl, &q, &pulled, &trocar, 0.002).unwrap();
            active = active.max(out.qp.map_or(0, |r| r.active));
            for (qk, v) in q.iter_mut().zip(out.qd.iter()) {
                *qk += 0.002 * v;
            }
        }
    });
    assert!(active >= 1, "no limit became active");
    assert_eq!(n, 0, "the QP step allocated");
}
