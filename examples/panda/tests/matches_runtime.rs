//! The f32 controller on generated kinematics follows the Panda scenario like the f64 numeric
//! runtime (`trocar_sim`): the same reference and trocar, joints within f32 accuracy, the trocar
//! held and the tip on the circle (measured with f64 forward kinematics of the numeric model).

use trocar::nalgebra::{SVector, Vector3};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_panda::sequence::reference_to_f32;
use trocar_panda::{control_step, controller, Q0};
use trocar_sim::simulation::{panda_reference, run, Scenario, ScenarioConfig, PANDA_TIP_DEPTH};

#[test]
fn f32_generated_controller_tracks_like_the_f64_numeric_run() {
    let steps = 2500; // 5 s of the 20 s scenario
    let dt = 0.002;
    let f64_run = run(
        &ScenarioConfig::new(Scenario::Panda).with_drift_correction(true),
        |_| {},
    )
    .unwrap();
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    let chain = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_chain::<7>()
        .unwrap();
    let q64 = |q: &[f32; 7]| SVector::<f64, 7>::from_fn(|k, _| f64::from(q[k]));
    let g0 = chain.forward_kinematics(&q64(&Q0));
    let trocar = g0.translation - g0.rotation.column(2) * PANDA_TIP_DEPTH;
    let trocar32 = [trocar.x as f32, trocar.y as f32, trocar.z as f32];
    let mut ctrl = controller();
    let mut q = Q0;
    let (mut worst, mut drift) = (0.0f64, 0.0f64);
    for k in 0..steps {
        let reference = reference_to_f32(&panda_reference(k as f64 * dt, &g0));
        let out = control_step(&mut ctrl, &q, &reference, &trocar32, dt as f32)
            .unwrap_or_else(|e| panic!("step {k}: {e}"));
        let row = &f64_run.rows[k].q;
        for j in 0..7 {
            worst = worst.max((f64::from(q[j]) - row[j]).abs());
        }
        // Distance of the trocar from the shaft (z of link 7's frame).
        let g = chain.link_frame(7, &q64(&q));
        let z: Vector3<f64> = g.rotation.column(2).into_owned();
        let rel = trocar - g.translation;
        drift = drift.max((rel - z * rel.dot(&z)).norm());
        for (qk, v) in q.iter_mut().zip(out.qd.iter()) {
            *qk += dt as f32 * v;
        }
    }
    let tip = chain.forward_kinematics(&q64(&q)).translation;
    let tip_error = (tip - panda_reference(steps as f64 * dt, &g0).position).norm();
    println!("f32 vs f64 joints {worst:.2e} rad, drift {drift:.2e} m, tip error {tip_error:.2e} m");
    assert!(worst < 1e-4, "f32 joints differ from f64 by {worst}");
    assert!(drift < 1e-4, "the trocar moved off the shaft by {drift} m");
    assert!(tip_error < 1e-4, "tip error {tip_error} m after 5 s");
}

