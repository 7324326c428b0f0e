//! The `trocar` command line (SPEC §5).
//!
//! ```text
//! trocar generate ROBOT.toml [-o OUT.rs] [--real f32|f64]
//! trocar eval ROBOT.toml --q 0.1,0.2,... [--param l_a=0.15 ...] [--what jr|manip|jc|jb0i|jb0e|fk|passive|det] [--json] [--numeric]
//! trocar verify ROBOT.toml [--samples N]
//! trocar jacobian --urdf FILE.urdf --tip LINK --q ... [--frame body|spatial] [--json]
//! trocar simulate SCENARIO [--method pinv|dls|fi] [--drift-correction on|off] [--csv OUT.csv] [--plot OUT.svg]
//! trocar preset unidirectional|bidirectional-zy|bidirectional-zx
//! ```
//!
//! `ROBOT.toml` may also be the name of a shipped description (`bidirectional-zy`, `dia10_like_zy`, ...),
//! or a closed mechanism (a TOML file with `[[chains]]`, or `four-bar`, `planar-stewart`): then
//! `generate` emits its closed-form reduced kinematics ([`trocar_codegen::closed_chain`]) and `eval` takes
//! all joint values with `--what jr|jc|passive|det`.
//! Matrices print as JSON `{"rows": R, "cols": C, "data": [[row], ...]}` with `--json`, as aligned
//! text otherwise. Errors go to stderr with a non-zero exit code and say what is wrong and where.

use clap::{Parser, Subcommand, ValueEnum};
use std::fmt;
use std::path::{Path, PathBuf};
use trocar_codegen::catalogue::Function;
use trocar_codegen::evaluate::{Evaluated, Generated};
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::{preset_names, DescriptionError, RobotDescription};
use trocar_model::Description;
use trocar_sim::verify::Candidate;

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
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Emit the generated Rust module for a robot description or a closed mechanism.
    Generate {
        /// Robot or mechanism description (TOML file or shipped name).
        robot: String,
        /// Output file (stdout when absent).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Scalar type of the generated code.
        #[arg(long, value_enum, default_value_t = RealArg::Generic)]
        real: RealArg,
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
            required = true
        )]
        q: Vec<f64>,
        /// Parameter values `name=value` (nominal values otherwise).
        #[arg(long = "param", value_parser = parse_param)]
        params: Vec<(String, f64)>,
        /// What to evaluate.
        #[arg(long, value_enum, default_value_t = What::Jr)]
        what: What,
        /// Print JSON.
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
            required = true
        )]
        q: Vec<f64>,
        /// Frame of the Jacobian.
        #[arg(long, value_enum, default_value_t = Frame::Body)]
        frame: Frame,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run one of the thesis's simulations (1, 2, 3, 4, exp421) or a closed-chain one.
    Simulate {
        /// Scenario name.
        scenario: String,
        /// Inverse used for J^r.
        #[arg(long, value_enum)]
        method: Option<Method>,
        /// Close the loop on the trocar position.
        #[arg(long, value_enum, default_value_t = OnOff::On)]
        drift_correction: OnOff,
        /// Write the trace as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write the figures (SVG; a .png path gives PNG).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Print a shipped description (TOML).
    Preset {
        /// Name of the preset.
        name: String,
    },
}

/// Scalar type of generated code.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RealArg {
    /// Generic over `T: trocar::Real`.
    Generic,
    /// `f32`.
    F32,
    /// `f64`.
    F64,
}

/// What `trocar eval` computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum What {
    /// Constrained Jacobian J^r_0e (3.15).
    Jr,
    /// Manipulability of J^r (3.36).
    Manip,
    /// J_c = Ad_gei Λ† (3.33).
    Jc,
    /// Partial body Jacobian J^B_0i (3.13).
    Jb0i,
    /// Body Jacobian J^B_0e (2.55).
    Jb0e,
    /// Forward kinematics g_0e as a 4×4 homogeneous matrix.
    Fk,
    /// Closed mechanisms: the passive map `−J_Cp⁻¹ J_Ca` of (7) (second source).
    Passive,
    /// Closed mechanisms: `det J_Cp` (zero at parallel singularities).
    Det,
}

