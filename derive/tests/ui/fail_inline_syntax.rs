use trocar_derive::constrained_robot;

#[constrained_robot(
    joints(
        torso: revolute(z, offset = (0, 0, 1)),
        shoulder: spherical(x),
        elbow: revolute(w),
    ),
    constraint(link = 2, h = (x, q), wrist = yz),
)]
struct Arm;

fn main() {}
