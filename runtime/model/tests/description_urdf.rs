//! URDF import: the hand-written arm7.urdf and arm7.toml describe the same arm (compared joint
//! frame by joint frame, axis by axis, at zero and random configurations), and URDF errors.
//!
//! The forward kinematics here is a small 4×4 composition written for the test, independent of the
//! runtime's kinematics. A body-Jacobian comparison URDF vs TOML belongs with the numeric runtime.

#![allow(clippy::needless_range_loop)] // small matrices, written index by index

use std::path::{Path, PathBuf};
use trocar_model::description::{JointKind, Origin, RobotDescription, Rotation};

type M4 = [[f64; 4]; 4];

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn mul(a: &M4, b: &M4) -> M4 {
    let mut out = [[0.0; 4]; 4];
    for r in 0..4 {
        for c in 0..4 {
            out[r][c] = (0..4).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

fn identity() -> M4 {
    let mut m = [[0.0; 4]; 4];
    for (k, row) in m.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    m
}

/// Rotation by `angle` about the unit `axis` (Rodrigues), as a 3×3 block of a 4×4.
fn rot(axis: [f64; 3], angle: f64) -> M4 {
    let [x, y, z] = axis;
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0.0],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0.0],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// The origin as a 4×4, rpy as three elementary rotations `Rz(y) Ry(p) Rx(r)`.
fn origin(o: &Origin) -> M4 {
    let r = match &o.rotation {
        Rotation::Rpy([roll, pitch, yaw]) => mul(
            &rot([0.0, 0.0, 1.0], *yaw),
            &mul(&rot([0.0, 1.0, 0.0], *pitch), &rot([1.0, 0.0, 0.0], *roll)),
        ),
        Rotation::Matrix(m) => {
            let mut out = identity();
            for a in 0..3 {
                out[a][..3].copy_from_slice(&m[a]);
            }
            out
        }
    };
    let mut t = r;
    for k in 0..3 {
        assert!(o.xyz[k].is_constant());
        t[k][3] = o.xyz[k].constant;
    }
    t
}

/// Base → joint k frames (after the joint's motion) and base → end effector, plus each joint's
/// axis in the base frame.
fn frames(d: &RobotDescription, q: &[f64]) -> (Vec<M4>, Vec<[f64; 3]>, M4) {
    let mut g = identity();
    let mut out = Vec::new();
    let mut axes = Vec::new();
    for (j, qk) in d.joints.iter().zip(q) {
        g = mul(&g, &origin(&j.origin));
        let motion = match j.kind {
            JointKind::Revolute { axis } => {
                axes.push(axis);
                rot(axis, *qk)
            }
            JointKind::Prismatic { axis } => {
                axes.push(axis);
                let mut m = identity();
                for k in 0..3 {
                    m[k][3] = axis[k] * qk;
                }
                m
            }
            JointKind::Twist { .. } => unreachable!("no twists in arm7"),
        };
        let a = axes.last_mut().unwrap();
        *a = [0, 1, 2].map(|r| (0..3).map(|k| g[r][k] * a[k]).sum());
        g = mul(&g, &motion);
        out.push(g);
    }
    let e = mul(&g, &origin(&d.end_effector.origin));
    (out, axes, e)
}

fn close(a: &M4, b: &M4, what: &str) {
    for r in 0..4 {
        for c in 0..4 {
            assert!(
                (a[r][c] - b[r][c]).abs() < 1e-12,
                "{what}: entry ({r}, {c}) {} vs {}",
                a[r][c],
                b[r][c]
            );
        }
    }
}

#[test]
fn arm7_urdf_and_toml_describe_the_same_arm() {
    let urdf = RobotDescription::from_urdf_file(data("arm7.urdf"), "tool").unwrap();
    let toml = RobotDescription::from_toml_file(data("arm7.toml")).unwrap();
    assert_eq!(urdf.joints.len(), 7);
    assert_eq!(urdf.name, "arm7");
    assert_eq!(urdf.end_effector.name, "tool");
    let names: Vec<_> = urdf.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        ["joint1", "joint2", "joint3", "joint4", "joint5", "joint6", "joint7"]
    );
    // Folded joints carry a matrix; the others keep their rpy exactly.
    assert!(matches!(
        urdf.joints[0].origin.rotation,
        Rotation::Matrix(_)
    ));
    assert!(matches!(
        urdf.joints[3].origin.rotation,
        Rotation::Matrix(_)
    ));
    assert_eq!(urdf.joints[5].origin, toml.joints[5].origin);
    assert_eq!(
        urdf.joints[3].kind,
        JointKind::Revolute {
            axis: [0.0, 0.0, -1.0]
        }
    );
    // The URDF line of each joint is recorded.
    assert_eq!(urdf.joints[0].location.unwrap().line, 48);

    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0
    };
    for sample in 0..50 {
        let q: Vec<f64> = if sample == 0 {
            vec![0.0; 7]
        } else {
            (0..7).map(|_| random()).collect()
        };
        let (fu, au, eu) = frames(&urdf, &q);
        let (ft, at, et) = frames(&toml, &q);
        for k in 0..7 {
            close(
                &fu[k],
                &ft[k],
                &format!("joint {} frame at q = {q:?}", k + 1),
            );
            for c in 0..3 {
                assert!((au[k][c] - at[k][c]).abs() < 1e-12, "joint {} axis", k + 1);
            }
        }
        close(&eu, &et, "end effector");
    }
}

