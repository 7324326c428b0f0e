//! `trocar generate`: the emitted Rust module of a serial robot or a closed mechanism, and the C
//! header of its C ABI.

use crate::args::RealArg;
use crate::output::{write_stdout, CliError, OutputKind, Outputs};
use crate::progress::with_spinner;
use std::path::Path;
use trocar_api::{Error, Robot};

/// Runs `trocar generate`: writes the module to `output` (or stdout), and the C header to
/// `c_header`; with `c_header` alone only the header is written.
pub(crate) fn run(
    robot: &str,
    output: Option<&Path>,
    real: RealArg,
    c_api: bool,
    c_header: Option<&Path>,
) -> Result<i32, CliError> {
    // The files the command reads (the description and its URDF), which no output may replace.
    let reads = if Path::new(robot).exists() {
        trocar_model::description::RobotDescription::files_read(robot)
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
    let robot = Robot::load(robot)?;
    let options = trocar_codegen::ModuleOptions {
        real: real.into(),
        c_api: c_api || c_header.is_some(),
        ..Default::default()
    };
    let write = |option: &str, path: &Path, text: &str| {
        std::fs::write(outputs.temporary(path), text)
            .map_err(|e| Error::Output(format!("{option} {}: {e}", path.display())))
    };
    if let Some(path) = c_header {
        let header = with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.c_header(&options),
        )?;
        write("--c-header", path, &header)?;
        if output.is_none() {
            outputs.commit()?;
            return Ok(0);
        }
    }
    let code = with_spinner(
        &format!("deriving the closed forms of `{}`", robot.name()),
        || robot.generate(&options),
    )?;
    match output {
        Some(path) => {
            write("-o", path, &code)?;
            outputs.commit()?;
        }
        None => write_stdout(&code)?,
    }
    Ok(0)
}
