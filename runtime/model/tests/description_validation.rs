//! One bad input per validation rule: the error names the field, and — the input being a file —
//! the line (and column) where it is written.

use std::path::Path;
use trocar_model::description::{
    preset, DescriptionError, JointKind, Location, Parameter, RobotDescription, Rotation,
};

/// A shipped description without its end-of-line comments (so that edits can match whole lines).
fn shipped(name: &str) -> String {
    preset(name)
        .unwrap()
        .lines()
        .map(|l| match l.find(" #") {
            Some(k) if !l.starts_with('#') => l[..k].trim_end(),
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// The shipped `bidirectional-zy` description: 8 joints, constraint on link 6, H = (x_r, z_r).
fn base() -> String {
    shipped("bidirectional-zy")
}

fn unidirectional() -> String {
    shipped("unidirectional")
}

/// Replaces the first `from` after the line `name = "joint"`.
fn in_joint(text: &str, joint: &str, from: &str, to: &str) -> String {
    let at = text.find(&format!("name = \"{joint}\"")).expect("joint");
    let k = at + text[at..].find(from).expect("pattern in joint");
    format!("{}{}{}", &text[..k], to, &text[k + from.len()..])
}

fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not in the text");
    text.replacen(from, to, 1)
}

/// 1-based line of the first occurrence of `needle` (after `after`, when given).
fn line_of(text: &str, needle: &str, after: Option<&str>) -> usize {
    let start = after.map_or(0, |a| text.find(a).expect("anchor"));
    let k = start + text[start..].find(needle).expect("needle");
    text[..k].matches('\n').count() + 1
}

fn fail(text: &str) -> DescriptionError {
    match RobotDescription::from_toml_str(text, Some(Path::new("robot.toml"))) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts the error's field, its line (that of `needle`, after `after`), a message fragment, and
/// that the display names file, line and field.
fn expect(
    text: &str,
    field: &str,
    needle: (&str, Option<&str>),
    message: &str,
) -> DescriptionError {
    let e = fail(text);
    assert_eq!(e.field, field, "{e}");
    assert_eq!(e.line, Some(line_of(text, needle.0, needle.1)), "{e}");
    assert!(e.column.is_some(), "{e}");
    assert!(e.message.contains(message), "`{message}` not in: {e}");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("robot.toml:{}:", e.line.unwrap())),
        "{shown}"
    );
    assert!(shown.contains(&format!("field `{field}`: ")), "{shown}");
    e
}

#[test]
fn the_base_descriptions_are_valid() {
    RobotDescription::from_toml_str(&base(), None).unwrap();
    RobotDescription::from_toml_str(&unidirectional(), None).unwrap();
}

#[test]
fn display_format() {
    let e = DescriptionError {
        file: Some("r.toml".into()),
        line: Some(3),
        column: Some(7),
        field: "joints[3].axis".into(),
        message: "bad".into(),
    };
    assert_eq!(e.to_string(), "r.toml:3:7: field `joints[3].axis`: bad");
}

// ---- bad TOML, unknown and missing keys ----

#[test]
fn syntax_error_has_a_position() {
    let text = replace_once(&base(), "axis = [0, 0, 1]", "axis = [0, 0, 1");
    let e = fail(&text);
    assert_eq!(e.field, "(document)", "{e}");
    assert!(e.message.contains("not valid TOML"), "{e}");
    // Where the parser notices the missing `]`: the next token, after a blank line.
    assert_eq!(
        e.line,
        Some(line_of(&text, "axis = [0, 0, 1\n", None) + 2),
        "{e}"
    );
    let e = fail("[robot\nname = 1");
    assert_eq!(e.field, "(document)", "{e}");
    assert_eq!(e.line, Some(1), "{e}");
    assert!(e.line.is_some() && e.column.is_some(), "{e}");
}

#[test]
fn unknown_key_names_key_and_table() {
    let text = in_joint(&base(), "elbow_pitch", "axis =", "axes = [1, 0, 0]\naxis =");
    let e = expect(
        &text,
        "joints[2].axes",
        ("axes", None),
        "unknown key `axes` in table `joints[2]`",
    );
    assert!(e.message.contains("expected one of"), "{e}");
    let text = replace_once(&base(), "wrist = \"zy\"", "wrist = \"zy\"\nlenght = 3");
    expect(
        &text,
        "constraint.lenght",
        ("lenght", None),
        "unknown key `lenght` in table `constraint`",
    );
    let text = replace_once(
        &base(),
        "[end_effector]",
        "[extra]\na = 1\n\n[end_effector]",
    );
    expect(
        &text,
        "extra",
        ("extra", None),
        "unknown key `extra` at the top level",
    );
    let text = replace_once(
        &base(),
        "name = \"tool\"",
        "name = \"tool\"\nypr = [0, 0, 0]",
    );
    expect(
        &text,
        "end_effector.ypr",
        ("ypr", None),
        "in table `end_effector`",
    );
}

#[test]
fn missing_key_names_key_and_table() {
    let text = in_joint(&base(), "elbow_pitch", "type = \"revolute\"\n", "");
    let e = fail(&text);
    assert_eq!(e.field, "joints[2].type", "{e}");
    assert!(e.message.contains("missing key `type`"), "{e}");
    let text = replace_once(&base(), "h = [\"x\", \"z\"]\n", "");
    let e = fail(&text);
    assert_eq!(e.field, "constraint.h", "{e}");
    assert!(
        e.message.contains("missing key `h` in table `constraint`"),
        "{e}"
    );
}

#[test]
fn wrong_types_name_the_field() {
    let text = in_joint(
        &base(),
        "elbow_pitch",
        "xyz = [0, 0.38, 0]",
        "xyz = [0, true, 0]",
    );
    expect(
        &text,
        "joints[2].xyz[1]",
        ("true", None),
        "expected a number or a parameter expression",
    );
    let text = in_joint(&base(), "elbow_pitch", "axis = [1, 0, 0]", "axis = [1, 0]");
    expect(&text, "joints[2].axis", ("[1, 0]", None), "length 2");
    let text = replace_once(&base(), "link = 6", "link = -6");
    expect(&text, "constraint.link", ("link = -6", None), "");
    let text = replace_once(&base(), "l_a = 0.15", "l_a = \"long\"");
    expect(
        &text,
        "parameters.l_a",
        ("l_a = ", None),
        "nominal value must be a number",
    );
    let text = in_joint(&base(), "shaft_7", "\"l_a + l_b\"", "\"l_a * l_b\"");
    expect(&text, "joints[6].xyz[1]", ("l_a * l_b", None), "not linear");
    let text = in_joint(&base(), "elbow_pitch", "revolute", "spherical");
    expect(
        &text,
        "joints[2].type",
        ("type", Some("elbow_pitch")),
        "unknown joint type",
    );
}

// ---- axes and twists ----

#[test]
fn zero_axis() {
    let text = in_joint(
        &base(),
        "elbow_pitch",
        "axis = [1, 0, 0]",
        "axis = [0, 0, 0]",
    );
    expect(
        &text,
        "joints[2].axis",
        ("axis", Some("elbow_pitch")),
        "the axis is zero",
    );
}

#[test]
fn non_unit_axis() {
    let text = in_joint(
        &base(),
        "forearm_roll",
        "axis = [0, 1, 0]",
        "axis = [0, 2, 0]",
    );
    let e = expect(
        &text,
        "joints[3].axis",
        ("axis", Some("forearm_roll")),
        "not a unit vector",
    );
    assert!(e.message.contains("write [0, 1, 0]"), "{e}");
    let text = in_joint(
        &base(),
        "torso",
        "type = \"revolute\"",
        "type = \"prismatic\"",
    );
    let text = in_joint(&text, "torso", "axis = [0, 0, 1]", "axis = [0, 0.5, 0.5]");
    expect(
        &text,
        "joints[0].axis",
        ("axis", Some("torso")),
        "not a unit vector",
    );
}

#[test]
fn twists() {
    let twist = |v: &str, w: &str| {
        in_joint(
            &base(),
            "torso",
            "type = \"revolute\"\nxyz = [0, 0, 0]\naxis = [0, 0, 1]",
            &format!("type = \"twist\"\nxyz = [0, 0, 0]\nv = {v}\nw = {w}"),
        )
    };
    // Valid: a revolute twist with a parametric moment, and a unit prismatic twist.
    RobotDescription::from_toml_str(&twist("[\"l_a\", 0, 0]", "[0, 0, 1]"), None).unwrap();
    RobotDescription::from_toml_str(&twist("[0, 1, 0]", "[0, 0, 0]"), None).unwrap();
    RobotDescription::from_toml_str(&twist("[0, \"l_a\", 0]", "[0, 0, 0]"), None).unwrap();
    let text = twist("[0, 0, 0]", "[0, 0, 2]");
    expect(&text, "joints[0].w", ("w = ", None), "‖ω‖ = 1");
    let text = twist("[0, 3, 0]", "[0, 0, 0]");
    expect(&text, "joints[0].v", ("v = ", None), "needs ‖v‖ = 1");
    let text = twist("[0, 0, 0]", "[0, 0, 0]");
    expect(&text, "joints[0].v", ("v = ", None), "needs ‖v‖ = 1");
    let text = twist("[\"l_q\", 0, 0]", "[0, 0, 1]");
    expect(
        &text,
        "joints[0].v[0]",
        ("\"l_q\"", None),
        "unknown parameter `l_q`",
    );
    let text = in_joint(&base(), "torso", "xyz", "v = [0, 0, 0]\nxyz");
    expect(
        &text,
        "joints[0].v",
        ("v = ", None),
        "has an `axis`, not a twist",
    );
}

// ---- rotations ----

#[test]
fn rotation_not_orthonormal() {
    let text = in_joint(
        &base(),
        "wrist_pitch",
        "axis",
        "rotation = [[1, 0, 0], [0, 1, 0.1], [0, 0, 1]]\naxis",
    );
    expect(
        &text,
        "joints[4].rotation",
        ("rotation", Some("wrist_pitch")),
        "not orthonormal",
    );
}

#[test]
fn rotation_with_determinant_minus_one() {
    let text = replace_once(
        &base(),
        "xyz = [0, \"l_8\", 0]",
        "xyz = [0, \"l_8\", 0]\nrotation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]",
    );
    expect(
        &text,
        "end_effector.rotation",
        ("rotation", None),
        "det R = -1",
    );
}

#[test]
fn rpy_and_rotation_together() {
    let text = in_joint(
        &base(),
        "wrist_pitch",
        "axis",
        "rpy = [0, 0, 0]\nrotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\naxis",
    );
    expect(
        &text,
        "joints[4].rotation",
        ("rotation", Some("wrist_pitch")),
        "not both",
    );
}

// ---- non-finite numbers ----

#[test]
fn non_finite_numbers() {
    let text = in_joint(
        &base(),
        "elbow_pitch",
        "axis = [1, 0, 0]",
        "axis = [1, 0, nan]",
    );
    expect(
        &text,
        "joints[2].axis",
        ("axis", Some("elbow_pitch")),
        "finite",
    );
    let text = in_joint(&base(), "elbow_pitch", "xyz", "rpy = [inf, 0, 0]\nxyz");
    expect(&text, "joints[2].rpy", ("rpy", None), "finite");
    let text = in_joint(&base(), "elbow_pitch", "0.38", "-inf");
    expect(&text, "joints[2].xyz[1]", ("-inf", None), "finite");
    let text = replace_once(&base(), "l_b = 0.18", "l_b = nan");
    expect(&text, "parameters.l_b", ("l_b = nan", None), "finite");
    let text = replace_once(
        &base(),
        "h = [\"x\", \"z\"]",
        "h = [[1, 0, 0, 0, 0, 0], [0, 0, inf, 0, 0, 0]]",
    );
    expect(&text, "constraint.h[1]", ("[0, 0, inf", None), "finite");
    let text = in_joint(&base(), "shaft_7", "\"l_a + l_b\"", "\"1e999*l_a\"");
    expect(&text, "joints[6].xyz[1]", ("1e999", None), "finite");
}

// ---- parameters ----

#[test]
fn unknown_parameter() {
    let text = in_joint(&base(), "shaft_7", "\"l_a + l_b\"", "\"l_a + l_q\"");
    let e = expect(
        &text,
        "joints[6].xyz[1]",
        ("l_a + l_q", None),
        "unknown parameter `l_q`",
    );
    assert!(e.message.contains("declared: l_a, l_b, l_8"), "{e}");
    let text = replace_once(&base(), "xyz = [0, \"l_8\", 0]", "xyz = [0, \"l_9\", 0]");
    expect(
        &text,
        "end_effector.xyz[1]",
        ("\"l_9\"", None),
        "unknown parameter `l_9`",
    );
    let text = replace_once(
        &base(),
        "xyz = [0, \"l_a\", 0]",
        "xyz = [\"l_z\", \"l_a\", 0]",
    );
    let e = fail(&text);
    assert_eq!(e.field, "constraint.xyz[0]", "{e}");
    assert_eq!(e.line, Some(line_of(&text, "\"l_z\"", None)));
}

#[test]
fn parameter_names_are_identifiers() {
    let text = replace_once(&base(), "l_8 = 0.21", "l_8 = 0.21\n\"2nd\" = 1.0");
    expect(
        &text,
        "parameters.2nd",
        ("\"2nd\"", None),
        "not an identifier",
    );
    let text = replace_once(&base(), "l_8 = 0.21", "l_8 = 0.21\ntype = 1.0");
    expect(
        &text,
        "parameters.type",
        ("type = 1.0", None),
        "Rust keyword",
    );
}

#[test]
fn duplicate_parameter_names() {
    // In TOML a duplicate key is a syntax error, at the second key.
    let text = replace_once(&base(), "l_8 = 0.21", "l_8 = 0.21\nl_a = 0.2");
    let e = fail(&text);
    assert_eq!(e.field, "parameters.l_a", "{e}");
    assert!(e.message.contains("duplicate key `l_a`"), "{e}");
    assert!(e.line.is_some());
    // Built in code.
    let mut d = RobotDescription::from_toml_str(&base(), None).unwrap();
    d.parameters.push(Parameter {
        name: "l_a".into(),
        value: 0.2,
    });
    let e = d.validate().unwrap_err();
    assert_eq!(e.field, "parameters.l_a");
    assert!(e.message.contains("declared twice"), "{e}");
}

#[test]
fn duplicate_joint_names() {
    let text = in_joint(
        &base(),
        "shaft_8",
        "name = \"shaft_8\"",
        "name = \"shaft_7\"",
    );
    // The second `shaft_7`.
    let second = text.rfind("name = \"shaft_7\"").unwrap();
    let e = fail(&text);
    assert_eq!(e.field, "joints[7].name", "{e}");
    assert_eq!(e.line, Some(text[..second].matches('\n').count() + 1));
    assert!(e.message.contains("already used by joints[6]"), "{e}");
}

// ---- the constraint ----

#[test]
fn h_row_of_wrong_width() {
    let text = replace_once(
        &base(),
        "h = [\"x\", \"z\"]",
        "h = [[1, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0]]",
    );
    expect(
        &text,
        "constraint.h[1]",
        ("[0, 0, 1, 0, 0]", None),
        "this one has 5",
    );
}

#[test]
fn h_unknown_letter_or_mixed_rows() {
    let text = replace_once(&base(), "h = [\"x\", \"z\"]", "h = [\"x\", \"w\"]");
    expect(
        &text,
        "constraint.h[1]",
        ("\"w\"", None),
        "unknown axis `w`",
    );
    let text = replace_once(
        &base(),
        "h = [\"x\", \"z\"]",
        "h = [\"x\", [0, 0, 1, 0, 0, 0]]",
    );
    expect(&text, "constraint.h", ("h = ", None), "axis letters");
}

#[test]
fn h_dependent_rows() {
    let text = replace_once(&base(), "wrist = \"zy\"\n", "");
    let text = replace_once(
        &text,
        "h = [\"x\", \"z\"]",
        "h = [[1, 0, 0, 0, 0, 1], [0, 0, 1, 0, 0, 0], [2, 0, 3, 0, 0, 2]]",
    );
    expect(
        &text,
        "constraint.h[2]",
        ("[2, 0, 3", None),
        "linear combination",
    );
    let text = replace_once(&unidirectional(), "h = [\"x\"]", "h = [\"x\", \"x\"]");
    expect(
        &text,
        "constraint.h[1]",
        ("\"x\"]", None),
        "linear combination",
    );
}

#[test]
fn h_zero_row() {
    let text = replace_once(
        &base(),
        "h = [\"x\", \"z\"]",
        "h = [[1, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]]",
    );
    expect(
        &text,
        "constraint.h[1]",
        ("[0, 0, 0, 0, 0, 0]", None),
        "zero",
    );
}

#[test]
fn h_empty() {
    let text = replace_once(&base(), "h = [\"x\", \"z\"]", "h = []");
    expect(&text, "constraint.h", ("h = []", None), "at least one row");
}

#[test]
fn h_more_than_five_rows() {
    let text = replace_once(&base(), "wrist = \"zy\"\n", "");
    let text = replace_once(
        &text,
        "h = [\"x\", \"z\"]",
        "h = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"]",
    );
    expect(&text, "constraint.h", ("h = ", None), "at most 5");
}

