//! `trocar generate`: the emitted Rust module of a serial robot or a closed mechanism, and the C
//! header of its C ABI.

use crate::output::{write_stdout, CliError, OutputKind, Outputs};
use crate::progress::with_spinner;
use std::path::Path;
use trocar_api::{Error, Robot};

/// Runs `trocar generate`: writes the module to `output` (or stdout), with the fused
/// `functions` besides the defaults (with their `f64` entry points choosing FMA at run time when
/// `fma_at_run_time`), and the C header to `c_header`; with `c_header` alone only the header is written. An output named `-` is stdout
/// (one of them at most).
pub(crate) fn run(
    robot: &str,
    output: Option<&Path>,
    real: trocar_api::Real,
    c_api: bool,
    c_header: Option<&Path>,
    functions: Vec<trocar_api::Fused>,
    fma_at_run_time: bool,
) -> Result<i32, CliError> {
    let stdout = Path::new("-");
    if output == Some(stdout) && c_header == Some(stdout) {
        return Err(Error::Input(
            "-o - and --c-header - both name stdout: write one of them to a file".into(),
        ));
    }
    let header_to_stdout = c_header == Some(stdout);
    let module_to_stdout = output == Some(stdout);
    let c_api = c_api || c_header.is_some();
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
        if c_header.is_some() || header_to_stdout {
            return Err(Error::Unsupported(format!(
                "`{}` is a scene: the C header is written for single robots",
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
    // The module, unless the header is the only output (`--c-header F|-` without `-o`).
    let code = if header.is_some() && output.is_none() && !module_to_stdout {
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
    if let Some(code) = &code {
        match output {
            Some(path) => write("-o", path, code)?,
            None => write_stdout(code)?,
        }
    }
    outputs.commit()?;
    Ok(0)
}
