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
        err.contains("--q: 2 values given") && err.contains("8 joints"),
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

/// `J^B_0i` and `g_0i` of `frame` of `runtime/model/tests/data/ur_tool0.urdf` at
/// q = (0.3, −0.7, 1.1, −0.4, 0.9, 0.2), from Pinocchio 4.1 (`getFrameJacobian(.., LOCAL)`,
/// `oMf`), row by row.
const PINOCCHIO_TOOL0: ([[f64; 6]; 6], [[f64; 4]; 3]) = (
    [
        [
            -0.67407071359069,
            0.16524252502450737,
            -0.0661361625518131,
            -0.04485481761576371,
            0.08065947935633423,
            -2.2056726290752362e-17,
        ],
        [
            0.1366408973360805,
            0.7325862382405579,
            0.4478197875196991,
            0.07487152709581983,
            -0.016350485924433583,
            -1.0880924808771152e-16,
        ],
        [
            0.34113820757233326,
            0.020674481854030573,
            -0.19379456364975337,
            -0.0741418917008352,
            -3.1889822694516144e-10,
            1.9607043738927593e-25,
        ],
        [
            -0.19866932860809072,
            -0.7677125214181126,
            -0.7677125214181126,
            -0.7677125214181126,
            0.19866933079506136,
            3.5897927727820247e-09,
        ],
        [
            -0.9800665782845629,
            0.15562303181373036,
            0.15562303181373036,
            0.15562303181373036,
            0.980066577841242,
            -1.7948966255767213e-09,
        ],
        [
            1.7660454975294265e-09,
            0.6216099713059209,
            0.6216099713059209,
            0.6216099713059209,
            1.0459359410535927e-09,
            1.0000000000000004,
        ],
    ],
    [
        [
            0.8088838543833036,
            -0.16396887194781204,
            0.5646424701970029,
            0.6699036122392841,
        ],
        [
            -0.5533872134305435,
            0.11217714188617797,
            0.8253356170975705,
            0.3750286505320545,
        ],
        [
            -0.19866932860809072,
            -0.9800665782845629,
            1.7660454975294265e-09,
            0.11555217376879325,
        ],
    ],
);

/// As [`PINOCCHIO_TOOL0`], of `tool_off` (off the last joint's axis, rotated).
const PINOCCHIO_TOOL_OFF: ([[f64; 6]; 6], [[f64; 4]; 3]) = (
    [
        [
            -0.45496119497052756,
            0.5425345065238362,
            0.16711683017831303,
            0.03395519793238394,
            0.06886894762954769,
            0.057100535229166374,
        ],
        [
            0.577578671610245,
            0.5352540169648806,
            0.3603043594215087,
            0.0819383879242519,
            -0.07894642917370613,
            -0.0011696388305826588,
        ],
        [
            0.3242324578544087,
            -0.2225999882199844,
            -0.31788474887343254,
            -0.07572689104100847,
            -0.032204007913294586,
            -0.011754182815116367,
        ],
        [
            -0.631376222092297,
            -0.46368408738393957,
            -0.46368408738393957,
            -0.46368408738393957,
            0.6313762243236389,
            0.19866933303923767,
        ],
        [
            -0.6928591140144829,
            0.6973058372217187,
            0.6973058372217187,
            0.6973058372217187,
            0.6928591133553788,
            0.2896294743420906,
        ],
        [
            0.3482963024545694,
            0.5465909224305158,
            0.5465909224305158,
            0.5465909224305158,
            -0.3482962997208341,
            0.936293364123697,
        ],
    ],
    [
        [
            0.7308456394991738,
            -0.38147257708667726,
            0.5659888021470861,
            0.7136614208721139,
        ],
        [
            -0.25928501191064324,
            0.6119027055487791,
            0.7472257768175445,
            0.3693248893767807,
        ],
        [
            -0.631376222092297,
            -0.6928591140144829,
            0.3482963024545694,
            0.1585954228600996,
        ],
    ],
);

