//! Values every front door refuses in the same words (docs/RELIABILITY.md's findings F18 onwards): a
//! joint speed limit that is not a positive number, trajectories too large to hold, a
//! trajectory file's byte-order mark and what its error messages may quote.

use trocar_api::{ControllerOptions, RcmOptions, Robot, RobotController, SpeedLimit};

/// A speed limit of NaN, 0, a negative number or infinity is refused by a shipped scenario as
/// by the controller, with the controller's message, before anything runs (NaN used to drop the
/// limit, 0 and −1 to hold the arm still).
#[test]
fn a_scenario_refuses_the_speed_limits_the_controller_refuses() {
    let robot = Robot::load("panda-laparoscope").unwrap();
    for v in [f64::NAN, 0.0, -1.0, f64::INFINITY, -0.0] {
        let options = RcmOptions {
            max_joint_speed: Some(SpeedLimit::At(v)),
            ..RcmOptions::default()
        };
        let mut progress = 0;
        let e = trocar_api::simulate("panda-laparoscope", &options, &mut |_| progress += 1)
            .expect_err("a speed limit that is not positive runs");
        assert_eq!(progress, 0, "refused after the run had begun");
        let controller = RobotController::new(
            &robot,
            ControllerOptions {
                max_joint_speed: Some(v),
                ..ControllerOptions::default()
            },
        )
        .expect_err("the controller takes a speed limit that is not positive");
        assert_eq!(e.to_string(), controller.to_string(), "{v}");
        assert!(e.to_string().contains("max_joint_speed"), "{e}");
        assert!(SpeedLimit::At(v).check().is_err(), "{v}");
    }
    assert!(SpeedLimit::At(2.0).check().is_ok());
    assert!(SpeedLimit::Unlimited.check().is_ok());
}

/// The Panda's start configuration of the shipped scenario and the tip there.
fn panda_start() -> (Robot, Vec<f64>, [f64; 3]) {
    let robot = Robot::load("panda-laparoscope").unwrap();
    let q0 = trocar_sim::simulation::PANDA_Q0.to_vec();
    let fk = robot
        .eval(trocar_api::Function::ForwardKinematics, &q0, &[])
        .unwrap();
    (robot, q0, [fk.data[3], fk.data[7], fk.data[11]])
}

/// A device that never ends (`/dev/zero`) reports a size of 0, which the 64 MiB cap used to
/// read: it was read until memory ran out. Now at most one byte more than the cap is read, and
/// the error says the limit.
#[test]
fn an_endless_trajectory_file_is_refused_after_the_cap() {
    let e = trocar_api::Trajectory::from_csv(std::path::Path::new("/dev/zero"))
        .expect_err("/dev/zero read as a trajectory");
    let message = e.to_string();
    assert!(
        message.starts_with("/dev/zero: the trajectory is larger than the 67108864 bytes"),
        "{message}"
    );
    assert_eq!(trocar_api::MAX_TRAJECTORY_BYTES, 64 << 20);
}

/// A two-row path that ends at t = 2001 s asks for 1 000 500 steps of 2 ms: it is refused
/// before the run, naming the row and the limit (the step cap used to be 10⁷, which bounded the
/// steps and not the trace's memory: 3.4 GB at t = 19 999 s).
#[test]
fn a_path_longer_than_the_step_cap_is_refused_before_the_run() {
    let (robot, q0, tip) = panda_start();
    let text = format!(
        "t,x,y,z,roll\n0,{0},{1},{2},0\n2001,{0},{1},{2},0\n",
        tip[0], tip[1], tip[2]
    );
    let trajectory = trocar_api::Trajectory::parse(&text, "long.csv").unwrap();
    let options = trocar_api::TrajectoryOptions {
        q0,
        trocar: None,
        controller: ControllerOptions::default(),
        dt: 0.002,
    };
    let mut progress = 0;
    let e = trocar_api::simulate_trajectory(&robot, &trajectory, &options, &mut |_| progress += 1)
        .expect_err("a path of 1 000 500 steps runs");
    assert_eq!(progress, 0, "refused after the run had begun");
    let message = e.to_string();
    assert!(
        message.starts_with("the trajectory:3: column `t`: the path ends at t = 2001 s"),
        "{message}"
    );
    assert!(message.contains("at most 1000000 steps"), "{message}");
    assert_eq!(trajectory.steps(0.002, "long.csv").ok(), None);
    // At the cap exactly: 2000 s.
    let at_cap = trocar_api::Trajectory::parse("t,x,y,z\n0,0,0,0\n2000,0,0,0\n", "p").unwrap();
    assert_eq!(
        at_cap.steps(0.002, "p").unwrap(),
        trocar_api::MAX_TRAJECTORY_STEPS
    );
}

