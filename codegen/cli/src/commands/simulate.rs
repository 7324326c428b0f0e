//! `trocar simulate`: the thesis's RCM scenarios and the closed-chain simulations.

use crate::args::{Method, OnOff, SpeedLimit};
use crate::output::{CliError, OutputKind, Outputs};
use crate::progress::with_progress;
use std::path::{Path, PathBuf};
use trocar_sim::plot::view3d;
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

/// The views of the arm `trocar simulate` draws (`--animate`, `--snapshot`, `--snapshot-times`;
/// `trocar_sim::plot::view3d`): serial arms only.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ArmViews {
    /// An animated GIF over the run.
    pub animate: Option<PathBuf>,
    /// A still image (`.png` or `.svg`).
    pub snapshot: Option<PathBuf>,
    /// The times (s) of the still image (default: start, middle, end).
    pub snapshot_times: Option<Vec<f64>>,
}

impl ArmViews {
    fn any(&self) -> bool {
        self.animate.is_some() || self.snapshot.is_some()
    }
}

/// Runs the simulation `scenario` (`1`, `2`, `3`, `4`, `exp421`, or a closed-chain scenario such
/// as `four-bar`), writes the trace to `csv` (the rows `csv_rows` selects), the figures to
/// `plot` (`.svg` or `.png`) and the views of the arm `views` when given, and returns the
/// summary `trocar simulate` prints to stderr. Every path is checked before the simulation runs
/// and the files are written whole, once it has succeeded (`output::Outputs`).
/// `options` and `views` apply to the RCM scenarios only.
pub fn simulate(
    scenario: &str,
    options: &RcmOptions,
    csv: Option<&Path>,
    csv_rows: simulation::CsvRows,
    plot: Option<&Path>,
    views: &ArmViews,
) -> Result<String, CliError> {
    let outputs = Outputs::check(&[
        ("--csv", csv, OutputKind::Data),
        ("--plot", plot, OutputKind::Figure),
        ("--animate", views.animate.as_deref(), OutputKind::Animation),
        ("--snapshot", views.snapshot.as_deref(), OutputKind::Figure),
    ])?;
    check_views(scenario, views)?;
    if options.method == Some(Method::All) {
        return compare_methods(scenario, options, csv, plot, views, outputs);
    }
    let run = run_simulation(scenario, options)?;
    if let Some(path) = csv {
        run.write_csv(outputs.temporary(path), csv_rows)
            .map_err(|e| outputs.explain(CliError(format!("--csv {}: {e}", path.display()))))?;
    }
    if let Some(path) = plot {
        run.write_plot(outputs.temporary(path))
            .map_err(|e| outputs.explain(CliError(format!("--plot {}: {e}", path.display()))))?;
    }
    if let AnyTrace::Rcm(trace) = &run.trace {
        write_views(trace, views, &outputs)?;
    }
    outputs.commit()?;
    Ok(run.summary)
}

/// `--method all`: runs the serial scenario with pinv, dls and fi, writes the figure comparing
/// them to `plot` (`trocar_sim::plot::write_comparison`) and returns the three summaries.
fn compare_methods(
    scenario: &str,
    options: &RcmOptions,
    csv: Option<&Path>,
    plot: Option<&Path>,
    views: &ArmViews,
    outputs: Outputs,
) -> Result<String, CliError> {
    if let Some(message) = method_all_conflict(csv.is_some(), views) {
        return Err(CliError(message));
    }
    serial_only(
        "--method all",
        scenario,
        "the methods are compared on the serial scenarios",
    )?;
    let mut summaries: Vec<String> = Vec::new();
    let mut traces = Vec::new();
    for method in [Method::Pinv, Method::Dls, Method::Fi] {
        let run = rcm_scenario(
            scenario,
            &RcmOptions {
                method: Some(method),
                ..*options
            },
        )?;
        // The scenario's note on the reference arm (a first line of its own) is printed once.
        let summary = match (summaries.first(), run.summary.split_once('\n')) {
            (Some(first), Some((note, rest)))
                if note.contains(" on the reference arm: ") && first.starts_with(note) =>
            {
                rest.to_string()
            }
            _ => run.summary,
        };
        summaries.push(summary);
        if let AnyTrace::Rcm(trace) = run.trace {
            traces.push(trace);
        }
    }
    if let Some(path) = plot {
        let refs: Vec<&simulation::Trace> = traces.iter().map(|t| &**t).collect();
        trocar_sim::plot::write_comparison(&refs, outputs.temporary(path))
            .map_err(|e| outputs.explain(CliError(format!("--plot {}: {e}", path.display()))))?;
    }
    outputs.commit()?;
    Ok(summaries.join("\n"))
}

/// Why `--method all` cannot be asked for with these outputs, if it cannot: `--csv`,
/// `--animate` and `--snapshot` each write one run.
pub(crate) fn method_all_conflict(csv: bool, views: &ArmViews) -> Option<String> {
    let option = [
        ("--csv", csv),
        ("--animate", views.animate.is_some()),
        ("--snapshot", views.snapshot.is_some()),
    ]
    .into_iter()
    .find_map(|(o, given)| given.then_some(o))?;
    Some(format!(
        "{option} writes one run; --method all compares pinv, dls and fi on one figure (--plot only)"
    ))
}

