//! `trocar simulate`: the thesis's RCM scenarios and the closed-chain simulations.

use crate::args::{Method, OnOff};
use crate::output::{CliError, OutputKind, Outputs};
use crate::progress::with_progress;
use std::path::Path;
use trocar_sim::{closed_chain, simulation};

/// Runs the simulation `scenario` (`1`, `2`, `3`, `4`, `exp421`, or a closed-chain scenario such
/// as `four-bar`), writes the trace to `csv` and the figures to `plot` (`.svg` or `.png`) when
/// given, and returns the summary `trocar simulate` prints to stderr. Both paths are checked
/// before the simulation runs and the files are written whole, once it has succeeded
/// (`output::Outputs`).
/// `method` (default: the scenario's) and `drift_correction` apply to the RCM scenarios only.
pub fn simulate(
    scenario: &str,
    method: Option<Method>,
    drift_correction: OnOff,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<String, CliError> {
    let outputs = Outputs::check(&[
        ("--csv", csv, OutputKind::Data),
        ("--plot", plot, OutputKind::Figure),
    ])?;
    let csv = csv.map(|p| outputs.temporary(p).to_path_buf());
    let plot = plot.map(|p| outputs.temporary(p).to_path_buf());
    let summary = if closed_chain::scenario_names().contains(&scenario) {
        closed_chain_scenario(
            scenario,
            method,
            drift_correction,
            csv.as_deref(),
            plot.as_deref(),
        )
    } else {
        rcm_scenario(
            scenario,
            method,
            drift_correction,
            csv.as_deref(),
            plot.as_deref(),
        )
    }
    .map_err(|e| outputs.explain(e))?;
    outputs.commit()?;
    Ok(summary)
}

/// Runs `trocar simulate`: the summary goes to stderr.
pub(crate) fn run(
    scenario: &str,
    method: Option<Method>,
    drift_correction: OnOff,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<i32, CliError> {
    eprintln!(
        "{}",
        simulate(scenario, method, drift_correction, csv, plot)?
    );
    Ok(0)
}

fn closed_chain_scenario(
    scenario: &str,
    method: Option<Method>,
    drift_correction: OnOff,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<String, CliError> {
    if method.is_some() || drift_correction == OnOff::Off {
        return Err(CliError(format!(
            "`{scenario}` is a closed-chain scenario: --method and --drift-correction apply to the RCM scenarios only"
        )));
    }
    let trace = with_progress(scenario, |progress| {
        closed_chain::simulate(
            scenario,
            &closed_chain::SimOptions::default(),
            Some(progress),
        )
    })
    .map_err(CliError::from_display)?;
    if let Some(path) = csv {
        trace
            .write_csv(path)
            .map_err(|e| CliError(format!("--csv {}: {e}", path.display())))?;
    }
    if let Some(path) = plot {
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let written = if png {
            trace.plot_png(path)
        } else {
            trace.plot_svg(path)
        };
        written.map_err(|e| CliError(format!("--plot {}: {e}", path.display())))?;
    }
    Ok(trace_summary(&trace.columns, &trace.rows))
}

fn rcm_scenario(
    scenario: &str,
    method: Option<Method>,
    drift_correction: OnOff,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<String, CliError> {
    let Ok(which) = simulation::Scenario::from_name(scenario) else {
        return Err(CliError(format!(
            "unknown scenario `{scenario}` (expected 1, 2, 3, 4, exp421, panda-laparoscope, or one of: {})",
            closed_chain::scenario_names().join(", ")
        )));
    };
    let method = match method {
        Some(Method::Pinv) => simulation::Method::Pinv,
        Some(Method::Dls) => simulation::Method::Dls,
        Some(Method::Fi) => simulation::Method::Fi,
        None => which.default_method(),
    };
    let config = simulation::ScenarioConfig::new(which)
        .with_method(method)
        .with_drift_correction(drift_correction == OnOff::On);
    let trace = with_progress(&format!("scenario {scenario}"), |progress| {
        simulation::run(&config, progress)
    })
    .map_err(CliError::from_display)?;
    if let Some(path) = csv {
        trace
            .write_csv(path)
            .map_err(|e| CliError(format!("--csv {}: {e}", path.display())))?;
    }
    if let Some(path) = plot {
        trocar_sim::plot::write_figure(&trace, path)
            .map_err(|e| CliError(format!("--plot {}: {e}", path.display())))?;
    }
    let s = trace.summary();
    let mut out = String::new();
    if let Some(note) = which.deviation() {
        out += &format!(
            "scenario {scenario} on the reference arm: {note} (see runtime/sim/CONTROL.md)\n"
        );
    }
    out += &format!(
        "scenario {scenario} ({method:?}, drift correction {}):\n  \
         max |vr - dv| after the first step {:.3e} m/s\n  \
         max RCM drift {:.3e} m (final {:.3e} m)\n  \
         max position error {:.3e} m (after 10 s {:.3e} m), max orientation error {:.3e}\n  \
         peak joint speed {:.3e} rad/s, min w_r {:.3e}, min w_i {:.3e}, min |q7| {:.3e} rad\n  \
         l_a in [{:.4}, {:.4}] m{}",
        if drift_correction == OnOff::On {
            "on"
        } else {
            "off"
        },
        s.max_rcm_velocity_error,
        s.max_drift,
        s.final_drift,
        s.max_ep,
        s.max_ep_after_10s,
        s.max_eo,
        s.peak_qd,
        s.min_w_r,
        s.min_w_i,
        s.min_abs_q7,
        s.l_a_range.0,
        s.l_a_range.1,
        s.min_limit_margin.map_or(String::new(), |m| format!(
            "\n  closest approach to a joint limit {m:.4} rad{}",
            if m < 0.0 { " (BEYOND A LIMIT)" } else { "" }
        )),
    );
    Ok(out)
}

/// One line a column: the final value and the largest magnitude.
fn trace_summary(columns: &[String], rows: &[Vec<f64>]) -> String {
    let mut out = String::from("column            final        max |.|");
    for (k, name) in columns.iter().enumerate().skip(1) {
        let last = rows.last().map_or(f64::NAN, |r| r[k]);
        let max = rows.iter().map(|r| r[k].abs()).fold(0.0, f64::max);
        out += &format!("\n{name:<12} {last:>12.4e} {max:>12.4e}");
    }
    out
}