#[test]
fn n_minus_r_below_six() {
    // Remove the torso: n = 7 joints, r = 2 rows.
    let text = base();
    let start = text.find("[[joints]]").unwrap();
    let end = start + 1 + text[start + 1..].find("[[joints]]").unwrap();
    let text = format!("{}{}", &text[..start], &text[end..]);
    let text = replace_once(&text, "link = 6", "link = 5");
    let e = expect(&text, "constraint.h", ("h = ", None), "requires n − r ≥ t");
    assert!(e.message.contains("n = 7, r = 2"), "{e}");
}

#[test]
fn constrained_link_out_of_range() {
    for link in ["0", "9", "1000"] {
        let text = replace_once(&base(), "link = 6", &format!("link = {link}"));
        let e = expect(&text, "constraint.link", ("link = ", None), "1 ≤ i ≤ n = 8");
        assert!(
            e.message.contains(&format!("constrained link {link}")),
            "{e}"
        );
    }
    // The last link is a link, but with the whole twist as the task J^r has too few columns.
    let text = replace_once(&base(), "link = 6", "link = 8");
    let d = RobotDescription::from_toml_str_unvalidated(&text, None).unwrap();
    let problems = d.problems();
    assert!(
        problems.iter().any(|p| p.field == "constraint.link"
            && p.message.contains("= 4 columns")
            && p.message.contains("t = 6")),
        "{problems:?}"
    );
}

