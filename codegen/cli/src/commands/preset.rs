//! `trocar preset`: the TOML text of a shipped description.

use crate::output::{write_stdout, CliError};
use trocar_model::description::preset_names;

/// The TOML text of the shipped description `name`.
pub fn preset(name: &str) -> Result<&'static str, CliError> {
    trocar_model::description::preset(name).ok_or_else(|| {
        CliError(format!(
            "unknown preset `{name}` (expected one of: {})",
            preset_names().collect::<Vec<_>>().join(", ")
        ))
    })
}

/// Runs `trocar preset`: prints the description.
pub(crate) fn run(name: &str) -> Result<i32, CliError> {
    write_stdout(preset(name)?)?;
    Ok(0)
}
