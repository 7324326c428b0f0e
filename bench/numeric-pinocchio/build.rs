use std::path::PathBuf;
fn main() {
    let prefix = PathBuf::from(std::env::var("TROCAR_PINOCCHIO_PREFIX").expect(
        "TROCAR_PINOCCHIO_PREFIX: the `cmeel.prefix` of a venv with pin, cmeel-eigen, cmeel-urdfdom-headers (run.sh sets it)",
    ));
    println!("cargo:rerun-if-env-changed=TROCAR_PINOCCHIO_PREFIX");
    println!("cargo:rerun-if-changed=../peers-harness/c/pinocchio_panda.cpp");
    let include = prefix.join("include");
    let lib = prefix.join("lib");
    let mut b = cc::Build::new();
    b.cpp(true)
        .compiler("g++")
        .opt_level(3)
        .flag("-std=c++17")
        .flag("-march=x86-64")
        .warnings(false)
        .include(&include)
        .include(include.join("eigen3"))
        .include(include.join("urdfdom_headers"))
        .file("../peers-harness/c/pinocchio_panda.cpp");
    for (k, v) in [
        ("NDEBUG", None),
        ("PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION", None),
        ("PINOCCHIO_WITH_URDFDOM", None),
        ("PINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION", Some("3")),
        ("PINOCCHIO_URDFDOM_HEADERS_MINOR_VERSION", Some("0")),
        ("PINOCCHIO_URDFDOM_HEADERS_PATCH_VERSION", Some("0")),
        ("PINOCCHIO_WITH_COLLISION", None),
        ("PINOCCHIO_WITH_HPP_FCL", None),
        ("COAL_BACKWARD_COMPATIBILITY_WITH_HPP_FCL", None),
        ("COAL_HAS_OCTOMAP", None),
        ("COAL_HAVE_OCTOMAP", None),
        ("OCTOMAP_MAJOR_VERSION", Some("1")),
        ("OCTOMAP_MINOR_VERSION", Some("10")),
        ("OCTOMAP_PATCH_VERSION", Some("0")),
        ("BOOST_MPL_LIMIT_LIST_SIZE", Some("30")),
        ("BOOST_MPL_LIMIT_VECTOR_SIZE", Some("30")),
        ("BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", None),
        ("BOOST_FUSION_INVOKE_MAX_ARITY", Some("12")),
    ] {
        b.define(k, v);
    }
    b.compile("pinocchio_panda");
    println!("cargo:rustc-link-search=native={}", lib.display());
    println!("cargo:rustc-link-lib=dylib=pinocchio_parsers");
    println!("cargo:rustc-link-lib=dylib=pinocchio_default");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
}
