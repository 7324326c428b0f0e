//! The f32 control step agrees with the f64 numeric runtime (`trocar_sim::robot::NumericRobot`,
//! faer solves) on the same law: `[v0i; θ̇_78] = J^rᵀ(J^r J^rᵀ + κ²I)⁻¹ u`,
//! `θ̇_1..6 = J^B_0iᵀ(J^B_0i J^B_0iᵀ + κ_b²I)⁻¹ Λ# v0i`.

mod common;

use trocar_firmware::{control_step, dia10, Tuning};

fn trocar_point(q: &[f32; 8], l_a: f32) -> [f32; 3] {
    let t = dia10::JointTrig::new(q);
    let (r, p) = dia10::forward_kinematics_i_trig(&t, &dia10::Params { l_a });
    [0, 1, 2].map(|k| p[k] + l_a * r[1][k])
}

fn check(q: [f64; 8], l_a: f64, u: [f64; 6], tuning: Tuning) {
    let qf = q.map(|x| x as f32);
    let trocar = trocar_point(&qf, l_a as f32);
    let uf = u.map(|x| x as f32);
    let step = control_step(&qf, &trocar, &uf, &tuning).expect("regular configuration");
    assert!(
        (step.l_a as f64 - l_a).abs() < 1e-5,
        "l_a {} vs {l_a}",
        step.l_a
    );

    let (expected, w) = common::numeric_rates(&q, l_a, &u, &tuning);
    assert!((w - step.manipulability as f64).abs() < 1e-4 * w.max(1.0));
    let scale = expected.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for (k, (a, b)) in step.qdot.iter().zip(&expected).enumerate() {
        assert!(
            (*a as f64 - b).abs() < 2e-3 * scale,
            "joint {}: firmware {a} vs runtime {b}",
            k + 1
        );
    }
}

#[test]
fn matches_the_numeric_runtime_at_q0() {
    let q0 = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    check(
        q0,
        0.15,
        [0.01, -0.02, 0.005, 0.0, 0.02, -0.01],
        Tuning::default(),
    );
    check(
        q0,
        0.22,
        [-0.03, 0.01, 0.0, 0.1, 0.0, 0.05],
        Tuning::default(),
    );
}

#[test]
fn matches_the_numeric_runtime_near_the_singularity_with_damping() {
    // θ7 → 0: w = l_b²|sin θ7|/l_a² drops below w0, the variable damping is on.
    let q = [0.1, -0.2, 0.8, 0.3, -0.5, 0.2, 0.01, -0.4];
    let tuning = Tuning::default();
    check(q, 0.15, [0.01, 0.0, 0.0, 0.0, 0.01, 0.0], tuning);
}

#[test]
fn trocar_off_the_link_is_refused() {
    let q0 = [0.0f32, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let trocar = trocar_point(&q0, 0.5);
    assert_eq!(
        control_step(&q0, &trocar, &[0.0; 6], &Tuning::default()),
        Err(trocar_firmware::StepError::TrocarOffLink)
    );
}
