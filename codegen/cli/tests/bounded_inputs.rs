//! Issue 27, items 5, 6 and 8: bounded work and inputs, and names that cannot be ambiguous. Each
//! input used to crash (a stack overflow), run for minutes, or be silently misread; now it is a
//! clear error, located where the description writes it, given quickly.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `trocar args…` in `dir`; returns its output.
fn trocar(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the trocar binary runs")
}

/// A fresh empty directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("bounded-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots")
}

/// The command fails with exit code 1 and a message containing every one of `expected`. (That
/// the refusal does no unbounded work first is shown by the inputs: each used to run for minutes
/// or crash; how long the refusal takes is not asserted here.)
fn refused(args: &[&str], dir: &Path, expected: &[&str]) {
    let out = trocar(args, dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {out:?}");
    assert!(!err.contains("panicked"), "{err}");
    for e in expected {
        assert!(err.contains(e), "{args:?}: `{e}` not in: {err}");
    }
}

/// The four-bar linkage with its first chain's tip at `x`.
fn four_bar_tip(dir: &Path, x: &str) -> &'static str {
    let text = std::fs::read_to_string(robots().join("mechanisms/four-bar.toml")).unwrap();
    let from = r#"tip = { x = "l3 + l4" }"#;
    assert!(text.contains(from));
    std::fs::write(
        dir.join("m.toml"),
        text.replacen(from, &format!(r#"tip = {{ x = "{x}" }}"#), 1),
    )
    .unwrap();
    "m.toml"
}

/// `l3^30000` overflowed the stack (abort); `(l3-l3+1)^2147483647` and `pi^-2000` ran for
/// minutes: exponents are at most 64 in magnitude, the error at the file's line.
#[test]
fn large_exponents_are_refused_where_written() {
    let dir = scratch("exponent");
    for x in [
        "l3^30000",
        "(l3-l3+1)^2147483647",
        "pi^-2000",
        "l3^99999999999999999999",
    ] {
        let m = four_bar_tip(&dir, x);
        for cmd in [
            &["generate", m][..],
            &["eval", m, "--q", "1,1,1,1", "--what", "jr"],
        ] {
            refused(
                cmd,
                &dir,
                &["m.toml:", "chains[0].tip.x", "exponent", "at most 64"],
            );
        }
    }
    // The largest exponent allowed works.
    let m = four_bar_tip(&dir, "l3^64 + l4");
    let out = trocar(&["generate", m], &dir);
    assert!(out.status.success(), "{out:?}");
}

/// `(l3+l4+l1+l2)^30` expanded to 5456 terms that the derivation multiplied for minutes.
#[test]
fn lengths_of_many_terms_are_refused() {
    let dir = scratch("terms");
    // Of value 1 with the nominal parameters: only its expansion is large.
    let m = four_bar_tip(&dir, "((l3+l4+l1+l2)/4.6)^30");
    refused(
        &["generate", m],
        &dir,
        &["chains[0].tip.x", "5456 terms", "at most 64"],
    );
}

/// A planar platform of `legs` legs (revolute, prismatic, revolute), three of them actuated:
/// `J_Cp` is square, of size 3 (legs − 1).
fn platform(legs: usize) -> String {
    let mut s =
        format!("name = \"p{legs}\"\noutputs = [\"x\", \"y\", \"phi\"]\n[parameters]\nl = 5.0\n");
    for k in 0..legs {
        let a = std::f64::consts::TAU * k as f64 / legs as f64;
        s += &format!(
            "[[chains]]\nname = \"leg{k}\"\nbase = {{ x = \"{:.3}\", y = \"{:.3}\" }}\n\
             tip = {{ x = \"l\", angle = \"{:.4}\" }}\n\
             [[chains.joints]]\nname = \"t{k}a\"\ntype = \"revolute\"\ninitial = {:.3}\n\
             [[chains.joints]]\nname = \"d{k}\"\ntype = \"prismatic\"\naxis = [1.0, 0.0]\n{}initial = 15.0\n\
             [[chains.joints]]\nname = \"t{k}b\"\ntype = \"revolute\"\ninitial = 0.1\n",
            20.0 * a.cos(),
            20.0 * a.sin(),
            -a,
            a + std::f64::consts::PI,
            if k < 3 { "active = true\n" } else { "" }
        );
    }
    s
}

/// Seven legs ran past 20 s, eight said "J_Cp: exponent or index overflow": the closed forms
/// are derived for at most 15 passive joints. Four legs still work.
#[test]
fn large_mechanisms_are_refused_quickly() {
    let dir = scratch("legs");
    std::fs::write(dir.join("p4.toml"), platform(4)).unwrap();
    let out = trocar(&["generate", "p4.toml"], &dir);
    assert!(out.status.success(), "{out:?}");
    for legs in [7, 8] {
        let file = format!("p{legs}.toml");
        std::fs::write(dir.join(&file), platform(legs)).unwrap();
        let size = format!("J_Cp is {0} × {0}", 3 * (legs - 1));
        refused(
            &["generate", &file],
            &dir,
            &[&file, "`chains`", &size, "at most 15"],
        );
    }
}

/// A description is read up to 16 MiB: `/dev/zero` used to be read without end.
#[cfg(unix)]
#[test]
fn input_files_are_read_up_to_16_mib() {
    let dir = scratch("size");
    refused(
        &["eval", "/dev/zero", "--q", "0"],
        &dir,
        &["/dev/zero", "larger than 16 MiB"],
    );
    let mut big = std::fs::read_to_string(robots().join("unidirectional.toml")).unwrap();
    big += &"#".repeat(17 << 20);
    std::fs::write(dir.join("big.toml"), big).unwrap();
    refused(
        &["generate", "big.toml"],
        &dir,
        &["big.toml", "larger than 16 MiB"],
    );
}

/// At most 64 joints, in a serial description and in a mechanism.
#[test]
fn at_most_64_joints() {
    let dir = scratch("joints");
    let text = std::fs::read_to_string(robots().join("unidirectional.toml")).unwrap();
    let joint = "\n[[joints]]\nname = \"extra\"\ntype = \"revolute\"\nxyz = [0, 0, 0.1]\naxis = [0, 0, 1]\n";
    let at = text.find("[[joints]]").unwrap();
    let many = format!("{}{}{}", &text[..at], joint.repeat(60), &text[at..]);
    std::fs::write(dir.join("many.toml"), many).unwrap();
    refused(
        &["generate", "many.toml"],
        &dir,
        &["many.toml", "joints[64]", "68 joints", "at most 64"],
    );
    let mut chain = String::from("name = \"long\"\noutputs = []\n[[chains]]\nname = \"c\"\n");
    for k in 0..70 {
        chain += &format!("[[chains.joints]]\nname = \"j{k}\"\ntype = \"revolute\"\n");
    }
    std::fs::write(dir.join("long.toml"), chain).unwrap();
    refused(
        &["eval", "long.toml", "--q", "0", "--numeric"],
        &dir,
        &["long.toml", "chains[0].joints[64]", "at most 64"],
    );
}

/// `verify --samples` is at most 10⁷, refused before the closed forms are derived.
#[test]
fn verify_samples_are_bounded() {
    let dir = scratch("samples");
    refused(
        &["verify", "no-such-robot", "--samples", "10000001"],
        &dir,
        &["--samples: 10000001", "at most 10000000"],
    );
}

/// Item 8: a parameter named `pi` was silently shadowed by π in every expression; `--q` given
/// twice concatenated the two lists (a duplicate `--param` is refused already).
#[test]
fn ambiguous_names_and_options_are_refused() {
    let dir = scratch("names");
    let text = std::fs::read_to_string(robots().join("unidirectional.toml")).unwrap();
    let with_pi = text.replacen("l_b = 0.18", "pi = 0.18\nl_b = 0.18", 1);
    assert_ne!(with_pi, text);
    std::fs::write(dir.join("pi.toml"), with_pi).unwrap();
    refused(
        &["eval", "pi.toml", "--q", "0,0,0,0,0,0,0,0", "--numeric"],
        &dir,
        &["pi.toml:", "parameters.pi", "constant π"],
    );
    let out = trocar(
        &[
            "eval",
            "unidirectional",
            "--q",
            "0.1,0.2,0.3,0.1",
            "--q",
            "0.2,0.3,0.1,0.1",
            "--numeric",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("--q"));
    let q = "0.1,0.2,0.3,0.1,0.2,0.3,0.1,0.1";
    refused(
        &[
            "eval",
            "unidirectional",
            "--q",
            q,
            "--param",
            "l_a=0.1",
            "--param",
            "l_a=0.2",
        ],
        &dir,
        &["l_a", "given twice"],
    );
}

/// Item 7 (mechanisms): the number rule for a mechanism's parameters, initial values, limits
/// and expression constants. `x = "l3*1e40"` with `--real f32` emitted `1e40_f32`, which does not
/// compile; a parameter of 1e40 or an initial value of 1e300 was accepted.
#[test]
fn mechanism_numbers_follow_the_number_rule() {
    let dir = scratch("number-rule");
    let text = std::fs::read_to_string(robots().join("mechanisms/four-bar.toml")).unwrap();
    for (from, to, field) in [
        (
            r#"tip = { x = "l3 + l4" }"#,
            r#"tip = { x = "l3*1e40" }"#,
            "chains[0].tip.x",
        ),
        ("l3 = 0.6", "l3 = 1e40", "parameters.l3"),
        (
            "initial = 1.2",
            "initial = 1e300",
            "chains[0].joints[0].initial",
        ),
        (
            "limits = [0.7227, 2.2784]",
            "limits = [0.7227, 1e-320]",
            "chains[0].joints[0].limits[1]",
        ),
        (
            r#"tip = { x = "l3 + l4" }"#,
            r#"tip = { x = "l3*1e5*1e5" }"#,
            "chains[0].tip.x",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        std::fs::write(dir.join("m.toml"), text.replacen(from, to, 1)).unwrap();
        refused(
            &["generate", "m.toml", "--real", "f32"],
            &dir,
            &["m.toml:", field],
        );
    }
}

/// Item 7 (URDF limits): a NaN or reversed `<limit>` was dropped silently (and with it the
/// robot's joint limits); it is an error naming the joint's limit and the URDF line.
#[test]
fn a_bad_urdf_limit_is_an_error() {
    let dir = scratch("urdf-limit");
    std::fs::create_dir(dir.join("urdf")).unwrap();
    std::fs::copy(
        robots().join("panda-laparoscope.toml"),
        dir.join("panda-laparoscope.toml"),
    )
    .unwrap();
    let urdf = std::fs::read_to_string(robots().join("urdf/panda.urdf")).unwrap();
    let at = urdf.find("lower=\"").expect("a limit") + "lower=\"".len();
    let end = at + urdf[at..].find('"').unwrap();
    for bad in ["nan", "1e300", "5"] {
        let text = format!("{}{bad}{}", &urdf[..at], &urdf[end..]);
        std::fs::write(dir.join("urdf/panda.urdf"), text).unwrap();
        refused(
            &["generate", "panda-laparoscope.toml"],
            &dir,
            &["panda.urdf", "limit"],
        );
    }
    std::fs::write(dir.join("urdf/panda.urdf"), urdf).unwrap();
    let out = trocar(&["generate", "panda-laparoscope.toml"], &dir);
    assert!(out.status.success(), "{out:?}");
}
