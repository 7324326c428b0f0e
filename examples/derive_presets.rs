//! `#[constrained_robot(preset = ...)]` on each thesis preset: prints `J^r_0e` and its
//! manipulability at `q0`, and compares them with the numeric runtime
//! (`trocar_sim::robot::NumericRobot`).
//!
//! Run: `cargo run --example derive_presets` (from the workspace root).

use trocar_derive::constrained_robot;
use trocar_examples::{max_difference, print_matrix, Dia10, Q0};
use trocar_model::description::RobotDescription;
use trocar_sim::robot::NumericRobot;

#[constrained_robot(preset = "unidirectional")]
struct Unidirectional;

#[constrained_robot(preset = "bidirectional-zy")]
struct BidirectionalZy;

#[constrained_robot(preset = "bidirectional-zx", real = "f64")]
struct BidirectionalZx;

fn compare<const C: usize>(preset: &str, jr: &[[f64; 6]; C], w: f64) {
    let d = RobotDescription::preset(preset).expect("shipped preset");
    let robot = NumericRobot::<f64>::from_description(&d, &[]).expect("valid preset");
    let numeric = robot.constrained_jacobian(&Q0).expect("constrained");
    let wn = robot.manipulability(&Q0).expect("constrained");
    println!(
        "  manipulability w = {w:.6} (numeric runtime {wn:.6}); max |J^r − numeric| = {:.1e}\n",
        max_difference(jr, &numeric)
    );
}

fn main() {
    println!("q0 = {Q0:?}\n");

    let p = Unidirectional::nominal_params::<f64>();
    let jr = Unidirectional::constrained_jacobian(&Q0, &p);
    print_matrix("unidirectional: J^r (3.24)", &jr);
    compare(
        "unidirectional",
        &jr,
        Unidirectional::manipulability(&Q0, &p),
    );

    let p = BidirectionalZy::nominal_params::<f64>();
    let jr = BidirectionalZy::constrained_jacobian(&Q0, &p);
    print_matrix("bidirectional-zy: J^r (3.28)", &jr);
    let w = BidirectionalZy::manipulability(&Q0, &p);
    println!(
        "  (3.42) l_b² |sin θ7| / l_a² = {:.6}",
        p.l_b * p.l_b * Q0[6].sin().abs() / (p.l_a * p.l_a)
    );
    compare("bidirectional-zy", &jr, w);

    let p = BidirectionalZx::nominal_params();
    let jr = BidirectionalZx::constrained_jacobian(&Q0, &p);
    print_matrix("bidirectional-zx: J^r (3.29, derived)", &jr);
    let w = BidirectionalZx::manipulability(&Q0, &p);
    println!(
        "  (3.41) l_b² |cos θ7| / l_a² = {:.6}",
        p.l_b * p.l_b * Q0[6].cos().abs() / (p.l_a * p.l_a)
    );
    compare("bidirectional-zx", &jr, w);

    let p = Dia10::nominal_params::<f64>();
    let jr = Dia10::constrained_jacobian(&Q0, &p);
    print_matrix("dia10_like_zy (file form): J^r", &jr);
    compare("dia10_like_zy", &jr, Dia10::manipulability(&Q0, &p));
}
