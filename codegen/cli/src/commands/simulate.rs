//! `trocar simulate`: the thesis's RCM scenarios and the closed-chain simulations.

use crate::args::{Method, OnOff, SpeedLimit};
use crate::output::{CliError, OutputKind, Outputs};
use crate::progress::with_progress;
use std::path::Path;
use trocar_sim::{closed_chain, simulation};

/// How an RCM scenario's controller runs (`trocar simulate`'s options).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RcmOptions {
    /// Inverse used for `J^r` (default: the scenario's).
    pub method: Option<Method>,
    /// The drift correction `K_r e_r`.
    pub drift_correction: OnOff,
    /// The joint speed limit (default: `trocar_sim::simulation::MAX_JOINT_SPEED`).
    pub max_joint_speed: Option<SpeedLimit>,
}

impl Default for RcmOptions {
    /// The scenario's method, drift correction on, the default speed limit.
    fn default() -> Self {
        RcmOptions {
            method: None,
            drift_correction: OnOff::On,
            max_joint_speed: None,
        }
    }
}

/// Runs the simulation `scenario` (`1`, `2`, `3`, `4`, `exp421`, or a closed-chain scenario such
/// as `four-bar`), writes the trace to `csv` and the figures to `plot` (`.svg` or `.png`) when
/// given, and returns the summary `trocar simulate` prints to stderr. Both paths are checked
/// before the simulation runs and the files are written whole, once it has succeeded
/// (`output::Outputs`).
/// `options` apply to the RCM scenarios only.
pub fn simulate(
    scenario: &str,
    options: &RcmOptions,
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
        closed_chain_scenario(scenario, options, csv.as_deref(), plot.as_deref())
    } else {
        rcm_scenario(scenario, options, csv.as_deref(), plot.as_deref())
    }
    .map_err(|e| outputs.explain(e))?;
    outputs.commit()?;
    Ok(summary)
}

/// Runs `trocar simulate`: the summary goes to stderr.
pub(crate) fn run(
    scenario: &str,
    options: &RcmOptions,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<i32, CliError> {
    eprintln!("{}", simulate(scenario, options, csv, plot)?);
    Ok(0)
}

fn closed_chain_scenario(
    scenario: &str,
    options: &RcmOptions,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<String, CliError> {
    if *options != RcmOptions::default() {
        return Err(CliError(format!(
            "`{scenario}` is a closed-chain scenario: --method, --drift-correction and --max-joint-speed apply to the RCM scenarios only"
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
    options: &RcmOptions,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<String, CliError> {
    let RcmOptions {
        method,
        drift_correction,
        max_joint_speed,
    } = *options;
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
    let mut config = simulation::ScenarioConfig::new(which)
        .with_method(method)
        .with_drift_correction(drift_correction == OnOff::On);
    match max_joint_speed {
        Some(SpeedLimit::None) => config = config.with_max_joint_speed(None),
        Some(SpeedLimit::At(v)) => config = config.with_max_joint_speed(Some(v)),
        None => {}
    }
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
        "scenario {scenario} ({method:?}, drift correction {}, joint speed limit {}):\n  \
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
        config
            .max_joint_speed
            .map_or("none".to_string(), |v| format!("{v} rad/s")),
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
