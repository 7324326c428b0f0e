//! Descriptions whose chain comes from a URDF (`[robot] urdf`, `base`, `tip`), constrained links
//! named by URDF link name, and `[task]` selections.

use std::path::PathBuf;
use trocar_model::description::{
    admission_problems, AdmissionError, JointKind, RobotDescription, Rotation,
};

fn robots() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots")
}

/// A TOML description written next to the shipped URDF (so `urdf = "urdf/panda.urdf"` resolves).
fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trocar-urdf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(dir.join("urdf")).unwrap();
    std::fs::copy(
        robots().join("urdf/panda.urdf"),
        dir.join("urdf/panda.urdf"),
    )
    .unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

const PANDA: &str = include_str!("../robots/panda-laparoscope.toml");

#[test]
fn the_shipped_panda_reads_from_its_urdf() {
    let file = RobotDescription::from_toml_file(robots().join("panda-laparoscope.toml")).unwrap();
    let shipped = RobotDescription::preset("panda-laparoscope").unwrap();
    assert_eq!(file.joints, shipped.joints);
    assert_eq!(file.joints.len(), 7);
    let names: Vec<&str> = file.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "panda_joint1",
            "panda_joint2",
            "panda_joint3",
            "panda_joint4",
            "panda_joint5",
            "panda_joint6",
            "panda_joint7"
        ]
    );
    // Franka's values, as written in the URDF.
    assert_eq!(file.joints[3].limits, Some([-3.0718, -0.0698]));
    assert_eq!(file.joints[0].origin.xyz[2].constant, 0.333);
    assert_eq!(
        file.joints[1].origin.rotation,
        Rotation::Rpy([-std::f64::consts::FRAC_PI_2, 0.0, 0.0])
    );
    assert!(matches!(
        file.joints[6].kind,
        JointKind::Revolute {
            axis: [0.0, 0.0, 1.0]
        }
    ));
    // panda_link8 is folded onto link 7 (fixed joint, 0.107 m along z): the constraint frame and
    // the end effector carry that offset.
    let c = file.constraint.as_ref().unwrap();
    assert_eq!(c.link, 7);
    assert_eq!(c.origin.xyz[2].constant, 0.107);
    assert_eq!(c.origin.xyz[2].terms, vec![(1.0, "l_a".to_string())]);
    assert_eq!(c.origin.xyz[0].constant, 0.0);
    assert!(c.origin.xyz[0].terms.is_empty());
    let ee = &file.end_effector;
    assert_eq!(ee.name, "laparoscope_tip");
    assert!((ee.origin.xyz[2].constant - 0.507).abs() < 1e-15);
    assert_eq!(file.task_rows(), 4);
    assert_eq!(
        file.task.as_ref().unwrap().select[3],
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    );
}

#[test]
fn a_constraint_on_the_last_link_needs_a_task_it_can_do() {
    // n = 7, i = 7, r = 2: J^r has (6 − 2) + 0 = 4 columns; the whole twist (t = 6) is infeasible.
    assert_eq!(admission_problems(7, 7, 2, 4), vec![]);
    assert_eq!(
        admission_problems(7, 7, 2, 6),
        vec![AdmissionError::TooFewJoints { n: 7, r: 2, t: 6 }]
    );
    assert_eq!(
        admission_problems(8, 8, 2, 6),
        vec![AdmissionError::TooFewColumns {
            m: 4,
            after: 0,
            r: 2,
            t: 6
        }]
    );
    assert_eq!(
        admission_problems(7, 7, 2, 5),
        vec![AdmissionError::TooFewColumns {
            m: 4,
            after: 0,
            r: 2,
            t: 5
        }]
    );
    let text = PANDA.replace(
        "select = [\"x\", \"y\", \"z\", \"rz\"]",
        "select = [\"x\", \"y\", \"z\", \"rx\", \"rz\"]",
    );
    let path = write("five_rows", &text);
    let e = RobotDescription::from_toml_file(&path).unwrap_err();
    assert_eq!(e.field, "task.select");
    assert!(e.message.contains("t = 5"), "{}", e.message);
    assert!(e.message.contains("= 4 columns"), "{}", e.message);
    assert_eq!(e.file.as_deref(), Some(path.as_path()));
    assert!(e.line.is_some());
    // Without [task], the thesis's n − r ≥ 6 with the numbers.
    let cut = PANDA.split("[task]").next().unwrap();
    let e = RobotDescription::from_toml_file(write("no_task", cut)).unwrap_err();
    assert_eq!(e.field, "constraint.h");
    assert!(e.message.contains("n = 7, r = 2, t = 6"), "{}", e.message);
    assert!(e.message.contains("[task]"), "{}", e.message);
}

