//! Generates the scene `three-ports` (f64) with its C ABI into `OUT_DIR/three_ports.rs`, and its
//! headers (`three_ports.h`, `three_ports.hpp`, the arms' `panda_laparoscope.h`/`.hpp`) beside it.
use trocar_codegen::{Builder, Real};

fn main() {
    if let Err(e) = Builder::new()
        .scene("../../../runtime/model/scenes/three-ports.toml")
        .real(Real::F64)
        .c_api(true)
        .compile()
    {
        // The scene file's own message: file, line and field.
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    println!("cargo:rerun-if-changed=build.rs");
}
