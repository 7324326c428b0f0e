//! Simulations: the thesis's RCM scenarios on the reference arm, the Panda laparoscope, and the
//! second source's closed chains; their traces as columns, CSV, figures and views of the arm.

use crate::error::{Error, Result};
use std::path::Path;
use trocar_sim::breathing::{self, PortMode};
use trocar_sim::plot::view3d;
use trocar_sim::simulation::{self, CsvRows, Method};
use trocar_sim::{closed_chain, plot, scene};

/// A joint speed limit for the RCM scenarios' controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpeedLimit {
    /// No limit (the thesis's controller).
    Unlimited,
    /// At most this speed (rad/s, m/s for a prismatic joint).
    At(f64),
}

impl SpeedLimit {
    /// Refuses a limit that is not a positive finite number (NaN would drop the limit, zero or a
    /// negative one would hold the arm still), by the rule [`crate::ControllerOptions`] follows
    /// for `max_joint_speed`, with its message: the scenarios, a user's trajectory and the
    /// controller refuse the same values in the same words.
    pub fn check(&self) -> Result<()> {
        match *self {
            SpeedLimit::Unlimited => Ok(()),
            SpeedLimit::At(v) => crate::ControllerOptions {
                max_joint_speed: Some(v),
                ..crate::ControllerOptions::default()
            }
            .check(),
        }
    }
}

/// How an RCM scenario's controller runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RcmOptions {
    /// Inverse used for `J^r` (default: the scenario's).
    pub method: Option<Method>,
    /// The drift correction `K_r e_r` (on by default).
    pub drift_correction: bool,
    /// The joint speed limit (default: [`simulation::MAX_JOINT_SPEED`]).
    pub max_joint_speed: Option<SpeedLimit>,
    /// How the controller knows a moving port (`panda-breathing` only; default: followed from
    /// the wall's force, [`PortMode::Estimated`]).
    pub port: Option<PortMode>,
}

impl Default for RcmOptions {
    /// The scenario's method, drift correction on, the default speed limit.
    fn default() -> Self {
        RcmOptions {
            method: None,
            drift_correction: true,
            max_joint_speed: None,
            port: None,
        }
    }
}

/// The names of the shipped scenarios: the RCM scenarios, then the closed-chain ones.
pub fn scenario_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = simulation::Scenario::ALL.iter().map(|s| s.name()).collect();
    names.extend_from_slice(closed_chain::scenario_names());
    names.extend_from_slice(scene::scenario_names());
    names.extend_from_slice(breathing::scenario_names());
    names
}

/// Whether `scenario` is a scene of several arms, each through its own port
/// ([`trocar_sim::scene`]).
pub fn is_scene(scenario: &str) -> bool {
    scene::is_scene(scenario)
}

/// Whether `scenario` is one of the closed-chain simulations.
pub fn is_closed_chain(scenario: &str) -> bool {
    closed_chain::scenario_names().contains(&scenario)
}

/// A finished simulation: its summary and its trace.
#[derive(Clone, Debug)]
pub struct SimulationRun {
    /// A few lines on the run: largest errors, drift, joint speeds, limits.
    pub summary: String,
    trace: AnyTrace,
}

#[derive(Clone, Debug)]
enum AnyTrace {
    Rcm(Box<simulation::Trace>),
    ClosedChain(closed_chain::MechanismTrace),
}

impl SimulationRun {
    /// A run of a serial robot from its trace and summary (how [`crate::simulate_trajectory`]
    /// returns a user's run).
    pub fn from_trace(trace: simulation::Trace, summary: String) -> Self {
        SimulationRun {
            summary,
            trace: AnyTrace::Rcm(Box::new(trace)),
        }
    }

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

    /// The RCM scenario's trace (`None` for a closed chain).
    pub fn rcm_trace(&self) -> Option<&simulation::Trace> {
        match &self.trace {
            AnyTrace::Rcm(t) => Some(t),
            AnyTrace::ClosedChain(_) => None,
        }
    }

