//! `trocar simulate`: the thesis's RCM scenarios and the closed-chain simulations
//! ([`trocar_api::simulate`]), their CSV, figures and views of the arm written atomically.

use crate::args::MethodArg;
use crate::output::{write_stderr, CliError, OutputKind, Outputs};
use crate::progress::with_progress;
use std::path::{Path, PathBuf};
use trocar_api::simulate::{self as sim, RcmOptions, SimulationRun};
use trocar_api::{CsvRows, Error};

/// The views of the arm `trocar simulate` draws (`--animate`, `--snapshot`, `--snapshot-times`):
/// serial arms only.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct ArmViews {
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

/// Why `--method all` cannot be asked for with these outputs, if it cannot: `--csv`,
/// `--animate` and `--snapshot` each write one run.
pub(crate) fn method_all_conflict(csv: bool, animate: bool, snapshot: bool) -> Option<String> {
    let option = [
        ("--csv", csv),
        ("--animate", animate),
        ("--snapshot", snapshot),
    ]
    .into_iter()
    .find_map(|(o, given)| given.then_some(o))?;
    Some(format!(
        "{option} writes one run; --method all compares pinv, dls and fi on one figure (--plot only)"
    ))
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
    sim::serial_only(
        option,
        scenario,
        "--animate and --snapshot draw the serial arms",
    )?;
    if let (Ok(which), Some(times)) = (
        trocar_sim::simulation::Scenario::from_name(scenario),
        &views.snapshot_times,
    ) {
        let end = which.duration();
        if let Some(t) = times.iter().find(|t| !(0.0..=end).contains(*t)) {
            return Err(Error::Input(format!(
                "--snapshot-times {t}: scenario {scenario} runs from 0 to {end} s"
            )));
        }
    }
    Ok(())
}

