use trocar_derive::constrained_robot;

// `JointTrig` is also an item of the generated module that the `_trig` functions take.
#[constrained_robot(preset = "bidirectional-zy")]
struct JointTrig;

fn main() {}
