//! Several outputs in one program (`Robot::fused_evaluator`): each output against its own
//! function's evaluator and against the numeric runtime, many configurations against one, and
//! the errors.

use trocar_api::{Error, Function, Robot};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

/// Joint values spread over `[-2.5, 2.5]` rad (a fixed sequence, so that a failure repeats).
fn configurations(n: usize, count: usize) -> Vec<Vec<f64>> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    (0..count)
        .map(|_| {
            (0..n)
                .map(|_| {
                    state = state
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1_442_695_040_888_963_407);
                    ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 5.0
                })
                .collect()
        })
        .collect()
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Every output of each set equals its own function's evaluation to rounding and the numeric
/// reference's (`trocar_model::reference`, the one `trocar verify` uses) to 1e-9 of its size,
/// in the order asked for.
#[test]
fn each_output_is_its_own_functions_value() {
    use Function::*;
    let sets: [(&str, &[Function]); 5] = [
        (
            "panda-laparoscope",
            &[ConstrainedLinkKinematics, PartialBodyJacobian],
        ),
        (
            "panda-laparoscope",
            &[PartialBodyJacobian, ForwardKinematics, ConstrainedJacobian],
        ),
        ("dia10_like_zy", &[ForwardKinematics, BodyJacobian]),
        (
            "dia10_like_zy",
            &[ConstrainedJacobian, Manipulability, ConstraintJacobianC],
        ),
        ("bidirectional-zx", &[Manipulability]),
    ];
    for (name, functions) in sets {
        let robot = Robot::load(name).unwrap();
        let model =
            NumericModel::<f64>::from_description(robot.description().unwrap(), &[]).unwrap();
        let values = robot.param_values(&[]).unwrap();
        let fused = robot.fused_evaluator(functions).unwrap();
        assert_eq!(fused.functions(), functions);
        let mut out = vec![f64::NAN; fused.len()];
        for q in configurations(robot.dof(), 40) {
            fused.eval_into(&q, &values, &mut out).unwrap();
            for (k, &f) in functions.iter().enumerate() {
                let got = &out[fused.range(k)];
                let alone = robot.eval(f, &q, &[]).unwrap();
                assert_eq!(fused.dims()[k], (alone.rows, alone.cols), "{name} {f}");
                let scale = alone.data.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let d = largest_difference(got, &alone.data);
                assert!(
                    d <= 1e-13 * scale,
                    "{name} {f}: {d:e} from its own function"
                );
                // The numeric reference of `trocar verify` (column-major; compared row by row).
                let reference = trocar_model::reference::evaluate(&model, f, &q)
                    .unwrap()
                    .unwrap();
                let rows: Vec<f64> = (0..reference.nrows())
                    .flat_map(|r| reference.row(r).iter().copied().collect::<Vec<_>>())
                    .collect();
                let d = largest_difference(got, &rows);
                assert!(
                    d <= 1e-9 * scale,
                    "{name} {f}: {d:e} from the numeric reference"
                );
            }
        }
    }
}

/// Many configurations give each configuration's single evaluation bit for bit, on one thread
/// and (from 512 configurations) on every core, with the poses' constant last rows.
#[test]
fn many_configurations_are_each_ones_evaluation() {
    let robot = Robot::load("panda-laparoscope").unwrap();
    let values = robot.param_values(&[]).unwrap();
    let fused = robot
        .fused_evaluator(&[
            Function::ForwardKinematics,
            Function::PartialBodyJacobian,
            Function::ConstrainedLinkKinematics,
        ])
        .unwrap();
    // None, a few, around the 64 configurations of `eval_many_each`'s buffer, and on every core.
    for count in [0, 3, 63, 64, 65, 700] {
        let qs = configurations(robot.dof(), count);
        let flat: Vec<f64> = qs.iter().flatten().copied().collect();
        let mut many = vec![f64::NAN; count * fused.len()];
        fused.eval_many(&flat, &values, &mut many).unwrap();
        let mut one = vec![f64::NAN; fused.len()];
        for (q, block) in qs.iter().zip(many.chunks_exact(fused.len())) {
            fused.eval_into(q, &values, &mut one).unwrap();
            let same = one
                .iter()
                .zip(block)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{count} configurations: differs at {q:?}");
            for k in [0, 2] {
                assert_eq!(&block[fused.range(k)][12..], &[0.0, 0.0, 0.0, 1.0]);
            }
        }
        // Each function's results in an array of its own: the same values.
        let mut each: Vec<Vec<f64>> = fused
            .dims()
            .iter()
            .map(|(r, c)| vec![f64::NAN; count * r * c])
            .collect();
        let mut slices: Vec<&mut [f64]> = each.iter_mut().map(|v| v.as_mut_slice()).collect();
        fused.eval_many_each(&flat, &values, &mut slices).unwrap();
        for (i, block) in many.chunks_exact(fused.len()).enumerate() {
            for (k, values) in each.iter().enumerate() {
                let size = fused.range(k).len();
                let got = &values[i * size..(i + 1) * size];
                let same = got
                    .iter()
                    .zip(&block[fused.range(k)])
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(
                    same,
                    "{count} configurations: function {k} of configuration {i}"
                );
            }
        }
    }
}