#[test]
fn arm7_folded_origins_match_an_independent_composition() {
    // joint4 = elbow_mount ∘ joint4's own origin, composed here from the URDF numbers.
    let urdf = RobotDescription::from_urdf_file(data("arm7.urdf"), "tool").unwrap();
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut mount = rot([0.0, 0.0, 1.0], half_pi);
    mount[0][3] = 0.0825;
    let mut own = rot([1.0, 0.0, 0.0], half_pi);
    own[1][3] = 0.02;
    own[2][3] = 0.01;
    close(
        &origin(&urdf.joints[3].origin),
        &mul(&mount, &own),
        "joint4 origin",
    );
}

#[test]
fn a_shorter_chain_ends_at_an_intermediate_link() {
    let d = RobotDescription::from_urdf_file(data("arm7.urdf"), "elbow_cover").unwrap();
    assert_eq!(d.joints.len(), 3);
    assert_eq!(d.end_effector.name, "elbow_cover");
    // The elbow mount became the end effector's origin.
    assert_eq!(d.end_effector.origin.xyz[0].constant, 0.0825);
    // A branch reached through fixed joints only has no joint: an error on the tip, which is
    // what to change.
    let camera = RobotDescription::from_urdf_file(data("arm7.urdf"), "camera").unwrap_err();
    assert_eq!(camera.field, "tip_link");
    assert!(camera.message.contains("fixed joints only"), "{camera}");
}

#[test]
fn the_import_converts_to_toml_and_back() {
    let urdf = RobotDescription::from_urdf_file(data("arm7.urdf"), "tool").unwrap();
    let text = urdf.to_toml_string();
    let back = RobotDescription::from_toml_str(&text, None).unwrap();
    for (a, b) in urdf.joints.iter().zip(&back.joints) {
        assert_eq!(a.origin, b.origin);
        assert_eq!(a.kind, b.kind);
    }
    assert_eq!(urdf.end_effector, back.end_effector);
}

fn urdf_error(text: &str, tip: &str) -> String {
    let e = RobotDescription::from_urdf_str(text, tip).unwrap_err();
    e.to_string()
}

const SMALL: &str = r#"<robot name="small">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="TYPE">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0 1" rpy="0 0 0"/>
    <axis xyz="AXIS"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="b"/><child link="c"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"#;

