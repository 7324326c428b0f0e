//! `trocar generate --cpp-header` and `--cmake`: the C++ header over the C ABI, and what the
//! command refuses (a mechanism or a scene, outputs that would collide, options the package does
//! not take). The package itself is built by the documents' example (`docs/c-and-cpp.md`) and by
//! `.ci/run`'s CMake build of `examples/cpp`.

use std::process::Command;

fn trocar(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_cpp_header_wraps_the_controller_object() {
    let (code, out, stderr) = trocar(&["generate", "panda-laparoscope", "--cpp-header", "-"]);
    assert_eq!(code, 0, "{stderr}");
    for needle in [
        "namespace trocar {",
        "namespace panda_laparoscope {",
        "#include \"panda_laparoscope.h\"",
        "class Controller {",
        "enum class Status : int {",
        "BadStorage = 10",
        "panda_laparoscope_controller_update(storage_",
        "alignas(PANDA_LAPAROSCOPE_CONTROLLER_ALIGN)",
        "constexpr Params kNominalParams = {{0.25}};",
    ] {
        assert!(out.contains(needle), "missing `{needle}`");
    }
    // With `float` for an `f32` module.
    let (code, out, _) = trocar(&[
        "generate",
        "panda-laparoscope",
        "--real",
        "f32",
        "--cpp-header",
        "-",
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("using Real = float;"));
}

#[test]
fn what_the_headers_and_package_cannot_take_is_refused() {
    let (code, out, stderr) = trocar(&["generate", "four-bar", "--cpp-header", "-"]);
    assert_ne!(code, 0);
    assert!(out.is_empty());
    assert!(stderr.contains("closed mechanism"), "{stderr}");
    let (code, _, stderr) = trocar(&["generate", "three-ports", "--cpp-header", "-"]);
    assert_ne!(code, 0);
    assert!(stderr.contains("scene"), "{stderr}");
    let (code, _, stderr) = trocar(&[
        "generate",
        "panda-laparoscope",
        "--cpp-header",
        "-",
        "--c-header",
        "-",
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("stdout"), "{stderr}");
    let dir = std::env::temp_dir().join(format!("trocar-cmake-refused-{}", std::process::id()));
    let dir_arg = dir.to_string_lossy().into_owned();
    for extra in [["-o", "x.rs"], ["--function", "s=fk,jb0e"]] {
        let mut args = vec!["generate", "panda-laparoscope", "--cmake", &dir_arg];
        args.extend(extra);
        let (code, _, stderr) = trocar(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(stderr.contains("--cmake"), "{stderr}");
    }
    assert!(!dir.exists(), "a refused --cmake wrote {}", dir.display());
}
