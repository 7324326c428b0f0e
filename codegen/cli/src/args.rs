//! The command-line arguments (clap types) of `trocar`.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use trocar_api::{Method, Real, SpeedLimit};

/// Command-line arguments of `trocar`.
#[derive(Debug, Parser)]
#[command(
    name = "trocar",
    version,
    about = "Constrained (RCM) kinematics: generate, evaluate, verify, simulate"
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands of `trocar`.
// Parsed once per process: the size of its largest variant (`simulate`'s options) costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Emit the generated Rust module for a robot description, a closed mechanism or a scene.
    Generate {
        /// Robot, mechanism or scene description (TOML file or shipped name: a scene file has a
        /// `[scene]` table; `three-ports`, `dia10-dual`).
        robot: String,
        /// Output file (stdout when absent).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Real type of the generated code.
        #[arg(long, default_value = "generic", value_parser = real_values())]
        real: Real,
        /// Also emit the C ABI: `extern "C"` functions `<module>_<function>(q, params, out)`
        /// (matrices column-major) and `<module>_controller_step` (serial robots).
        #[arg(long)]
        c_api: bool,
        /// Write the C header of the C ABI to this file (`#define`d sizes, one prototype per
        /// function); alone, only the header is written.
        #[arg(long, value_name = "OUT.h")]
        c_header: Option<PathBuf>,
        /// Write the C++ header over the C ABI to this file (header-only, namespace
        /// `trocar::<module>`: the controller object as an RAII class, `std::array` and pointer
        /// signatures, `enum class Status`); serial robots with a controller. Include it with
        /// the C header beside it.
        #[arg(long, value_name = "OUT.hpp")]
        cpp_header: Option<PathBuf>,
        /// Write a CMake and pkg-config package of the C ABI into this directory: the C and C++
        /// headers, the static library (built with cargo, release), and
        /// `lib/cmake/trocar_<module>/trocar_<module>Config.cmake`, so that
        /// `find_package(trocar_<module>)` and `target_link_libraries(... trocar::<module>)`
        /// work. For a scene, the scene's C object (`<scene>_scene_init`, `_update`, ...) with
        /// its arms' C ABI, and the scene's and the arms' headers. `--real f32` for a `float`
        /// ABI (default: `double`).
        #[arg(long, value_name = "DIR")]
        cmake: Option<PathBuf>,
        /// Also emit a function computing several outputs in one program, e.g.
        /// `step=fk,jb0e,jr` (outputs by name or short name, as `eval --what` takes them);
        /// repeatable. Every module already has `pose_and_jacobian=fk,jb0e` and, with a
        /// constraint, `link_pose_and_jacobian=fk0i,jb0i`.
        #[arg(long = "function", value_name = "NAME=OUTPUT,...", value_parser = trocar_api::Fused::parse)]
        functions: Vec<trocar_api::Fused>,
        /// Also emit each fused function's `f64` entry points `<name>_f64` and
        /// `<name>_trig_f64`, with fused multiply-adds chosen at run time: built for the
        /// default x86-64 target with trocar's `std` feature, on a CPU with AVX2 and FMA they
        /// run the function compiled for those (results' last bits then depend on the CPU).
        /// Needs `--real generic`; the generated module needs Rust 1.89 or later.
        #[arg(long)]
        fma_at_run_time: bool,
    },
    /// Evaluate the constrained Jacobian and friends at a configuration.
    Eval {
        /// Robot or mechanism description (TOML file or shipped name).
        robot: String,
        /// All n joint values, base first, comma separated.
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required = true,
            action = clap::ArgAction::Set
        )]
        q: Vec<f64>,
        /// Parameter values `name=value` (nominal values otherwise).
        #[arg(long = "param", value_parser = parse_param)]
        params: Vec<(String, f64)>,
        /// What to evaluate: a function of the generated module by its name or short name —
        /// serial robots: constrained_jacobian (jr), manipulability (manip),
        /// constrained_task_jacobian (task), constraint_jacobian_c (jc), partial_body_jacobian
        /// (jb0i), body_jacobian (jb0e), forward_kinematics (fk), forward_kinematics_i (fk0i),
        /// lambda_null_space, lambda_pinv, constraint_frame, ...; closed mechanisms:
        /// reduced_jacobian (jr), constraint_jacobian (jc), passive_map (passive),
        /// constraint_determinant (det), task_jacobian (ja). Several, comma-separated
        /// (`fk0i,jb0i`): each printed under its name (`--json`: one object keyed by the names),
        /// a serial robot's computed by one program that shares their common values.
        #[arg(long, default_value = "jr")]
        what: String,
        /// Print JSON `{"rows", "cols", "data": [[row], ...]}`: row by row (generated functions
        /// return their arrays column by column, `a[col][row]`). Without it, text with row and
        /// column labels.
        #[arg(long)]
        json: bool,
        /// Use the numeric runtime instead of the derived closed form.
        #[arg(long)]
        numeric: bool,
    },
    /// Check generated expressions against the numeric runtime and finite differences.
    Verify {
        /// Robot description (TOML file or shipped description name).
        robot: String,
        /// Number of random configurations.
        #[arg(long, default_value_t = 1000)]
        samples: usize,
        /// Seed of the random configurations.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Body or spatial Jacobian of a URDF chain.
    Jacobian {
        /// The URDF file.
        #[arg(long)]
        urdf: PathBuf,
        /// The tip link (end effector).
        #[arg(long)]
        tip: String,
        /// All joint values from the root to the tip, comma separated.
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required = true,
            action = clap::ArgAction::Set
        )]
        q: Vec<f64>,
        /// Frame of the Jacobian.
        #[arg(long, value_enum, default_value_t = Frame::Body)]
        frame: Frame,
        /// Print JSON `{"rows", "cols", "data": [[row], ...]}`: row by row (generated functions
        /// return their arrays column by column, `a[col][row]`). Without it, text with row and
        /// column labels.
        #[arg(long)]
        json: bool,
    },
    /// Run one of the thesis's simulations (1, 2, 3, 4, exp421), the Panda laparoscope
    /// (panda-laparoscope), a closed-chain one, or a robot along its own trajectory.
    Simulate {
        /// Scenario name, or a robot (shipped name or TOML description) with --trajectory or a
        /// [simulation] section.
        scenario: String,
        /// Inverse used for J^r (default: the scenario's). `all` runs pinv, dls, fi and qp and
        /// draws one figure comparing them to --plot (serial scenarios, and a robot along a
        /// trajectory; not with --csv, --animate or --snapshot).
        #[arg(long, value_parser = method_values())]
        method: Option<String>,
        /// Close the loop on the trocar position.
        #[arg(long, value_enum, default_value_t = OnOff::On)]
        drift_correction: OnOff,
        /// Joint speed limit in rad/s (`none` for none, as in the thesis; default 2). Above it
        /// the task slows down and the motion that keeps the link on the trocar is kept.
        #[arg(long, value_name = "RAD_PER_S", value_parser = parse_speed_limit)]
        max_joint_speed: Option<SpeedLimit>,
        /// Write the trace as CSV (checked before the run, written whole when it succeeds).
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write every N-th row of the trace to --csv (the first and the last always).
        #[arg(long, value_name = "N", requires = "csv", conflicts_with = "dt",
              allow_hyphen_values = true, value_parser = clap::value_parser!(u64).range(1..))]
        every: Option<u64>,
        /// Write the rows of the trace at the times 0, DT, 2 DT, ... s to --csv (the first and the
        /// last always; a DT below the sample time writes every row).
        #[arg(long, value_name = "SECONDS", requires = "csv", allow_hyphen_values = true,
              value_parser = parse_seconds)]
        dt: Option<f64>,
        /// Write the figures to a `.svg` or `.png` file (checked before the run).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Write an animated `.gif` of the arm (stick figure, instrument shaft, trocar, tip
        /// path; two viewpoints) over the run; of a scene, every arm, shaft and port and the
        /// closest shafts. Not for closed chains.
        #[arg(long, value_name = "GIF")]
        animate: Option<PathBuf>,
        /// Write a still `.png` or `.svg` of the arm at --snapshot-times. One serial arm only.
        #[arg(long)]
        snapshot: Option<PathBuf>,
        /// Drive the robot SCENARIO names (a shipped robot or a TOML description) along this
        /// tip path instead of running a shipped scenario (a description file whose
        /// [simulation] section names a trajectory runs it without this flag): a CSV with a header, `t` (s,
        /// increasing), `x,y,z` (m, base frame) and, for a task that commands orientation,
        /// `roll` (rad about the tip's z, relative to q0) or `qw,qx,qy,qz`. At most 64 MiB
        /// read and 10⁶ control steps of 2 ms (2000 s).
        #[arg(long, value_name = "PATH.csv")]
        trajectory: Option<PathBuf>,
        /// With a robot's own trajectory: the start configuration, all joints, base first
        /// (default: the description's [simulation] q0).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        q0: Option<Vec<f64>>,
        /// With a robot's own trajectory: the trocar point x,y,z (m, base frame); default: the
        /// description's [simulation] trocar, else the constraint frame's origin at q0.
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        trocar: Option<Vec<f64>>,
        /// How `panda-breathing`'s controller knows its moving port: `fixed` where it was at the
        /// start, `known` its trajectory fed forward, `estimated` followed from the wall's force
        /// on the shaft (the default); `registered` (`panda-registration` only) from the shaft's
        /// lines while the instrument pivots about the port, no force measured.
        #[arg(long, value_name = "MODE", value_parser = port_values())]
        port: Option<trocar_api::PortMode>,
        /// With `--port known` (or alone): the port's measured trajectory, a CSV `t,x,y,z` of its
        /// displacement from where it was at the start (m, base frame), fed forward instead of
        /// the scenario's own motion; it must cover the run.
        #[arg(long, value_name = "F.csv")]
        port_trajectory: Option<PathBuf>,
        /// Times (s) drawn by --snapshot, comma-separated (default: start, middle, end).
        #[arg(
            long,
            value_name = "T1,T2,...",
            value_delimiter = ',',
            requires = "snapshot",
            value_parser = parse_time
        )]
        snapshot_times: Option<Vec<f64>>,
    },
    /// Locate the port from measured joint positions of the instrument pivoting about it: the
    /// point nearest to the shaft's lines (least squares), with its deviation.
    RegisterPort {
        /// Robot description with a constraint (TOML file or shipped name).
        robot: String,
        /// CSV of joint positions, one pose per row, columns `q1..qn` (other columns, such as
        /// a `trocar simulate` CSV's, are skipped).
        #[arg(long, value_name = "F.csv")]
        joints: PathBuf,
        /// The least spread of the shaft's directions (degrees, root mean square of their
        /// angles from their common direction) taken to place the port along the shaft.
        #[arg(
            long,
            default_value_t = 2.0,
            value_name = "DEG",
            allow_hyphen_values = true
        )]
        least_spread: f64,
        /// Weigh each pose `1/λ` times the one before (λ in (0, 1]), for a port that moved.
        #[arg(long, value_name = "LAMBDA", allow_hyphen_values = true)]
        forgetting: Option<f64>,
        /// Print JSON: `port`, `covariance` (rows, m²), `deviation` (m), `residual` (m),
        /// `spread_deg`, `lines`.
        #[arg(long)]
        json: bool,
    },
    /// Print a shipped description (TOML).
    Preset {
        /// Name of the preset.
        name: String,
    },
    /// List the shipped robots, mechanisms and simulation scenarios.
    List,
}

