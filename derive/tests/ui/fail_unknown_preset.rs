use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-yz")]
struct Arm;

fn main() {}