    /// Writes the rows `rows` of the trace to `path` as CSV.
    pub fn write_csv(&self, path: &Path, rows: CsvRows) -> Result<(), String> {
        match &self.trace {
            AnyTrace::Rcm(t) => t.write_csv_rows(path, rows).map_err(|e| e.to_string()),
            AnyTrace::ClosedChain(t) => t.write_csv_rows(path, rows).map_err(|e| e.to_string()),
        }
    }

    /// Draws the run's figures to `path` (`.svg` or `.png`).
    pub fn write_plot(&self, path: &Path) -> Result<(), String> {
        match &self.trace {
            AnyTrace::Rcm(t) => plot::write_figure(t, path).map_err(|e| e.to_string()),
            AnyTrace::ClosedChain(t) => {
                let written = match plot::ImageFormat::of(path) {
                    Some(plot::ImageFormat::Png) => t.plot_png(path),
                    _ => t.plot_svg(path),
                };
                written.map_err(|e| e.to_string())
            }
        }
    }

    /// Draws the arm at `times` (s; default: start, middle, end) to `path` (`.png`/`.svg`).
    pub fn write_snapshot(&self, path: &Path, times: Option<&[f64]>) -> Result<(), String> {
        let trace = self.arm_trace()?;
        let times = times.map_or_else(|| view3d::default_snapshot_times(trace), <[f64]>::to_vec);
        view3d::write_snapshot(trace, path, &times).map_err(|e| e.to_string())
    }

    /// Animates the arm over the run into the GIF `path` (a scene: all its arms, their shafts,
    /// ports and the closest shafts); `progress` gets the fraction done.
    pub fn write_animation(
        &self,
        path: &Path,
        progress: &mut dyn FnMut(f64),
    ) -> Result<(), String> {
        if let AnyTrace::ClosedChain(t) = &self.trace {
            if is_scene(&t.name) {
                let geometry = scene::geometry(&t.name).map_err(|e| e.to_string())?;
                return trocar_sim::plot::scene_view::write_scene_animation(
                    t,
                    &geometry,
                    path,
                    trocar_sim::plot::scene_view::SCENE_FRAMES,
                    progress,
                )
                .map_err(|e| e.to_string());
            }
        }
        let trace = self.arm_trace()?;
        view3d::write_animation(trace, path, view3d::ANIMATION_FRAMES, progress)
            .map_err(|e| e.to_string())
    }

    fn arm_trace(&self) -> Result<&simulation::Trace, String> {
        self.rcm_trace()
            .ok_or_else(|| "the views of the arm draw the serial arms only".to_string())
    }
}

/// Refuses a closed-chain `scenario` for `argument` (the library's name of an option), which
/// does `what` only on the serial scenarios (named from [`simulation::Scenario::ALL`]).
pub fn serial_only(argument: &'static str, scenario: &str, what: &str) -> Result<()> {
    let kind = if is_closed_chain(scenario) {
        "a closed-chain scenario"
    } else if is_scene(scenario) {
        "a scene of several arms"
    } else {
        return Ok(());
    };
    let names: Vec<&str> = simulation::Scenario::ALL.iter().map(|s| s.name()).collect();
    Err(Error::argument(
        argument,
        format!("`{scenario}` is {kind}; {what} only ({})", names.join(", ")),
    ))
}

/// Runs the simulation `scenario` (`1`, `2`, `3`, `4`, `exp421`, `panda-laparoscope`, or a
/// closed-chain scenario such as `four-bar`); `options` apply to the RCM scenarios only;
/// `progress` gets the fraction done.
pub fn simulate(
    scenario: &str,
    options: &RcmOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    simulate_with_port_data(scenario, options, None, progress)
}

