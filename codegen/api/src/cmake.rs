//! A CMake (and pkg-config) package of a robot's C ABI (`trocar generate ROBOT --cmake DIR`):
//! the C and C++ headers, the static library built by cargo, and the files that let
//! `find_package(trocar_<module>)` + `target_link_libraries(... trocar::<module>)` (or
//! `pkg-config trocar_<module>`) find them.
//!
//! ```text
//! DIR/include/<module>.h, <module>.hpp
//! DIR/lib/libtrocar_<module>.a
//! DIR/lib/cmake/trocar_<module>/trocar_<module>Config.cmake, ...ConfigVersion.cmake
//! DIR/lib/pkgconfig/trocar_<module>.pc
//! DIR/crate/  the crate the library is built from (Cargo.toml, the generated module)
//! ```
//!
//! The library is the generated module with its C ABI in a `staticlib` crate over the `trocar`
//! runtime — from this source tree where the command line was built in one, else from the
//! registry — built with `cargo build --release` (cargo must be on the `PATH`), in `DIR/crate/target`
//! or, where `CARGO_TARGET_DIR` is set, there (the packages of several robots then share one build
//! of the runtime). A scene's package ([`cmake_scene_package`]) holds the scene's C object and its
//! arms' C ABIs, with the scene's and the arms' headers.

use crate::error::{Error, Result};
use crate::Robot;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The runtime crate's directory in the source tree this library was built from, if it is
/// still there.
fn runtime_source() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime");
    dir.join("Cargo.toml")
        .is_file()
        .then(|| dir.canonicalize().ok())
        .flatten()
}

/// Writes `text` to `path` through a temporary file beside it, so that no half-written file
/// is left.
fn write_file(path: &Path, text: &[u8]) -> Result<()> {
    let fail = |e: std::io::Error| Error::Output(format!("{}: {e}", path.display()));
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(fail)?;
    }
    let temporary = path.with_extension("tmp~");
    std::fs::write(&temporary, text).map_err(fail)?;
    std::fs::rename(&temporary, path).map_err(fail)
}

