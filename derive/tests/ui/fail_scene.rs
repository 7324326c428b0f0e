use trocar_derive::constrained_robot;

#[constrained_robot(scene = "four-ports")]
struct Ports;

#[constrained_robot(scene = "dia10-dual", checks)]
struct Dual;

fn main() {}
