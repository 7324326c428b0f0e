//! Puts `memory.x` (the board's memory map) where `cortex-m-rt`'s `link.x` finds it, and makes
//! the reference tables (`TROCAR_QEMU_REFERENCES`, written by
//! `cargo run -p trocar-panda --example qemu_references`) a dependency of the build.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("OUT_DIR is writable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=TROCAR_QEMU_REFERENCES");
}
