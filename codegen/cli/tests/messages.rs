//! Issue 27, items 11 and 7: answers where the command used to do something else than asked
//! (`-o -` wrote a file named `-`, `preset` refused a mechanism `list` shows, a directory hid a
//! shipped robot), and numbers outside the number rule (joint limits, `--snapshot-times`, an
//! `f32` module's constants) refused where they are written.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `trocar args…` in `dir`: `(exit code, stdout, stderr)`.
fn trocar_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh empty directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("messages-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots")
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// `-o -` is stdout (it wrote a file named `-`), and so is `--c-header -`; both at once is an
/// error.
#[test]
fn a_dash_is_stdout() {
    let dir = scratch("dash");
    let (code, out, err) = trocar_in(&dir, &["generate", "bidirectional-zy", "-o", "-"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.starts_with("// This file is @generated"),
        "{}",
        &out[..80.min(out.len())]
    );
    let (code, out, err) = trocar_in(&dir, &["generate", "bidirectional-zy", "--c-header", "-"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("#define") && !out.contains("pub mod"),
        "{}",
        &out[..200.min(out.len())]
    );
    let (code, _, err) = trocar_in(
        &dir,
        &["generate", "bidirectional-zy", "-o", "-", "--c-header", "-"],
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("stdout"), "{err}");
    assert!(names_in(&dir).is_empty(), "{:?}", names_in(&dir));
}

/// `preset` prints the mechanisms `list` shows; a directory named like a shipped description
/// does not hide it.
#[test]
fn shipped_names_are_found() {
    let dir = scratch("shipped");
    let (code, out, err) = trocar_in(&dir, &["preset", "four-bar"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("[[chains]]"), "{out}");
    for name in ["bidirectional-zy", "four-bar"] {
        std::fs::create_dir(dir.join(name)).unwrap();
    }
    let (code, out, err) = trocar_in(
        &dir,
        &[
            "eval",
            "bidirectional-zy",
            "--q",
            "0,0.1,0.2,0.3,0.4,0.5,0.6,0.7",
            "--numeric",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("v_x"), "{out}");
    let (code, out, err) = trocar_in(&dir, &["preset", "four-bar"]);
    assert_eq!((code, out.contains("[[chains]]")), (0, true), "{err}");
    let (code, _, err) = trocar_in(&dir, &["generate", "four-bar"]);
    assert_eq!(code, 0, "{err}");
}

/// `--snapshot-times` and `--dt` values follow the number rule (a subnormal or infinite time was
/// taken).
#[test]
fn snapshot_times_follow_the_number_rule() {
    let dir = scratch("snapshot-times");
    for (bad, why) in [
        ("1e-320", "subnormal"),
        ("inf", "not finite"),
        ("-1", "negative"),
    ] {
        let (code, _, err) = trocar_in(
            &dir,
            &[
                "simulate",
                "exp421",
                "--snapshot",
                "s.png",
                "--snapshot-times",
                &format!("0.1,{bad}"),
            ],
        );
        assert_eq!(code, 2, "{bad}: {err}");
        assert!(
            err.contains("--snapshot-times") && err.contains(why),
            "{bad}: {err}"
        );
    }
    assert!(names_in(&dir).is_empty());
    // And `--dt`: a subnormal or huge sample time was taken.
    for (bad, why) in [("1e-320", "subnormal"), ("1e300", "beyond")] {
        let (code, _, err) =
            trocar_in(&dir, &["simulate", "exp421", "--csv", "t.csv", "--dt", bad]);
        assert_eq!(code, 2, "{bad}: {err}");
        assert!(err.contains("--dt") && err.contains(why), "{bad}: {err}");
    }
    assert!(names_in(&dir).is_empty());
}

/// A description with `urdf = "urdf/panda.urdf"` next to a copy of the shipped URDF, edited.
fn panda_in(dir: &Path, edit: impl Fn(String) -> String) {
    std::fs::create_dir_all(dir.join("urdf")).unwrap();
    std::fs::copy(robots().join("panda-laparoscope.toml"), dir.join("p.toml")).unwrap();
    let urdf = std::fs::read_to_string(robots().join("urdf/panda.urdf")).unwrap();
    std::fs::write(dir.join("urdf/panda.urdf"), edit(urdf)).unwrap();
}

/// Item 7: a `continuous` joint used to drop `JOINT_LIMITS` for the whole robot; the module now
/// has each joint's bounds, typed (`None` for the continuous joint).
#[test]
fn a_continuous_joint_keeps_the_other_limits() {
    let dir = scratch("continuous");
    panda_in(&dir, |urdf| {
        let at = urdf
            .find("<joint name=\"panda_joint7\" type=\"revolute\">")
            .unwrap();
        format!(
            "{}{}",
            &urdf[..at],
            urdf[at..].replacen("type=\"revolute\"", "type=\"continuous\"", 1)
        )
    });
    let (code, out, err) = trocar_in(&dir, &["generate", "p.toml"]);
    assert_eq!(code, 0, "{err}");
    syn::parse_file(&out).expect("the module parses");
    let flat: String = out.split_whitespace().collect();
    let head = "pubconstJOINT_RANGES:[Option<[f64;2]>;N]=[";
    let at = flat.find(head).expect("JOINT_RANGES") + head.len();
    let rows = &flat[at..at + flat[at..].find("];").unwrap()];
    assert_eq!(rows.matches("Some(").count(), 6, "{rows}");
    assert_eq!(rows.matches("None").count(), 1, "{rows}");
    assert!(
        rows.trim_end_matches(',').ends_with("None"),
        "joint 7 last: {rows}"
    );
    assert!(rows.starts_with("Some([-2.8973f64,2.8973f64])"), "{rows}");
    assert!(
        !flat.contains("pubconstJOINT_LIMITS"),
        "JOINT_LIMITS needs every joint's limits"
    );
}

/// Item 7: joint limits in TOML follow the number rule (±1e300 were emitted as 301-digit
/// literals).
#[test]
fn toml_limits_follow_the_number_rule() {
    let dir = scratch("toml-limits");
    let text = std::fs::read_to_string(robots().join("bidirectional-zy.toml")).unwrap();
    let at = text.find("axis = ").unwrap();
    let at = at + text[at..].find('\n').unwrap() + 1;
    for (limits, why) in [
        ("[-1e300, 1e300]", "beyond"),
        ("[0, 1e-320]", "subnormal"),
        ("[0.5, -0.5]", "lower < upper"),
    ] {
        let edited = format!("{}limits = {limits}\n{}", &text[..at], &text[at..]);
        std::fs::write(dir.join("r.toml"), edited).unwrap();
        let (code, _, err) = trocar_in(&dir, &["generate", "r.toml"]);
        assert_eq!(code, 1, "{limits}: {err}");
        assert!(
            err.contains("r.toml:") && err.contains("joints[0].limits") && err.contains(why),
            "{limits}: {err}"
        );
    }
}

/// A trocar beyond the instrument's tip is refused at the values `--param` gives, not only at
/// the nominal ones.
#[test]
fn a_parameter_value_puts_the_trocar_outside_the_instrument() {
    let dir = scratch("param-trocar");
    let q = "0,-0.3,0,-2.2,0,2.0,0.8";
    let (code, _, err) = trocar_in(
        &dir,
        &[
            "eval",
            "panda-laparoscope",
            "--q",
            q,
            "--param",
            "l_a=0.45",
            "--numeric",
        ],
    );
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--param: l_a=0.45") && err.contains("outside the instrument"),
        "{err}"
    );
    let (code, _, err) = trocar_in(
        &dir,
        &[
            "eval",
            "panda-laparoscope",
            "--q",
            q,
            "--param",
            "l_a=0.3",
            "--numeric",
        ],
    );
    assert_eq!(code, 0, "{err}");
}

/// `generate --fma-at-run-time`: the fused functions' `f64` entry points in the module; with
/// `--real f64` a one-line refusal and no file.
#[test]
fn fma_at_run_time_in_generate() {
    let dir = scratch("fma-at-run-time");
    let (code, out, err) = trocar_in(&dir, &["generate", "dia10_like_zy", "--fma-at-run-time"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("pub fn pose_and_jacobian_f64("), "{out}");
    assert!(
        out.contains("pub fn link_pose_and_jacobian_trig_f64("),
        "{out}"
    );
    // The C header: each fused function's outputs one after the other, FMA chosen at run time.
    let (code, h, err) = trocar_in(
        &dir,
        &[
            "generate",
            "dia10_like_zy",
            "--fma-at-run-time",
            "--c-header",
            "-",
        ],
    );
    assert_eq!(code, 0, "{err}");
    for line in [
        "#define DIA10_LIKE_ZY_POSE_AND_JACOBIAN_LEN 60",
        "#define DIA10_LIKE_ZY_POSE_AND_JACOBIAN_FK_OFFSET 0",
        "#define DIA10_LIKE_ZY_POSE_AND_JACOBIAN_JB0E_OFFSET 12",
        "int dia10_like_zy_link_pose_and_jacobian(const double *q, const double *params, double *out);",
        "Fused multiply-adds are chosen at run time",
    ] {
        assert!(h.contains(line), "{line} missing from\n{h}");
    }
    let (code, _, err) = trocar_in(
        &dir,
        &[
            "generate",
            "dia10_like_zy",
            "--real",
            "f64",
            "--fma-at-run-time",
            "-o",
            "m.rs",
        ],
    );
    assert_ne!(code, 0);
    assert!(
        err.contains("fma_at_run_time needs a module generic over the scalar (real = generic), not real = f64"),
        "{err}"
    );
    assert!(names_in(&dir).is_empty(), "{:?}", names_in(&dir));
}
