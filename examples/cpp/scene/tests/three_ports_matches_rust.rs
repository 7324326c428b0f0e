//! `three_ports.cpp` (the C++ program over the scene's package) against the same loop in Rust
//! over the same C ABI: every value of every row within 1e-12 (they are the same arithmetic:
//! the program is built without FMA contraction), and against the command line's run of the
//! scene (`trocar simulate three-ports`, the numeric model) as `c_loop_matches_rust` compares the
//! Rust loop. Ignored by default: it needs the program's output, named by
//! `TROCAR_CPP_SCENE_OUTPUT` (CI builds the program with CMake, runs it and sets it).

mod common;

#[test]
#[ignore = "needs the C++ program's output (TROCAR_CPP_SCENE_OUTPUT)"]
fn cpp_three_ports_matches_the_rust_loop() {
    let path = std::env::var("TROCAR_CPP_SCENE_OUTPUT")
        .expect("TROCAR_CPP_SCENE_OUTPUT names the output of build/three_ports");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header line")
        .split(',')
        .map(str::to_string)
        .collect();
    assert_eq!(header, common::columns(), "the program's columns");
    let cpp: Vec<Vec<f64>> = lines
        .enumerate()
        .map(|(r, line)| {
            line.split(',')
                .map(|v| {
                    v.parse::<f64>()
                        .unwrap_or_else(|e| panic!("row {r}: `{v}`: {e}"))
                })
                .collect()
        })
        .collect();
    let rust = common::c_run();
    let (d, row, column) = common::largest_difference(&cpp, &rust);
    println!(
        "C++ against the Rust loop: largest difference {d:.2e} (row {row}, {})",
        header[column]
    );
    assert!(
        d <= 1e-12,
        "the C++ run differs from the Rust loop by {d:e} at row {row}, {}",
        header[column]
    );
    let cli = common::rust_run();
    let (d, row, column) = common::largest_difference(&cpp, &cli);
    println!(
        "C++ against `trocar simulate three-ports`: largest difference {d:.2e} (row {row}, {})",
        header[column]
    );
    assert!(d <= 1e-10, "{d:e} at row {row}, {}", header[column]);
    let closest = cpp.iter().map(|r| r[43]).fold(f64::INFINITY, f64::min);
    assert!(closest >= 0.010, "the shafts came within {closest} m");
}
