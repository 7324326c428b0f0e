//! Two Pandas, each through its own port 7 cm from the other's, whose tips are sent across each
//! other's path: `trocar::control::scene`. Without the coupling the shafts meet; with it their
//! distance (measured here from forward kinematics, independently of the step) stays above the
//! safety distance at every step, both ports hold and every joint keeps its limits. A scene of
//! one arm steps exactly as its controller alone.

// Arm by arm and joint by joint: the index names the arm in several arrays at once.
#![allow(clippy::needless_range_loop)]

use nalgebra::{SVector, Vector3};
use trocar::control::scene::{Between, Coupling, Scene};
use trocar::control::{Damper, Damping, HardLimits, Method, Rcm};
use trocar::distance::segment_distance;
use trocar::se3::Se3;
use trocar_sim::scene::{controller, reference, Kin};

const Q0: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
const DT: f64 = 0.002;
const SAFETY: f64 = 0.005;

fn panda() -> (Kin, HardLimits<f64, 7>) {
    trocar_sim::scene::panda().unwrap()
}

struct Run {
    min_distance: f64,
    min_tip_distance: f64,
    max_drift: f64,
    joints_within: bool,
    coupling_active_steps: usize,
}

/// Both arms for 3 s, with the coupling or without it.
fn run(coupled: bool) -> Run {
    run_with(coupled, None, Between::Shafts, SAFETY)
}

/// [`run`] with each arm's step by `method` (the scene's QP step by default), the coupling
/// `between` the shafts or the tips with its safety distance `safety`.
fn run_with(coupled: bool, method: Option<Method<f64>>, between: Between, safety: f64) -> Run {
    let (kin, limits) = panda();
    let q0 = SVector::<f64, 7>::from(Q0);
    let g_0e = kin.chain.forward_kinematics(&q0);
    let g_0i = kin.chain.link_frame(7, &q0);
    let trocar = kin.shaft.constraint_pose(&g_0i, 0.25).translation;
    // Arm b faces arm a, its port 7 cm from a's along x: b's base at 2 x_port + 0.07, turned
    // half a turn about z.
    let turn = nalgebra::Matrix3::new(-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    let bases = [
        Se3::identity(),
        Se3::new(turn, Vector3::new(2.0 * trocar.x + 0.07, 0.0, 0.0)),
    ];
    let kins = [kin, kin];
    let mut one = controller(limits);
    if let Some(m) = method {
        one.config.method = m;
    }
    let mut arms = [one, one];
    let damper = Damper {
        influence: 0.03,
        safety,
        gain: 0.1,
    };
    let couplings = [Coupling {
        arms: (0, 1),
        between,
        damper: if coupled {
            damper
        } else {
            // Influence below the safety distance: never acts.
            Damper {
                influence: 0.0,
                safety: 0.0,
                gain: 0.0,
            }
        },
    }];
    let mut scene = Scene::<f64, 1, 14, 2>::new(couplings);
    let rcm = Rcm {
        trocar,
        dv: SVector::zeros(),
    };
    // Each tip 12 cm toward the other arm's side (its own +x), 1 cm apart sideways.
    let shifts = [
        Vector3::new(0.12, 0.005, 0.0),
        Vector3::new(0.12, 0.005, 0.0),
    ];
    let mut q = [q0, q0];
    let mut out = Run {
        min_distance: f64::INFINITY,
        min_tip_distance: f64::INFINITY,
        max_drift: 0.0,
        joints_within: true,
        coupling_active_steps: 0,
    };
    for step in 0..1500 {
        let t = step as f64 * DT;
        let references = [0, 1].map(|k| reference(&g_0e, shifts[k], t));
        let o = scene
            .step::<Kin, 2, 7, 7, 2, 4, 4, 4, 4>(
                &mut arms,
                &kins,
                &q,
                &references,
                &[rcm, rcm],
                &bases,
                &[],
                DT,
            )
            .unwrap();
        out.coupling_active_steps += usize::from(o.coupling_active);
        for k in 0..2 {
            q[k] += o.qd[k] * DT;
            for j in 0..7 {
                out.joints_within &= q[k][j] >= limits.lower[j] && q[k][j] <= limits.upper[j];
            }
        }
        // Measured from forward kinematics: the shafts from the ports to the tips, and each
        // shaft's distance from its port.
        let mut ends = [Vector3::zeros(); 4];
        for k in 0..2 {
            let tip = kin.chain.forward_kinematics(&q[k]);
            let flange = kin.chain.link_frame(7, &q[k]);
            let axis: Vector3<f64> = flange.rotation.column(2).into_owned();
            let rel = trocar - flange.translation;
            out.max_drift = out.max_drift.max((rel - axis * rel.dot(&axis)).norm());
            ends[2 * k] = bases[k].transform_point(&trocar);
            ends[2 * k + 1] = bases[k].transform_point(&tip.translation);
        }
        let d = segment_distance(&ends[0], &ends[1], &ends[2], &ends[3]).distance;
        out.min_distance = out.min_distance.min(d);
        out.min_tip_distance = out.min_tip_distance.min((ends[1] - ends[3]).norm());
    }
    out
}

#[test]
fn the_coupling_keeps_two_shafts_apart() {
    let free = run(false);
    // The scene is meaningful: alone, the shafts come closer than the safety distance.
    assert!(
        free.min_distance < SAFETY,
        "uncoupled: {} m",
        free.min_distance
    );
    assert_eq!(free.coupling_active_steps, 0);
    let coupled = run(true);
    println!(
        "min shaft distance: {:.2e} m uncoupled, {:.2e} m coupled ({} steps with the coupling \
         active); drift {:.2e} m",
        free.min_distance, coupled.min_distance, coupled.coupling_active_steps, coupled.max_drift
    );
    assert!(coupled.coupling_active_steps > 0);
    assert!(
        coupled.min_distance >= SAFETY * (1.0 - 1e-6),
        "{} m",
        coupled.min_distance
    );
    assert!(coupled.max_drift <= 1e-4, "drift {} m", coupled.max_drift);
    assert!(coupled.joints_within && free.joints_within);
}

/// A coupling between the tips (their paths cross 1 cm apart): alone they come within 1 cm of
/// each other, coupled they keep 1.5 cm, measured from forward kinematics; the ports hold.
#[test]
fn the_tip_coupling_keeps_two_tips_apart() {
    let tip_safety = 0.015;
    let free = run_with(false, None, Between::Tips, tip_safety);
    assert!(
        free.min_tip_distance < tip_safety,
        "uncoupled: {} m",
        free.min_tip_distance
    );
    let coupled = run_with(true, None, Between::Tips, tip_safety);
    println!(
        "min tip distance: {:.2e} m uncoupled, {:.2e} m coupled ({} steps active); drift {:.2e} m",
        free.min_tip_distance,
        coupled.min_tip_distance,
        coupled.coupling_active_steps,
        coupled.max_drift
    );
    assert!(coupled.coupling_active_steps > 0);
    assert!(
        coupled.min_tip_distance >= tip_safety * (1.0 - 1e-6),
        "{} m",
        coupled.min_tip_distance
    );
    assert!(coupled.max_drift <= 1e-4, "drift {} m", coupled.max_drift);
    assert!(coupled.joints_within);
}

/// The arms' own steps by the inverses instead of the QP: the scene's step keeps the couplings
/// all the same (the arms' own steps hold their ports and rate boxes; the couplings are the
/// scene's).
#[test]
fn every_method_keeps_the_shafts_apart() {
    let methods = [
        Method::Pinv,
        Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 1e-3,
        }),
        Method::Fi {
            gamma_r: 5.0,
            gamma_l: 5.0,
        },
    ];
    for method in methods {
        let r = run_with(true, Some(method), Between::Shafts, SAFETY);
        assert!(
            r.min_distance >= SAFETY * (1.0 - 1e-6),
            "{method:?}: {} m",
            r.min_distance
        );
        assert!(r.max_drift <= 1e-4, "{method:?}: drift {} m", r.max_drift);
        assert!(r.joints_within && r.coupling_active_steps > 0, "{method:?}");
    }
}