/// `--real`'s values: the real type of generated code ([`Real`]) by its name.
fn real_values() -> impl TypedValueParser<Value = Real> {
    PossibleValuesParser::new([
        PossibleValue::new("generic").help(
            "generic over `T: trocar::Arith` (straight-line functions, which also run on \
             `trocar::emitted::lanes`) and `T: trocar::Real` (the functions that test a value)",
        ),
        PossibleValue::new("f32"),
        PossibleValue::new("f64"),
    ])
    .try_map(|s| s.parse::<Real>())
}

/// Frame of `trocar jacobian`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Frame {
    /// Body Jacobian (2.55).
    Body,
    /// Spatial Jacobian (2.53).
    Spatial,
}

/// `--port`'s values: each [`trocar_api::PortMode`] by its name.
fn port_values() -> impl TypedValueParser<Value = trocar_api::PortMode> {
    PossibleValuesParser::new(
        trocar_api::PortMode::ALL
            .iter()
            .map(|m| PossibleValue::new(m.name())),
    )
    .map(|s| trocar_api::PortMode::from_name(&s).expect("one of the names offered"))
}

/// `--method`'s values: each [`Method`] by its name, and `all` (pinv, dls, fi and qp compared
/// on one figure).
fn method_values() -> PossibleValuesParser {
    PossibleValuesParser::new(
        Method::ALL
            .iter()
            .map(|m| PossibleValue::new(m.name()).help(m.summary()))
            .chain([PossibleValue::new(ALL_METHODS).help(
                "`trocar simulate` only: pinv, dls, fi and qp, compared on one figure (--plot)",
            )]),
    )
}

