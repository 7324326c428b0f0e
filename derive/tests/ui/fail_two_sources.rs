use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-zy", file = "robots/arm.toml")]
struct Arm;

#[constrained_robot(real = "f32")]
struct NoSource;

fn main() {}