/// A scene of one arm, without couplings, steps exactly as its controller does alone.
#[test]
fn one_arm_steps_as_its_controller() {
    let (kin, limits) = panda();
    let q0 = SVector::<f64, 7>::from(Q0);
    let g_0e = kin.chain.forward_kinematics(&q0);
    let trocar = kin
        .shaft
        .constraint_pose(&kin.chain.link_frame(7, &q0), 0.25)
        .translation;
    let rcm = Rcm {
        trocar,
        dv: SVector::zeros(),
    };
    let mut alone = controller(limits);
    let mut arms = [controller(limits)];
    let mut scene = Scene::<f64, 0, 7, 0>::new([]);
    let (mut qa, mut qs) = (q0, q0);
    for step in 0..1000 {
        let r = reference(&g_0e, Vector3::new(0.05, -0.03, 0.02), step as f64 * DT);
        let a = alone.step(&kin, &qa, &r, &rcm, DT).unwrap();
        let s = scene
            .step::<Kin, 1, 7, 7, 2, 4, 4, 4, 2>(
                &mut arms,
                &[kin],
                &[qs],
                &[r],
                &[rcm],
                &[Se3::identity()],
                &[],
                DT,
            )
            .unwrap();
        assert_eq!(a.qd, s.qd[0], "step {step}");
        qa += a.qd * DT;
        qs += s.qd[0] * DT;
    }
}

/// Sizes that do not add up are refused.
#[test]
fn sizes_are_checked() {
    let (kin, limits) = panda();
    let q0 = SVector::<f64, 7>::from(Q0);
    let rcm = Rcm {
        trocar: kin
            .shaft
            .constraint_pose(&kin.chain.link_frame(7, &q0), 0.25)
            .translation,
        dv: SVector::zeros(),
    };
    let r = reference(&kin.chain.forward_kinematics(&q0), Vector3::zeros(), 0.0);
    let mut arms = [controller(limits)];
    let mut scene = Scene::<f64, 0, 8, 0>::new([]);
    let e = scene
        .step::<Kin, 1, 7, 7, 2, 4, 4, 4, 2>(
            &mut arms,
            &[kin],
            &[q0],
            &[r],
            &[rcm],
            &[Se3::identity()],
            &[],
            DT,
        )
        .unwrap_err();
    assert_eq!(e, trocar::control::scene::SceneError::Sizes);
}
