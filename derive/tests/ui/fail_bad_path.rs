use trocar_derive::constrained_robot;

#[constrained_robot(file = "robots/no_such_arm.toml", real = "f32")]
struct Arm;

fn main() {}
