//! Pinocchio's C++ on the Panda, the peers harness's `c/pinocchio_panda.cpp`, built as the
//! harness builds it (`c/pinocchio_build.rs`), from `$TROCAR_PINOCCHIO_PREFIX` (run.sh sets it).
use std::path::PathBuf;

include!("../peers-harness/c/pinocchio_build.rs");

fn main() {
    let prefix = PathBuf::from(std::env::var("TROCAR_PINOCCHIO_PREFIX").expect(
        "TROCAR_PINOCCHIO_PREFIX: the `cmeel.prefix` of a venv with pin, cmeel-eigen, cmeel-urdfdom-headers (run.sh sets it)",
    ));
    println!("cargo:rerun-if-env-changed=TROCAR_PINOCCHIO_PREFIX");
    println!("cargo:rerun-if-changed=../peers-harness/c/pinocchio_build.rs");
    compile_pinocchio_panda(
        &PathBuf::from("../peers-harness/c/pinocchio_panda.cpp"),
        &prefix,
    );
}