/// The package of `robot`'s C ABI in `dir`, in `real` (`f64`, or `f32`; a generic module's C
/// ABI is `f64`); `progress` hears what is being done. Returns the package's name
/// (`trocar_<module>`).
pub fn cmake_package(
    robot: &Robot,
    real: crate::Real,
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<String> {
    let options = crate::ModuleOptions {
        real,
        c_api: true,
        ..Default::default()
    };
    progress(&format!("deriving the closed forms of `{}`", robot.name()));
    let header = robot.c_header(&options)?;
    let cpp = robot.cpp_header(&options)?;
    let code = robot.generate(&options)?;
    let module = trocar_codegen::module_name(robot.name());
    let headers = vec![
        (format!("{module}.h"), header),
        (format!("{module}.hpp"), cpp),
    ];
    write_package(&module, &code, &headers, dir, progress)
}

/// The package of a scene's C ABI in `dir` (`trocar generate SCENE --cmake DIR`): its library
/// holds the scene's C object and each arm module's C ABI; its headers are the scene's
/// `<scene>.h`, `<scene>.hpp` and each arm module's. As [`cmake_package`] otherwise.
pub fn cmake_scene_package(
    scene: &trocar_model::scene::SceneDescription,
    real: crate::Real,
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<String> {
    let options = crate::ModuleOptions {
        real,
        ..Default::default()
    };
    progress(&format!(
        "deriving the closed forms of the scene `{}` ({} arms)",
        scene.name,
        scene.arms.len()
    ));
    let files = trocar_codegen::scene::generate_scene_c(scene, &options)?;
    let module = trocar_codegen::module_name(&scene.name);
    write_package(&module, &files.code, &files.headers, dir, progress)
}

/// Writes the package of the module `module` (its code `code`, its headers `(file, text)`) into
/// `dir`: the crate of its static library, built with cargo, the library, the headers and the
/// CMake and pkg-config files.
fn write_package(
    module: &str,
    code: &str,
    headers: &[(String, String)],
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<String> {
    let package = format!("trocar_{module}");
    let dir = if dir.is_absolute() {
        dir.to_path_buf()
    } else {
        std::env::current_dir()
            .map_err(|e| Error::Output(format!("the current directory: {e}")))?
            .join(dir)
    };
    // The crate of the static library.
    let crate_dir = dir.join("crate");
    let runtime = match runtime_source() {
        Some(path) => format!(
            "{{ path = {:?}, default-features = false, features = [\"std\"] }}",
            path.display().to_string()
        ),
        None => format!(
            "{{ version = \"{}\", default-features = false, features = [\"std\"] }}",
            env!("CARGO_PKG_VERSION")
        ),
    };
    let manifest = format!(
        "# The static library of `{module}`'s C ABI (trocar generate --cmake).\n\
         [package]\nname = \"{package}\"\nversion = \"{version}\"\nedition = \"2021\"\npublish = false\n\n\
         [lib]\npath = \"lib.rs\"\ncrate-type = [\"staticlib\"]\n\n\
         [dependencies]\ntrocar = {runtime}\n\n\
         [profile.release]\ncodegen-units = 1\n\n\
         # Its own workspace, wherever the package is written.\n[workspace]\n",
        version = env!("CARGO_PKG_VERSION"),
    );
    write_file(&crate_dir.join("Cargo.toml"), manifest.as_bytes())?;
    write_file(
        &crate_dir.join("lib.rs"),
        format!(
            "//! The C ABI of `{module}` as a static library (trocar generate --cmake).\n\
             include!(\"{module}.rs\");\n"
        )
        .as_bytes(),
    )?;
    write_file(&crate_dir.join(format!("{module}.rs")), code.as_bytes())?;
    progress(&format!("building lib{package}.a with cargo (release)"));
    // The crate's own target directory, unless CARGO_TARGET_DIR names one (shared by the
    // packages of several robots: the runtime built once).
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| crate_dir.join("target"));
    let output = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .args(["rustc", "--release", "--quiet", "--manifest-path"])
        .arg(crate_dir.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(&target)
        .args(["--", "--print", "native-static-libs"])
        .output()
        .map_err(|e| {
            Error::Output(format!(
                "--cmake: cargo could not be started ({e}); the package's library is built with cargo"
            ))
        })?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        return Err(Error::Output(format!(
            "--cmake: building the library in {} failed:\n{stderr}",
            crate_dir.display()
        )));
    }
    // What the static library needs from the system (Rust's standard library's dependencies).
    let native: Vec<String> = stderr
        .lines()
        .find_map(|l| l.split("native-static-libs:").nth(1))
        .map(|libs| libs.split_whitespace().map(str::to_string).collect())
        .unwrap_or_default();
    let library = format!("lib{package}.a");
    let built = target.join("release").join(&library);
    let bytes =
        std::fs::read(&built).map_err(|e| Error::Output(format!("{}: {e}", built.display())))?;
    write_file(&dir.join("lib").join(&library), &bytes)?;
    for (file, text) in headers {
        write_file(&dir.join("include").join(file), text.as_bytes())?;
    }
    let links: Vec<String> = native
        .iter()
        .filter_map(|l| l.strip_prefix("-l"))
        .map(str::to_string)
        .collect();
    let config = format!(
        "# CMake package of `{module}`'s C ABI, generated by trocar (trocar generate --cmake).\n\
         # find_package({package}) defines the imported target trocar::{module}: the static\n\
         # library and the headers {module}.h (C) and {module}.hpp (C++17).\n\
         get_filename_component(_trocar_prefix \"${{CMAKE_CURRENT_LIST_DIR}}/../../..\" ABSOLUTE)\n\
         if(NOT TARGET trocar::{module})\n  \
         add_library(trocar::{module} STATIC IMPORTED)\n  \
         set_target_properties(trocar::{module} PROPERTIES\n    \
         IMPORTED_LOCATION \"${{_trocar_prefix}}/lib/{library}\"\n    \
         INTERFACE_INCLUDE_DIRECTORIES \"${{_trocar_prefix}}/include\"\n    \
         INTERFACE_LINK_LIBRARIES \"{links}\")\n\
         endif()\n\
         unset(_trocar_prefix)\n",
        links = links.join(";"),
    );
    let cmake_dir = dir.join("lib").join("cmake").join(&package);
    write_file(
        &cmake_dir.join(format!("{package}Config.cmake")),
        config.as_bytes(),
    )?;
    let version = format!(
        "# The version of {package} (trocar's): any request of the same major version is met.\n\
         set(PACKAGE_VERSION \"{v}\")\n\
         if(PACKAGE_FIND_VERSION_MAJOR STREQUAL \"{major}\" AND NOT PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)\n  \
         set(PACKAGE_VERSION_COMPATIBLE TRUE)\n\
         else()\n  set(PACKAGE_VERSION_COMPATIBLE FALSE)\nendif()\n\
         if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)\n  set(PACKAGE_VERSION_EXACT TRUE)\nendif()\n",
        v = env!("CARGO_PKG_VERSION"),
        major = env!("CARGO_PKG_VERSION_MAJOR"),
    );
    write_file(
        &cmake_dir.join(format!("{package}ConfigVersion.cmake")),
        version.as_bytes(),
    )?;
    let pc = format!(
        "# pkg-config file of `{module}`'s C ABI, generated by trocar (trocar generate --cmake).\n\
         prefix={prefix}\nlibdir=${{prefix}}/lib\nincludedir=${{prefix}}/include\n\n\
         Name: {package}\n\
         Description: trocar-generated kinematics and constrained controller of {module} (C ABI)\n\
         Version: {v}\n\
         Libs: -L${{libdir}} -l{package} {native}\n\
         Cflags: -I${{includedir}}\n",
        prefix = dir.display(),
        v = env!("CARGO_PKG_VERSION"),
        native = native.join(" "),
    );
    write_file(
        &dir.join("lib")
            .join("pkgconfig")
            .join(format!("{package}.pc")),
        pc.as_bytes(),
    )?;
    Ok(package)
}
