//! `trocar verify`: the generated closed forms of a serial robot against the numeric runtime
//! and finite differences.

use crate::output::{write_stdout, CliError};
use crate::progress::with_progress;
use crate::robot::robot_error;
use trocar_codegen::catalogue::Function;
use trocar_codegen::evaluate::Generated;
use trocar_model::Description;
use trocar_sim::verify::{Candidate, Report, Tolerances};

/// The generated closed forms, interpreted exactly as emitted, as the candidate `trocar verify`
/// checks against the numeric runtime ([`trocar_sim::verify`]).
#[derive(Clone, Copy, Debug)]
pub struct GeneratedCandidate<'a>(pub &'a Generated);

impl Candidate for GeneratedCandidate<'_> {
    fn evaluate(&self, function: Function, q: &[f64], params: &[f64]) -> Option<faer::Mat<f64>> {
        let m = self.0.evaluate(function, q, params)?;
        Some(faer::Mat::from_fn(m.rows, m.cols, |r, c| m.get(r, c)))
    }
}

/// Checks the generated closed forms of the serial robot `robot` (file or shipped name) at
/// `samples` random configurations drawn from `seed`; `progress` receives the fraction done.
pub fn verify(
    robot: &str,
    samples: usize,
    seed: u64,
    progress: impl FnMut(f64),
) -> Result<Report, CliError> {
    let Description::Serial(desc) = Description::load(robot)? else {
        return Err(CliError(format!(
            "`{robot}` is a closed mechanism: `verify` checks serial robots; compare the \
             closed form with the runtime by `trocar eval {robot} --q ... --what jr` \
             with and without `--numeric`"
        )));
    };
    if samples == 0 {
        return Err(CliError("--samples must be at least 1".into()));
    }
    let generated = Generated::new(&desc).map_err(CliError::from_display)?;
    trocar_sim::verify::verify(
        &desc,
        &GeneratedCandidate(&generated),
        samples,
        seed,
        Tolerances::default(),
        progress,
    )
    .map_err(robot_error(&desc))
}

/// Runs `trocar verify`: prints the report; exit code 1 when a check fails.
pub(crate) fn run(robot: &str, samples: usize, seed: u64) -> Result<i32, CliError> {
    let report = with_progress("verify", |progress| verify(robot, samples, seed, progress))?;
    write_stdout(&report.to_string())?;
    if report.passed() {
        write_stdout("all checks passed\n")?;
        Ok(0)
    } else {
        for c in report.checks.iter().filter(|c| !c.passed()) {
            eprintln!("mismatch in `{}` at q = {:?}", c.name, c.worst_q);
        }
        Ok(1)
    }
}
