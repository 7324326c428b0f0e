//! Compiles the peers' generated C (written by `bench/peers_gen.py` into `bench/out/`, or
//! `$TROCAR_PEERS_OUT`) with `-O3 -march=native` (`-march=x86-64` with
//! `$TROCAR_PEERS_DEFAULT_ISA`), as a user of CasADi or SymPy would; with the
//! feature `pinocchio`, Pinocchio's C++ on the Panda (`c/pinocchio_panda.cpp`) with g++ `-O3` at
//! the default x86-64 ISA (see `pinocchio` below).
use std::path::{Path, PathBuf};

include!("c/pinocchio_build.rs");

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
    // The Rust-emitting peers' code (bench/peers_rust_gen.py), included by src/rust_peers.rs.
    for f in ["wrenfold_peers.rs", "symforce_peers.rs"] {
        let p = out.join(f);
        if !p.exists() {
            panic!(
                "{} is missing: run bench/peers.sh (or `python bench/peers_rust_gen.py bench/out`) first",
                p.display()
            );
        }
        println!("cargo:rerun-if-changed={}", p.display());
    }
    let rust_dir = out.canonicalize().expect("the peers' output directory");
    println!(
        "cargo:rustc-env=TROCAR_PEERS_RUST_DIR={}",
        rust_dir.display()
    );
    println!("cargo:rerun-if-changed=c/floor.c");
    for f in ["oblique7.toml", "panda-link6-rcm.toml", "panda-link8.toml"] {
        println!("cargo:rerun-if-changed={f}");
    }
    println!("cargo:rerun-if-env-changed=TROCAR_PEERS_OUT");
    // valgrind 3.19 cannot decode AVX-512 (EVEX): the callgrind build turns it off for both languages.
    println!("cargo:rerun-if-env-changed=TROCAR_PEERS_NO_AVX512");
    let no_avx512 = std::env::var_os("TROCAR_PEERS_NO_AVX512").is_some();
    // The Panda's default-ISA run (bench/peers.sh, with RUSTFLAGS="-C target-cpu=x86-64"): the
    // peers' C at the default x86-64 ISA too, like Pinocchio.
    println!("cargo:rerun-if-env-changed=TROCAR_PEERS_DEFAULT_ISA");
    let default_isa = std::env::var_os("TROCAR_PEERS_DEFAULT_ISA").is_some();
    let mut b = cc::Build::new();
    b.compiler("gcc")
        .opt_level(3)
        .flag(if default_isa {
            "-march=x86-64"
        } else {
            "-march=native"
        })
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
            // The Franka Panda with a laparoscope (its chain from urdf/panda.urdf): module
            // `panda_laparoscope`, whose forward_kinematics_i / partial_body_jacobian are g_0i
            // and J^B_0i of its constrained link frame F_i = panda_link7's (panda_joint8's fixed
            // 0.107 m is folded into g_ir), compared with Pinocchio (feature `pinocchio`).
            .robot(robots.join("panda-laparoscope.toml"))
            // Bench-only: the same chain up to panda_link8, no constraint (module `panda_link8`:
            // forward_kinematics and body_jacobian of the flange itself).
            .robot(manifest.join("panda-link8.toml"))
            .compile()
            .expect("trocar code generation");
        // The cases whose peers compute g_0e, J^B_0i and J^r together get exactly those three
        // as one fused program with out-parameters (`step_outputs`, issue 29's fused outputs on
        // request), as a controller's build script would ask for them: dia10_like, and the
        // bench-only generic robots with a computed Λ#, a 7-DOF chain with oblique float axes
        // and 2 explicit H rows (module `oblique7`, written by `bench/chains.py --peers`) and the
        // Panda with the RCM on panda_link6 (`panda_link6_rcm`).
        {
            use trocar_codegen::catalogue::Function;
            trocar_codegen::Builder::new()
                .robot(robots.join("dia10_like_zy.toml"))
                .robot(manifest.join("oblique7.toml"))
                .robot(manifest.join("panda-link6-rcm.toml"))
                .function(
                    "step_outputs",
                    [
                        Function::ForwardKinematics,
                        Function::PartialBodyJacobian,
                        Function::ConstrainedJacobian,
                    ],
                )
                .compile()
                .expect("trocar code generation");
            // The same Panda and step cases with `f64` entry points choosing FMA at run time
            // (`fma_at_run_time`): modules `<name>_fma`, whose `_f64` functions the IMPLs
            // `ours_f64_fma` and `ours_f64_given_trig_fma` call.
            trocar_codegen::Builder::new()
                .robot_as(
                    robots.join("panda-laparoscope.toml"),
                    "panda_laparoscope_fma",
                )
                .robot_as(robots.join("dia10_like_zy.toml"), "dia10_like_zy_fma")
                .robot_as(manifest.join("oblique7.toml"), "oblique7_fma")
                .robot_as(manifest.join("panda-link6-rcm.toml"), "panda_link6_rcm_fma")
                .function(
                    "step_outputs",
                    [
                        Function::ForwardKinematics,
                        Function::PartialBodyJacobian,
                        Function::ConstrainedJacobian,
                    ],
                )
                .fma_at_run_time(true)
                .compile()
                .expect("trocar code generation");
        }
    }

    if std::env::var_os("CARGO_FEATURE_PINOCCHIO").is_some() {
        pinocchio(&manifest);
    }
    println!("cargo:rustc-link-lib=m");
}

/// Pinocchio's C++ on the Panda, `c/pinocchio_panda.cpp` ([`compile_pinocchio_panda`], shared
/// with `bench/numeric-pinocchio`), from `$TROCAR_PINOCCHIO_PREFIX` or the `cmeel.prefix` of
/// `bench/.venv`.
fn pinocchio(manifest: &Path) {
    println!("cargo:rerun-if-env-changed=TROCAR_PINOCCHIO_PREFIX");
    println!("cargo:rerun-if-changed=c/pinocchio_build.rs");
    let prefix = match std::env::var_os("TROCAR_PINOCCHIO_PREFIX") {
        Some(p) => PathBuf::from(p),
        None => venv_prefix(&manifest.join("../.venv")).unwrap_or_else(|| {
            panic!(
                "feature `pinocchio`: set TROCAR_PINOCCHIO_PREFIX to the `cmeel.prefix` of an \
                 environment with pin, cmeel-eigen and cmeel-urdfdom-headers (bench/peers.sh does)"
            )
        }),
    };
    compile_pinocchio_panda(&manifest.join("c/pinocchio_panda.cpp"), &prefix);
}

/// `<venv>/lib/python3.*/site-packages/cmeel.prefix`, if there is one.
fn venv_prefix(venv: &Path) -> Option<PathBuf> {
    let lib = std::fs::read_dir(venv.join("lib")).ok()?;
    lib.filter_map(|e| e.ok())
        .map(|e| e.path().join("site-packages/cmeel.prefix"))
        .find(|p| p.join("include/pinocchio").is_dir())
}
