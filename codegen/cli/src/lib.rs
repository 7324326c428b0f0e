//! The `trocar` command line.
//!
//! ```text
//! trocar generate ROBOT.toml [-o OUT.rs] [--real f32|f64] [--c-api] [--c-header OUT.h] [--function NAME=OUTPUT,...]
//! trocar eval ROBOT.toml --q 0.1,0.2,... [--param l_a=0.15 ...] [--what constrained_jacobian|jr|manip|task|jc|jb0i|jb0e|fk|...|passive|det] [--json] [--numeric]
//! trocar verify ROBOT.toml [--samples N]
//! trocar jacobian --urdf FILE.urdf --tip LINK --q ... [--frame body|spatial] [--json]
//! trocar simulate SCENARIO [--method pinv|dls|fi|all] [--drift-correction on|off] [--csv OUT.csv] [--plot OUT.svg] [--animate OUT.gif] [--snapshot OUT.png]
//! trocar simulate panda-breathing [--port fixed|known|estimated|registered] [--port-trajectory F.csv] [--csv ...] [--plot ...]
//! trocar simulate ROBOT.toml [--trajectory PATH.csv] [--q0 ...] [--trocar x,y,z] [--csv ...] [--plot ...] [--animate ...] [--snapshot ...]
//! trocar register-port ROBOT.toml --joints F.csv [--least-spread DEG] [--forgetting LAMBDA] [--json]
//! trocar preset unidirectional|bidirectional-zy|bidirectional-zx
//! trocar list
//! ```
//!
//! `ROBOT.toml` may also be the name of a shipped description (`bidirectional-zy`, `dia10_like_zy`, ...),
//! or a closed mechanism (a TOML file with `[[chains]]`, or `four-bar`, `planar-stewart`): then
//! `generate` emits its closed-form reduced kinematics (the generator's `closed_chain`) and `eval` takes
//! all joint values with `--what jr|jc|passive|det`.
//! Matrices print as JSON `{"rows": R, "cols": C, "data": [[row], ...]}` with `--json`, as aligned
//! text otherwise. Errors go to stderr with a non-zero exit code and say what is wrong and where.
//!
//! The commands are argument parsing and printing over the library [`trocar_api`], which
//! computes every answer (and is what the Python package uses too); [`run`] executes a parsed
//! [`Cli`] and prints as the binary does.
#![warn(missing_docs)]

mod args;
mod commands;
mod output;
mod progress;

use clap::Parser;

pub use args::{Cli, Command, Frame, OnOff};
pub use trocar_api::Error as CliError;

/// Runs the command line with the process arguments and returns the exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    if let Some(e) = args::usage_error(&cli) {
        let _ = e.print();
        return 2;
    }
    run(cli).unwrap_or_else(|e| output::print_error(&e))
}

/// Runs a parsed command, printing its answer; returns the exit code, or an error to print.
pub fn run(cli: Cli) -> Result<i32, CliError> {
    match cli.command {
        Command::Generate {
            robot,
            output,
            real,
            c_api,
            c_header,
            cpp_header,
            cmake,
            functions,
            fma_at_run_time,
        } => commands::generate::run(
            &robot,
            output.as_deref(),
            real,
            c_api,
            commands::generate::Headers {
                c: c_header.as_deref(),
                cpp: cpp_header.as_deref(),
                cmake: cmake.as_deref(),
            },
            functions,
            fma_at_run_time,
        ),
        Command::Eval {
            robot,
            q,
            params,
            what,
            json,
            numeric,
        } => commands::eval::run(&robot, &q, &params, &what, json, numeric),
        Command::Verify {
            robot,
            samples,
            seed,
        } => commands::verify::run(&robot, samples, seed),
        Command::Jacobian {
            urdf,
            tip,
            q,
            frame,
            json,
        } => commands::jacobian::run(&urdf, &tip, &q, frame, json),
        Command::Simulate {
            scenario,
            method,
            drift_correction,
            max_joint_speed,
            csv,
            every,
            dt,
            plot,
            animate,
            snapshot,
            snapshot_times,
            trajectory,
            q0,
            trocar,
            port,
            port_trajectory,
        } => {
            let options = trocar_api::RcmOptions {
                method: args::method(method.as_deref()),
                drift_correction: drift_correction == OnOff::On,
                max_joint_speed,
                port,
            };
            // A robot's own trajectory: given, or named by the description's [simulation].
            let own = trajectory.is_some()
                || (trocar_api::Scenario::from_name(&scenario).is_err()
                    && std::path::Path::new(&scenario).is_file());
            if own && (port.is_some() || port_trajectory.is_some()) {
                Err(CliError::Input(
                    "--port: applies to the scenario `panda-breathing` (a port that moves), not to a robot's own trajectory".into(),
                ))
            } else if own {
                commands::simulate::run_trajectory(
                    &scenario,
                    trajectory.as_deref(),
                    &commands::simulate::UserRun {
                        method,
                        options,
                        q0,
                        trocar,
                        csv,
                        csv_rows: args::csv_rows(every, dt),
                        plot,
                        views: commands::simulate::ArmViews {
                            animate,
                            snapshot,
                            snapshot_times,
                        },
                    },
                )
            } else if q0.is_some() || trocar.is_some() {
                Err(CliError::Input(format!(
                    "{}: applies to a robot's own trajectory (--trajectory, or a description file with a [simulation] section); scenario `{scenario}` has its start and its trocar",
                    if q0.is_some() { "--q0" } else { "--trocar" }
                )))
            } else {
                commands::simulate::run(
                    &scenario,
                    method,
                    &options,
                    port_trajectory.as_deref(),
                    csv.as_deref(),
                    args::csv_rows(every, dt),
                    plot.as_deref(),
                    &commands::simulate::ArmViews {
                        animate,
                        snapshot,
                        snapshot_times,
                    },
                )
            }
        }
        Command::RegisterPort {
            robot,
            joints,
            least_spread,
            forgetting,
            json,
        } => commands::register_port::run(&robot, &joints, least_spread, forgetting, json),
        Command::Preset { name } => commands::preset::run(&name),
        Command::List => commands::list::run(),
    }
}
