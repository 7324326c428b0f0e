//! Scene files: the shipped scenes read, the mirror image checked against the original chain,
//! and every rule of the stack's admission refusing with its file, line and field.

use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use trocar::se3::Se3;
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;
use trocar_model::reference;
use trocar_model::scene::{mirrored, SceneDescription};

#[test]
fn the_shipped_scenes_read() {
    let three = SceneDescription::shipped("three-ports").unwrap();
    assert_eq!(three.name, "three_ports");
    assert_eq!(three.arms.len(), 3);
    assert_eq!(three.scene_joints(), 21);
    assert_eq!(three.couplings.len(), 3);
    assert!(three.shared_joints().is_empty());
    assert_eq!(three.arms[2].camera.as_ref().unwrap().looks_at, vec![0, 1]);
    // The ports where the file puts them: on a circle of 4 cm at 90°, 210°, 330°.
    let ports = three.ports().unwrap();
    for (k, a) in [90.0f64, 210.0, 330.0].iter().enumerate() {
        let want = Vector3::new(a.to_radians().cos(), a.to_radians().sin(), 0.0) * 0.04;
        let got = three.arms[k].base.transform_point(&ports[k]);
        assert!((got - want).norm() < 1e-15, "{k}: {got} vs {want}");
    }
    let dual = SceneDescription::shipped("dia10-dual").unwrap();
    assert_eq!(dual.scene_joints(), 15);
    assert_eq!(dual.shared_joints(), vec![(1, 0, 0, 0)]);
    assert_eq!(dual.joint_map()[0][0], 0);
    assert_eq!(dual.joint_map()[1][0], 0);
    assert_eq!(dual.joint_map()[1][1], 8);
    // Mirror images: the left port is the right one's with x negated.
    let ports = dual.ports().unwrap();
    assert!((ports[0] - Vector3::new(-ports[1].x, ports[1].y, ports[1].z)).norm() < 1e-15);
}

fn m() -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0))
}

proptest! {
    /// The mirror image, its torso kept, at `q` is `M g(−q) M` of the original, for the end
    /// effector and every link, from the original's forward kinematics (every joint revolute,
    /// the torso about `z` through the origin).
    #[test]
    fn the_mirror_image_is_the_mirrored_chain(q in proptest::collection::vec(-3.0f64..3.0, 8)) {
        let d = RobotDescription::preset("dia10_like_zy").unwrap();
        let original = NumericModel::<f64>::from_description(&d, &[]).unwrap();
        let image = NumericModel::<f64>::from_description(&mirrored(&d, 1), &[]).unwrap();
        let flipped: Vec<f64> = q.iter().map(|x| -x).collect();
        let check = |a: Se3<f64>, b: Se3<f64>| {
            let want = Se3::new(m() * b.rotation * m(), m() * b.translation);
            (a.rotation - want.rotation).amax().max((a.translation - want.translation).amax())
        };
        let e = check(
            reference::forward_kinematics(&image, &q).unwrap(),
            reference::forward_kinematics(&original, &flipped).unwrap(),
        );
        prop_assert!(e < 1e-12, "tip {e:e}");
        for k in 1..=8 {
            let e = check(
                reference::link_frame(&image, k, &q).unwrap(),
                reference::link_frame(&original, k, &flipped).unwrap(),
            );
            prop_assert!(e < 1e-12, "link {k}: {e:e}");
        }
    }
}

