//! Generates the Panda laparoscope's kinematics (f32) into `OUT_DIR/panda.rs`, from the shipped
//! description `panda-laparoscope.toml` and the Franka URDF it names (both tracked: editing either
//! regenerates).
use trocar_codegen::{Builder, Real};

fn main() {
    if let Err(e) = Builder::new()
        .robot_as("../../runtime/model/robots/panda-laparoscope.toml", "panda")
        .real(Real::F32)
        .compile()
    {
        // The description's own message: file, line and field.
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    println!("cargo:rerun-if-changed=build.rs");
}
