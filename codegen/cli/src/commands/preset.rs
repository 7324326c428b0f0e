//! `trocar preset`: the TOML text of a shipped description.

use crate::output::{write_stdout, CliError};

/// Runs `trocar preset`: prints the description.
pub(crate) fn run(name: &str) -> Result<i32, CliError> {
    write_stdout(trocar_api::preset(name)?)?;
    Ok(0)
}
