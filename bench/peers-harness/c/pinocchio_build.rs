// The build of `c/pinocchio_panda.cpp` against Pinocchio's wheels, `include!`d by the build
// scripts of `bench/peers-harness` and `bench/numeric-pinocchio` (one list of flags and
// definitions for both harnesses).

/// Pinocchio (pip wheel `pin`, which brings `libpinocchio`; Eigen and the urdfdom headers from
/// `cmeel-eigen` and `cmeel-urdfdom-headers`), all under one `cmeel.prefix`.
///
/// Built with g++ `-O3` at the DEFAULT x86-64 ISA (`-march=x86-64`, no `-march=native`): the
/// wheel's libraries are built for it, and a `-march=native` build of this file segfaults on
/// this AVX-512 machine (in `free` from `ModelTpl::~ModelTpl`): most likely Eigen's alignment
/// (`EIGEN_MAX_ALIGN_BYTES`: 16 at the default ISA, 64 with AVX-512), part of the layout of
/// Pinocchio's `Model` and `Data`, then disagrees with the library. The definitions are those of
/// the CMake target `pinocchio::pinocchio` (`lib/cmake/pinocchio/pinocchioTargets.cmake`, coal's
/// too, plus a Release build's `NDEBUG`), so
/// `computeFrameJacobian`, `forwardKinematics` and `updateFramePlacement` on `VectorXd` /
/// `Matrix6x` are the library's explicitly instantiated ones, as in a CMake user's build.
fn compile_pinocchio_panda(cpp: &std::path::Path, prefix: &std::path::Path) {
    println!("cargo:rerun-if-changed={}", cpp.display());
    let include = prefix.join("include");
    let lib = prefix.join("lib");
    for need in [
        include.join("pinocchio/algorithm/frames.hpp"),
        include.join("eigen3/Eigen/Core"),
        include.join("urdfdom_headers/urdf_model/model.h"),
        lib.join("libpinocchio_default.so"),
        lib.join("libpinocchio_parsers.so"),
    ] {
        if !need.exists() {
            panic!("Pinocchio: {} is missing", need.display());
        }
    }
    let mut b = cc::Build::new();
    b.cpp(true)
        .compiler("g++")
        .opt_level(3)
        .flag("-std=c++17")
        // The default ISA, stated (cc adds it only when rustc's target-cpu is the default).
        .flag("-march=x86-64")
        .warnings(false)
        .include(&include)
        .include(include.join("eigen3"))
        .include(include.join("urdfdom_headers"))
        .file(cpp);
    for (k, v) in [
        // A CMake Release build's -DNDEBUG (the wheel's libraries are built so: no assert text).
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
    // The bench, test and driver binaries find the wheel's libraries without LD_LIBRARY_PATH.
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
}
