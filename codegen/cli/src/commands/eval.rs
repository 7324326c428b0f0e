//! `trocar eval`: a quantity of a serial robot or a closed mechanism at one configuration, from
//! the generated closed forms or (`--numeric`) the numeric runtime ([`trocar_api::Robot`]); with
//! several (`--what fk0i,jb0i`), a serial robot's from one program that shares their common
//! values.

use crate::output::{print_matrix, to_json, write_stderr, write_stdout, CliError};
use crate::progress::with_spinner;
use trocar_api::Robot;

/// Runs `trocar eval`: prints the matrix as JSON or aligned text (several: each under its name,
/// or one JSON object keyed by the names as given), and a note on stderr where the Jacobian
/// behind one is singular.
pub(crate) fn run(
    robot: &str,
    q: &[f64],
    params: &[(String, f64)],
    what: &str,
    json: bool,
    numeric: bool,
) -> Result<i32, CliError> {
    let robot = Robot::load(robot)?;
    let names: Vec<&str> = what.split(',').map(str::trim).collect();
    if names.iter().any(|name| name.is_empty()) {
        return Err(trocar_api::Error::Input(format!(
            "--what {what}: an empty name (give names separated by single commas, e.g. fk0i,jb0i)"
        )));
    }
    let functions = names
        .iter()
        .map(|name| robot.function(name))
        .collect::<Result<Vec<_>, _>>()?;
    robot.check_q(q)?;
    robot.param_values(params)?;
    let outs = if numeric {
        trocar_api::Robot::check_outputs(&functions)?;
        functions
            .iter()
            .map(|&f| robot.eval_numeric(f, q, params))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.derive(),
        )?;
        match functions[..] {
            [function] => vec![robot.eval(function, q, params)?],
            _ => robot.eval_several(&functions, q, params)?,
        }
    };
    if let [function] = functions[..] {
        print_matrix(&outs[0], json, robot.labels(function))?;
    } else if json {
        // One object, each quantity under the name it was asked by.
        let entries: Vec<String> = names
            .iter()
            .zip(&outs)
            .map(|(name, m)| format!("\"{name}\": {}", to_json(m)))
            .collect();
        write_stdout(&format!("{{{}}}\n", entries.join(", ")))?;
    } else {
        for (k, (&function, m)) in functions.iter().zip(&outs).enumerate() {
            let gap = if k == 0 { "" } else { "\n" };
            write_stdout(&format!(
                "{gap}{} ({}):\n",
                function.short_name(),
                function.name()
            ))?;
            print_matrix(m, false, robot.labels(function))?;
        }
    }
    for (&function, out) in functions.iter().zip(&outs) {
        // The answer is the Jacobian to test, unless it is the manipulability.
        let shown = (function != trocar_api::Function::Manipulability).then_some(out);
        if let Some(note) = robot.singularity(function, q, params, numeric, shown)? {
            write_stderr(&format!("note: {note}\n"));
        }
    }
    Ok(0)
}
