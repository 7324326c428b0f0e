//! `trocar simulate`: the thesis's RCM scenarios and the closed-chain simulations
//! ([`trocar_api::simulate`]), their CSV, figures and views of the arm written atomically.

use crate::args::{method_all_conflict, ALL_METHODS};
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

/// Refuses, before the run, views of a closed chain and snapshot times outside the scenario.
fn check_views(scenario: &str, views: &ArmViews) -> Result<(), CliError> {
    if !views.any() {
        return Ok(());
    }
    if sim::is_scene(scenario) {
        // A scene is animated (all its arms); its stills are not drawn.
        if views.snapshot.is_some() {
            return Err(Error::argument(
                "snapshot",
                format!(
                    "`{scenario}` is a scene of several arms: --animate draws it, --snapshot \
                     draws one serial arm"
                ),
            ));
        }
        return Ok(());
    }
    let option = if views.animate.is_some() {
        "animate"
    } else {
        "snapshot"
    };
    sim::serial_only(
        option,
        scenario,
        "--animate and --snapshot draw the serial arms",
    )?;
    if let (Ok(which), Some(times)) = (
        trocar_api::Scenario::from_name(scenario),
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
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    scenario: &str,
    method: Option<String>,
    options: &RcmOptions,
    port_trajectory: Option<&Path>,
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
    let summary = if method.as_deref() == Some(ALL_METHODS) {
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
            let traces: Vec<&trocar_api::Trace> =
                runs.iter().filter_map(SimulationRun::rcm_trace).collect();
            trocar_api::write_comparison(&traces, outputs.temporary(path))
                .map_err(|e| outputs.explain(format!("--plot {}: {e}", path.display())))?;
        }
        runs.iter()
            .map(|r| r.summary.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    } else {
        let label = if sim::is_closed_chain(scenario) {
            scenario.to_string()
        } else if sim::is_scene(scenario) {
            format!("scene {scenario}")
        } else {
            format!("scenario {scenario}")
        };
        let run = with_progress(&label, |progress| {
            sim::simulate_with_port_data(scenario, options, port_trajectory, progress)
        })?;
        write_run(&outputs, &run, csv, csv_rows, plot, views)?;
        run.summary
    };
    outputs.commit()?;
    write_stderr(&format!("{summary}\n"));
    Ok(0)
}

/// Writes a finished run's outputs to the temporary files of `outputs` (committed by the
/// caller): the CSV, the figures, the still and the animation of the arm.
fn write_run(
    outputs: &Outputs,
    run: &SimulationRun,
    csv: Option<&Path>,
    csv_rows: CsvRows,
    plot: Option<&Path>,
    views: &ArmViews,
) -> Result<(), CliError> {
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
    Ok(())
}

/// What `trocar simulate ROBOT --trajectory PATH.csv` is given besides the robot and the path.
#[derive(Clone, Debug)]
pub(crate) struct UserRun {
    /// `--method`.
    pub method: Option<String>,
    /// The controller's options (`--drift-correction`, `--max-joint-speed`).
    pub options: RcmOptions,
    /// `--q0`.
    pub q0: Option<Vec<f64>>,
    /// `--trocar`.
    pub trocar: Option<Vec<f64>>,
    /// `--csv`.
    pub csv: Option<PathBuf>,
    /// `--every`, `--dt`: the rows of `--csv`.
    pub csv_rows: CsvRows,
    /// `--plot`.
    pub plot: Option<PathBuf>,
    /// `--animate`, `--snapshot`, `--snapshot-times`.
    pub views: ArmViews,
}

/// Runs `trocar simulate ROBOT --trajectory PATH.csv` (or `trocar simulate ROBOT.toml` when the
/// description has a `[simulation]` section that names the path; the flags override the
/// section): the robot's constrained controller along the user's tip path ([`trocar_api::simulate_trajectory`]); the CSV, the figures and the views
/// of the arm are checked before the run and written whole once it has succeeded, the summary
/// goes to stderr.
pub(crate) fn run_trajectory(
    robot: &str,
    path: Option<&Path>,
    user: &UserRun,
) -> Result<i32, CliError> {
    let name = robot;
    let robot = trocar_api::Robot::load(name)?;
    if robot.description().is_none() {
        return Err(Error::Unsupported(format!(
            "`{name}` is a closed mechanism: a trajectory drives a serial robot's tip"
        )));
    }
    let section = robot.simulation_section()?.unwrap_or_default();
    let trocar = match &user.trocar {
        None => None,
        Some(v) => {
            let [x, y, z] = v.as_slice() else {
                return Err(Error::Input(format!(
                    "--trocar: three values x,y,z (m, base frame), got {}",
                    v.len()
                )));
            };
            if let Err((k, problem)) = trocar_api::validity::check_all(v) {
                return Err(Error::Input(format!("--trocar: value {} {problem}", k + 1)));
            }
            Some([*x, *y, *z])
        }
    };
    let all = user.method.as_deref() == Some(ALL_METHODS);
    if all {
        if let Some(message) = method_all_conflict(
            user.csv.is_some(),
            user.views.animate.is_some(),
            user.views.snapshot.is_some(),
        ) {
            return Err(Error::Input(message));
        }
    }
    let request = trocar_api::RunRequest {
        trajectory: path.map(Path::to_path_buf),
        q0: user.q0.clone(),
        trocar,
        method: crate::args::method(user.method.as_deref()),
        drift_correction: (!user.options.drift_correction).then_some(false),
        max_joint_speed: user.options.max_joint_speed,
    };
    // The files the command reads: the trajectory, the description and its URDF; every output
    // is checked against them before anything else is asked of the run.
    let mut reads: Vec<PathBuf> = request
        .trajectory
        .iter()
        .chain(&section.trajectory)
        .take(1)
        .cloned()
        .collect();
    if Path::new(name).is_file() {
        reads.extend(trocar_api::files_read(name));
    }
    let outputs = Outputs::check(
        &[
            ("--csv", user.csv.as_deref(), OutputKind::Data),
            ("--plot", user.plot.as_deref(), OutputKind::Figure),
            (
                "--animate",
                user.views.animate.as_deref(),
                OutputKind::Animation,
            ),
            (
                "--snapshot",
                user.views.snapshot.as_deref(),
                OutputKind::Figure,
            ),
        ],
        &reads,
    )?;
    let (path, options) = request.resolve(&robot, &section)?;
    let trajectory = trocar_api::Trajectory::from_csv(&path)?;
    if let (Some(times), Some(end)) = (&user.views.snapshot_times, trajectory.t.last()) {
        if let Some(t) = times.iter().find(|t| !(0.0..=*end).contains(*t)) {
            return Err(Error::Input(format!(
                "--snapshot-times {t}: the trajectory runs from 0 to {end} s"
            )));
        }
    }
    if all {
        // Each method along the same path, from the same start, on one figure.
        let mut runs = Vec::with_capacity(trocar_api::Method::ALL.len());
        for method in trocar_api::Method::ALL {
            let mut options = options.clone();
            options.controller.method = method;
            runs.push(with_progress(
                &format!("trajectory ({})", method.name()),
                |progress| trocar_api::simulate_trajectory(&robot, &trajectory, &options, progress),
            )?);
        }
        if let Some(path) = user.plot.as_deref() {
            let traces: Vec<&trocar_api::Trace> =
                runs.iter().filter_map(SimulationRun::rcm_trace).collect();
            trocar_api::write_comparison(&traces, outputs.temporary(path))
                .map_err(|e| outputs.explain(format!("--plot {}: {e}", path.display())))?;
        }
        outputs.commit()?;
        let summary: Vec<&str> = runs.iter().map(|r| r.summary.as_str()).collect();
        write_stderr(&format!("{}\n", summary.join("\n")));
        return Ok(0);
    }
    let run = with_progress("trajectory", |progress| {
        trocar_api::simulate_trajectory(&robot, &trajectory, &options, progress)
    })?;
    write_run(
        &outputs,
        &run,
        user.csv.as_deref(),
        user.csv_rows,
        user.plot.as_deref(),
        &user.views,
    )?;
    outputs.commit()?;
    write_stderr(&format!("{}\n", run.summary));
    Ok(0)
}