/// The f32 QP step on generated kinematics runs the scenario `panda-laparoscope-limits` as the
/// f64 QP step on the numeric runtime does: the same joints to f32 accuracy through the
/// withdrawal to `l_max` and the roll into joint 7's speed limit, every limit kept (the URDF's,
/// read here from the description, and the depth bounds), the trocar held.
#[test]
fn f32_qp_step_keeps_the_limits_like_the_f64_run() {
    use trocar_panda::{
        qp_controller, ACCELERATION_LIMITS, DEPTH_LIMITS, JERK_LIMITS, SPEED_LIMITS,
    };
    use trocar_sim::simulation::{panda_limits_reference, Method};
    let steps = 4000; // 8 s of the 12 s scenario: the withdrawal, the roll and its return
    let dt = 0.002;
    // The f64 run with the f32 controller's `κ` (0.01: in `f32` a floor of 1e-3, the scenario's,
    // is below the solver's curvature tolerance `ε^{2/3}` relative to `JᵀJ`).
    let mut config = ScenarioConfig::new(Scenario::PandaLimits)
        .with_method(Method::Qp)
        .with_drift_correction(true);
    config.qp_kappa = 0.01;
    let f64_run = run(&config, |_| {}).unwrap();
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    for (k, j) in d.joints.iter().enumerate() {
        let urdf = j
            .speed_limit
            .expect("the URDF gives every joint a velocity");
        assert!(
            (urdf - f64::from(SPEED_LIMITS[k])).abs() < 1e-6,
            "joint {k}"
        );
        assert_eq!(
            j.acceleration_limit,
            Some(f64::from(ACCELERATION_LIMITS[k]))
        );
        assert_eq!(j.jerk_limit, Some(f64::from(JERK_LIMITS[k])));
    }
    let chain = NumericModel::<f64>::from_description(&d, &[])
        .unwrap()
        .to_chain::<7>()
        .unwrap();
    let q64 = |q: &[f32; 7]| SVector::<f64, 7>::from_fn(|k, _| f64::from(q[k]));
    let g0 = chain.forward_kinematics(&q64(&Q0));
    let trocar = g0.translation - g0.rotation.column(2) * PANDA_TIP_DEPTH;
    let trocar32 = [trocar.x as f32, trocar.y as f32, trocar.z as f32];
    let mut ctrl = qp_controller();
    let mut q = Q0;
    let (mut worst, mut drift) = (0.0f64, 0.0f64);
    for k in 0..steps {
        let reference = reference_to_f32(&panda_limits_reference(k as f64 * dt, &g0));
        let out = control_step(&mut ctrl, &q, &reference, &trocar32, dt as f32)
            .unwrap_or_else(|e| panic!("step {k}: {e}"));
        assert!(out.qp.is_some());
        let row = &f64_run.rows[k].q;
        for j in 0..7 {
            worst = worst.max((f64::from(q[j]) - row[j]).abs());
            let [lo, hi] = d.joints[j].limits.unwrap();
            assert!(
                f64::from(q[j]) >= lo && f64::from(q[j]) <= hi,
                "step {k}: q{} = {} outside [{lo}, {hi}]",
                j + 1,
                q[j]
            );
            assert!(
                out.qd[j].abs() <= SPEED_LIMITS[j] * (1.0 + 1e-6),
                "step {k}: qd{} = {}",
                j + 1,
                out.qd[j]
            );
        }
        let g = chain.link_frame(7, &q64(&q));
        let z: Vector3<f64> = g.rotation.column(2).into_owned();
        let rel = trocar - g.translation;
        drift = drift.max((rel - z * rel.dot(&z)).norm());
        // l_a from f64 forward kinematics: the trocar's offset along the shaft from the flange.
        let l_a = rel.dot(&z) - 0.107;
        assert!(
            l_a >= f64::from(DEPTH_LIMITS[0]) && l_a <= f64::from(DEPTH_LIMITS[1]) + 1e-6,
            "step {k}: l_a = {l_a}, {:?}, controller l_a {}",
            out.qp,
            out.l_a
        );
        for (qk, v) in q.iter_mut().zip(out.qd.iter()) {
            *qk += dt as f32 * v;
        }
    }
    println!("f32 QP vs f64 QP joints {worst:.2e} rad, drift {drift:.2e} m");
    // Measured: 1.4e-3 rad, reached during the roll into joint 7's speed limit (4.2-5.2 s),
    // where the acceleration bounds change the working set at nearly every step and the
    // redundant motion that rolls the flange is not pulled back (2.1e-4 rad before the URDF's
    // acceleration and jerk limits); 1.4e-5 rad until then.
    assert!(worst < 2e-3, "f32 joints differ from f64 by {worst}");
    assert!(drift < 1e-4, "the trocar moved off the shaft by {drift} m");
}
