//! Values every front door refuses in the same words (RELIABILITY.md's findings F20 onwards): a
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
        let started = std::time::Instant::now();
        let e = trocar_api::simulate("panda-laparoscope", &options, &mut |_| {})
            .expect_err("a speed limit that is not positive runs");
        assert!(
            started.elapsed().as_secs_f64() < 5.0,
            "refused after the run"
        );
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
