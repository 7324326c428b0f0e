use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-zy")]
struct Arm {
    q: [f64; 8],
}

fn main() {}
