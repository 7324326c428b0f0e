//! The inline forms of `#[constrained_robot]`: the structured one and `toml = "..."`, both the
//! bidirectional-zy preset written out; they agree with the preset.
//!
//! Run: `cargo run --example derive_inline` (from the workspace root).

use trocar_derive::constrained_robot;
use trocar_examples::{print_matrix, Q0};

#[constrained_robot(
    name = "inline_zy",
    params(l_a = 0.15, l_b = 0.18, l_8 = 0.21),
    joints(
        torso: revolute(z),
        shoulder_pitch: revolute(x, xyz = (0.194, 0, 1.037)),
        elbow_pitch: revolute(x, xyz = (0, 0.38, 0)),
        forearm_roll: revolute(y),
        wrist_pitch: revolute(x, xyz = (0, 0.39, 0)),
        wrist_roll: revolute(y),
        shaft_7: revolute(z, xyz = (0, l_a + l_b, 0)),
        shaft_8: revolute(y),
    ),
    end_effector(name = "tool", xyz = (0, l_8, 0)),
    constraint(link = 6, xyz = (0, l_a, 0), h = (x, z), wrist = zy),
    real = "f64",
)]
struct Structured;

#[constrained_robot(toml = r#"
    [robot]
    name = "toml_zy"
    [parameters]
    l_a = 0.15
    l_b = 0.18
    l_8 = 0.21
    [[joints]]
    name = "torso"
    type = "revolute"
    axis = [0, 0, 1]
    [[joints]]
    name = "shoulder_pitch"
    type = "revolute"
    xyz = [0.194, 0, 1.037]
    axis = [1, 0, 0]
    [[joints]]
    name = "elbow_pitch"
    type = "revolute"
    xyz = [0, 0.38, 0]
    axis = [1, 0, 0]
    [[joints]]
    name = "forearm_roll"
    type = "revolute"
    axis = [0, 1, 0]
    [[joints]]
    name = "wrist_pitch"
    type = "revolute"
    xyz = [0, 0.39, 0]
    axis = [1, 0, 0]
    [[joints]]
    name = "wrist_roll"
    type = "revolute"
    axis = [0, 1, 0]
    [[joints]]
    name = "shaft_7"
    type = "revolute"
    xyz = [0, "l_a + l_b", 0]
    axis = [0, 0, 1]
    [[joints]]
    name = "shaft_8"
    type = "revolute"
    axis = [0, 1, 0]
    [end_effector]
    xyz = [0, "l_8", 0]
    [constraint]
    link = 6
    xyz = [0, "l_a", 0]
    h = ["x", "z"]
    wrist = "zy"
"#)]
struct Toml;

#[constrained_robot(preset = "bidirectional-zy", real = "f64")]
struct Preset;

fn main() {
    let p = Structured::nominal_params();
    let a = Structured::constrained_jacobian(&Q0, &p);
    print_matrix("structured inline form: J^r", &a);
    println!("  w = {:.6}", Structured::manipulability(&Q0, &p));

    let b = Toml::constrained_jacobian(&Q0, &Toml::nominal_params());
    let c = Preset::constrained_jacobian(&Q0, &Preset::nominal_params());
    let diff = |x: &[[f64; 6]; 6], y: &[[f64; 6]; 6]| {
        x.iter()
            .flatten()
            .zip(y.iter().flatten())
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max)
    };
    println!(
        "max |structured − preset| = {:.1e}, max |toml − preset| = {:.1e}",
        diff(&a, &c),
        diff(&b, &c)
    );
    assert!(diff(&a, &c) < 1e-12 && diff(&b, &c) < 1e-12);
}
