//! Generates the arm's closed-form kinematics (f32) into `OUT_DIR/dia10.rs`.
use trocar_codegen::{Builder, Real};

fn main() {
    if let Err(e) = Builder::new()
        .robot_as("robots/dia10_like_zy.toml", "dia10")
        .real(Real::F32)
        .compile()
    {
        // The description's own message: file, line and field.
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    println!("cargo:rerun-if-changed=build.rs");
}