/// A CSV saved with a UTF-8 byte-order mark (as spreadsheets write it) was refused with the
/// invisible character in the message ("no column `t`", the header's first column being
/// `\u{feff}t`); it is read as without the mark, with the same line numbers.
#[test]
fn a_byte_order_mark_before_the_header_is_skipped() {
    let plain = "t,x,y,z\n0,0,0,0\n1,0.1,0,0\n";
    let marked = format!("\u{feff}{plain}");
    let a = trocar_api::Trajectory::parse(plain, "p.csv").unwrap();
    let b = trocar_api::Trajectory::parse(&marked, "p.csv").unwrap();
    assert_eq!(a, b);
    let bad = "\u{feff}t,x,y,z\n0,0,0,0\n1,zero,0,0\n";
    let e = trocar_api::Trajectory::parse(bad, "p.csv").unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.csv:3: column `x`: `zero` is not a number",
        "{e}"
    );
    let dir = std::env::temp_dir().join(format!("trocar-bom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bom.csv");
    std::fs::write(&path, marked.as_bytes()).unwrap();
    assert_eq!(trocar_api::Trajectory::from_csv(&path).unwrap().t, a.t);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file that is not a trajectory (`[simulation] trajectory = "../../etc/passwd"`) had its first
/// line quoted in the error ("it has: root:x:0:0:..."): a header without a column `t` is now
/// described by its number of fields, not by its text. A header with `t` still lists its
/// columns, which helps with a misspelt one.
#[test]
fn a_file_that_is_not_a_trajectory_is_not_quoted() {
    let secret = "root:x:0:0:secret-word:/root:/bin/bash,second field\nmore,text\n";
    let e = trocar_api::Trajectory::parse(secret, "passwd").unwrap_err();
    let message = e.to_string();
    assert!(!message.contains("secret-word"), "{message}");
    assert!(!message.contains("root"), "{message}");
    assert!(
        message.starts_with("passwd:1: no column `t`: this line, the first that is not blank or a `#` comment, has 2 comma-separated fields and none is `t`"),
        "{message}"
    );
    let e = trocar_api::Trajectory::parse("t,x,why,z\n0,0,0,0\n1,0,0,0\n", "p.csv").unwrap_err();
    assert!(
        e.to_string()
            .contains("p.csv:1: no column `y` (the header names t, x, y, z and optionally roll or qw, qx, qy, qz; it has: t, x, why, z)"),
        "{e}"
    );
}

/// A target rotation that is not a proper rotation (a zero matrix, a reflection) was taken by
/// the library's controller as some orientation; the rule Python applies holds for every caller.
#[test]
fn a_target_rotation_must_be_a_rotation() {
    let robot = trocar_api::Robot::load("panda-laparoscope").unwrap();
    let mut ctrl =
        trocar_api::RobotController::new(&robot, trocar_api::ControllerOptions::default()).unwrap();
    let q = [
        0.0,
        -std::f64::consts::FRAC_PI_4,
        0.0,
        -3.0 * std::f64::consts::FRAC_PI_4,
        0.0,
        std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_4,
    ];
    let trocar = [0.3068905665929411, 0.0, 0.34028205230283923];
    let mut target = trocar_api::Target {
        position: [0.3068905665929411, 0.0, 0.19028205230283923],
        rotation: Some([[0.0; 3]; 3]),
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
    };
    let err = ctrl
        .step(&q, &target, &trocar, &[0.0, 0.0], 0.002)
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("target.rotation: not a rotation matrix"),
        "{err}"
    );
    target.rotation = Some([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]);
    assert!(ctrl.step(&q, &target, &trocar, &[0.0, 0.0], 0.002).is_err());
    let s = std::f64::consts::FRAC_1_SQRT_2;
    target.rotation = Some([[s, -s, 0.0], [-s, -s, 0.0], [0.0, 0.0, -1.0]]);
    let step = ctrl.step(&q, &target, &trocar, &[0.0, 0.0], 0.002).unwrap();
    assert_eq!(step.status, trocar_api::StepStatus::Held);
}