/// Frame of `trocar jacobian`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Frame {
    /// Body Jacobian (2.55).
    Body,
    /// Spatial Jacobian (2.53).
    Spatial,
}

/// Inverse used by the controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Moore–Penrose pseudo-inverse.
    Pinv,
    /// Damped least squares with variable damping (3.44)–(3.46).
    Dls,
    /// Filtered inverse (3.47)–(3.50).
    Fi,
}

/// A switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OnOff {
    /// On.
    On,
    /// Off.
    Off,
}

fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected name=value"))?;
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: `{value}` is not a number"))?;
    if !value.is_finite() {
        return Err(format!("`{s}`: the value must be finite"));
    }
    Ok((name.trim().to_string(), value))
}

/// An error of the command line: printed to stderr, exit code 1.
#[derive(Debug)]
pub struct CliError(pub String);

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CliError {}

impl From<DescriptionError> for CliError {
    fn from(e: DescriptionError) -> Self {
        CliError(e.to_string())
    }
}

/// `trocar eval` for a closed mechanism: `--what jr` (reduced Jacobian (8)), `jc` (`J_C`),
/// `passive` (`−J_Cp⁻¹ J_Ca`, (7)) or `det` (`det J_Cp`), at all joint values `q`; from the
/// generated closed forms (interpreted exactly as emitted) or, with `numeric`, the runtime.
pub fn eval_mechanism(
    m: &MechanismModel,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
    numeric: bool,
) -> Result<MatrixOut, CliError> {
    let names = m.joint_names();
    let n = names.len();
    if q.len() != n {
        return Err(CliError(format!(
            "--q: `{}` has {n} joints ({}), got {} values",
            m.name,
            names.join(", "),
            q.len()
        )));
    }
    if let Some(k) = q.iter().position(|x| !x.is_finite()) {
        return Err(CliError(format!("--q: value {k} is not finite")));
    }
    let mut values = m.nominal_values();
    for (name, value) in params {
        let k = m.parameter_index(name).ok_or_else(|| {
            CliError(format!(
                "unknown parameter `{name}` (the mechanism declares: {})",
                m.parameter_names().join(", ")
            ))
        })?;
        values[k] = *value;
    }
    let (active, passive) = m.partition();
    let (na, np, no) = (active.len(), passive.len(), m.outputs.len());
    let singular = || {
        CliError(format!(
            "J_Cp is singular at this configuration (parallel singularity of `{}`)",
            m.name
        ))
    };
    if numeric {
        let mech = trocar_sim::closed_chain::Mechanism::from_model(m, &values)
            .map_err(|e| CliError(e.to_string()))?;
        let theta = trocar::nalgebra::DVector::from_row_slice(q);
        let d = mech
            .differential(&theta)
            .map_err(|e| CliError(e.to_string()))?;
        return Ok(match what {
            What::Jc => MatrixOut::from_nalgebra(&d.j_c),
            What::Det if d.j_cp.is_square() => MatrixOut {
                rows: 1,
                cols: 1,
                data: vec![vec![trocar_sim::closed_chain::linalg::determinant(&d.j_cp)]],
            },
            What::Jr | What::Passive => {
                let r = mech.reduced(&theta).map_err(|e| CliError(e.to_string()))?;
                if what == What::Jr {
                    MatrixOut::from_nalgebra(&r.jacobian)
                } else {
                    MatrixOut::from_nalgebra(&r.passive_map)
                }
            }
            _ => return Err(unsupported_for_mechanism(what)),
        });
    }
    let d = trocar_codegen::closed_chain::derive(m)?;
    let generated = Generated::mechanism(&d);
    let eval = |f: Function| {
        generated
            .outputs(f, q, &values)
            .ok_or_else(|| CliError(format!("internal: no generated `{f}`")))
    };
    let out = match what {
        What::Jc => column_major(&eval(Function::ConstraintJacobian)?, d.j_c.rows(), n),
        What::Det => column_major(&eval(Function::ConstraintDeterminant)?, 1, 1),
        What::Jr | What::Passive => {
            let (function, count) = if what == What::Jr {
                (Function::ReducedJacobianNumerator, no)
            } else {
                (Function::PassiveMapNumerator, np)
            };
            // Column-major, row 0 of every column is det J_Cp.
            let num = eval(function)?;
            let rows = 1 + count;
            let mut data = vec![vec![0.0; na]; count];
            for a in 0..na {
                let det = num[a * rows];
                if !(det.is_finite() && det != 0.0) {
                    return Err(singular());
                }
                for (r, row) in data.iter_mut().enumerate() {
                    row[a] = num[a * rows + 1 + r] / det;
                }
            }
            MatrixOut {
                rows: count,
                cols: na,
                data,
            }
        }
        _ => return Err(unsupported_for_mechanism(what)),
    };
    if out.data.iter().flatten().any(|v| !v.is_finite()) {
        return Err(singular());
    }
    Ok(out)
}

