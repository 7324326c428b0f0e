//! Mechanism descriptions: the shipped files and errors that name the field.

use trocar_sim::closed_chain::{description, ClosedChainError, JointType, Output};

fn field_of(src: &str) -> (String, String, Option<usize>) {
    match description::from_toml_str(src) {
        Err(ClosedChainError::Description(d)) => (d.field, d.message, d.line),
        other => panic!("expected a description error, got {other:?}"),
    }
}

const GOOD: &str = r#"
name = "tiny"
outputs = ["phi"]
[parameters]
a = 1.0
[[chains]]
name = "c1"
base = { x = "-a/2" }
tip = { x = "a" }
[[chains.joints]]
name = "q1"
type = "revolute"
active = true
[[chains.joints]]
name = "q2"
type = "revolute"
origin = { x = 1.2 }
[[chains]]
name = "c2"
base = { x = "a/2" }
tip = { x = 0.5 }
[[chains.joints]]
name = "q3"
type = "revolute"
[[chains.joints]]
name = "q4"
type = "revolute"
origin = { x = 1.4 }
"#;

#[test]
fn shipped_mechanisms() {
    let fb = description::shipped("four-bar").unwrap();
    assert_eq!(fb.joint_names(), ["theta1", "theta3", "theta2", "theta4"]);
    assert_eq!(fb.active_indices(), [0]);
    assert_eq!(fb.outputs, [Output::Phi]);
    assert_eq!(fb.chains[0].base.x, -0.5);
    assert!((fb.chains[0].tip.x - 2.0).abs() < 1e-15); // l3 + l4
    assert_eq!(fb.effective_dof(), 1);
    let st = description::shipped("planar-stewart").unwrap();
    assert!(matches!(
        st.chains[1].joints[1].kind,
        JointType::Prismatic { .. }
    ));
    assert!((st.chains[2].tip.angle + 4.0 * std::f64::consts::PI / 3.0).abs() < 1e-15);
    let co = description::shipped("cooperative-arms").unwrap();
    assert_eq!(co.n_joints(), 8);
    assert_eq!(co.joint_names()[3], "arm1_contact1");
    assert!(description::shipped("five-bar").is_err());
    description::from_toml_str(GOOD).unwrap();
    // The files on disk are the ones compiled in.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../model/robots/mechanisms/");
    for f in [
        "four-bar.toml",
        "planar-stewart.toml",
        "cooperative-arms.toml",
    ] {
        description::from_toml_file(format!("{dir}{f}")).unwrap();
    }
}

#[test]
fn errors_name_the_field() {
    let (f, m, line) = field_of(&GOOD.replace(
        "type = \"revolute\"\norigin = { x = 1.4 }",
        "type = \"spherical\"\norigin = { x = 1.4 }",
    ));
    assert_eq!(f, "chains[1].joints[1].type");
    assert_eq!(
        line,
        Some(27),
        "line of `type` in the second joint of the second chain"
    );
    assert!(m.contains("spherical"));
    let (f, _, _) = field_of(&GOOD.replace("origin = { x = 1.2 }", "origin = { x = 1.2, z = 3 }"));
    assert_eq!(f, "chains[0].joints[1].origin.z");
    let (f, m, line) = field_of(&GOOD.replace("\"-a/2\"", "\"-b/2\""));
    assert_eq!(f, "chains[0].base.x");
    assert_eq!(line, Some(8));
    assert!(m.contains("unknown parameter `b`"));
    let (f, _, _) = field_of(&GOOD.replace("outputs = [\"phi\"]", "outputs = [\"psi\"]"));
    assert_eq!(f, "outputs[0]");
    let (f, _, _) = field_of(&GOOD.replace("name = \"q3\"", "name = \"q1\""));
    assert_eq!(f, "chains[1].joints[0].name");
    let (f, _, _) = field_of(&GOOD.replace("active = true\n", "active = \"yes\"\n"));
    assert_eq!(f, "chains[0].joints[0].active");
    let (f, _, _) =
        field_of(&GOOD.replace("active = true\n", "active = true\nlimits = [2.0, 1.0]\n"));
    assert_eq!(f, "chains[0].joints[0].limits");
    let (f, _, _) = field_of(&GOOD.replace("name = \"tiny\"\n", ""));
    assert_eq!(f, "name");
    let (f, _, _) = field_of(&GOOD.replace("active = true\n", ""));
    assert_eq!(f, "chains");
    // A contact row mixing rotation and translation.
    let bad = description::COOPERATIVE_TOML.replacen("h = [[0, 0, 1]]", "h = [[1, 0, 1]]", 1);
    let (f, _, _) = field_of(&bad);
    assert_eq!(f, "chains[0].contact.h[0]");
    // Syntax errors carry the line.
    let (_, m, line) = field_of("name = \"x\"\noutputs = [\"phi\"\n");
    assert!(m.contains("TOML"));
    assert!(line.is_some());
    // File errors name the file.
    match description::from_toml_file("/nonexistent/mech.toml") {
        Err(ClosedChainError::Description(d)) => {
            assert!(d.file.unwrap().ends_with("mech.toml"))
        }
        other => panic!("{other:?}"),
    }
    // Display mentions the field.
    let e = description::from_toml_str(&GOOD.replace("\"-a/2\"", "\"-b/2\"")).unwrap_err();
    assert!(e.to_string().contains("chains[0].base.x"));
}

#[test]
fn errors_in_shipped_files_point_at_the_line() {
    // Break the third joint's type in the Stewart file and check the reported line.
    let src = description::STEWART_TOML.replacen("type = \"prismatic\"", "type = \"screw\"", 2);
    let line_of_second = src
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("\"screw\""))
        .nth(1)
        .unwrap()
        .0
        + 1;
    match description::from_toml_str(&src) {
        Err(ClosedChainError::Description(d)) => {
            assert_eq!(d.field, "chains[0].joints[1].type");
            let first = src.lines().position(|l| l.contains("\"screw\"")).unwrap() + 1;
            assert_eq!(d.line, Some(first));
            assert!(first < line_of_second);
        }
        other => panic!("{other:?}"),
    }
}