/// Reads `text` as a scene file in a temporary folder (beside `files`) and returns the error.
fn refused(text: &str, files: &[(&str, &str)]) -> String {
    let dir = tempfile::tempdir().unwrap();
    for (name, body) in files {
        std::fs::write(dir.path().join(name), body).unwrap();
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let e = SceneDescription::from_toml_file(&path).unwrap_err();
    assert_eq!(e.file.as_deref(), Some(path.as_path()));
    e.to_string()
}

const PANDA_ARM: &str = r#"
[[arms]]
name = "a"
robot = "panda-laparoscope"
q0 = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
"#;

fn panda_arm(name: &str, x: f64) -> String {
    format!(
        "[[arms]]\nname = \"{name}\"\nrobot = \"panda-laparoscope\"\nbase = {{ xyz = [{x}, 0, 0] }}\nq0 = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]\n"
    )
}

#[test]
fn errors_name_the_line_and_field() {
    let head = "[scene]\nname = \"s\"\n";
    // Unknown arm in a coupling: the coupling's line.
    let text = format!(
        "{head}{}{}\n[[couplings]]\nbetween = [\"a\", \"c\"]\nsafety = 0.01\ninfluence = 0.03\n",
        panda_arm("a", 0.0),
        panda_arm("b", 0.3)
    );
    let e = refused(&text, &[]);
    assert!(
        e.contains(":15:")
            && e.contains("couplings[0].between[1]")
            && e.contains("no arm named `c`"),
        "{e}"
    );
    // Influence within the safety distance.
    let text = format!(
        "{head}{}{}\n[[couplings]]\nbetween = [\"a\", \"b\"]\nsafety = 0.03\ninfluence = 0.02\n",
        panda_arm("a", 0.0),
        panda_arm("b", 0.3)
    );
    let e = refused(&text, &[]);
    assert!(
        e.contains(":17:") && e.contains("couplings[0].influence"),
        "{e}"
    );
    // q0 of the wrong length, and a value outside the joint's range.
    let e = refused(
        &format!("{head}[[arms]]\nname = \"a\"\nrobot = \"panda-laparoscope\"\nq0 = [0, 0]\n"),
        &[],
    );
    assert!(
        e.contains(":6:") && e.contains("arms[0].q0") && e.contains("2 values for the 7 joints"),
        "{e}"
    );
    let e = refused(&format!("{head}[[arms]]\nname = \"a\"\nrobot = \"panda-laparoscope\"\nq0 = [0, 0, 0, 0.5, 0, 1, 0]\n"), &[]);
    assert!(
        e.contains("arms[0].q0[3]") && e.contains("outside joint"),
        "{e}"
    );
    // An unknown robot, an unknown parameter, an unknown key, a name that is no module name.
    let e = refused(
        &format!("{head}[[arms]]\nname = \"a\"\nrobot = \"nowhere.toml\"\nq0 = []\n"),
        &[],
    );
    assert!(
        e.contains(":5:") && e.contains("arms[0].robot") && e.contains("nowhere.toml"),
        "{e}"
    );
    let e = refused(
        &format!("{head}{PANDA_ARM}parameters = {{ l_b = 0.2 }}\n"),
        &[],
    );
    assert!(
        e.contains("arms[0].parameters.l_b") && e.contains("l_a"),
        "{e}"
    );
    let e = refused(&format!("{head}{PANDA_ARM}colour = \"red\"\n"), &[]);
    assert!(e.contains("unknown key `colour`"), "{e}");
    let e = refused(
        &format!("[scene]\nname = \"Three Ports\"\n{PANDA_ARM}"),
        &[],
    );
    assert!(e.contains(":2:") && e.contains("scene.name"), "{e}");
    // A base given twice over.
    let e = refused(
        &format!("{head}{PANDA_ARM}base = {{ xyz = [0, 0, 0], port = [0, 0, 0] }}\n"),
        &[],
    );
    assert!(e.contains("arms[0].base") && e.contains("not both"), "{e}");
    // A camera looking at itself.
    let e = refused(
        &format!("{head}{PANDA_ARM}camera = {{ looks_at = [\"a\"], tolerance = 0.01 }}\n"),
        &[],
    );
    assert!(e.contains("arms[0].camera.looks_at[0]"), "{e}");
}

#[test]
fn the_stack_is_admitted_as_a_whole() {
    let head = "[scene]\nname = \"s\"\n";
    // Rule 2: arms of two kinds.
    let text = format!("{head}{PANDA_ARM}\n[[arms]]\nname = \"b\"\nrobot = \"dia10_like_zy\"\nq0 = [0, 0, 0, 0, 0, 0, 0, 0]\n");
    let e = refused(&text, &[]);
    assert!(e.contains("arms[1].robot") && e.contains("one kind"), "{e}");
    // Rule 3: a shared torso whose twists differ (the second arm's base moved).
    let dual = |base: &str| {
        format!(
            "{head}[[arms]]\nname = \"l\"\nrobot = \"dia10_like_zy\"\nmirror = true\nshares = {{ arm = \"r\", joints = 1 }}\nq0 = [0, 0.3, -0.9, -0.28, 0.62, -0.1, -0.5, -0.3]\n\n[[arms]]\nname = \"r\"\nrobot = \"dia10_like_zy\"\n{base}q0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n"
        )
    };
    assert!(SceneDescription::from_toml_str(&dual(""), None).is_ok());
    let e = refused(&dual("base = { xyz = [0.01, 0, 0] }\n"), &[]);
    assert!(
        e.contains("arms[0].shares") && e.contains("not joint 1"),
        "{e}"
    );
    // Rule 4: two shafts that start inside their safety distance.
    let text = format!(
        "{head}{}{}\n[[couplings]]\nbetween = [\"a\", \"b\"]\nsafety = 0.01\ninfluence = 0.03\n",
        panda_arm("a", 0.0),
        panda_arm("b", 0.005)
    );
    let e = refused(&text, &[]);
    assert!(
        e.contains("couplings[0].safety") && e.contains("inside the safety distance"),
        "{e}"
    );
    // The same as tips: 5 mm apart.
    let text = text.replace("safety = 0.01", "kind = \"tips\"\nsafety = 0.01");
    let e = refused(&text, &[]);
    assert!(e.contains("0.0050 m apart"), "{e}");
    // Rule 5: two arms sharing every joint, one port for both: their rows are the same rows.
    let text = format!(
        "{head}[[arms]]\nname = \"l\"\nrobot = \"dia10_like_zy\"\nshares = {{ arm = \"r\", joints = 8 }}\nq0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n\n[[arms]]\nname = \"r\"\nrobot = \"dia10_like_zy\"\nq0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n"
    );
    let e = refused(&text, &[]);
    assert!(e.contains("field `arms`") && e.contains("dependent"), "{e}");
    // An arm without a port.
    let no_port = RobotDescription::preset("dia10_like_zy")
        .unwrap()
        .to_toml_string();
    let cut = no_port.find("[constraint]").unwrap();
    let text = format!(
        "{head}[[arms]]\nname = \"a\"\nrobot = \"arm.toml\"\nq0 = [0, 0, 0, 0, 0, 0, 0, 0]\n"
    );
    let e = refused(&text, &[("arm.toml", &no_port[..cut])]);
    assert!(
        e.contains("arms[0].robot") && e.contains("no constraint"),
        "{e}"
    );
}

/// Two arms sharing the torso of a third listed last: one torso in the scene's joints, through
/// the chain of `shares`.
#[test]
fn shared_joints_are_merged_through_every_arm() {
    let mut scene = SceneDescription::shipped("dia10-dual").unwrap();
    let mut third = scene.arms[1].clone();
    third.name = "third".into();
    third.shares = None;
    scene.arms[1].shares = Some((2, 1));
    scene.arms.push(third);
    // left shares right's torso, right shares third's: one torso for the three.
    let map = scene.joint_map();
    assert_eq!(map[0][0], map[1][0]);
    assert_eq!(map[1][0], map[2][0]);
    assert_eq!(scene.scene_joints(), 1 + 3 * 7);
}

/// A mirrored joint counts its angle the other way: its range is negated (the Panda's joint 4,
/// [−3.0718, −0.0698], becomes [0.0698, 3.0718]).
#[test]
fn a_mirror_image_negates_its_joint_ranges() {
    let d = RobotDescription::preset("panda-laparoscope").unwrap();
    let m = mirrored(&d, 0);
    for (a, b) in d.joints.iter().zip(&m.joints) {
        let [lo, hi] = a.limits.unwrap();
        assert_eq!(b.limits, Some([-hi, -lo]));
    }
}

#[test]
fn mutual_shares_and_a_second_camera_are_refused() {
    let head = "[scene]\nname = \"s\"\n";
    let arm = |name: &str, extra: &str| {
        format!("[[arms]]\nname = \"{name}\"\nrobot = \"dia10_like_zy\"\n{extra}q0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n")
    };
    let text = format!(
        "{head}{}{}",
        arm("a", "shares = { arm = \"b\", joints = 1 }\n"),
        arm("b", "shares = { arm = \"a\", joints = 1 }\n")
    );
    let e = SceneDescription::from_toml_str(&text, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("arms[0].shares.arm") && e.contains("already shares"),
        "{e}"
    );
    let text = format!(
        "{head}{}{}{}",
        arm("a", "base = { xyz = [0, 0, 0] }\n"),
        arm(
            "b",
            "base = { xyz = [1, 0, 0] }\ncamera = { looks_at = [\"a\"], tolerance = 0.01 }\n"
        ),
        arm(
            "c",
            "base = { xyz = [2, 0, 0] }\ncamera = { looks_at = [\"a\"], tolerance = 0.01 }\n"
        )
    );
    let e = SceneDescription::from_toml_str(&text, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("arms[2].camera") && e.contains("second camera"),
        "{e}"
    );
}
