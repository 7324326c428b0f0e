//! The generated programs of every shipped and fixture description agree with the numeric
//! runtime and with finite differences (`trocar verify` as a library).

use trocar_check::verify::{verify, Tolerances};
use trocar_codegen::evaluate::Generated;
use trocar_model::description::{preset_names, RobotDescription};

fn check(description: &RobotDescription, samples: usize) {
    let generated = Generated::new(description).expect("derivable");
    let report = verify(
        description,
        &generated,
        samples,
        11,
        Tolerances::default(),
        |_| {},
    )
    .expect("numeric runtime accepts the description");
    assert!(report.passed(), "{report}");
    // Without a constraint: g_0e and J^B_0e against the numeric runtime and the two
    // finite-difference checks of g_0e; with one, the twelve functions of a constrained module
    // and the differences of g_0i besides; with a task, S and S J^r as well. Then the fused
    // functions: `pose_and_jacobian`'s two outputs and its J^B_0e against differences of its
    // g_0e, with a constraint `link_pose_and_jacobian`'s likewise.
    let expected = match (&description.constraint, &description.task) {
        (None, _) => 4 + 3,
        (Some(_), None) => 15 + 6,
        (Some(_), Some(_)) => 17 + 6,
    };
    assert_eq!(report.checks.len(), expected, "{report}");
}

#[test]
fn shipped_descriptions() {
    for name in preset_names() {
        check(&RobotDescription::preset(name).unwrap(), 500);
    }
}

/// URDF-based robots: the constraint on the last link with a task (`iiwa-endoscope`; the Panda is
/// a shipped description, above) and on a middle link (`iiwa-link6`).
#[test]
fn urdf_robots_on_the_last_and_a_middle_link() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../runtime/model/robots/");
    for file in ["iiwa-endoscope.toml", "iiwa-link6.toml"] {
        check(
            &RobotDescription::from_toml_file(format!("{root}{file}")).unwrap(),
            300,
        );
    }
}

#[test]
fn fixtures_with_rotated_rcm_prismatic_joint_and_three_row_h() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/generated/robots/");
    for file in ["rotated_rcm.toml", "chain9_prismatic.toml"] {
        check(
            &RobotDescription::from_toml_file(format!("{root}{file}")).unwrap(),
            200,
        );
    }
}

#[test]
fn urdf_arm_without_constraint() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../runtime/model/tests/data/arm7.urdf"
    );
    check(
        &RobotDescription::from_urdf_file(path, "tool").unwrap(),
        200,
    );
}

/// Oblique axes everywhere: every link frame is turned so that its joint's axis is z, the
/// constrained link's and the last one's included, and turned back where the results are
/// expressed (`g_0i`, `J^B_0i`, the end effector).
#[test]
fn oblique_axes_on_every_joint() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/oblique7.toml");
    let description = RobotDescription::from_toml_file(path).unwrap();
    let d = trocar_codegen::derivation::derive(&description).unwrap();
    assert!(
        d.frame_turns.iter().all(Option::is_some),
        "every axis is oblique"
    );
    check(&description, 300);
    fused_sets_match_the_reference(&description);
    // A short chain, whose expanded forms are emitted where they are cheaper: the constrained
    // link's and the last joint's axes oblique.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/dia10_oblique.toml");
    let description = RobotDescription::from_toml_file(path).unwrap();
    let d = trocar_codegen::derivation::derive(&description).unwrap();
    let turned: Vec<bool> = d.frame_turns.iter().map(Option::is_some).collect();
    assert_eq!(
        turned,
        [false, false, false, false, false, true, false, true]
    );
    check(&description, 300);
    fused_sets_match_the_reference(&description);
    // Without a constraint: g_0e and J^B_0e end at the turned last frame.
    let mut free = RobotDescription::from_toml_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/oblique7.toml"
    ))
    .unwrap();
    free.constraint = None;
    free.task = None;
    check(&free, 200);
}

/// Fused programs of several outputs, among them the one that builds `g_0e` as `g_0i · g_ie`
/// and so starts a product at the (turned) constrained link, against the numeric reference.
fn fused_sets_match_the_reference(description: &RobotDescription) {
    use trocar_api::{Function as F, Robot};
    let robot = Robot::from_description(description.clone());
    let model =
        trocar_model::numeric::NumericModel::<f64>::from_description(description, &[]).unwrap();
    let values = robot.param_values(&[]).unwrap();
    let n = robot.dof();
    for set in [
        vec![F::ForwardKinematics, F::PartialBodyJacobian],
        vec![F::ForwardKinematics, F::ConstrainedLinkKinematics],
        vec![
            F::ConstrainedJacobian,
            F::ForwardKinematics,
            F::BodyJacobian,
        ],
    ] {
        let fused = robot.fused_evaluator(&set).unwrap();
        let mut out = vec![0.0; fused.len()];
        for s in 0..50 {
            let q: Vec<f64> = (0..n)
                .map(|k| ((s * n + k) as f64 * 0.618_033_988_75).fract() * 5.0 - 2.5)
                .collect();
            fused.eval_into(&q, &values, &mut out).unwrap();
            for (k, &f) in set.iter().enumerate() {
                let want = trocar_model::reference::evaluate(&model, f, &q)
                    .unwrap()
                    .unwrap();
                let got = &out[fused.range(k)];
                let worst = (0..want.nrows())
                    .flat_map(|r| (0..want.ncols()).map(move |c| (r, c)))
                    .map(|(r, c)| (got[r * want.ncols() + c] - want[(r, c)]).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-12, "{}: {f} off by {worst:e}", description.name);
            }
        }
    }
}