/// A constraint on a link that fixed joints attach to the last moving joint's child (a UR arm's
/// `tool0`, and a frame off the joint's axis): `F_i` is the named link's frame, so `J^B_0i` and
/// `g_0i` are Pinocchio's of that frame, from the closed form and from the numeric runtime, and
/// `verify` agrees; the constraint offset is written relative to it (`g_ir` as written).
#[test]
fn a_named_link_is_the_frame_of_jb0i_and_fk_i() {
    let urdf = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../runtime/model/tests/data/ur_tool0.urdf")
        .canonicalize()
        .unwrap();
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("named-frame");
    std::fs::create_dir_all(&dir).unwrap();
    let q = "0.3,-0.7,1.1,-0.4,0.9,0.2";
    for (link, (jb0i, g0i)) in [("tool0", PINOCCHIO_TOOL0), ("tool_off", PINOCCHIO_TOOL_OFF)] {
        let toml = dir.join(format!("{link}.toml"));
        std::fs::write(
            &toml,
            format!(
                "[robot]\nname = \"ur_{link}\"\nurdf = \"{}\"\ntip = \"tool_off\"\n\n\
                 [parameters]\nl_a = 0.2\n\n[end_effector]\nxyz = [0, 0, 0.4]\n\n\
                 [constraint]\nlink = \"{link}\"\n\
                 xyz = [0.01, -0.02, \"l_a\"]\nh = [\"x\", \"y\"]\n\n\
                 [task]\nselect = [\"x\", \"y\", \"z\", \"rz\"]\n",
                urdf.display()
            ),
        )
        .unwrap();
        let toml = toml.to_str().unwrap();
        for numeric in [false, true] {
            let run = |what: &str| {
                let mut args = vec!["eval", toml, "--q", q, "--what", what, "--json"];
                if numeric {
                    args.push("--numeric");
                }
                let (code, out, err) = trocar(&args);
                assert_eq!(code, 0, "{link} {what} numeric={numeric}: {err}");
                json_matrix(&out)
            };
            let (rows, cols, data) = run("jb0i");
            assert_eq!((rows, cols), (6, 6));
            for (r, row) in jb0i.iter().enumerate() {
                for (c, x) in row.iter().enumerate() {
                    assert!(
                        (data[r][c] - x).abs() < 1e-9,
                        "{link} numeric={numeric}: J^B_0i[{r}][{c}] = {} vs Pinocchio {x}",
                        data[r][c]
                    );
                }
            }
            if numeric {
                // The numeric runtime evaluates J^B_0i, not g_0i or g_ir.
                continue;
            }
            let (_, _, data) = run("fk0i");
            for (r, row) in g0i.iter().enumerate() {
                for (c, x) in row.iter().enumerate() {
                    assert!(
                        (data[r][c] - x).abs() < 1e-9,
                        "{link} numeric={numeric}: g_0i[{r}][{c}] = {} vs Pinocchio {x}",
                        data[r][c]
                    );
                }
            }
            // g_ir is the offset as written, relative to the named link.
            let (_, _, data) = run("constraint_frame");
            let p: Vec<f64> = data[..3].iter().map(|row| row[3]).collect();
            assert!(
                (p[0] - 0.01).abs() < 1e-15
                    && (p[1] + 0.02).abs() < 1e-15
                    && (p[2] - 0.2).abs() < 1e-15,
                "{link}: g_ir translation {p:?}"
            );
        }
        let (code, out, err) = trocar(&["verify", toml, "--samples", "20"]);
        assert_eq!(code, 0, "{link}: {out}{err}");
    }
}

/// At a configuration where `J^r` (6 × 7) has exact rank 5, the LU of `J Jᵀ` meets a zero pivot:
/// the numeric manipulability is 0, as the closed form's, not an error about a result that is not
/// finite.
#[test]
fn the_numeric_manipulability_is_zero_at_an_exact_singularity() {
    let q = "1.5707963267948966,0.5,0,0,0,0,0,1.5707963267948966,0";
    for numeric in [true, false] {
        let mut args = vec![
            "eval",
            "runtime/model/tests/data/chain9_rank5.toml",
            "--q",
            q,
            "--what",
            "manip",
            "--json",
        ];
        if numeric {
            args.push("--numeric");
        }
        let (code, out, err) = trocar(&args);
        assert_eq!(code, 0, "numeric={numeric}: {err}");
        let (_, _, data) = json_matrix(&out);
        assert!(
            data[0][0].abs() < 1e-12,
            "numeric={numeric}: {}",
            data[0][0]
        );
        assert!(err.contains("rank 5 of 6"), "{err}");
    }
}
