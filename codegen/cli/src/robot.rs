//! The numeric serial robot of a description, and the joint-value check shared by `eval` and
//! `jacobian`.

use crate::output::CliError;
use trocar_model::description::RobotDescription;
use trocar_sim::robot::{Robot, RobotError};

/// Turns a numeric-robot error into a command-line error naming the description's file.
pub(crate) fn robot_error(desc: &RobotDescription) -> impl Fn(RobotError) -> CliError + '_ {
    move |e| {
        let file = desc
            .source
            .as_ref()
            .map(|p| format!("{}: ", p.display()))
            .unwrap_or_default();
        CliError(format!("{file}{e}"))
    }
}

/// The numeric robot of a description with the parameter values `values` (declaration order).
pub(crate) fn numeric_robot(
    desc: &RobotDescription,
    values: &[f64],
) -> Result<Robot<f64>, CliError> {
    let overrides: Vec<(String, f64)> = desc
        .parameters
        .iter()
        .map(|p| p.name.clone())
        .zip(values.iter().copied())
        .collect();
    Robot::from_description(desc, &overrides).map_err(robot_error(desc))
}

/// Checks that `q` has one finite value per joint.
pub(crate) fn check_q(desc: &RobotDescription, q: &[f64]) -> Result<(), CliError> {
    if q.len() != desc.joints.len() {
        return Err(CliError(format!(
            "--q has {} values but `{}` has {} joints (give all joint values, base first)",
            q.len(),
            desc.name,
            desc.joints.len()
        )));
    }
    if let Err((k, problem)) = trocar_model::validity::check_all(q) {
        return Err(CliError(format!(
            "--q: value {} ({:e}) {problem}",
            k + 1,
            q[k]
        )));
    }
    Ok(())
}
