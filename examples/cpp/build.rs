//! Generates the Panda laparoscope's kinematics (f64) with their C ABI into
//! `OUT_DIR/panda_laparoscope.rs`, and the C header `panda_laparoscope.h` beside it.
use trocar_codegen::{Builder, Real};

fn main() {
    if let Err(e) = Builder::new()
        .robot("../../runtime/model/robots/panda-laparoscope.toml")
        .real(Real::F64)
        .c_api(true)
        .compile()
    {
        // The description's own message: file, line and field.
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    println!("cargo:rerun-if-changed=build.rs");
}