/// The `--method` value that compares every method.
pub(crate) const ALL_METHODS: &str = "all";

/// The method `--method` names, `None` when absent or `all`.
pub(crate) fn method(value: Option<&str>) -> Option<Method> {
    value.and_then(Method::from_name)
}

/// The usage error of a parsed command line that clap's rules cannot express: `--method all`
/// with `--csv`, `--animate` or `--snapshot` (one run's outputs).
pub(crate) fn usage_error(cli: &Cli) -> Option<clap::Error> {
    use clap::CommandFactory;
    let Command::Simulate {
        method: Some(method),
        csv,
        animate,
        snapshot,
        ..
    } = &cli.command
    else {
        return None;
    };
    if method != ALL_METHODS {
        return None;
    }
    let message = method_all_conflict(csv.is_some(), animate.is_some(), snapshot.is_some())?;
    Some(Cli::command().error(clap::error::ErrorKind::ArgumentConflict, message))
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
        "{option} writes one run; --method all compares pinv, dls, fi and qp on one figure (--plot only)"
    ))
}

/// A sample time for `--dt`: a positive, finite number of seconds.
fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    // The number rule (`trocar_api::validity`: not subnormal, at most 1e6), then the rule of
    // the library's `CsvRows::check`, with the value as the user wrote it.
    trocar_api::validity::check(v).map_err(|p| format!("`{s}` {p}"))?;
    trocar_api::CsvRows::Period(v)
        .check()
        .map_err(|_| format!("`{s}`: must be a positive, finite number of seconds"))?;
    Ok(v)
}