/// Runs `trocar simulate`: every output path is checked before the simulation runs, the files
/// are written whole once it has succeeded, and the summary goes to stderr.
pub(crate) fn run(
    scenario: &str,
    method: Option<MethodArg>,
    options: &RcmOptions,
    csv: Option<&Path>,
    csv_rows: CsvRows,
    plot: Option<&Path>,
    views: &ArmViews,
) -> Result<i32, CliError> {
    let outputs = Outputs::check(
        &[
            ("--csv", csv, OutputKind::Data),
            ("--plot", plot, OutputKind::Figure),
            ("--animate", views.animate.as_deref(), OutputKind::Animation),
            ("--snapshot", views.snapshot.as_deref(), OutputKind::Figure),
        ],
        &[],
    )?;
    check_views(scenario, views)?;
    let summary = if method == Some(MethodArg::All) {
        if let Some(message) = method_all_conflict(
            csv.is_some(),
            views.animate.is_some(),
            views.snapshot.is_some(),
        ) {
            return Err(Error::Input(message));
        }
        let runs = with_progress(&format!("scenario {scenario}"), |progress| {
            sim::compare_methods(scenario, options, progress)
        })?;
        if let Some(path) = plot {
            let traces: Vec<&trocar_sim::simulation::Trace> =
                runs.iter().filter_map(SimulationRun::rcm_trace).collect();
            trocar_sim::plot::write_comparison(&traces, outputs.temporary(path))
                .map_err(|e| outputs.explain(format!("--plot {}: {e}", path.display())))?;
        }
        runs.iter()
            .map(|r| r.summary.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    } else {
        let label = if sim::is_closed_chain(scenario) {
            scenario.to_string()
        } else {
            format!("scenario {scenario}")
        };
        let run = with_progress(&label, |progress| {
            sim::simulate(scenario, options, progress)
        })?;
        let written = |option: &str, path: &Path, r: Result<(), String>| {
            r.map_err(|e| outputs.explain(format!("{option} {}: {e}", path.display())))
        };
        if let Some(path) = csv {
            written(
                "--csv",
                path,
                run.write_csv(outputs.temporary(path), csv_rows),
            )?;
        }
        if let Some(path) = plot {
            written("--plot", path, run.write_plot(outputs.temporary(path)))?;
        }
        if let Some(path) = &views.snapshot {
            written(
                "--snapshot",
                path,
                run.write_snapshot(outputs.temporary(path), views.snapshot_times.as_deref()),
            )?;
        }
        if let Some(path) = &views.animate {
            let r = with_progress("animation", |progress| {
                run.write_animation(outputs.temporary(path), progress)
            });
            written("--animate", path, r)?;
        }
        run.summary
    };
    outputs.commit()?;
    write_stderr(&format!("{summary}\n"));
    Ok(0)
}

/// What `trocar simulate ROBOT --trajectory PATH.csv` is given besides the robot and the path.
#[derive(Clone, Debug)]
pub(crate) struct UserRun {
    /// `--method`.
    pub method: Option<MethodArg>,
    /// The controller's options (`--drift-correction`, `--max-joint-speed`).
    pub options: RcmOptions,
    /// `--q0`.
    pub q0: Option<Vec<f64>>,
    /// `--trocar`.
    pub trocar: Option<Vec<f64>>,
    /// `--csv`.
    pub csv: Option<PathBuf>,
    /// `--plot`, `--animate`, `--snapshot`: not drawn for a user's trajectory yet.
    pub plot: Option<PathBuf>,
    /// See `plot`.
    pub animate: Option<PathBuf>,
    /// See `plot`.
    pub snapshot: Option<PathBuf>,
}

/// Runs `trocar simulate ROBOT --trajectory PATH.csv`: the robot's constrained controller along
/// the user's tip path ([`trocar_api::simulate_trajectory`]); the CSV is written whole once the
/// run has succeeded, the summary goes to stderr.
pub(crate) fn run_trajectory(robot: &str, path: &Path, user: &UserRun) -> Result<i32, CliError> {
    for (option, given) in [
        ("--plot", user.plot.is_some()),
        ("--animate", user.animate.is_some()),
        ("--snapshot", user.snapshot.is_some()),
    ] {
        if given {
            return Err(Error::Input(format!(
                "{option}: the figures and views of the arm are drawn for the shipped scenarios;                  with --trajectory, write --csv and plot its columns"
            )));
        }
    }
    // The files the command reads: the trajectory, the description and its URDF.
    let mut reads = vec![path.to_path_buf()];
    if Path::new(robot).exists() {
        reads.extend(trocar_model::description::RobotDescription::files_read(
            robot,
        ));
    }
    let outputs = Outputs::check(&[("--csv", user.csv.as_deref(), OutputKind::Data)], &reads)?;
    let robot = trocar_api::Robot::load(robot)?;
    let trajectory = trocar_api::Trajectory::from_csv(path)?;
    let q0 = user.q0.clone().ok_or_else(|| {
        Error::Input(format!(
            "--trajectory: give the start configuration with --q0 q1,...,q{} (all joints of `{}`, base first)",
            robot.dof(),
            robot.name()
        ))
    })?;
    let trocar = match &user.trocar {
        None => None,
        Some(v) => {
            let [x, y, z] = v.as_slice() else {
                return Err(Error::Input(format!(
                    "--trocar: three values x,y,z (m, base frame), got {}",
                    v.len()
                )));
            };
            if let Err((k, problem)) = trocar_model::validity::check_all(v) {
                return Err(Error::Input(format!("--trocar: value {} {problem}", k + 1)));
            }
            Some([*x, *y, *z])
        }
    };
    let mut controller = trocar_api::ControllerOptions::default();
    match user.method {
        Some(MethodArg::All) => {
            return Err(Error::Input(
                "--method all compares the shipped scenarios; with --trajectory give one method"
                    .into(),
            ))
        }
        Some(m) => controller.method = m.method().unwrap_or(controller.method),
        None => {}
    }
    if !user.options.drift_correction {
        controller.kr = 0.0;
    }
    match user.options.max_joint_speed {
        Some(trocar_api::SpeedLimit::Unlimited) => controller.max_joint_speed = None,
        Some(trocar_api::SpeedLimit::At(v)) => controller.max_joint_speed = Some(v),
        None => {}
    }
    let options = trocar_api::TrajectoryOptions {
        q0,
        trocar,
        controller,
        dt: 0.002,
    };
    let run = with_progress("trajectory", |progress| {
        trocar_api::simulate_trajectory(&robot, &trajectory, &options, progress)
    })?;
    if let Some(csv) = &user.csv {
        run.write_csv(outputs.temporary(csv))
            .map_err(|e| outputs.explain(format!("--csv {}: {e}", csv.display())))?;
    }
    outputs.commit()?;
    write_stderr(&format!("{}\n", run.summary));
    Ok(0)
}
