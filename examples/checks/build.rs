//! The modules of the shipped `bidirectional-zy` in `f64` and `f32` with their checks (and, generic,
//! `arm_feature` with its checks behind the feature `checks`), and a copy
//! of each with one sign flipped in `constrained_jacobian` (entry (0, 0) of `J^r_0e`, `-(x1 * c8)`
//! written `(x1 * c8)`), which the checks must reject.

use std::path::PathBuf;
use trocar_codegen::{Builder, Real};

const ROBOT: &str = "../../runtime/model/robots/bidirectional-zy.toml";

fn main() {
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    for (real, suffix) in [(Real::F64, "f64"), (Real::F32, "f32")] {
        let module = format!("arm_{suffix}");
        let files = Builder::new()
            .robot_as(ROBOT, &module)
            .real(real)
            .checks(true)
            .generate()
            .unwrap_or_else(|e| panic!("trocar-codegen: {e}"));
        let code = &files[&format!("{module}.rs")];
        std::fs::write(out.join(format!("{module}.rs")), code).expect("writing the module");
        let corrupted = flip_first_negation(code, "pub fn constrained_jacobian(").replace(
            &format!("pub mod {module}"),
            &format!("pub mod corrupted_{suffix}"),
        );
        std::fs::write(out.join(format!("corrupted_{suffix}.rs")), corrupted)
            .expect("writing the corrupted module");
    }
    // The checks behind the crate's feature `checks`, for its integration tests.
    Builder::new()
        .robot_as(ROBOT, "arm_feature")
        .checks_feature("checks")
        .out_dir(&out)
        .emit_rerun_if_changed(false)
        .compile()
        .unwrap_or_else(|e| panic!("trocar-codegen: {e}"));
    println!("cargo:rerun-if-changed={ROBOT}");
    println!("cargo:rerun-if-changed=build.rs");
}

/// `code` with the first negation `-(` of the function that starts with `signature` written `(`.
fn flip_first_negation(code: &str, signature: &str) -> String {
    let start = code.find(signature).expect("the function is generated");
    let at = start
        + code[start..]
            .find("-(")
            .expect("the function negates a term");
    format!("{}{}", &code[..at], &code[at + 1..])
}
