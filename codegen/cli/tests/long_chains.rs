//! Long and generic chains: the derivation keeps them as an expression graph (shared
//! subexpressions) and float geometry floating, so a 30-joint chain or a 9-joint chain with
//! oblique float axes and an explicit `H` generates in well under a second (release build;
//! BENCHMARKS.md has the times) instead of minutes, and `verify` checks the generated
//! expressions against the numeric runtime and finite differences at 200 configurations.

use std::path::PathBuf;

mod common;

/// A chain of `n` revolute joints with the constraint (`H` as given) at `link`.
fn chain(
    name: &str,
    n: usize,
    link: usize,
    h: &str,
    joint: impl Fn(usize) -> ([f64; 3], [f64; 3]),
) -> String {
    let mut s = format!("[robot]\nname = \"{name}\"\n\n[parameters]\nl_a = 0.11\n\n");
    for k in 0..n {
        let (xyz, axis) = joint(k);
        s += &format!(
            "[[joints]]\nname = \"j{}\"\ntype = \"revolute\"\nxyz = {xyz:?}\naxis = {axis:?}\n\n",
            k + 1
        );
    }
    s + &format!(
        "[end_effector]\nname = \"tool\"\nxyz = [0, 0.09, 0]\n\n[constraint]\nlink = {link}\nxyz = [0, \"l_a\", 0]\nh = {h}\n"
    )
}

/// Oblique unit axes and offsets with 17 significant digits, as a calibrated URDF has them.
fn oblique(k: usize) -> ([f64; 3], [f64; 3]) {
    let t = k as f64 + 1.0;
    let a = [(0.7 * t).sin(), (1.3 * t).cos(), (0.4 * t + 0.5).sin()];
    let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    (
        [
            0.02 * (2.1 * t).sin(),
            0.1 + 0.03 * (1.7 * t).cos(),
            0.02 * (0.9 * t).sin(),
        ],
        [a[0] / norm, a[1] / norm, a[2] / norm],
    )
}

/// Axes x, y, z in turn, 0.1 m apart along y.
fn aligned(k: usize) -> ([f64; 3], [f64; 3]) {
    let axes = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
    ([0.01 * (k % 3) as f64, 0.1, 0.0], axes[k % 3])
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("long-chains");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn verify(path: &std::path::Path) {
    let (code, text, err) = common::trocar(&["verify", path.to_str().unwrap(), "--samples", "200"]);
    assert_eq!(code, 0, "{text}\n{err}");
    assert!(text.contains("all checks passed"), "{text}");
    for check in [
        "fk:",
        "jr:",
        "jc:",
        "manip:",
        "jb0i: generated vs finite differences",
    ] {
        assert!(text.contains(check), "no `{check}` row: {text}");
    }
}

#[test]
fn a_nine_joint_oblique_float_chain_with_explicit_h_verifies() {
    let h = "[[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]";
    verify(&write("oblique9", &chain("oblique9", 9, 6, h, oblique)));
}

#[test]
fn a_thirty_joint_chain_constrained_at_link_15_verifies() {
    verify(&write(
        "a30",
        &chain("a30", 30, 15, "[\"x\", \"z\"]", aligned),
    ));
}

#[test]
fn a_twenty_four_joint_oblique_chain_generates_a_whole_module() {
    let h = "[[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]";
    let path = write("oblique24", &chain("oblique24", 24, 12, h, oblique));
    let (status, code, err) = common::trocar(&["generate", path.to_str().unwrap()]);
    assert_eq!(status, 0, "{err}");
    for f in [
        "pub fn constrained_jacobian",
        "pub fn manipulability",
        "pub fn forward_kinematics",
    ] {
        assert!(code.contains(f), "no `{f}`");
    }
    // Floating geometry: no literal longer than an f64's shortest representation.
    assert!(
        !code.contains("0000000000000000000000"),
        "a long literal in the module"
    );
}
