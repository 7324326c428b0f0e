//! The `trocar` binary's numeric subcommands, run as a user would.

mod common;

use common::{json_matrix, trocar};

const Q0: &str = "0,-0.3,0.9,0.2,-0.6,0.1,0.5,0.3";

#[test]
fn json_keys_come_in_the_spec_order() {
    let (code, out, _) = trocar(&["eval", "bidirectional-zy", "--numeric", "--q", Q0, "--json"]);
    assert_eq!(code, 0);
    assert!(
        out.starts_with(r#"{"rows": 6, "cols": 6, "data": [["#),
        "{out}"
    );
}

#[test]
fn zy_manipulability_is_the_thesis_closed_form() {
    // (3.42): w_r = l_b² |sin θ7| / l_a², independent of everything else.
    let (code, out, err) = trocar(&[
        "eval",
        "bidirectional-zy",
        "--numeric",
        "--what",
        "manip",
        "--json",
        "--q",
        Q0,
        "--param",
        "l_a=0.12",
        "--param",
        "l_b=0.2",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, data) = json_matrix(&out);
    let expected = 0.2f64.powi(2) * 0.5f64.sin().abs() / 0.12f64.powi(2);
    assert!(
        (data[0][0] - expected).abs() < 1e-12,
        "{} vs {expected}",
        data[0][0]
    );
}

#[test]
fn jr_has_the_thesis_shape_and_unit_last_column() {
    let (code, out, _) = trocar(&["eval", "unidirectional", "--numeric", "--json", "--q", Q0]);
    assert_eq!(code, 0);
    let (rows, cols, data) = json_matrix(&out);
    assert_eq!((rows, cols), (6, 7));
    // Last column of (3.24): joint 8 about y of the end-effector frame.
    let last: Vec<f64> = data.iter().map(|r| r[6]).collect();
    assert_eq!(last, vec![0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
}

#[test]
fn forward_kinematics_is_homogeneous() {
    let (code, out, _) = trocar(&[
        "eval",
        "dia10_like_zy",
        "--numeric",
        "--what",
        "fk",
        "--json",
        "--q",
        Q0,
    ]);
    assert_eq!(code, 0);
    let (rows, cols, data) = json_matrix(&out);
    assert_eq!((rows, cols), (4, 4));
    assert_eq!(data[3], vec![0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn user_errors_say_what_and_where() {
    let (code, _, err) = trocar(&["eval", "bidirectional-zy", "--numeric", "--q", "0,1"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("--q has 2 values") && err.contains("8 joints"),
        "{err}"
    );

    let (code, _, err) = trocar(&[
        "eval",
        "bidirectional-zy",
        "--numeric",
        "--q",
        Q0,
        "--param",
        "l_z=1",
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("l_z"), "{err}");

    let (code, _, err) = trocar(&["eval", "no/such/robot.toml", "--numeric", "--q", Q0]);
    assert_eq!(code, 1);
    assert!(err.contains("no/such/robot.toml"), "{err}");

    let (code, _, err) = trocar(&[
        "eval",
        "bidirectional-zy",
        "--numeric",
        "--q",
        "0,nan,0,0,0,0,0,0",
    ]);
    assert_ne!(code, 0, "{err}");

    let (code, _, err) = trocar(&["preset", "bidirectional"]);
    assert_eq!(code, 1);
    assert!(err.contains("bidirectional-zy"), "{err}");

    let (code, _, _) = trocar(&["eval"]);
    assert_eq!(code, 2, "usage errors exit with 2");
}

#[test]
fn preset_prints_a_description_that_reads_back() {
    let (code, out, _) = trocar(&["preset", "bidirectional-zx"]);
    assert_eq!(code, 0);
    let d = trocar_model::description::RobotDescription::from_toml_str(&out, None)
        .expect("valid description");
    assert_eq!(d.name, "bidirectional_zx");
}

#[test]
fn urdf_jacobian_matches_the_same_arm_in_toml() {
    let q = "0.1,0.2,0.3,0.4,0.5,0.6,0.7";
    let (code, urdf, err) = trocar(&[
        "jacobian",
        "--urdf",
        "runtime/model/tests/data/arm7.urdf",
        "--tip",
        "tool",
        "--q",
        q,
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, toml, err) = trocar(&[
        "eval",
        "runtime/model/tests/data/arm7.toml",
        "--numeric",
        "--what",
        "jb0e",
        "--q",
        q,
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let (a, b) = (json_matrix(&urdf).2, json_matrix(&toml).2);
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
    }
}

#[test]
fn closed_form_eval_equals_numeric_eval() {
    for robot in ["unidirectional", "bidirectional-zx", "dia10_like_zy"] {
        for what in ["jr", "jc", "jb0i", "jb0e", "fk", "manip"] {
            let args = |numeric: bool| {
                let mut a = vec![
                    "eval", robot, "--what", what, "--json", "--q", Q0, "--param", "l_a=0.17",
                ];
                if numeric {
                    a.push("--numeric");
                }
                trocar(&a)
            };
            let ((c1, generated, e1), (c2, numeric, e2)) = (args(false), args(true));
            assert_eq!((c1, c2), (0, 0), "{e1}{e2}");
            let (a, b) = (json_matrix(&generated), json_matrix(&numeric));
            assert_eq!((a.0, a.1), (b.0, b.1), "{robot} {what}");
            for (ra, rb) in a.2.iter().zip(&b.2) {
                for (x, y) in ra.iter().zip(rb) {
                    assert!((x - y).abs() < 1e-12, "{robot} {what}: {x} vs {y}");
                }
            }
        }
    }
}

#[test]
fn verify_passes_on_the_shipped_robots_and_prints_a_table() {
    for robot in [
        "unidirectional",
        "bidirectional-zy",
        "bidirectional-zx",
        "dia10_like_zx",
    ] {
        let (code, out, err) = trocar(&["verify", robot, "--samples", "200"]);
        assert_eq!(code, 0, "{out}{err}");
        assert!(
            out.contains("jr: generated vs numeric") && out.contains("all checks passed"),
            "{out}"
        );
    }
    let (code, _, err) = trocar(&["verify", "bidirectional-zy", "--samples", "0"]);
    assert_eq!(code, 1, "{err}");
}

#[test]
fn generate_writes_a_formatted_module() {
    let dir = std::env::temp_dir().join(format!("trocar-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("zy.rs");
    let (code, _, err) = trocar(&[
        "generate",
        "bidirectional-zy",
        "--real",
        "f32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("// This file is @generated"),
        "{}",
        &text[..80]
    );
    assert!(text.contains("pub fn constrained_jacobian") && text.contains("f32"));
    syn::parse_file(&text).expect("the module parses as Rust");
    let (code, _, err) = trocar(&["generate", "runtime/model/tests/data/does-not-exist.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("does-not-exist.toml"), "{err}");
}

/// A reader that closes the pipe early (`trocar generate … | head -c 10`) ends the command
/// normally: no panic on the broken pipe, exit code 0.
#[test]
fn a_closed_stdout_is_not_a_panic() {
    use std::process::{Command, Stdio};
    for args in [
        &["generate", "dia10_like_zy"][..],
        &["eval", "bidirectional-zy", "--q", Q0, "--json"][..],
        &["preset", "bidirectional-zy"][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_trocar"))
            .args(args)
            .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the trocar binary runs");
        drop(child.stdout.take()); // the reader goes away before anything is written
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
    }
}
