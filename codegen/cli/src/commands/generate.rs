//! `trocar generate`: the emitted Rust module of a serial robot or a closed mechanism.

use crate::args::RealArg;
use crate::output::{write_stdout, CliError, OutputKind, Outputs};
use crate::progress::with_spinner;
use std::path::Path;
use trocar_model::Description;

/// The generated Rust module of `robot` (file or shipped name): the closed forms of a serial
/// robot, or the reduced kinematics of a closed mechanism, in the scalar type `real`.
pub fn generate(robot: &str, real: RealArg) -> Result<String, CliError> {
    let real = match real {
        RealArg::Generic => trocar_codegen::Real::Generic,
        RealArg::F32 => trocar_codegen::Real::F32,
        RealArg::F64 => trocar_codegen::Real::F64,
    };
    let options = trocar_codegen::ModuleOptions {
        real,
        ..Default::default()
    };
    match Description::load(robot)? {
        Description::Mechanism(m) => trocar_codegen::generate_mechanism_string(&m, &options),
        Description::Serial(desc) => with_spinner(
            &format!("deriving the closed forms of `{}`", desc.name),
            || trocar_codegen::generate_module_string(&desc, &options),
        ),
    }
    .map_err(CliError::from_display)
}

/// Runs `trocar generate`: writes the module to `output`, or stdout.
pub(crate) fn run(robot: &str, output: Option<&Path>, real: RealArg) -> Result<i32, CliError> {
    let outputs = Outputs::check(&[("-o", output, OutputKind::Data)])?;
    let code = generate(robot, real)?;
    match output {
        Some(path) => {
            std::fs::write(outputs.temporary(path), code)
                .map_err(|e| CliError(format!("-o {}: {e}", path.display())))?;
            outputs.commit()?;
        }
        None => write_stdout(&code)?,
    }
    Ok(0)
}
