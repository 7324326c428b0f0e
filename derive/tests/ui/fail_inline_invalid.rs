use trocar_derive::constrained_robot;

// Several problems, each reported at its own token by the description's validation.
#[constrained_robot(
    params(l_a = 0.15, l_b = 0.18),
    joints(
        torso: revolute(z),
        shoulder: revolute(x, xyz = (0.194, 0, 1.037)),
        elbow: revolute(axis = (1, 1, 0), xyz = (0, 0.38, 0)),
        roll: revolute(y),
        pitch: revolute(x, xyz = (0, 0.39, 0)),
        wrist: revolute(y),
        shaft_7: revolute(z, xyz = (0, l_a + l_b, 0)),
        shaft_8: revolute(y),
    ),
    end_effector(xyz = (0, l_8, 0)),
    constraint(link = 6, xyz = (0, l_a, 0), h = (x, z), wrist = zy),
)]
struct Arm;

fn main() {}
