//! Runnable examples of trocar (see `derive_presets.rs`, `derive_inline.rs`; run them with
//! `cargo run --example derive_presets` from the workspace root), and the file form of
//! `#[constrained_robot]`: the reference arm's kinematics from `robots/dia10_like_zy.toml`.
//!
//! The expansion contains `include_bytes!` of the description file, so editing it recompiles
//! this crate (and touching nothing does not).
#![warn(missing_docs)]

use trocar_derive::constrained_robot;

/// The reference arm `dia10_like` with the zy wrist (docs/reference-robots.md), generic over the
/// scalar; `checks` adds `dia10::Checks` for the tests (`trocar_check`).
#[constrained_robot(file = "robots/dia10_like_zy.toml", checks)]
pub struct Dia10;

/// The thesis's start configuration `q0` (docs/reference-robots.md).
pub const Q0: [f64; 8] = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];

/// Prints a 6 × C column-major matrix row by row.
pub fn print_matrix<const C: usize>(title: &str, a: &[[f64; 6]; C]) {
    println!("{title} (6 × {C}):");
    for r in 0..6 {
        let row: Vec<String> = a.iter().map(|col| format!("{:>9.4}", col[r])).collect();
        println!("  [{}]", row.join(" "));
    }
}

/// Largest entry-wise difference between a column-major array and a numeric matrix.
pub fn max_difference<const C: usize>(a: &[[f64; 6]; C], b: &faer::Mat<f64>) -> f64 {
    assert_eq!((b.nrows(), b.ncols()), (6, C));
    let mut d = 0.0f64;
    for (c, col) in a.iter().enumerate() {
        for (r, x) in col.iter().enumerate() {
            d = d.max((x - b[(r, c)]).abs());
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use trocar_model::description::RobotDescription;
    use trocar_sim::robot::NumericRobot;

    #[test]
    fn file_form_matches_the_numeric_runtime() {
        let p = Dia10::nominal_params::<f64>();
        let jr = Dia10::constrained_jacobian(&Q0, &p);
        let d = RobotDescription::from_toml_file(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/dia10_like_zy.toml"),
        )
        .unwrap();
        let robot = NumericRobot::<f64>::from_description(&d, &[]).unwrap();
        let numeric = robot.constrained_jacobian(&Q0).unwrap();
        assert!(max_difference(&jr, &numeric) < 1e-12);
        let w = Dia10::manipulability(&Q0, &p);
        assert!((w - robot.manipulability(&Q0).unwrap()).abs() < 1e-12);
    }

    #[test]
    fn the_attributes_checks_match_the_numeric_runtime() {
        trocar_check::assert_matches_numeric::<dia10::Checks>("robots/dia10_like_zy.toml", 300);
    }
}