#[test]
fn urdf_errors_name_file_and_field() {
    let missing = PANDA.replace("urdf/panda.urdf", "urdf/nope.urdf");
    let e = RobotDescription::from_toml_file(write("missing", &missing)).unwrap_err();
    assert_eq!(e.field, "robot.urdf");
    assert!(e.message.contains("nope.urdf"), "{}", e.message);
    assert_eq!(e.line, Some(13));

    let unknown = PANDA.replace("link = \"panda_link7\"", "link = \"panda_hand\"");
    let e = RobotDescription::from_toml_file(write("unknown_link", &unknown)).unwrap_err();
    assert_eq!(e.field, "constraint.link");
    assert!(
        e.message.contains("panda_hand") && e.message.contains("panda_link8"),
        "{}",
        e.message
    );
    assert!(e.line.is_some());

    let tip = PANDA.replace("tip = \"panda_link8\"", "tip = \"panda_linkX\"");
    let e = RobotDescription::from_toml_file(write("unknown_tip", &tip)).unwrap_err();
    assert_eq!(e.field, "robot.tip");
    assert!(e.message.contains("panda_linkX"), "{}", e.message);
    assert_eq!(e.line, Some(15));

    // The tip above the base.
    let above = PANDA
        .replace("base = \"panda_link0\"", "base = \"panda_link5\"")
        .replace("tip = \"panda_link8\"", "tip = \"panda_link3\"");
    let e = RobotDescription::from_toml_file(write("above", &above)).unwrap_err();
    assert_eq!(e.field, "robot.tip");
    assert!(e.message.contains("not below the base"), "{}", e.message);

    let base_link = PANDA.replace("link = \"panda_link7\"", "link = \"panda_link0\"");
    let e = RobotDescription::from_toml_file(write("base_link", &base_link)).unwrap_err();
    assert_eq!(e.field, "constraint.link");
    assert!(e.message.contains("fixed to the base"), "{}", e.message);

    let bad_limits = "[robot]\nname = \"a\"\n[[joints]]\nname = \"j\"\ntype = \"revolute\"\naxis = [0, 0, 1]\nlimits = [1, -1]\n";
    let e = RobotDescription::from_toml_str(bad_limits, None).unwrap_err();
    assert_eq!(e.field, "joints[0].limits");
    assert_eq!(e.line, Some(7));

    let by_name_without_urdf = "[robot]\nname = \"a\"\n[[joints]]\nname = \"j\"\ntype = \"revolute\"\naxis = [0, 0, 1]\n[constraint]\nlink = \"l\"\nh = [\"x\"]\n";
    let e = RobotDescription::from_toml_str(by_name_without_urdf, None).unwrap_err();
    assert_eq!(e.field, "constraint.link");

    let joints_too = PANDA.replace(
        "[parameters]",
        "[[joints]]\nname = \"x\"\ntype = \"revolute\"\naxis = [0, 0, 1]\n\n[parameters]",
    );
    let e = RobotDescription::from_toml_file(write("joints_too", &joints_too)).unwrap_err();
    assert_eq!(e.field, "joints[0]");
}

#[test]
fn mimic_joints_and_undeclared_links_are_rejected() {
    let urdf = std::fs::read_to_string(robots().join("urdf/panda.urdf")).unwrap();
    let mimic = urdf.replacen(
        "<axis xyz=\"0 0 1\"/>",
        "<axis xyz=\"0 0 1\"/>\n    <mimic joint=\"panda_joint2\"/>",
        1,
    );
    let e = RobotDescription::from_urdf_str(&mimic, "panda_link8").unwrap_err();
    assert!(e.field.ends_with(".mimic"), "{}", e.field);
    assert!(e.line.is_some());
    let undeclared = urdf.replace("<link name=\"panda_link8\"/>", "");
    let e = RobotDescription::from_urdf_str(&undeclared, "panda_link8").unwrap_err();
    assert_eq!(e.field, "tip_link");
}