fn small(kind: &str, axis: &str) -> String {
    SMALL.replace("TYPE", kind).replace("AXIS", axis)
}

#[test]
fn urdf_errors_name_the_problem() {
    assert!(RobotDescription::from_urdf_str(&small("revolute", "0 0 1"), "c").is_ok());
    let p = RobotDescription::from_urdf_str(&small("prismatic", "0 3 0"), "c").unwrap();
    assert_eq!(
        p.joints[0].kind,
        JointKind::Prismatic {
            axis: [0.0, 1.0, 0.0]
        }
    );

    let e = urdf_error(&small("revolute", "0 0 1"), "nowhere");
    assert!(
        e.contains("tip_link") && e.contains("unknown tip link `nowhere`"),
        "{e}"
    );
    let e = urdf_error(&small("revolute", "0 0 0"), "c");
    assert!(e.contains("joint[j1].axis") && e.contains("3:"), "{e}");
    let e = urdf_error(&small("floating", "0 0 1"), "c");
    assert!(
        e.contains("joint[j1].type") && e.contains("floating"),
        "{e}"
    );
    let e = urdf_error(&small("planar", "0 0 1"), "c");
    assert!(e.contains("planar"), "{e}");
    let e = urdf_error("<robot name=", "c");
    assert!(e.contains("not well-formed XML"), "{e}");
    let e = RobotDescription::from_urdf_file(data("no-such-file.urdf"), "c").unwrap_err();
    assert!(e.message.contains("cannot read"));
    // A joint that is not on the path is ignored, whatever its type.
    let branch = small("revolute", "0 0 1").replace(
        "</robot>",
        r#"<link name="d"/><joint name="free" type="floating"><parent link="a"/><child link="d"/></joint></robot>"#,
    );
    assert_eq!(
        RobotDescription::from_urdf_str(&branch, "c")
            .unwrap()
            .joints
            .len(),
        2
    );
}