fn unsupported_for_mechanism(what: What) -> CliError {
    CliError(format!(
        "--what {}: not defined for a closed mechanism (use jr, jc, passive or det)",
        what.to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default()
    ))
}

fn column_major(v: &[f64], rows: usize, cols: usize) -> MatrixOut {
    MatrixOut {
        rows,
        cols,
        data: (0..rows)
            .map(|r| (0..cols).map(|c| v[c * rows + r]).collect())
            .collect(),
    }
}

/// A matrix in row-major order, as printed by the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixOut {
    /// Row count.
    pub rows: usize,
    /// Column count.
    pub cols: usize,
    /// Entries, row by row.
    pub data: Vec<Vec<f64>>,
}

impl MatrixOut {
    /// From a nalgebra matrix.
    pub fn from_nalgebra<R: trocar::nalgebra::Dim, C: trocar::nalgebra::Dim, S>(
        m: &trocar::nalgebra::Matrix<f64, R, C, S>,
    ) -> Self
    where
        S: trocar::nalgebra::RawStorage<f64, R, C>,
    {
        let (rows, cols) = m.shape();
        MatrixOut {
            rows,
            cols,
            data: (0..rows)
                .map(|r| (0..cols).map(|c| m[(r, c)]).collect())
                .collect(),
        }
    }

    /// From a faer matrix (the numeric runtime's answers).
    pub fn from_faer(m: &faer::Mat<f64>) -> Self {
        MatrixOut {
            rows: m.nrows(),
            cols: m.ncols(),
            data: (0..m.nrows())
                .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
                .collect(),
        }
    }

    /// From a generated function's value (column-major).
    pub fn from_evaluated(m: &Evaluated) -> Self {
        column_major(&m.values, m.rows, m.cols)
    }

    /// The SPEC §5 JSON form `{"rows": R, "cols": C, "data": [[row], ...]}`.
    pub fn to_json(&self) -> String {
        let data =
            serde_json::to_string(&self.data).expect("finite or null numbers always serialise");
        format!(
            r#"{{"rows": {}, "cols": {}, "data": {data}}}"#,
            self.rows, self.cols
        )
    }