/// Wrong requests and wrong arguments are errors that say what is wrong.
#[test]
fn errors_name_what_is_wrong() {
    let robot = Robot::load("dia10_like_zy").unwrap();
    let message = |r: Result<trocar_api::FusedEvaluator<'_>, Error>| r.unwrap_err().to_string();
    assert!(message(robot.fused_evaluator(&[])).contains("no quantity asked for"));
    let twice = message(robot.fused_evaluator(&[Function::ForwardKinematics; 2]));
    assert!(twice.contains("`fk` asked for twice"), "{twice}");
    let task = message(robot.fused_evaluator(&[Function::ConstrainedTaskJacobian]));
    assert!(task.contains("not a function of this module"), "{task}");

    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../runtime/model/tests/data/arm7.urdf"
    );
    let free = Robot::from_description(RobotDescription::from_urdf_file(path, "tool").unwrap());
    let jr = message(
        free.fused_evaluator(&[Function::ForwardKinematics, Function::ConstrainedJacobian]),
    );
    assert!(
        jr.starts_with("what: `fk,jr`") && jr.contains("`jr`"),
        "{jr}"
    );

    let mechanism = Robot::load("four-bar").unwrap();
    let m = message(mechanism.fused_evaluator(&[Function::ReducedJacobian]));
    assert!(m.contains("closed mechanism"), "{m}");

    let fused = robot
        .fused_evaluator(&[Function::ForwardKinematics, Function::ConstrainedJacobian])
        .unwrap();
    let values = robot.param_values(&[]).unwrap();
    let mut out = vec![0.0; fused.len()];
    let short = fused.eval_into(&[0.0; 3], &values, &mut out).unwrap_err();
    assert!(short.to_string().contains("joints"), "{short}");
    let mut small = vec![0.0; fused.len() - 1];
    let q = vec![0.1; robot.dof()];
    let len = fused.eval_into(&q, &values, &mut small).unwrap_err();
    assert!(len.to_string().contains("output holds"), "{len}");
    let mut many = vec![0.0; 2 * fused.len()];
    let mut bad = vec![0.1; 2 * robot.dof()];
    bad[robot.dof() + 1] = f64::NAN;
    let nan = fused.eval_many(&bad, &values, &mut many).unwrap_err();
    assert!(
        nan.to_string().contains("configuration 1: joint 2"),
        "{nan}"
    );
    let (a, b) = (fused.range(0).len(), fused.range(1).len());
    let (mut pose, mut jr) = (vec![0.0; 2 * a], vec![0.0; 2 * b]);
    let nan = fused
        .eval_many_each(&bad, &values, &mut [&mut pose, &mut jr])
        .unwrap_err();
    assert!(
        nan.to_string().contains("configuration 1: joint 2"),
        "{nan}"
    );
    let good = vec![0.1; 2 * robot.dof()];
    let one = fused
        .eval_many_each(&good, &values, &mut [&mut pose])
        .unwrap_err();
    assert!(
        one.to_string().contains("1 outputs given for 2 functions"),
        "{one}"
    );
    let short = fused
        .eval_many_each(&good, &values, &mut [&mut pose, &mut jr[1..]])
        .unwrap_err();
    assert!(short.to_string().contains("output 1 holds"), "{short}");
}

/// A result that is not finite names its function and configuration, whichever order the
/// functions are in and whichever way they are evaluated (dia10_like's `J^r` divides by `l_a`).
#[test]
fn a_result_that_is_not_finite_names_its_function() {
    let robot = Robot::load("dia10_like_zy").unwrap();
    let values = robot.param_values(&[("l_a".into(), 0.0)]).unwrap();
    let n = robot.dof();
    let qs: Vec<f64> = configurations(n, 3).into_iter().flatten().collect();
    for set in [
        [Function::ForwardKinematics, Function::ConstrainedJacobian],
        [Function::ConstrainedJacobian, Function::ForwardKinematics],
    ] {
        let fused = robot.fused_evaluator(&set).unwrap();
        let mut out = vec![0.0; fused.len()];
        let one = fused.eval_into(&qs[..n], &values, &mut out).unwrap_err();
        let mut many = vec![0.0; 3 * fused.len()];
        let all = fused.eval_many(&qs, &values, &mut many).unwrap_err();
        let mut each: Vec<Vec<f64>> = (0..2)
            .map(|k| vec![0.0; 3 * fused.range(k).len()])
            .collect();
        let mut slices: Vec<&mut [f64]> = each.iter_mut().map(|v| v.as_mut_slice()).collect();
        let split = fused.eval_many_each(&qs, &values, &mut slices).unwrap_err();
        for (e, at) in [
            (one, "this configuration"),
            (all, "configuration 0"),
            (split, "configuration 0"),
        ] {
            let m = e.to_string();
            assert!(m.contains("`constrained_jacobian` is not finite"), "{m}");
            assert!(m.contains(at) && m.contains("`l_a` = 0e0"), "{m}");
        }
    }
}

/// The program of a set is built once and shared by threads asking for it at the same time.
#[test]
fn threads_share_one_program() {
    let robot = Robot::load("panda-laparoscope").unwrap();
    let values = robot.param_values(&[]).unwrap();
    let set = [Function::BodyJacobian, Function::ForwardKinematics];
    let q = configurations(robot.dof(), 1).remove(0);
    let results: Vec<Vec<f64>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                scope.spawn(|| {
                    let fused = robot.fused_evaluator(&set).unwrap();
                    let mut out = vec![0.0; fused.len()];
                    fused.eval_into(&q, &values, &mut out).unwrap();
                    out
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(results.windows(2).all(|w| w[0] == w[1]));
}