/// [`simulate`], with a moving-port scenario's known port fed forward from measured data: a
/// CSV `t,x,y,z` of the port's displacement from where it was at the start (base frame, m),
/// interpolated between rows, its velocity the rows' differences (`--port-trajectory`; it needs
/// `--port known`, the default with it). The data must cover the run.
pub fn simulate_with_port_data(
    scenario: &str,
    options: &RcmOptions,
    port_data: Option<&Path>,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    if let Some(path) = port_data {
        if !breathing::is_moving_port(scenario) {
            return Err(Error::argument(
                "port_trajectory",
                format!(
                    "`{scenario}` has a port known exactly; a port's trajectory is fed forward in {}",
                    breathing::scenario_names().join(" and ")
                ),
            ));
        }
        if !matches!(options.port, None | Some(PortMode::Known)) {
            return Err(Error::argument(
                "port_trajectory",
                "a measured port trajectory is what the known port follows: --port known (or none)",
            ));
        }
        let data = crate::Trajectory::from_csv(path)?;
        let shown = path.display();
        let duration = breathing::duration_of(scenario);
        let (first, last) = (data.t[0], data.t[data.t.len() - 1]);
        if first > 0.0 || last < duration {
            return Err(Error::Input(format!(
                "{shown}: the port's trajectory covers {first} s to {last} s; the run lasts 0 s to {duration} s"
            )));
        }
        let known = |t: f64| {
            let at = data.at(t, &nalgebra::Matrix3::identity());
            (
                nalgebra::Vector3::from(at.position),
                nalgebra::Vector3::from(at.velocity),
            )
        };
        let options = RcmOptions {
            port: Some(PortMode::Known),
            ..*options
        };
        return breathing_scenario(scenario, &options, Some(&known), progress);
    }
    if options.port.is_some() && !breathing::is_moving_port(scenario) {
        return Err(Error::argument(
            "port",
            format!(
                "`{scenario}` has a port known exactly; the port's modes are those of {}",
                breathing::scenario_names().join(" and ")
            ),
        ));
    }
    if breathing::is_moving_port(scenario) {
        breathing_scenario(scenario, options, None, progress)
    } else if is_closed_chain(scenario) {
        closed_chain_scenario(scenario, options, progress)
    } else if is_scene(scenario) {
        scene_scenario(scenario, options, progress)
    } else {
        rcm_scenario(scenario, options, progress)
    }
}