/// Parses one `--snapshot-times` value: a time in seconds under the number rule
/// (`trocar_api::validity`: finite, not subnormal, at most 1e6) and not negative; whether it
/// lies within the scenario is checked before the run.
fn parse_time(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    trocar_api::validity::check(v).map_err(|p| format!("`{s}` {p}"))?;
    if v < 0.0 {
        return Err(format!("`{s}`: a time is not negative"));
    }
    Ok(v)
}

/// The rows `trocar simulate` writes to its CSV, from `--every` and `--dt`.
pub fn csv_rows(every: Option<u64>, dt: Option<f64>) -> trocar_api::CsvRows {
    use trocar_api::CsvRows;
    match (every, dt) {
        (Some(n), _) => CsvRows::Every(usize::try_from(n).unwrap_or(usize::MAX)),
        (None, Some(dt)) => CsvRows::Period(dt),
        (None, None) => CsvRows::All,
    }
}

/// Parses `--max-joint-speed`: `none`, or a positive number that passes the number rule
/// (`trocar_api::validity`).
fn parse_speed_limit(s: &str) -> Result<SpeedLimit, String> {
    if s.eq_ignore_ascii_case("none") {
        return Ok(SpeedLimit::Unlimited);
    }
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number (rad/s) or `none`"))?;
    trocar_api::validity::check(v).map_err(|p| format!("`{s}`: {p}"))?;
    if v <= 0.0 {
        return Err(format!("`{s}`: a speed limit must be positive (or `none`)"));
    }
    Ok(SpeedLimit::At(v))
}

/// A switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OnOff {
    /// On.
    On,
    /// Off.
    Off,
}

/// Parses one `--param name=value` (the value obeying [`trocar_api::validity`]).
fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected name=value"))?;
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: `{value}` is not a number"))?;
    if let Err(problem) = trocar_api::validity::check(value) {
        return Err(format!("`{s}`: {value:e} {problem}"));
    }
    Ok((name.trim().to_string(), value))
}
