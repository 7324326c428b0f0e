//! `trocar generate`: the emitted Rust module of a serial robot or a closed mechanism, the C and
//! C++ headers of its C ABI, and a CMake package of it.

use crate::output::{write_stdout, CliError, OutputKind, Outputs};
use crate::progress::with_spinner;
use std::path::Path;
use trocar_api::{Error, Robot};

/// The C ABI's outputs of `trocar generate`: the C header, the C++ header, the CMake package.
pub(crate) struct Headers<'a> {
    /// `--c-header`.
    pub c: Option<&'a Path>,
    /// `--cpp-header`.
    pub cpp: Option<&'a Path>,
    /// `--cmake`.
    pub cmake: Option<&'a Path>,
}

/// Runs `trocar generate`: writes the module to `output` (or stdout), with the fused
/// `functions` besides the defaults (with their `f64` entry points choosing FMA at run time when
/// `fma_at_run_time`), the C header, the C++ header and the CMake package where `headers` asks;
/// with headers alone only they are written. An output named `-` is stdout (one of them at
/// most).
pub(crate) fn run(
    robot: &str,
    output: Option<&Path>,
    real: trocar_api::Real,
    c_api: bool,
    headers: Headers<'_>,
    functions: Vec<trocar_api::Fused>,
    fma_at_run_time: bool,
) -> Result<i32, CliError> {
    let c_header = headers.c;
    let cpp_header = headers.cpp;
    let stdout = Path::new("-");
    if output == Some(stdout) && c_header == Some(stdout) {
        return Err(Error::Input(
            "-o - and --c-header - both name stdout: write one of them to a file".into(),
        ));
    }
    if cpp_header == Some(stdout) && (output == Some(stdout) || c_header == Some(stdout)) {
        return Err(Error::Input(
            "--cpp-header - and another output both name stdout: write one of them to a file"
                .into(),
        ));
    }
    if let Some(dir) = headers.cmake {
        if output.is_some() || c_header.is_some() || cpp_header.is_some() {
            return Err(Error::Input(
                "--cmake DIR writes the headers and the library into DIR: give it alone".into(),
            ));
        }
        if fma_at_run_time || !functions.is_empty() {
            return Err(Error::Input(
                "--cmake packages the module's C ABI as it is: no --function or --fma-at-run-time"
                    .into(),
            ));
        }
        let package = match trocar_api::load_scene(robot)? {
            // A scene's package: the scene's C object and its arms' C ABI.
            Some(scene) => crate::progress::with_stages("--cmake", |stage| {
                trocar_api::cmake_scene_package(&scene, real, dir, stage)
            })?,
            None => {
                let robot = Robot::load(robot)?;
                crate::progress::with_stages("--cmake", |stage| {
                    trocar_api::cmake_package(&robot, real, dir, stage)
                })?
            }
        };
        eprintln!(
            "wrote {}: find_package({package}) and target_link_libraries(... trocar::{})",
            dir.display(),
            package.trim_start_matches("trocar_")
        );
        return Ok(0);
    }
    let cpp_to_stdout = cpp_header == Some(stdout);
    let header_to_stdout = c_header == Some(stdout);
    let module_to_stdout = output == Some(stdout);
    let c_api = c_api || c_header.is_some() || cpp_header.is_some();
    let cpp_header = cpp_header.filter(|p| *p != stdout);
    let output = output.filter(|p| *p != stdout);
    let c_header = c_header.filter(|p| *p != stdout);
    // The files the command reads (the description and its URDF), which no output may replace.
    let reads = if Path::new(robot).is_file() {
        trocar_api::files_read(robot)
    } else {
        Vec::new()
    };
    let outputs = Outputs::check(
        &[
            ("-o", output, OutputKind::Data),
            ("--c-header", c_header, OutputKind::Data),
            ("--cpp-header", cpp_header, OutputKind::Data),
        ],
        &reads,
    )?;
    let options = trocar_api::ModuleOptions {
        real,
        c_api,
        functions,
        fma_at_run_time,
        ..Default::default()
    };
    let write = |option: &str, path: &Path, text: &str| {
        std::fs::write(outputs.temporary(path), text)
            .map_err(|e| Error::Output(format!("{option} {}: {e}", path.display())))
    };
    if let Some(scene) = trocar_api::load_scene(robot)? {
        if c_header.is_some() || header_to_stdout || cpp_header.is_some() || cpp_to_stdout {
            return Err(Error::Unsupported(format!(
                "`{}` is a scene: its C and C++ headers (the scene's and its arms') and its \
                 library are written together by --cmake DIR",
                scene.name
            )));
        }
        let code = with_spinner(
            &format!(
                "deriving the closed forms of the scene `{}` ({} arms)",
                scene.name,
                scene.arms.len()
            ),
            || trocar_api::generate_scene(&scene, &options),
        )?;
        match output {
            Some(path) => write("-o", path, &code)?,
            None => write_stdout(&code)?,
        }
        outputs.commit()?;
        return Ok(0);
    }
    let robot = Robot::load(robot)?;
    let header = if c_header.is_some() || header_to_stdout {
        Some(with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.c_header(&options),
        )?)
    } else {
        None
    };
    let cpp = if cpp_header.is_some() || cpp_to_stdout {
        Some(robot.cpp_header(&options)?)
    } else {
        None
    };
    // The module, unless headers are the only outputs (`--c-header F|-` without `-o`).
    let code = if (header.is_some() || cpp.is_some()) && output.is_none() && !module_to_stdout {
        None
    } else {
        Some(with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.generate(&options),
        )?)
    };
    // Nothing is written before every text is ready.
    if let Some(header) = &header {
        match c_header {
            Some(path) => write("--c-header", path, header)?,
            None => write_stdout(header)?,
        }
    }
    if let Some(cpp) = &cpp {
        match cpp_header {
            Some(path) => write("--cpp-header", path, cpp)?,
            None => write_stdout(cpp)?,
        }
    }
    if let Some(code) = &code {
        match output {
            Some(path) => write("-o", path, code)?,
            None => write_stdout(code)?,
        }
    }
    outputs.commit()?;
    Ok(0)
}
