//! `SceneStepper`: a loop of one's own stepping `three-ports` or `dia10-dual` (Euler, as the shipped run
//! integrates) gives the shipped run's joints row by row, in the scene's order; a bad `q` or `t`
//! is refused with its argument named, and a scene that cannot be stepped is named.

use trocar_api::{Error, SceneStepper, StepStatus};

#[test]
fn a_loop_of_ones_own_gives_the_shipped_run() {
    for (name, arms, joints) in [
        ("three-ports", vec!["left", "right", "endoscope"], 21),
        ("dia10-dual", vec!["left", "right"], 15),
    ] {
        let trace = trocar_sim::scene::simulate(name, true, |_| {}).unwrap();
        let mut scene = SceneStepper::new(name, true).unwrap();
        assert_eq!(scene.arms(), arms);
        assert_eq!(scene.ports().len(), arms.len());
        let n = scene.joints();
        assert_eq!(n, joints);
        let mut q = scene.q0();
        let dt = scene.dt();
        let mut least = f64::INFINITY;
        for (step, row) in trace.rows.iter().enumerate() {
            // The trace's row at t: t, q1..qn.
            for k in 0..n {
                assert_eq!(q[k], row[1 + k], "{name} step {step}, q{}", k + 1);
            }
            if step + 1 == trace.rows.len() {
                break;
            }
            let out = scene.step(&q, step as f64 * dt).unwrap();
            assert!(out.coupling_held);
            assert!(out.statuses.iter().all(|s| *s == StepStatus::Held));
            least = out.distances.iter().copied().fold(least, f64::min);
            for (qk, qd) in q.iter_mut().zip(&out.qd) {
                *qk += qd * dt;
            }
        }
        assert!(least >= scene.safety() * (1.0 - 1e-6), "{name}: {least}");
        // Reset: the start again.
        scene.reset();
        let first = scene.step(&scene.q0(), 0.0).unwrap();
        let mut again = SceneStepper::new(name, true).unwrap();
        assert_eq!(first, again.step(&again.q0(), 0.0).unwrap());
    }
}

#[test]
fn bad_joints_or_times_and_other_scenes_are_refused() {
    let mut scene = SceneStepper::new("three-ports", true).unwrap();
    let q = scene.q0();
    let argument = |e: Error| match e {
        Error::Argument { argument, problem } => format!("{argument}: {problem}"),
        other => panic!("{other}"),
    };
    let e = argument(scene.step(&q[..20], 0.0).unwrap_err());
    assert!(
        e.contains("q: 20 values given; the scene has 21 joints"),
        "{e}"
    );
    let mut bad = q.clone();
    bad[4] = f64::NAN;
    let e = argument(scene.step(&bad, 0.0).unwrap_err());
    assert!(e.contains("q[4] is NaN"), "{e}");
    let e = argument(scene.step(&q, f64::INFINITY).unwrap_err());
    assert!(e.starts_with("t: "), "{e}");
    let e = argument(SceneStepper::new("four-bar", true).unwrap_err());
    assert!(
        e.contains("`four-bar` is not a scene that can be stepped"),
        "{e}"
    );
    // The scene is still usable after refusals.
    assert!(scene.step(&q, 0.0).is_ok());
}
