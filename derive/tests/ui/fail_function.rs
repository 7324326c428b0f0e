use trocar_derive::constrained_robot;

// An unknown output and a name the module already has: both at their tokens.
#[constrained_robot(preset = "bidirectional-zy", function(step(fk, jb), body_jacobian(fk)))]
struct Arm;

// An output twice: at the function's name.
#[constrained_robot(preset = "bidirectional-zy", function(twice(fk, jr, fk)))]
struct Arm2;

fn main() {}