#[test]
fn wrist_inconsistent_with_h() {
    let text = replace_once(&base(), "h = [\"x\", \"z\"]", "h = [\"x\"]");
    expect(
        &text,
        "constraint.wrist",
        ("wrist = ", None),
        "needs H = (x_r, z_r)",
    );
    let text = replace_once(&base(), "h = [\"x\", \"z\"]", "h = [\"z\", \"x\"]");
    expect(
        &text,
        "constraint.wrist",
        ("wrist = ", None),
        "needs H = (x_r, z_r)",
    );
    let text = replace_once(&unidirectional(), "h = [\"x\"]", "h = [\"x\", \"z\"]");
    expect(
        &text,
        "constraint.wrist",
        ("wrist = ", None),
        "needs H = x_r",
    );
    let text = replace_once(&base(), "wrist = \"zy\"", "wrist = \"xy\"");
    expect(
        &text,
        "constraint.wrist",
        ("wrist = ", None),
        "unknown wrist `xy`",
    );
}

#[test]
fn wrist_inconsistent_with_the_joints_after_the_constraint() {
    let text = in_joint(&base(), "shaft_8", "axis = [0, 1, 0]", "axis = [1, 0, 0]");
    let e = expect(
        &text,
        "joints[7].axis",
        ("axis", Some("shaft_8")),
        "revolute about y",
    );
    assert!(e.message.contains("wrist `zy`"), "{e}");
    let zx = shipped("bidirectional-zx");
    let text = in_joint(&zx, "shaft_8", "axis = [1, 0, 0]", "axis = [0, 1, 0]");
    expect(
        &text,
        "joints[7].axis",
        ("axis", Some("shaft_8")),
        "revolute about x",
    );
    let text = in_joint(&base(), "shaft_7", "axis = [0, 0, 1]", "axis = [0, 1, 0]");
    expect(
        &text,
        "joints[6].axis",
        ("axis", Some("shaft_7")),
        "revolute about z",
    );
    let text = in_joint(&base(), "shaft_7", "revolute", "prismatic");
    expect(
        &text,
        "joints[6].axis",
        ("axis", Some("shaft_7")),
        "revolute about z",
    );
    // Constraint on link 7: the wrist would need a joint 9.
    let text = replace_once(&base(), "wrist = \"zy\"", "wrist = \"zy\"");
    let text = replace_once(&text, "link = 6", "link = 7");
    let e = fail(&text);
    assert!(e.message.contains("needs two joints after"), "{e}");
}

