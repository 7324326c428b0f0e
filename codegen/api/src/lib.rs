//! # trocar-api — trocar as a library
//!
//! Everything the `trocar` command line and the Python package do, as typed functions: load a
//! description once ([`Robot::load`]), derive its closed forms once and evaluate them compiled
//! ([`Robot::eval`], [`Robot::evaluator`] for one configuration or many), check them
//! ([`Robot::verify`]), emit them ([`Robot::generate`]), run the constrained controller on the
//! robot ([`RobotController`]) and the shipped simulations ([`simulate()`]). Nothing here parses
//! command lines or prints; long work reports progress through a callback, and every failure is
//! an [`Error`] whose message says what is wrong and where (file, line, field; a value given
//! by the caller by the library's name of its argument, [`Error::Argument`]).
//!
//! This crate is the one door to trocar for programs: the `trocar` command line maps its flags
//! onto it and the Python package its keyword arguments, and neither reaches below it. The
//! quantities are the catalogue's [`Function`]s (`constrained_jacobian`, …, with short names
//! such as `jr` resolved by [`Robot::function`]); the real type of generated code is
//! [`Real`]; the controller's method is [`Method`].
//!
//! ```no_run
//! use trocar_api::{Function, Robot};
//! let robot = Robot::load("panda-laparoscope")?;
//! let q = [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8];
//! let pose = robot.eval(Function::ForwardKinematics, &q, &[])?; // 4 × 4
//! let jb0i = robot.evaluator(Function::PartialBodyJacobian)?;    // compiled, reusable
//! let mut out = vec![0.0; jb0i.len()];
//! jb0i.eval_into(&q, &[0.25], &mut out)?;
//! # Ok::<(), trocar_api::Error>(())
//! ```
#![warn(missing_docs)]

pub mod cmake;
mod controller;
mod error;
mod evaluation;
pub mod plant;
pub mod port;
mod robot;
pub mod scene;
pub mod simulate;
mod trajectory;

pub use cmake::{cmake_package, cmake_scene_package};
pub use controller::{
    proper_rotation, ControllerOptions, RobotController, Step, Target, ROTATION_TOLERANCE,
    SUPPORTED,
};
pub use error::{Error, Result};
pub use evaluation::Evaluation;
pub use port::{register_port, shaft_line, JointRows};
pub use robot::{urdf_jacobian, Evaluator, FusedEvaluator, Robot, MAX_SAMPLES, TWIST};
pub use scene::{generate_scene, load_scene, SceneStep, SceneStepper};
pub use simulate::{simulate, RcmOptions, SimulationRun, SpeedLimit};
pub use trajectory::{
    simulate_robot, simulate_trajectory, Orientation, RunRequest, Trajectory, TrajectoryOptions,
    TrajectoryRun, MAX_REFERENCE_ANGULAR_SPEED, MAX_REFERENCE_SPEED, MAX_TRAJECTORY_BYTES,
    MAX_TRAJECTORY_STEPS, START_TOLERANCE,
};
pub use trocar::control::{RateRelaxation, StepStatus};
pub use trocar::port::{PortEstimate, PortFollower, Wall};
pub use trocar_codegen::{ModuleOptions, Real};
pub use trocar_model::catalogue::{Function, Fused};
pub use trocar_model::description::SimulationDesc;
/// The number rule every value given to the library obeys (finite, not subnormal, at most
/// 1e6 in magnitude), for callers that check their own inputs the same way.
pub use trocar_model::validity;
pub use trocar_sim::breathing::PortMode;
pub use trocar_sim::plot::{write_comparison, write_time_panels, ImageFormat, TimePanel};
pub use trocar_sim::simulation::{CsvRows, Method, Scenario, Trace};

/// The files a description at `path` is read from: `path` itself and, when its chain comes from
/// a URDF (`[robot] urdf = "…"`), that URDF; for a scene, its arms' description files and their
/// URDFs too. Unreadable files are listed all the same.
pub fn files_read(path: impl AsRef<std::path::Path>) -> Vec<std::path::PathBuf> {
    let path = path.as_ref();
    let scene = std::fs::read_to_string(path)
        .is_ok_and(|t| trocar_model::scene::SceneDescription::is_scene_text(&t));
    if scene {
        trocar_model::scene::SceneDescription::files_read(path)
    } else {
        trocar_model::description::RobotDescription::files_read(path)
    }
}

/// The names of everything shipped, as the library and the command line accept them.
#[derive(Clone, Debug, PartialEq)]
pub struct Shipped {
    /// Serial robot descriptions.
    pub robots: Vec<&'static str>,
    /// Closed mechanisms.
    pub mechanisms: Vec<&'static str>,
    /// Simulation scenarios: the RCM scenarios, then the closed-chain ones.
    pub scenarios: Vec<&'static str>,
}

/// Everything shipped with trocar.
pub fn shipped() -> Shipped {
    Shipped {
        robots: trocar_model::description::preset_names().collect(),
        mechanisms: trocar_model::closed_chain::SHIPPED.to_vec(),
        scenarios: simulate::scenario_names(),
    }
}

/// The TOML text of the shipped description `name` (a serial robot or a closed mechanism).
pub fn preset(name: &str) -> Result<&'static str> {
    trocar_model::description::preset(name)
        .or_else(|| trocar_model::closed_chain::shipped_text(name))
        .ok_or_else(|| {
            let s = shipped();
            Error::Input(format!(
                "unknown preset `{name}` (expected one of: {})",
                s.robots
                    .iter()
                    .chain(&s.mechanisms)
                    .copied()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
}

/// The generated Rust module of `robot` (a shipped name or a file) for the real type `real`.
pub fn generate(robot: &str, real: Real) -> Result<String> {
    Robot::load(robot)?.generate(&ModuleOptions {
        real,
        ..Default::default()
    })
}