/// URDF files that are not well-formed XML, or that the URDF reader refuses, are reported with a
/// line and column (they used to carry none: "not a valid URDF: No elements found").
#[test]
fn urdf_document_errors_have_a_line() {
    let good = small("revolute", "0 0 1");
    let located = |text: &str| {
        let e = RobotDescription::from_urdf_str(text, "c").unwrap_err();
        assert_eq!(e.field, "(document)", "{e}");
        (
            e.line.expect("a line"),
            e.column.expect("a column"),
            e.message,
        )
    };
    // Truncated inside an attribute value, and inside an element.
    let (line, _, message) = located(&good[..good.find("<axis").unwrap() + 12]);
    assert_eq!(line, 6, "{message}");
    let cut = &good[..good.find("</joint>").unwrap()];
    let (line, _, message) = located(cut);
    assert_eq!(line, 8, "{message}");
    assert!(
        message.contains("ends inside <joint> (opened at line 3)"),
        "{message}"
    );
    // A mismatched end tag.
    let (line, _, message) = located(&good.replacen("</joint>", "</jont>", 1));
    assert_eq!(line, 8, "{message}");
    assert!(
        message.contains("`</joint>`") && message.contains("`</jont>`"),
        "{message}"
    );
    // An attribute without a value (the URDF reader's own position).
    let (line, column, message) = located(&good.replacen(r#"type="revolute""#, "type kind", 1));
    assert_eq!((line, column), (3, 25), "{message}");
    // A vector with a word in it: the line of the value.
    let (line, _, message) = located(&good.replace(r#"xyz="0 0 1""#, r#"xyz="0 0 abc""#));
    assert_eq!(line, 5, "{message}");
    // No element at all.
    let (line, _, message) = located("   ");
    assert_eq!(line, 1, "{message}");
    // Elements nested 14,000 deep (the URDF reader overflowed the stack and aborted): refused
    // at the 65th level (the 64th `<x>` inside `<robot>`).
    let deep = good.replacen(
        "<link name=\"a\"/>",
        &format!(
            "{}<link name=\"a\"/>{}",
            "<x>\n".repeat(14_000),
            "</x>".repeat(14_000)
        ),
        1,
    );
    let (line, _, message) = located(&deep);
    assert_eq!(line, 1 + 64, "{message}");
    assert!(message.contains("nested more than 64 levels"), "{message}");
}

#[test]
fn a_constraint_can_be_added_to_an_import() {
    use trocar_model::description::{ConstraintDesc, Linear};
    let d = RobotDescription::from_urdf_file(data("arm7.urdf"), "tool").unwrap();
    let c = ConstraintDesc {
        link: 6,
        origin: Origin {
            xyz: [
                Linear::constant(0.0),
                Linear::constant(0.0),
                Linear::constant(0.1),
            ],
            rotation: Rotation::Rpy([0.0; 3]),
        },
        h: vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
        wrist: None,
    };
    let constrained = d.clone().with_constraint(c.clone()).unwrap();
    assert_eq!(constrained.constraint, Some(c.clone()));
    // Two rows leave n − r = 5 < 6.
    let mut two = c;
    two.h.push([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    let e = d.with_constraint(two).unwrap_err();
    assert_eq!(e.field, "constraint.h");
    assert!(
        e.message.contains("n − r ≥ t") && e.message.contains("t = 6"),
        "{e}"
    );
}

/// Issue 27, item 11: a root element other than `<robot>` was read as a robot without links; a
/// cycle of joints away from the path to the tip was accepted; a tip that no moving joint carries
/// was blamed on `[[joints]]`; an unknown tip listed every link of the file.
#[test]
fn urdf_structure_errors_are_located() {
    let good = small("revolute", "0 0 1");
    let e = RobotDescription::from_urdf_str(
        &good
            .replace("<robot name=\"small\">", "<model name=\"small\">")
            .replace("</robot>", "</model>"),
        "c",
    )
    .unwrap_err();
    assert_eq!(e.field, "(document)", "{e}");
    assert!(
        e.message.contains("<model>") && e.message.contains("<robot>"),
        "{e}"
    );
    assert_eq!(e.line, Some(1));

    // A cycle x → y → x beside the chain.
    let cycle = good.replace(
        "</robot>",
        "  <link name=\"x\"/><link name=\"y\"/>\n  <joint name=\"xy\" type=\"fixed\"><parent link=\"x\"/><child link=\"y\"/></joint>\n  <joint name=\"yx\" type=\"fixed\"><parent link=\"y\"/><child link=\"x\"/></joint>\n</robot>",
    );
    let e = RobotDescription::from_urdf_str(&cycle, "c").unwrap_err();
    assert!(e.field == "joint[xy]" || e.field == "joint[yx]", "{e}");
    assert!(e.message.contains("cycle"), "{e}");
    assert!(e.line.is_some(), "{e}");

    // The tip hangs from the root by a fixed joint only.
    let fixed = good.replace(
        "</robot>",
        "  <link name=\"tool\"/>\n  <joint name=\"f\" type=\"fixed\"><parent link=\"a\"/><child link=\"tool\"/></joint>\n</robot>",
    );
    let e = RobotDescription::from_urdf_str(&fixed, "tool").unwrap_err();
    assert_eq!(e.field, "tip_link", "{e}");
    assert!(e.message.contains("fixed joints only"), "{e}");

    // 5,000 links: the message names 20 and counts the rest.
    let mut many = String::from("<robot name=\"many\">\n");
    for k in 0..5000 {
        many += &format!("<link name=\"l{k}\"/>\n");
    }
    many += "</robot>\n";
    let e = RobotDescription::from_urdf_str(&many, "nowhere").unwrap_err();
    assert!(
        e.message.contains("… and 4980 more"),
        "{}",
        &e.message[..200.min(e.message.len())]
    );
    assert!(e.message.len() < 400, "{} bytes", e.message.len());
}