/// Runs the serial scenario `scenario` with pinv, DLS, FI and the QP in turn (for the figure comparing
/// them, [`plot::write_comparison`]); the scenario's note on the reference arm is given once.
pub fn compare_methods(
    scenario: &str,
    options: &RcmOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Vec<SimulationRun>> {
    serial_only(
        "method",
        scenario,
        "the methods are compared on the serial scenarios",
    )?;
    let mut runs: Vec<SimulationRun> = Vec::new();
    for (k, method) in Method::ALL.into_iter().enumerate() {
        let mut part = |f: f64| progress((k as f64 + f) / Method::ALL.len() as f64);
        let mut run = rcm_scenario(
            scenario,
            &RcmOptions {
                method: Some(method),
                ..*options
            },
            &mut part,
        )?;
        // The scenario's note on the reference arm (a first line of its own) is given once.
        if let (Some(first), Some((note, rest))) = (runs.first(), run.summary.split_once('\n')) {
            if note.contains(" on the reference arm: ") && first.summary.starts_with(note) {
                run.summary = rest.to_string();
            }
        }
        runs.push(run);
    }
    Ok(runs)
}

fn closed_chain_scenario(
    scenario: &str,
    options: &RcmOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    if *options != RcmOptions::default() {
        return Err(Error::Input(format!(
            "`{scenario}` is a closed-chain scenario: the method, the drift correction and the joint speed limit apply to the RCM scenarios only"
        )));
    }
    let trace = closed_chain::simulate(
        scenario,
        &closed_chain::SimOptions::default(),
        Some(progress),
    )
    .map_err(|e| Error::Simulation(e.to_string()))?;
    Ok(SimulationRun {
        summary: trace_summary(&trace.columns, &trace.rows),
        trace: AnyTrace::ClosedChain(trace),
    })
}

/// `panda-breathing` with the port known as `options.port` asks (the QP step with the URDF's
/// limits and the drift correction: no other option).
fn breathing_scenario(
    scenario: &str,
    options: &RcmOptions,
    known: Option<breathing::KnownPort<'_>>,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    let mode = options.port.unwrap_or(PortMode::Estimated);
    let alone = RcmOptions {
        port: options.port,
        ..RcmOptions::default()
    };
    let qp_only = RcmOptions {
        method: Some(Method::Qp),
        ..alone
    };
    if *options != alone && *options != qp_only {
        return Err(Error::Input(format!(
            "`{scenario}` runs the QP step with the drift correction and the URDF's limits \
             (--method qp or none, --port fixed|known|estimated|registered; no other option)"
        )));
    }
    let trace = breathing::simulate_with(scenario, mode, known, progress)
        .map_err(|e| Error::Simulation(e.to_string()))?;
    let last = |name: &str| trace.last(name).unwrap_or(f64::NAN);
    let peak = |name: &str| {
        trace
            .column(name)
            .unwrap_or_default()
            .into_iter()
            .fold(0.0, f64::max)
    };
    let summary = format!(
        "scenario {scenario} (qp, the port {}):\n  peak force of the wall on the shaft {:.3} N (at the end {:.3} N)\n  the shaft at most {:.3e} m from the true port, {:.3e} m from the port held\n  the port held at the end {:.3e} m from the true port\n  the tip at most {:.3e} m from its target",
        match mode {
            PortMode::Fixed => "fixed where it was at the start",
            PortMode::Known if known.is_some() => "known from its measured trajectory, fed forward",
            PortMode::Known => "known: its trajectory fed forward",
            PortMode::Estimated => "followed from the wall's force",
            PortMode::Registered =>
                "registered from the shaft's lines while the instrument pivoted, no force measured",
        },
        peak("port_force"),
        last("port_force"),
        peak("port_offset"),
        peak("rcm_drift"),
        last("estimate_error"),
        peak("ep_norm"),
    );
    Ok(SimulationRun {
        summary,
        trace: AnyTrace::ClosedChain(trace),
    })
}

fn scene_scenario(
    scenario: &str,
    options: &RcmOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    let qp_only = RcmOptions {
        method: Some(Method::Qp),
        ..RcmOptions::default()
    };
    if *options != RcmOptions::default() && *options != qp_only {
        return Err(Error::Input(format!(
            "`{scenario}` is a scene of several arms: it runs the QP step with the drift \
             correction and the URDF's limits (--method qp or none; no other option)"
        )));
    }
    let trace =
        scene::simulate(scenario, true, progress).map_err(|e| Error::Simulation(e.to_string()))?;
    let column = |name: &str| trace.column(name).unwrap_or_default();
    let max = |v: Vec<f64>| v.into_iter().fold(0.0, f64::max);
    let arms: Vec<&str> = trace
        .columns
        .iter()
        .filter_map(|c| c.strip_suffix(".rcm_drift"))
        .collect();
    let mut summary = format!(
        "scene {scenario} (qp, drift correction on, {} arms: {}):",
        arms.len(),
        arms.join(", ")
    );
    if trace.columns.iter().any(|c| c == "min_shaft_distance") {
        let min_distance = column("min_shaft_distance")
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let active = column("coupling_active")
            .iter()
            .filter(|v| **v > 0.0)
            .count();
        summary += &format!(
            "\n  min shaft distance {min_distance:.3e} m (safety {:.3e} m), the couplings \
             active in {active} of {} rows",
            scene::safety(scenario).map_err(|e| Error::Simulation(e.to_string()))?,
            trace.rows.len()
        );
    }
    for arm in &arms {
        let tip = column(&format!("{arm}.ep_norm"));
        summary += &format!(
            "\n  {arm}: max drift {:.3e} m, max tip error {:.3e} m (final {:.3e} m)",
            max(column(&format!("{arm}.rcm_drift"))),
            max(tip.clone()),
            tip.last().copied().unwrap_or(f64::NAN)
        );
    }
    if trace.columns.iter().any(|c| c == "endoscope.view_error") {
        summary += &format!(
            "\n  endoscope's view axis off the instruments' midpoint: max {:.3e} rad \
             (tolerance {:.3e} rad)",
            max(column("endoscope.view_error")),
            scene::view_tolerance().map_err(|e| Error::Simulation(e.to_string()))?
        );
    }
    Ok(SimulationRun {
        summary,
        trace: AnyTrace::ClosedChain(trace),
    })
}

fn rcm_scenario(
    scenario: &str,
    options: &RcmOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<SimulationRun> {
    let Ok(which) = simulation::Scenario::from_name(scenario) else {
        return Err(Error::Input(format!(
            "unknown scenario `{scenario}` (expected 1, 2, 3, 4, exp421, panda-laparoscope, or one of: {}, {})",
            closed_chain::scenario_names().join(", "),
            scene::scenario_names().join(", ")
        )));
    };
    let method = options.method.unwrap_or_else(|| which.default_method());
    let mut config = simulation::ScenarioConfig::new(which)
        .with_method(method)
        .with_drift_correction(options.drift_correction);
    match options.max_joint_speed {
        Some(SpeedLimit::Unlimited) => config = config.with_max_joint_speed(None),
        Some(limit @ SpeedLimit::At(v)) => {
            limit.check()?;
            config = config.with_max_joint_speed(Some(v));
        }
        None => {}
    }
    let trace = simulation::run(&config, progress).map_err(|e| Error::Simulation(e.to_string()))?;
    let s = trace.summary();
    let mut out = String::new();
    if let Some(note) = which.deviation() {
        out += &format!("scenario {scenario} on the reference arm: {note} (see docs/CONTROL.md)\n");
    }
    out += &format!(
        "scenario {scenario} ({method:?}, drift correction {}, joint speed limit {}):\n  \
         max |vr - dv| after the first step {:.3e} m/s\n  \
         max RCM drift {:.3e} m (final {:.3e} m)\n  \
         max position error {:.3e} m (after 10 s {:.3e} m), max orientation error {:.3e}\n  \
         peak joint speed {:.3e} rad/s, min w_r {:.3e}, min w_i {:.3e}, min |q7| {:.3e} rad\n  \
         l_a in [{:.4}, {:.4}] m{}",
        if options.drift_correction {
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

/// The reference the Panda laparoscope scenario (`panda-laparoscope`) tracks at time `t` (s):
/// the tip's desired pose and velocities in the base frame, from the arm's pose at its start
/// configuration [`simulation::PANDA_Q0`] — what a user's controller loop is given to replay the
/// scenario step by step.
pub fn panda_target(t: f64) -> Result<crate::Target> {
    if !t.is_finite() {
        return Err(Error::Input(format!("t = {t}: must be finite")));
    }
    let robot = crate::Robot::load("panda-laparoscope")?;
    let model = robot.numeric()?.model();
    let chain = model.to_chain::<7>().map_err(|e| Error::Robot {
        file: None,
        message: e.to_string(),
    })?;
    let g0 = chain.forward_kinematics(&nalgebra::SVector::<f64, 7>::from(simulation::PANDA_Q0));
    let r = simulation::panda_reference(t, &g0);
    Ok(crate::Target {
        position: r.position.into(),
        rotation: Some(std::array::from_fn(|i| {
            std::array::from_fn(|j| r.rotation[(i, j)])
        })),
        velocity: r.velocity.into(),
        angular_velocity: r.angular_velocity.into(),
    })
}
