//! `trocar generate`: the emitted Rust module of a serial robot or a closed mechanism.

use crate::args::RealArg;
use crate::output::{write_stdout, CliError, OutputKind, Outputs};
use crate::progress::with_spinner;
use std::path::Path;
use trocar_api::{Error, Robot};

/// Runs `trocar generate`: writes the module to `output`, or stdout.
pub(crate) fn run(robot: &str, output: Option<&Path>, real: RealArg) -> Result<i32, CliError> {
    let outputs = Outputs::check(&[("-o", output, OutputKind::Data)])?;
    let robot = Robot::load(robot)?;
    let options = trocar_codegen::ModuleOptions {
        real: real.into(),
        ..Default::default()
    };
    let code = with_spinner(
        &format!("deriving the closed forms of `{}`", robot.name()),
        || robot.generate(&options),
    )?;
    match output {
        Some(path) => {
            std::fs::write(outputs.temporary(path), code)
                .map_err(|e| Error::Output(format!("-o {}: {e}", path.display())))?;
            outputs.commit()?;
        }
        None => write_stdout(&code)?,
    }
    Ok(0)
}
