//! Singular configurations are reported by one rule (`trocar_model::singularity`), the same for
//! the generated closed forms and the numeric runtime: the reference arm's `J^r` at `q7 = 0` and
//! `q7 = π` (it used to print `w = 0` and `w = 1.8e-16` without a word), and the four-bar's
//! parallel singularity at `(0, π, 0, π)`, where the closed form used to answer (it tested
//! `det J_Cp != 0`, which rounding decides) while the numeric runtime refused.

use std::process::Command;

fn trocar(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn q_with_q7(q7: &str) -> String {
    format!("--q=0,-0.3,0.9,0.2,-0.6,0.1,{q7},0.3")
}

#[test]
fn the_reference_arm_at_q7_zero_and_pi_is_reported_singular_by_both_paths() {
    for q7 in ["0", "3.141592653589793", "-3.141592653589793"] {
        for numeric in [false, true] {
            let q = q_with_q7(q7);
            let mut args = vec!["eval", "bidirectional-zy", q.as_str(), "--what", "manip"];
            if numeric {
                args.push("--numeric");
            }
            let (code, stdout, stderr) = trocar(&args);
            assert_eq!(code, Some(0), "{args:?}: {stderr}");
            let w: f64 = stdout.trim().parse().unwrap();
            assert!(w.abs() < 1e-12, "{args:?}: w = {w}");
            assert!(
                stderr.contains("note: J^r is singular at this configuration: rank 5 of 6")
                    && stderr
                        .contains("manipulability is below 1e-9 × largest^6: zero at this scale"),
                "{args:?}: {stderr}"
            );
            args[4] = "jr";
            let (code, _, stderr) = trocar(&args);
            assert_eq!(code, Some(0), "{args:?}: {stderr}");
            assert!(stderr.contains("J^r is singular"), "{args:?}: {stderr}");
        }
    }
}

#[test]
fn near_but_not_at_the_singularity_there_is_no_note() {
    // q7 = 1e-6: σ_min / σ_max of order 1e-7, far above the relative tolerance 1e-9.
    for q7 in ["1e-6", "0.5"] {
        for numeric in [false, true] {
            let q = q_with_q7(q7);
            let mut args = vec!["eval", "bidirectional-zy", q.as_str(), "--what", "manip"];
            if numeric {
                args.push("--numeric");
            }
            let (code, stdout, stderr) = trocar(&args);
            assert_eq!(code, Some(0), "{args:?}: {stderr}");
            assert!(stdout.trim().parse::<f64>().unwrap() > 0.0);
            assert!(!stderr.contains("singular"), "{args:?}: {stderr}");
        }
    }
}

#[test]
fn the_four_bar_parallel_singularity_is_refused_by_both_paths() {
    let q = "--q=0,3.141592653589793,0,3.141592653589793";
    for what in ["jr", "passive"] {
        for numeric in [false, true] {
            let mut args = vec!["eval", "four-bar", q, "--what", what];
            if numeric {
                args.push("--numeric");
            }
            let (code, stdout, stderr) = trocar(&args);
            assert_eq!(code, Some(1), "{args:?}: {stdout} {stderr}");
            assert!(stdout.is_empty(), "{args:?}: {stdout}");
            assert!(
                stderr.contains("singular") && stderr.contains("parallel"),
                "{args:?}: {stderr}"
            );
        }
    }
}

/// With `l_a = 1e-150` the manipulability is huge (1.55e298) yet `J^r` is singular relative to
/// its largest singular value: the note says so without claiming the printed value is zero, and
/// the value prints in scientific notation, not as 300 digits.
#[test]
fn a_huge_manipulability_of_a_relatively_singular_jr_is_stated_consistently() {
    let q = q_with_q7("0.5");
    let (code, out, err) = trocar(&[
        "eval",
        "bidirectional-zy",
        q.as_str(),
        "--what",
        "manip",
        "--param",
        "l_a=1e-150",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let w: f64 = out.trim().parse().unwrap();
    assert!(w > 1e290 && out.trim().len() < 20, "{out}");
    assert!(err.contains("below 1e-9 × largest^6"), "{err}");
    assert!(!err.contains("is 0"), "{err}");
}

/// A mechanism whose `J_Cp` is not square has no `det J_Cp`: the error says why, instead of
/// refusing `det` while suggesting it.
#[test]
fn det_of_a_non_square_j_cp_is_refused_with_the_reason() {
    let q = "--q=0.3,0.3,0.3,0.3,0.3,0.3,0.3,0.3";
    let (code, _, err) = trocar(&["eval", "cooperative-arms", q, "--what", "det", "--numeric"]);
    assert_eq!(code, Some(1));
    assert!(err.contains("3 × 2, not square"), "{err}");
    assert!(!err.contains("or det)"), "{err}");
}