#[test]
fn wrist_needs_the_thesis_constraint_frame() {
    let text = replace_once(&base(), "xyz = [0, \"l_a\", 0]", "xyz = [0, 0.15, 0]");
    expect(
        &text,
        "constraint.xyz[1]",
        ("0.15, 0]", Some("[constraint]")),
        "single parameter name",
    );
    let text = replace_once(&base(), "xyz = [0, \"l_a\", 0]", "xyz = [0, \"2*l_a\", 0]");
    expect(
        &text,
        "constraint.xyz[1]",
        ("\"2*l_a\"", None),
        "g_ir = (I, (0, l_a, 0))",
    );
    let text = replace_once(&base(), "xyz = [0, \"l_a\", 0]", "xyz = [0.1, \"l_a\", 0]");
    expect(
        &text,
        "constraint.xyz[0]",
        ("0.1, \"l_a\"", None),
        "must be 0",
    );
    let text = replace_once(
        &base(),
        "xyz = [0, \"l_a\", 0]",
        "xyz = [0, \"l_a\", 0]\nrpy = [0, 0, 0.3]",
    );
    expect(
        &text,
        "constraint.rpy",
        ("rpy", Some("[constraint]")),
        "identity",
    );
    let text = replace_once(&base(), "l_a = 0.15", "l_a = 0");
    expect(
        &text,
        "constraint.xyz[1]",
        ("\"l_a\", 0]", Some("[constraint]")),
        "divides by it",
    );
    // Without a wrist, any g_ir is accepted.
    let text = replace_once(&base(), "wrist = \"zy\"\n", "");
    let text = replace_once(
        &text,
        "xyz = [0, \"l_a\", 0]",
        "xyz = [0.1, 0.15, 0]\nrpy = [0, 0, 0.3]",
    );
    RobotDescription::from_toml_str(&text, None).unwrap();
}

