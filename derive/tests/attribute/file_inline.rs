//! The file form (f32) and the structured inline form (generic), and that they agree.
use trocar_derive::constrained_robot;

#[constrained_robot(file = "tests/ui/robots/arm.toml", real = "f32")]
struct FileArm;

#[constrained_robot(
    params(l_a = 0.15),
    joints(
        torso: revolute(z),
        shoulder_pitch: revolute(x, xyz = (0.194, 0, 1.037)),
        elbow_pitch: revolute(x, xyz = (0, 0.38, 0)),
        forearm_roll: revolute(y),
        wrist_pitch: revolute(x, xyz = (0, 0.39, 0)),
        wrist_roll: revolute(y),
        shaft_7: revolute(axis = (0, 0, 1), xyz = (0, 0.33, 0)),
        shaft_8: revolute(y, rpy = (0, 0, 0)),
    ),
    end_effector(name = "tool", xyz = (0, 0.21, 0)),
    constraint(link = 6, xyz = (0, l_a, 0), h = (x, z), wrist = zy),
)]
pub struct InlineArm;

#[constrained_robot(toml = r#"
[robot]
name = "planar"
[[joints]]
name = "a"
type = "revolute"
axis = [0, 0, 1]
[[joints]]
name = "b"
type = "prismatic"
axis = [1, 0, 0]
"#)]
struct Planar;

#[test]
fn compiles_and_runs() {
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let a = InlineArm::constrained_jacobian(&q, &InlineArmParams::nominal());
    let qf = q.map(|x| x as f32);
    let b = FileArm::constrained_jacobian(&qf, &FileArm::nominal_params());
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!((x - *y as f64).abs() < 1e-5, "{x} vs {y}");
    }
    let (_r, p) = Planar::forward_kinematics(&[0.0f64, 2.0], &Planar::nominal_params());
    assert_eq!(p, [2.0, 0.0, 0.0]);
    assert_eq!(Planar::N, 2);
}
