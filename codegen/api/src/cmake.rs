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
//! registry — built with `cargo build --release` (cargo must be on the `PATH`).

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
    let target = crate_dir.join("target");
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
    write_file(
        &dir.join("include").join(format!("{module}.h")),
        header.as_bytes(),
    )?;
    write_file(
        &dir.join("include").join(format!("{module}.hpp")),
        cpp.as_bytes(),
    )?;
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
