//! Compiles DAQP's C sources (from its PyPI sdist, fetched by `fetch-daqp.sh` into
//! `bench/out/daqp-VERSION`, or `DAQP_SRC` pointing at a `csrc` directory) and the shim.
use std::path::PathBuf;

fn main() {
    let csrc = std::env::var_os("DAQP_SRC")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../out/daqp-0.11.0/csrc"));
    println!("cargo:rerun-if-env-changed=DAQP_SRC");
    println!("cargo:rerun-if-changed=c/daqp_shim.c");
    if !csrc.join("src/daqp.c").exists() {
        panic!(
            "DAQP's sources are not at {} (run bench/qp-peers/fetch-daqp.sh, or set DAQP_SRC)",
            csrc.display()
        );
    }
    let mut build = cc::Build::new();
    build
        .include(csrc.join("include"))
        .opt_level(3)
        .warnings(false);
    // The same instruction set as the Rust code it is compared with: -march=native only when
    // the Rust code is built with `-C target-cpu=native` (QP_PEERS_NATIVE=1, see run.sh).
    println!("cargo:rerun-if-env-changed=QP_PEERS_NATIVE");
    if std::env::var_os("QP_PEERS_NATIVE").is_some() {
        build.flag("-march=native");
    }
    for f in std::fs::read_dir(csrc.join("src")).unwrap() {
        let path = f.unwrap().path();
        if path.extension().is_some_and(|e| e == "c") {
            build.file(path);
        }
    }
    build.file("c/daqp_shim.c");
    build.compile("daqp");
    println!("cargo:rustc-link-lib=m");
}
