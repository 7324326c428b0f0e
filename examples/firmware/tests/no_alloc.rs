//! The control step does not allocate: a counting global allocator sees zero allocations on this
//! thread across many steps (and the count is checked to work by allocating once on purpose).

use trocar_counting_allocator::{allocations_during, Counting};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn control_step_does_not_allocate() {
    use trocar_firmware::{control_step, Tuning};
    let q0 = [0.0f32, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let t = trocar_firmware::dia10::JointTrig::new(&q0);
    let (r, p) = trocar_firmware::dia10::forward_kinematics_i_trig(
        &t,
        &trocar_firmware::dia10::Params { l_a: 0.15 },
    );
    let trocar = [0, 1, 2].map(|k| p[k] + 0.15 * r[1][k]);
    let tuning = Tuning::default();

    // The counter works.
    let n = allocations_during(|| {
        std::hint::black_box(Box::new(1u64));
    });
    assert_eq!(n, 1);

    let mut q = q0;
    let n = allocations_during(|| {
        for k in 0..1000 {
            let u = [
                0.01,
                -0.02 * (k as f32 * 0.01).sin(),
                0.005,
                0.0,
                0.02,
                -0.01,
            ];
            let step = control_step(&q, &trocar, &u, &tuning).expect("regular");
            for (qi, dq) in q.iter_mut().zip(step.qdot) {
                *qi += 0.002 * dq;
            }
        }
        std::hint::black_box(&q);
    });
    assert_eq!(n, 0, "the control step allocated {n} times");
}
