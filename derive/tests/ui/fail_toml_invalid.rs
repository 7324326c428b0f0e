use trocar_derive::constrained_robot;

#[constrained_robot(toml = r#"
[robot]
name = "two_joints"

[[joints]]
name = "a"
type = "revolute"
axis = [0, 0, 1]

[[joints]]
name = "b"
type = "helical"
axis = [0, 0, 1]
"#)]
struct Arm;

fn main() {}
