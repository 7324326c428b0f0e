//! The scene `three-ports` through its C ABI (the scene object, its start, its distances and the
//! endoscope's camera, the endoscope aimed by its arm's controller object) steps as the Rust run
//! of `trocar simulate three-ports` does. The C ABI runs on the generated closed forms, the
//! command line on the numeric model: their kinematics agree to rounding, and the run keeps that
//! agreement — the joints within 1e-12 rad and the shafts' distance within 1e-12 m at every row,
//! the rates (the QPs' solutions, which amplify their data's rounding) within 1e-10 rad/s — and
//! keeps the shafts 10 mm apart.

mod common;

#[test]
fn c_loop_matches_the_rust_run() {
    let c = common::c_run();
    let rust = common::rust_run();
    let names = common::columns();
    let pick = |rows: &[Vec<f64>], columns: &dyn Fn(&str) -> bool| -> Vec<Vec<f64>> {
        rows.iter()
            .map(|r| {
                r.iter()
                    .zip(&names)
                    .filter(|(_, n)| columns(n))
                    .map(|(v, _)| *v)
                    .collect()
            })
            .collect()
    };
    let is_rate = |n: &str| n.starts_with("qd");
    let (joints, rates) = (
        common::largest_difference(&pick(&c, &|n| !is_rate(n)), &pick(&rust, &|n| !is_rate(n))),
        common::largest_difference(&pick(&c, &is_rate), &pick(&rust, &is_rate)),
    );
    println!(
        "largest difference: joints and distances {:.2e} (row {}), rates {:.2e} (row {})",
        joints.0, joints.1, rates.0, rates.1
    );
    assert!(
        joints.0 <= 1e-12,
        "joints or distances differ by {:e} at row {}",
        joints.0,
        joints.1
    );
    assert!(
        rates.0 <= 1e-10,
        "rates differ by {:e} at row {}",
        rates.0,
        rates.1
    );
    let closest = c.iter().map(|r| r[43]).fold(f64::INFINITY, f64::min);
    assert!(closest >= 0.010, "the shafts came within {closest} m");
}
