//! `trocar verify`: the generated closed forms of a serial robot against the numeric runtime
//! and finite differences ([`trocar_api::Robot::verify`]).

use crate::output::{write_stderr, write_stdout, CliError};
use crate::progress::{with_progress, with_spinner};
use trocar_api::Robot;

/// Runs `trocar verify`: prints the report; exit code 1 when a check fails.
pub(crate) fn run(robot: &str, samples: usize, seed: u64) -> Result<i32, CliError> {
    Robot::check_samples(samples)?;
    let robot = Robot::load(robot)?;
    if robot.description().is_some() {
        with_spinner(
            &format!("deriving the closed forms of `{}`", robot.name()),
            || robot.derive(),
        )?;
    }
    let report = with_progress("verify", |progress| robot.verify(samples, seed, progress))?;
    write_stdout(&report.to_string())?;
    if report.passed() {
        write_stdout("all checks passed\n")?;
        Ok(0)
    } else {
        for c in report.checks.iter().filter(|c| !c.passed()) {
            write_stderr(&format!(
                "mismatch in `{}` at q = {:?}\n",
                c.name, c.worst_q
            ));
        }
        Ok(1)
    }
}