#[test]
fn robot_name_and_joint_count() {
    let text = replace_once(&base(), "name = \"bidirectional_zy\"", "name = \"\"");
    expect(&text, "robot.name", ("name", None), "needs a name");
    let e = fail("[robot]\nname = \"empty\"\n");
    assert_eq!(e.field, "joints");
    let e = fail("[parameters]\nl = 1\n");
    assert_eq!(e.field, "robot");
    assert!(
        e.message.contains("missing key `robot` at the top level"),
        "{e}"
    );
}

#[test]
fn validate_on_a_description_built_in_code() {
    let mut d = RobotDescription::preset("bidirectional-zy").unwrap();
    d.validate().unwrap();
    assert!(d.problems().is_empty());
    d.joints[2].kind = JointKind::Revolute {
        axis: [0.0, 0.0, 0.0],
    };
    d.joints[4].origin.rotation =
        Rotation::Matrix([[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let problems = d.problems();
    assert_eq!(problems.len(), 2);
    assert_eq!(problems[0].field, "joints[2].axis");
    // The joint's recorded location gives the line; the file is the description's source.
    assert_eq!(
        problems[0].line,
        d.joints[2].location.map(|l: Location| l.line)
    );
    assert_eq!(problems[0].file, d.source);
    assert_eq!(problems[1].field, "joints[4].rotation");
    assert_eq!(d.validate().unwrap_err(), problems[0]);
}

#[test]
fn from_toml_file_names_the_file() {
    let dir = std::env::temp_dir().join(format!("trocar-desc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    let text = in_joint(
        &base(),
        "elbow_pitch",
        "axis = [1, 0, 0]",
        "axis = [0, 0, 0]",
    );
    std::fs::write(&path, &text).unwrap();
    let e = RobotDescription::from_toml_file(&path).unwrap_err();
    assert_eq!(e.file.as_deref(), Some(path.as_path()));
    assert!(
        e.to_string().starts_with(&format!(
            "{}:{}:",
            path.display(),
            line_of(&text, "axis", Some("elbow_pitch"))
        )),
        "{e}"
    );
    let e = RobotDescription::from_toml_file(dir.join("missing.toml")).unwrap_err();
    assert!(e.message.contains("cannot read"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every number obeys one rule (`trocar_model::validity`): finite, not subnormal, within ±1e6.
/// `xyz = [0, 0.21, 1e308]` used to be accepted.
#[test]
fn numbers_obey_one_rule() {
    let text = replace_once(&base(), "l_8 = 0.21", "l_8 = 1e308");
    expect(
        &text,
        "parameters.l_8",
        ("l_8 = 1e308", None),
        "beyond ±1e6",
    );
    let text = replace_once(
        &base(),
        "xyz = [0.194, 0, 1.037]",
        "xyz = [0.194, 0, 1e308]",
    );
    expect(
        &text,
        "joints[1].xyz[2]",
        ("xyz = [0.194, 0, 1e308]", None),
        "beyond ±1e6",
    );
    let text = replace_once(&base(), "l_b = 0.18", "l_b = 1e-320");
    expect(&text, "parameters.l_b", ("l_b = 1e-320", None), "subnormal");
}

/// A file that is not UTF-8 is refused with the line, column and byte offset of the first bad
/// byte (it used to say only "stream did not contain valid UTF-8").
#[test]
fn non_utf8_files_name_the_first_bad_byte() {
    let dir = std::env::temp_dir().join(format!("trocar-utf8-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("robot.toml");
    std::fs::write(&path, b"[robot]\nname = \"ab\xffc\"\n").unwrap();
    let e = RobotDescription::from_toml_file(&path).unwrap_err();
    assert_eq!((e.line, e.column), (Some(2), Some(11)), "{e}");
    assert!(e.message.contains("0xff at byte offset 18"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
