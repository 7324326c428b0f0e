//! `trocar list`: what ships with trocar (robots, mechanisms, simulation scenarios).

use crate::output::{write_stdout, CliError};

/// Runs `trocar list`.
pub(crate) fn run() -> Result<i32, CliError> {
    let s = trocar_api::shipped();
    let mut out = String::new();
    out += "robots (generate, eval, verify, preset):\n";
    for r in &s.robots {
        out += &format!("  {r}\n");
    }
    out += "mechanisms (generate, eval, preset):\n";
    for m in &s.mechanisms {
        out += &format!("  {m}\n");
    }
    out += "scenarios (simulate):\n";
    for sc in &s.scenarios {
        out += &format!("  {sc}\n");
    }
    out += "A description file (TOML, its chain possibly from a URDF) is accepted wherever a robot or mechanism name is.\n";
    write_stdout(&out)?;
    Ok(0)
}
