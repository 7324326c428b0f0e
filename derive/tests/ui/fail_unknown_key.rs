use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-zy", precision = "f32", real = "f16")]
struct Arm;

fn main() {}