    /// Aligned text, one row a line.
    pub fn to_text(&self) -> String {
        let cells: Vec<Vec<String>> = self
            .data
            .iter()
            .map(|r| r.iter().map(|v| format!("{v:.9}")).collect())
            .collect();
        let width = cells.iter().flatten().map(String::len).max().unwrap_or(0);
        cells
            .iter()
            .map(|r| {
                r.iter()
                    .map(|c| format!("{c:>width$}"))
                    .collect::<Vec<_>>()
                    .join("  ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// Runs the command line with the process arguments and returns the exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}

/// Runs a parsed command; returns the exit code, or an error to print.
pub fn run(cli: Cli) -> Result<i32, CliError> {
    match cli.command {
        Command::Preset { name } => {
            let text = trocar_model::description::preset(&name).ok_or_else(|| {
                CliError(format!(
                    "unknown preset `{name}` (expected one of: {})",
                    preset_names().collect::<Vec<_>>().join(", ")
                ))
            })?;
            print!("{text}");
            Ok(0)
        }
        Command::Simulate {
            scenario,
            method,
            drift_correction,
            csv,
            plot,
        } => simulate(
            &scenario,
            method,
            drift_correction,
            csv.as_deref(),
            plot.as_deref(),
        ),
        Command::Eval {
            robot,
            q,
            params,
            what,
            json,
            numeric,
        } => {
            let desc = match Description::load(&robot)? {
                Description::Mechanism(m) => {
                    let out = eval_mechanism(&m, &q, &params, what, numeric)?;
                    println!("{}", if json { out.to_json() } else { out.to_text() });
                    return Ok(0);
                }
                Description::Serial(desc) => desc,
            };
            let out = if numeric {
                eval_numeric(&desc, &q, &params, what)?
            } else {
                eval_generated(&desc, &q, &params, what)?
            };
            println!("{}", if json { out.to_json() } else { out.to_text() });
            Ok(0)
        }
        Command::Jacobian {
            urdf,
            tip,
            q,
            frame,
            json,
        } => {
            let desc = RobotDescription::from_urdf_file(&urdf, &tip)?;
            let robot = numeric_robot(&desc, &[])?;
            check_q(&desc, &q)?;
            let j = match frame {
                Frame::Body => robot.body_jacobian(&q),
                Frame::Spatial => robot.spatial_jacobian(&q),
            }
            .map_err(robot_error(&desc))?;
            let out = MatrixOut::from_faer(&j);
            println!("{}", if json { out.to_json() } else { out.to_text() });
            Ok(0)
        }
        Command::Generate {
            robot,
            output,
            real,
        } => {
            let real = match real {
                RealArg::Generic => trocar_codegen::Real::Generic,
                RealArg::F32 => trocar_codegen::Real::F32,
                RealArg::F64 => trocar_codegen::Real::F64,
            };
            let options = trocar_codegen::ModuleOptions {
                real,
                ..Default::default()
            };
            let code = match Description::load(&robot)? {
                Description::Mechanism(m) => {
                    trocar_codegen::generate_mechanism_string(&m, &options)
                        .map_err(|e| CliError(e.to_string()))?
                }
                Description::Serial(desc) => {
                    trocar_codegen::generate_module_string(&desc, &options)
                        .map_err(|e| CliError(e.to_string()))?
                }
            };
            match output {
                Some(path) => std::fs::write(&path, code)
                    .map_err(|e| CliError(format!("{}: {e}", path.display())))?,
                None => print!("{code}"),
            }
            Ok(0)
        }
        Command::Verify {
            robot,
            samples,
            seed,
        } => {
            let Description::Serial(desc) = Description::load(&robot)? else {
                return Err(CliError(format!(
                    "`{robot}` is a closed mechanism: `verify` checks serial robots; compare the \
                     closed form with the runtime by `trocar eval {robot} --q ... --what jr` \
                     with and without `--numeric`"
                )));
            };
            if samples == 0 {
                return Err(CliError("--samples must be at least 1".into()));
            }
            let generated = Generated::new(&desc).map_err(|e| CliError(e.to_string()))?;
            let bar = progress_bar(samples as u64, "verify");
            let report = trocar_sim::verify::verify(
                &desc,
                &GeneratedCandidate(&generated),
                samples,
                seed,
                trocar_sim::verify::Tolerances::default(),
                |f| bar.set_position((f * samples as f64).round() as u64),
            )
            .map_err(robot_error(&desc))?;
            bar.finish_and_clear();
            print!("{report}");
            if report.passed() {
                println!("all checks passed");
                Ok(0)
            } else {
                for c in report.checks.iter().filter(|c| !c.passed()) {
                    eprintln!("mismatch in `{}` at q = {:?}", c.name, c.worst_q);
                }
                Ok(1)
            }
        }
    }
}

/// `trocar eval` without `--numeric`: the generated closed forms, interpreted exactly as emitted.
pub fn eval_generated(
    desc: &RobotDescription,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
) -> Result<MatrixOut, CliError> {
    check_q(desc, q)?;
    let generated = Generated::new(desc).map_err(|e| CliError(e.to_string()))?;
    let mut values = generated.nominal_params();
    for (name, value) in params {
        let k = desc
            .parameters
            .iter()
            .position(|p| &p.name == name)
            .ok_or_else(|| {
                CliError(format!(
                    "unknown parameter `{name}` (the description declares: {})",
                    desc.parameters
                        .iter()
                        .map(|p| p.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        values[k] = *value;
    }
    let function = match what {
        What::Jr => Function::ConstrainedJacobian,
        What::Manip => Function::Manipulability,
        What::Jc => Function::ConstraintJacobianC,
        What::Jb0i => Function::PartialBodyJacobian,
        What::Jb0e => Function::BodyJacobian,
        What::Fk => Function::ForwardKinematics,
        What::Passive | What::Det => return Err(serial_only(desc, what)),
    };
    let m = generated.evaluate(function, q, &values).ok_or_else(|| {
        CliError(format!(
            "`{}` has no generated `{function}` (a robot without [constraint] has only fk and jb0e)",
            desc.name
        ))
    })?;
    if m.values.iter().any(|v| !v.is_finite()) {
        return Err(CliError(format!(
            "`{function}` is not finite at this configuration (a parameter that divides is zero?)"
        )));
    }
    Ok(MatrixOut::from_evaluated(&m))
}

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

fn robot_error(desc: &RobotDescription) -> impl Fn(trocar_sim::robot::RobotError) -> CliError + '_ {
    move |e| {
        let file = desc
            .source
            .as_ref()
            .map(|p| format!("{}: ", p.display()))
            .unwrap_or_default();
        CliError(format!("{file}{e}"))
    }
}

/// The numeric robot of a description with parameter overrides.
pub fn numeric_robot(
    desc: &RobotDescription,
    params: &[(String, f64)],
) -> Result<trocar_sim::robot::Robot<f64>, CliError> {
    trocar_sim::robot::Robot::from_description(desc, params).map_err(robot_error(desc))
}

/// Checks that `q` has one finite value per joint.
pub fn check_q(desc: &RobotDescription, q: &[f64]) -> Result<(), CliError> {
    if q.len() != desc.joints.len() {
        return Err(CliError(format!(
            "--q has {} values but `{}` has {} joints (give all joint values, base first)",
            q.len(),
            desc.name,
            desc.joints.len()
        )));
    }
    if let Some(k) = q.iter().position(|v| !v.is_finite()) {
        return Err(CliError(format!("--q: value {} is not finite", k + 1)));
    }
    Ok(())
}

/// `trocar eval --numeric`: the runtime's numeric kinematics.
pub fn eval_numeric(
    desc: &RobotDescription,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
) -> Result<MatrixOut, CliError> {
    check_q(desc, q)?;
    if matches!(what, What::Passive | What::Det) {
        return Err(serial_only(desc, what));
    }
    let robot = numeric_robot(desc, params)?;
    let err = robot_error(desc);
    let needs_constraint = matches!(what, What::Jr | What::Manip | What::Jc | What::Jb0i);
    if needs_constraint && desc.constraint.is_none() {
        return Err(CliError(format!(
            "`{}` has no [constraint]: only --what jb0e and fk apply",
            desc.name
        )));
    }
    Ok(match what {
        What::Jr => MatrixOut::from_faer(&robot.constrained_jacobian(q).map_err(err)?),
        What::Manip => {
            let w = robot.manipulability(q).map_err(err)?;
            MatrixOut {
                rows: 1,
                cols: 1,
                data: vec![vec![w]],
            }
        }
        What::Jc => MatrixOut::from_faer(&robot.moving_rcm_jacobian(q).map_err(err)?),
        What::Jb0i => MatrixOut::from_faer(&robot.partial_body_jacobian(q).map_err(err)?),
        What::Jb0e => MatrixOut::from_faer(&robot.body_jacobian(q).map_err(err)?),
        What::Fk => MatrixOut::from_faer(&robot.forward_kinematics_matrix(q).map_err(err)?),
        What::Passive | What::Det => return Err(serial_only(desc, what)),
    })
}

fn serial_only(desc: &RobotDescription, what: What) -> CliError {
    CliError(format!(
        "--what {}: only for closed mechanisms (`{}` is a serial robot)",
        what.to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default(),
        desc.name
    ))
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

fn simulate(
    scenario: &str,
    method: Option<Method>,
    drift_correction: OnOff,
    csv: Option<&Path>,
    plot: Option<&Path>,
) -> Result<i32, CliError> {
    use trocar_sim::closed_chain;
    if closed_chain::scenario_names().contains(&scenario) {
        if method.is_some() || drift_correction == OnOff::Off {
            return Err(CliError(format!(
                "`{scenario}` is a closed-chain scenario: --method and --drift-correction apply to the RCM scenarios only"
            )));
        }
        let bar = progress_bar(1000, scenario);
        let mut progress = |f: f64| bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
        let trace = closed_chain::simulate(
            scenario,
            &closed_chain::SimOptions::default(),
            Some(&mut progress),
        )
        .map_err(|e| CliError(e.to_string()))?;
        bar.finish_and_clear();
        if let Some(path) = csv {
            trace.write_csv(path).map_err(|e| CliError(e.to_string()))?;
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
            written.map_err(|e| CliError(e.to_string()))?;
        }
        eprintln!("{}", trace_summary(&trace.columns, &trace.rows));
        return Ok(0);
    }
    use trocar_sim::simulation;
    let Ok(which) = simulation::Scenario::from_name(scenario) else {
        return Err(CliError(format!(
            "unknown scenario `{scenario}` (expected 1, 2, 3, 4, exp421, or one of: {})",
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
    let bar = progress_bar(1000, &format!("scenario {scenario}"));
    let trace = simulation::run(&config, |f| {
        bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64)
    })
    .map_err(|e| CliError(e.to_string()))?;
    bar.finish_and_clear();
    if let Some(path) = csv {
        trace
            .write_csv(path)
            .map_err(|e| CliError(format!("{}: {e}", path.display())))?;
    }
    if let Some(path) = plot {
        trocar_sim::plot::write_figure(&trace, path).map_err(|e| CliError(e.to_string()))?;
    }
    let s = trace.summary();
    if let Some(note) = which.deviation() {
        eprintln!("scenario {scenario} on the reference arm: {note} (see runtime/sim/CONTROL.md)");
    }
    eprintln!(
        "scenario {scenario} ({method:?}, drift correction {}):\n  \
         max |vr - dv| after the first step {:.3e} m/s\n  \
         max RCM drift {:.3e} m (final {:.3e} m)\n  \
         max position error {:.3e} m (after 10 s {:.3e} m), max orientation error {:.3e}\n  \
         peak joint speed {:.3e} rad/s, min w_r {:.3e}, min w_i {:.3e}, min |q7| {:.3e} rad\n  \
         l_a in [{:.4}, {:.4}] m",
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
    );
    Ok(0)
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