/// Refuses a closed-chain `scenario` for `option`, which `what` only on the serial scenarios
/// (named from `simulation::Scenario::ALL`).
fn serial_only(option: &str, scenario: &str, what: &str) -> Result<(), CliError> {
    if !closed_chain::scenario_names().contains(&scenario) {
        return Ok(());
    }
    let names: Vec<&str> = simulation::Scenario::ALL.iter().map(|s| s.name()).collect();
    Err(CliError(format!(
        "{option}: `{scenario}` is a closed-chain scenario; {what} only ({})",
        names.join(", ")
    )))
}

/// Refuses, before the run, views of a closed chain and snapshot times outside the scenario.
fn check_views(scenario: &str, views: &ArmViews) -> Result<(), CliError> {
    if !views.any() {
        return Ok(());
    }
    let option = if views.animate.is_some() {
        "--animate"
    } else {
        "--snapshot"
    };
    serial_only(
        option,
        scenario,
        "--animate and --snapshot draw the serial arms",
    )?;
    if let (Ok(which), Some(times)) = (
        simulation::Scenario::from_name(scenario),
        &views.snapshot_times,
    ) {
        let end = which.duration();
        if let Some(t) = times.iter().find(|t| !(0.0..=end).contains(*t)) {
            return Err(CliError(format!(
                "--snapshot-times {t}: scenario {scenario} runs from 0 to {end} s"
            )));
        }
    }
    Ok(())
}

/// Writes the views of the arm of an RCM run into the outputs' temporary files.
fn write_views(
    trace: &simulation::Trace,
    views: &ArmViews,
    outputs: &Outputs,
) -> Result<(), CliError> {
    if let Some(path) = &views.snapshot {
        let times = views
            .snapshot_times
            .clone()
            .unwrap_or_else(|| view3d::default_snapshot_times(trace));
        view3d::write_snapshot(trace, outputs.temporary(path), &times).map_err(|e| {
            outputs.explain(CliError(format!("--snapshot {}: {e}", path.display())))
        })?;
    }
    if let Some(path) = &views.animate {
        with_progress("animation", |progress| {
            view3d::write_animation(
                trace,
                outputs.temporary(path),
                view3d::ANIMATION_FRAMES,
                progress,
            )
        })
        .map_err(|e| outputs.explain(CliError(format!("--animate {}: {e}", path.display()))))?;
    }
    Ok(())
}

/// A finished simulation: what `trocar simulate` prints, and the trace it writes with `--csv`.
#[derive(Clone, Debug)]
pub struct SimulationRun {
    /// The summary `trocar simulate` prints to stderr.
    pub summary: String,
    trace: AnyTrace,
}

#[derive(Clone, Debug)]
enum AnyTrace {
    Rcm(Box<simulation::Trace>),
    ClosedChain(closed_chain::Trace),
}

impl SimulationRun {
    /// The trace as named columns (`t` first), as the CSV has them.
    pub fn columns(&self) -> Vec<(String, Vec<f64>)> {
        match &self.trace {
            AnyTrace::Rcm(t) => t.columns(),
            AnyTrace::ClosedChain(t) => t
                .columns
                .iter()
                .enumerate()
                .map(|(k, name)| (name.clone(), t.rows.iter().map(|r| r[k]).collect()))
                .collect(),
        }
    }

    fn write_csv(&self, path: &Path, rows: simulation::CsvRows) -> Result<(), String> {
        match &self.trace {
            AnyTrace::Rcm(t) => t.write_csv_rows(path, rows).map_err(|e| e.to_string()),
            AnyTrace::ClosedChain(t) => t.write_csv_rows(path, rows).map_err(|e| e.to_string()),
        }
    }

    fn write_plot(&self, path: &Path) -> Result<(), String> {
        match &self.trace {
            AnyTrace::Rcm(t) => trocar_sim::plot::write_figure(t, path).map_err(|e| e.to_string()),
            AnyTrace::ClosedChain(t) => {
                let written = match trocar_sim::plot::ImageFormat::of(path) {
                    Some(trocar_sim::plot::ImageFormat::Png) => t.plot_png(path),
                    _ => t.plot_svg(path),
                };
                written.map_err(|e| e.to_string())
            }
        }
    }
}

/// Runs the simulation `scenario` (as [`simulate`], without writing files) and returns its
/// summary and trace.
pub fn run_simulation(scenario: &str, options: &RcmOptions) -> Result<SimulationRun, CliError> {
    if closed_chain::scenario_names().contains(&scenario) {
        closed_chain_scenario(scenario, options)
    } else {
        rcm_scenario(scenario, options)
    }
}

/// Runs `trocar simulate`: the summary goes to stderr.
pub(crate) fn run(
    scenario: &str,
    options: &RcmOptions,
    csv: Option<&Path>,
    csv_rows: simulation::CsvRows,
    plot: Option<&Path>,
    views: &ArmViews,
) -> Result<i32, CliError> {
    eprintln!(
        "{}",
        simulate(scenario, options, csv, csv_rows, plot, views)?
    );
    Ok(0)
}

fn closed_chain_scenario(scenario: &str, options: &RcmOptions) -> Result<SimulationRun, CliError> {
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
    Ok(SimulationRun {
        summary: trace_summary(&trace.columns, &trace.rows),
        trace: AnyTrace::ClosedChain(trace),
    })
}

fn rcm_scenario(scenario: &str, options: &RcmOptions) -> Result<SimulationRun, CliError> {
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
        Some(Method::All) => {
            return Err(CliError(
                "--method all runs three simulations: it compares them on one figure (`trocar simulate SCENARIO --method all --plot OUT.png`), not as one run".into(),
            ))
        }
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
    Ok(SimulationRun {
        summary: out,
        trace: AnyTrace::Rcm(Box::new(trace)),
    })
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
