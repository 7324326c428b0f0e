//! `trocar eval`: a quantity of a serial robot or a closed mechanism at one configuration, from
//! the generated closed forms or (`--numeric`) the numeric runtime ([`trocar_api::Robot`]).

use crate::output::{print_matrix, write_stderr, CliError};
use crate::progress::with_spinner;
use trocar_api::Robot;

/// Runs `trocar eval`: prints the matrix as JSON or aligned text, and a note on stderr where the
/// Jacobian behind it is singular.
pub(crate) fn run(
    robot: &str,
    q: &[f64],
    params: &[(String, f64)],
    what: &str,
    json: bool,
    numeric: bool,
) -> Result<i32, CliError> {
    let robot = Robot::load(robot)?;
    let function = robot.function(what)?;
    robot.check_q(q)?;
    robot.param_values(params)?;
    // The trocar on the instrument at the values given, not only at the nominal ones.
    if let (Some(desc), false) = (robot.description(), params.is_empty()) {
        let mut at = desc.clone();
        for (name, value) in params {
            if let Some(p) = at.parameters.iter_mut().find(|p| &p.name == name) {
                p.value = *value;
            }
        }
        if let Some((name, message)) = trocar_model::description::trocar_beyond_tip(&at) {
            return Err(trocar_api::Error::Input(format!(
                "--param {name}={}: {message}",
                at.parameter(&name).unwrap_or(f64::NAN)
            )));
        }
    }
    let out = if numeric {
        robot.eval_numeric(function, q, params)?
    } else {
        with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.derive(),
        )?;
        robot.eval(function, q, params)?
    };
    print_matrix(&out, json, robot.labels(function))?;
    // The answer is the Jacobian to test, unless it is the manipulability.
    let shown = (function != trocar_api::Function::Manipulability).then_some(&out);
    if let Some(note) = robot.singularity(function, q, params, numeric, shown)? {
        write_stderr(&format!("note: {note}\n"));
    }
    Ok(0)
}
