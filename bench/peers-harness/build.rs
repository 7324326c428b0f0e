//! Compiles the peers' generated C (written by `bench/peers_gen.py` into `bench/out/`, or
//! `$TROCAR_PEERS_OUT`) with `-O3 -march=native`, as a user of CasADi or SymPy would.
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let out = std::env::var("TROCAR_PEERS_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|_| manifest.join("../out"));
    let files = ["casadi_peers.c", "casadi_cse_peers.c", "sympy_peers.c"];
    for f in files {
        let p = out.join(f);
        if !p.exists() {
            panic!(
                "{} is missing: run bench/peers.sh (or `python bench/peers_gen.py bench/out`) first",
                p.display()
            );
        }
        println!("cargo:rerun-if-changed={}", p.display());
    }
    println!("cargo:rerun-if-changed=c/floor.c");
    println!("cargo:rerun-if-env-changed=TROCAR_PEERS_OUT");
    // valgrind 3.19 cannot decode AVX-512 (EVEX): the callgrind build turns it off for both languages.
    println!("cargo:rerun-if-env-changed=TROCAR_PEERS_NO_AVX512");
    let no_avx512 = std::env::var_os("TROCAR_PEERS_NO_AVX512").is_some();
    let mut b = cc::Build::new();
    b.compiler("gcc")
        .opt_level(3)
        .flag("-march=native")
        .warnings(false)
        .file(manifest.join("c/floor.c"));
    if no_avx512 {
        b.flag("-mno-avx512f");
    }
    for f in files {
        b.file(out.join(f));
    }
    b.compile("peers");

    // trocar's generated modules (feature `ours`), from the shipped descriptions, generic over Real.
    #[cfg(feature = "ours")]
    {
        let robots = manifest.join("../../runtime/model/robots");
        trocar_codegen::Builder::new()
            .robot(robots.join("unidirectional.toml"))
            .robot(robots.join("bidirectional-zy.toml"))
            .robot(robots.join("bidirectional-zx.toml"))
            .robot(robots.join("dia10_like_zy.toml"))
            .compile()
            .expect("trocar code generation");
    }
    println!("cargo:rustc-link-lib=m");
}
