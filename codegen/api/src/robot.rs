//! A robot loaded once: its description parsed, its closed forms derived and compiled on first
//! use, its numeric runtime built once, and every quantity of the catalogue evaluated from them.

use crate::error::{Error, Result};
use crate::evaluation::Evaluation;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};
use trocar_codegen::catalogue::Function;
use trocar_codegen::evaluate::{Compiled, FusedProgram, Generated};
use trocar_codegen::ir::Layout;
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::RobotDescription;
use trocar_model::Description;
use trocar_sim::robot::NumericRobot;

/// A robot or closed mechanism, loaded once.
///
/// [`Robot::load`] parses the description (a shipped name or a TOML file whose chain may come
/// from a URDF); the closed forms are derived, optimised and compiled once, on the first call
/// that needs them ([`Robot::derive`]), and every evaluation after that runs the compiled
/// straight-line programs ([`trocar_codegen::evaluate::Compiled`]), bit for bit what the
/// generated `f64` module computes. The numeric runtime (`numeric = true`) is built once for the
/// nominal parameters.
///
/// ```no_run
/// use trocar_api::{Function, Robot};
/// let robot = Robot::load("panda-laparoscope")?;
/// let q = [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8];
/// let jb0i = robot.eval(Function::PartialBodyJacobian, &q, &[])?; // 6 × 7
/// assert_eq!((jb0i.rows, jb0i.cols), (6, 7));
/// # Ok::<(), trocar_api::Error>(())
/// ```
#[derive(Debug)]
pub struct Robot {
    /// The shipped name or the path it was loaded from.
    source: String,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    Serial(Box<Serial>),
    Mechanism(Box<Mechanism>),
}

#[derive(Debug)]
struct Serial {
    desc: RobotDescription,
    generated: OnceLock<Generated>,
    numeric: OnceLock<NumericRobot<f64>>,
    /// The fused programs built so far ([`Robot::fused_evaluator`]), by their functions.
    fused: Mutex<Vec<(Vec<Function>, Arc<Fusion>)>>,
}

#[derive(Debug)]
struct Mechanism {
    model: MechanismModel,
    /// The generated functions and the number of structural equations (rows of `J_C`).
    generated: OnceLock<(Generated, usize)>,
}

/// How a function's outputs become an [`Evaluation`].
#[derive(Clone, Copy, Debug)]
struct Shape {
    layout: Layout,
}

impl Shape {
    fn dims(self) -> (usize, usize) {
        match self.layout {
            Layout::Scalar => (1, 1),
            Layout::Matrix { rows, cols } => (rows, cols),
            Layout::Transform => (4, 4),
        }
    }
}

/// The most configurations [`Robot::verify`] checks (`trocar verify --samples`): 10⁷.
pub const MAX_SAMPLES: usize = 10_000_000;

impl Robot {
    /// Loads a shipped description by name (`panda-laparoscope`, `four-bar`, ...) or a TOML file
    /// (a serial robot, its chain possibly from a URDF, or a closed mechanism with
    /// `[[chains]]`). Errors name the file, line and field.
    pub fn load(name_or_path: impl AsRef<Path>) -> Result<Self> {
        let path = name_or_path.as_ref();
        let given = path.to_string_lossy().into_owned();
        // A file is kept by its absolute path, so that messages and reloads do not depend on
        // the working directory.
        let source = if path.is_file() {
            path.canonicalize()
                .map_or(given.clone(), |p| p.to_string_lossy().into_owned())
        } else {
            given.clone()
        };
        let kind = match Description::load(&given)? {
            Description::Serial(desc) => Kind::Serial(Box::new(Serial {
                desc,
                generated: OnceLock::new(),
                numeric: OnceLock::new(),
                fused: Mutex::new(Vec::new()),
            })),
            Description::Mechanism(model) => Kind::Mechanism(Box::new(Mechanism {
                model,
                generated: OnceLock::new(),
            })),
        };
        Ok(Robot { source, kind })
    }

    /// A serial robot from a description already read.
    pub fn from_description(desc: RobotDescription) -> Self {
        Robot {
            source: desc
                .source
                .as_ref()
                .map_or_else(|| desc.name.clone(), |p| p.display().to_string()),
            kind: Kind::Serial(Box::new(Serial {
                desc,
                generated: OnceLock::new(),
                numeric: OnceLock::new(),
                fused: Mutex::new(Vec::new()),
            })),
        }
    }

    /// What the robot was loaded from: the shipped name, or the file's absolute path.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// `[robot] name`, or the mechanism's name.
    pub fn name(&self) -> &str {
        match &self.kind {
            Kind::Serial(s) => &s.desc.name,
            Kind::Mechanism(m) => &m.model.name,
        }
    }

    /// Whether this is a closed mechanism (its joint values are all joints, active and passive).
    pub fn is_mechanism(&self) -> bool {
        matches!(self.kind, Kind::Mechanism(_))
    }

    /// The serial description, unless this is a closed mechanism.
    pub fn description(&self) -> Option<&RobotDescription> {
        match &self.kind {
            Kind::Serial(s) => Some(&s.desc),
            Kind::Mechanism(_) => None,
        }
    }

    /// The closed mechanism's model, if this is one.
    pub fn mechanism(&self) -> Option<&MechanismModel> {
        match &self.kind {
            Kind::Serial(_) => None,
            Kind::Mechanism(m) => Some(&m.model),
        }
    }

    /// The joints' names, base first (all joints of a mechanism).
    pub fn joint_names(&self) -> Vec<String> {
        match &self.kind {
            Kind::Serial(s) => s.desc.joints.iter().map(|j| j.name.clone()).collect(),
            Kind::Mechanism(m) => m.model.joint_names(),
        }
    }

    /// Number of joint values the robot's functions take.
    pub fn dof(&self) -> usize {
        match &self.kind {
            Kind::Serial(s) => s.desc.joints.len(),
            Kind::Mechanism(m) => m.model.joint_names().len(),
        }
    }

    /// Each joint's position limits `[lower, upper]` (rad or m) where the description has them
    /// (URDF `<limit>` or `limits = [..]`); `None` for a joint without (and for mechanisms).
    pub fn joint_limits(&self) -> Vec<Option<[f64; 2]>> {
        match &self.kind {
            Kind::Serial(s) => s.desc.joints.iter().map(|j| j.limits).collect(),
            Kind::Mechanism(m) => vec![None; m.model.joint_names().len()],
        }
    }

    /// The parameters and their nominal values, in declaration order.
    pub fn params(&self) -> Vec<(String, f64)> {
        match &self.kind {
            Kind::Serial(s) => s
                .desc
                .parameters
                .iter()
                .map(|p| (p.name.clone(), p.value))
                .collect(),
            Kind::Mechanism(m) => m
                .model
                .parameters
                .iter()
                .map(|p| (p.name.clone(), p.nominal))
                .collect(),
        }
    }

    /// The parameter values in declaration order: the nominal ones with `overrides`
    /// (`(name, value)`) applied. An undeclared name is an error naming the declared ones.
    pub fn param_values(&self, overrides: &[(String, f64)]) -> Result<Vec<f64>> {
        let declared = self.params();
        let mut values: Vec<f64> = declared.iter().map(|(_, v)| *v).collect();
        let mut seen: Vec<&str> = Vec::new();
        for (name, value) in overrides {
            let k = declared
                .iter()
                .position(|(n, _)| n == name)
                .ok_or_else(|| {
                    let owner = if self.is_mechanism() {
                        "mechanism"
                    } else {
                        "description"
                    };
                    Error::argument(
                        "params",
                        format!(
                            "unknown parameter `{name}` (the {owner} declares: {})",
                            declared
                                .iter()
                                .map(|(n, _)| n.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })?;
            if let Err(problem) = trocar_model::validity::check(*value) {
                return Err(Error::argument(
                    "params",
                    format!("{name}={value:e}: {value:e} {problem}"),
                ));
            }
            if seen.contains(&name.as_str()) {
                return Err(Error::argument(
                    "params",
                    format!("{name} given twice (give each parameter once)"),
                ));
            }
            seen.push(name);
            values[k] = *value;
        }
        // The trocar on the instrument at the values given, not only at the nominal ones.
        if let (Some(desc), false) = (self.description(), overrides.is_empty()) {
            let mut at = desc.clone();
            for (name, value) in overrides {
                if let Some(p) = at.parameters.iter_mut().find(|p| &p.name == name) {
                    p.value = *value;
                }
            }
            if let Some((name, message)) = trocar_model::description::trocar_beyond_tip(&at) {
                return Err(Error::argument(
                    "params",
                    format!(
                        "{name}={}: {message}",
                        at.parameter(&name).unwrap_or(f64::NAN)
                    ),
                ));
            }
        }
        Ok(values)
    }

    /// The function that `name` names for this robot: a catalogue name (`constrained_jacobian`)
    /// or its short form (`jr`) ([`Function::resolve`]); the error lists the names there are.
    pub fn function(&self, name: &str) -> Result<Function> {
        Function::resolve(name, self.is_mechanism()).ok_or_else(|| {
            let names = self
                .quantities()
                .iter()
                .map(|f| format!("{} ({})", f.short_name(), f.name()))
                .collect::<Vec<_>>()
                .join(", ");
            Error::argument(
                "what",
                if self.is_mechanism() {
                    format!(
                        "`{name}` is not defined for a closed mechanism (`{}` has: {names})",
                        self.name()
                    )
                } else {
                    format!(
                        "`{name}` is not a quantity of the robot `{}` (expected one of: {names})",
                        self.name()
                    )
                },
            )
        })
    }

    /// The functions [`Robot::eval`] evaluates for this robot (what the generated module has,
    /// and for a mechanism its reduced Jacobian and passive map).
    pub fn quantities(&self) -> Vec<Function> {
        match &self.kind {
            Kind::Serial(s) => Function::SERIAL
                .into_iter()
                .filter(|f| {
                    let constrained = s.desc.constraint.is_some();
                    let task = s.desc.task.is_some();
                    match f {
                        Function::ForwardKinematics | Function::BodyJacobian => true,
                        Function::TaskSelection | Function::ConstrainedTaskJacobian => {
                            constrained && task
                        }
                        _ => constrained,
                    }
                })
                .collect(),
            Kind::Mechanism(_) => vec![
                Function::ReducedJacobian,
                Function::ConstraintJacobian,
                Function::PassiveMap,
                Function::ConstraintDeterminant,
                Function::TaskJacobian,
            ],
        }
    }

    /// Derives, optimises and compiles the closed forms, once; later calls return them at once.
    /// Deriving a long or oblique chain can take seconds: a caller that shows progress calls
    /// this first.
    pub fn derive(&self) -> Result<&Generated> {
        match &self.kind {
            Kind::Serial(s) => {
                if let Some(g) = s.generated.get() {
                    return Ok(g);
                }
                let g = Generated::new(&s.desc)?;
                Ok(s.generated.get_or_init(|| g))
            }
            Kind::Mechanism(m) => {
                if let Some((g, _)) = m.generated.get() {
                    return Ok(g);
                }
                let d = trocar_codegen::closed_chain::derive(&m.model)?;
                let rows = d.j_c.rows();
                let g = Generated::mechanism(&d);
                Ok(&m.generated.get_or_init(|| (g, rows)).0)
            }
        }
    }

    /// Checks that `q` has one finite value per joint, within the number rule.
    pub fn check_q(&self, q: &[f64]) -> Result<()> {
        self.check_joints("q", q)
    }

    /// [`Robot::check_q`] for joint values given as the argument `argument` (`q0`, the start of
    /// a run, names itself in the error).
    pub(crate) fn check_joints(&self, argument: &'static str, q: &[f64]) -> Result<()> {
        let n = self.dof();
        if q.len() != n {
            return Err(Error::argument(
                argument,
                match &self.kind {
                    Kind::Serial(s) => format!(
                        "{} values given, `{}` has {} joints (give all joint values, base first)",
                        q.len(),
                        s.desc.name,
                        n
                    ),
                    Kind::Mechanism(m) => format!(
                        "`{}` has {n} joints ({}), got {} values",
                        m.model.name,
                        m.model.joint_names().join(", "),
                        q.len()
                    ),
                },
            ));
        }
        if let Err((k, problem)) = trocar_model::validity::check_all(q) {
            let names = self.joint_names();
            return Err(Error::argument(
                argument,
                if self.is_mechanism() {
                    format!("value {} ({}, {:e}) {problem}", k + 1, names[k], q[k])
                } else {
                    format!("value {} ({:e}) {problem}", k + 1, q[k])
                },
            ));
        }
        Ok(())
    }

    /// `function` at joint values `q` (all joints, base first) with the parameter overrides
    /// `params`, from the generated closed forms, evaluated as emitted: a matrix row by row (a
    /// pose as the 4 × 4 homogeneous matrix, a scalar 1 × 1). A result that is not finite is an
    /// error that says what it divides by.
    pub fn eval(
        &self,
        function: Function,
        q: &[f64],
        params: &[(String, f64)],
    ) -> Result<Evaluation> {
        self.check_q(q)?;
        let values = self.param_values(params)?;
        self.eval_with(function, q, &values)
    }

    /// Several functions at joint values `q` with the parameter overrides `params`, each as
    /// [`Robot::eval`] gives it, in the order asked for: a serial robot's from one program that
    /// computes every value they share once ([`Robot::fused_evaluator`]), a closed mechanism's
    /// one by one.
    pub fn eval_several(
        &self,
        functions: &[Function],
        q: &[f64],
        params: &[(String, f64)],
    ) -> Result<Vec<Evaluation>> {
        self.check_q(q)?;
        let values = self.param_values(params)?;
        if self.is_mechanism() {
            Robot::check_outputs(functions)?;
            return functions
                .iter()
                .map(|&f| self.eval_with(f, q, &values))
                .collect();
        }
        let e = self.fused_evaluator(functions)?;
        let mut out = vec![0.0; e.len()];
        e.eval_into(q, &values, &mut out)?;
        Ok(e.dims()
            .iter()
            .enumerate()
            .map(|(k, &(rows, cols))| Evaluation {
                rows,
                cols,
                data: out[e.range(k)].to_vec(),
            })
            .collect())
    }

    /// [`Robot::eval`] with the parameter values given in declaration order (no checks of `q`).
    pub fn eval_with(&self, function: Function, q: &[f64], values: &[f64]) -> Result<Evaluation> {
        match &self.kind {
            Kind::Serial(_) => {
                let e = self.evaluator(function)?;
                let mut m = Evaluation {
                    rows: e.rows(),
                    cols: e.cols(),
                    data: vec![0.0; e.len()],
                };
                e.eval_into(q, values, &mut m.data)?;
                Ok(m)
            }
            Kind::Mechanism(_) => self.mechanism_generated(function, q, values),
        }
    }

    /// The compiled evaluator of `function`, for callers that evaluate it often (one
    /// configuration or many): serial robots' functions and mechanisms' polynomial ones.
    pub fn evaluator(&self, function: Function) -> Result<Evaluator<'_>> {
        let generated = self.derive()?;
        let missing = || {
            let desc = self.description();
            Error::Unsupported(match desc {
                Some(d) if function == Function::ConstrainedTaskJacobian && d.task.is_none() => {
                    return no_task(d);
                }
                Some(d) => format!(
                    "`{}` has no generated `{function}` (a robot without [constraint] has only fk and jb0e)",
                    d.name
                ),
                None => format!(
                    "`{}` is not defined for a closed mechanism (use jr, jc, passive or det)",
                    function.short_name()
                ),
            })
        };
        let compiled = generated.compiled(function).ok_or_else(missing)?;
        let layout = generated.shape(function).ok_or_else(missing)?;
        let row_major = generated
            .row_major_positions(function)
            .ok_or_else(missing)?;
        Ok(Evaluator {
            robot: self,
            generated,
            function,
            compiled,
            shape: Shape { layout },
            row_major,
        })
    }

    /// Several functions of a serial robot as one compiled program that computes every value
    /// they share once (the pose of a link and its Jacobian share the whole walk along the
    /// chain): the program a fused function of these outputs has in the generated module
    /// (`trocar generate --function NAME=OUTPUT,...`). The first call with a set builds its
    /// program (about as long as `trocar generate`; tens of milliseconds on a 7-joint arm);
    /// later calls with the same functions in the same order reuse it.
    ///
    /// ```no_run
    /// use trocar_api::{Function, Robot};
    /// let robot = Robot::load("panda-laparoscope")?;
    /// let both = robot.fused_evaluator(&[
    ///     Function::ConstrainedLinkKinematics, // g_0i, 4 × 4
    ///     Function::PartialBodyJacobian,       // J^B_0i, 6 × 7
    /// ])?;
    /// let mut out = vec![0.0; both.len()];
    /// both.eval_into(&[0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8], &robot.param_values(&[])?, &mut out)?;
    /// let (pose, jacobian) = (&out[both.range(0)], &out[both.range(1)]);
    /// # Ok::<(), trocar_api::Error>(())
    /// ```
    ///
    /// An error when `functions` is empty, names one twice or one the robot does not have, or
    /// the robot is a closed mechanism.
    pub fn fused_evaluator(&self, functions: &[Function]) -> Result<FusedEvaluator<'_>> {
        Robot::check_outputs(functions)?;
        let Kind::Serial(s) = &self.kind else {
            return Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: several outputs in one program are built for serial \
                 robots (evaluate jr, jc, passive and det one by one)",
                self.name()
            )));
        };
        let generated = self.derive()?;
        let cached = |list: &[(Vec<Function>, Arc<Fusion>)]| {
            list.iter()
                .find(|(f, _)| f == functions)
                .map(|(_, fusion)| Arc::clone(fusion))
        };
        // A poisoned lock held only a list that was complete at every step.
        let found = cached(&s.fused.lock().unwrap_or_else(|e| e.into_inner()));
        let fusion = match found {
            Some(fusion) => fusion,
            None => {
                // Built outside the lock: another thread may build the same set meanwhile, and
                // the first one stored is kept.
                let program = generated.fuse(functions).map_err(|e| match e {
                    trocar_codegen::Error::Function { name, message } => {
                        Error::argument("what", format!("`{name}`: {message}"))
                    }
                    e => Error::Generation(e),
                })?;
                let built = Arc::new(Fusion::new(program));
                let mut list = s.fused.lock().unwrap_or_else(|e| e.into_inner());
                match cached(&list) {
                    Some(fusion) => fusion,
                    None => {
                        list.push((functions.to_vec(), Arc::clone(&built)));
                        built
                    }
                }
            }
        };
        Ok(FusedEvaluator {
            robot: self,
            generated,
            fusion,
        })
    }

    /// `function` from the numeric runtime instead of the closed forms (serial robots: `jr`,
    /// `manip`, `task`, `jc`, `jb0i`, `jb0e`, `fk`; mechanisms: `jr`, `jc`, `passive`, `det`).
    pub fn eval_numeric(
        &self,
        function: Function,
        q: &[f64],
        params: &[(String, f64)],
    ) -> Result<Evaluation> {
        self.check_q(q)?;
        let values = self.param_values(params)?;
        let out = match &self.kind {
            Kind::Serial(s) => self.serial_numeric(s, function, q, &values, params.is_empty())?,
            Kind::Mechanism(m) => mechanism_numeric(&m.model, function, q, &values)?,
        };
        if out.is_finite() {
            Ok(out)
        } else {
            Err(Error::NotFinite(format!(
                "`{}`, evaluated numerically: the result is not finite at this configuration and these \
                 parameter values (an extreme parameter value, or a singular configuration)",
                function.short_name()
            )))
        }
    }

    fn robot_error(&self) -> impl Fn(trocar_sim::robot::RobotError) -> Error + '_ {
        move |e| Error::Robot {
            file: self.description().and_then(|d| d.source.clone()),
            message: e.to_string(),
        }
    }

    /// The numeric robot at the nominal parameters, built once.
    pub fn numeric(&self) -> Result<&NumericRobot<f64>> {
        let Kind::Serial(s) = &self.kind else {
            return Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: it has no serial numeric robot",
                self.name()
            )));
        };
        if let Some(r) = s.numeric.get() {
            return Ok(r);
        }
        let r = NumericRobot::from_description(&s.desc, &[]).map_err(self.robot_error())?;
        Ok(s.numeric.get_or_init(|| r))
    }

    fn serial_numeric(
        &self,
        s: &Serial,
        function: Function,
        q: &[f64],
        values: &[f64],
        nominal: bool,
    ) -> Result<Evaluation> {
        let built;
        let robot = if nominal {
            self.numeric()?
        } else {
            let overrides: Vec<(String, f64)> = s
                .desc
                .parameters
                .iter()
                .map(|p| p.name.clone())
                .zip(values.iter().copied())
                .collect();
            built =
                NumericRobot::from_description(&s.desc, &overrides).map_err(self.robot_error())?;
            &built
        };
        let err = self.robot_error();
        let constrained_only = matches!(
            function,
            Function::ConstrainedJacobian
                | Function::Manipulability
                | Function::ConstraintJacobianC
                | Function::PartialBodyJacobian
                | Function::ConstrainedTaskJacobian
        );
        if constrained_only && s.desc.constraint.is_none() {
            return Err(Error::Unsupported(format!(
                "`{}` has no [constraint]: only jb0e and fk apply",
                s.desc.name
            )));
        }
        Ok(match function {
            Function::ConstrainedJacobian => {
                Evaluation::from_faer(&robot.constrained_jacobian(q).map_err(err)?)
            }
            Function::Manipulability => Evaluation::scalar(robot.manipulability(q).map_err(err)?),
            Function::ConstrainedTaskJacobian => {
                if s.desc.task.is_none() {
                    return Err(no_task(&s.desc));
                }
                Evaluation::from_faer(&robot.constrained_task_jacobian(q).map_err(err)?)
            }
            Function::ConstraintJacobianC => {
                Evaluation::from_faer(&robot.constraint_jacobian_c(q).map_err(err)?)
            }
            Function::PartialBodyJacobian => {
                Evaluation::from_faer(&robot.partial_body_jacobian(q).map_err(err)?)
            }
            Function::BodyJacobian => Evaluation::from_faer(&robot.body_jacobian(q).map_err(err)?),
            Function::ForwardKinematics => {
                Evaluation::from_faer(&robot.forward_kinematics_matrix(q).map_err(err)?)
            }
            other => {
                return Err(Error::Unsupported(format!(
                    "`{}`: the numeric runtime evaluates jr, manip, task, jc, \
                     jb0i, jb0e and fk",
                    other.short_name()
                )))
            }
        })
    }

    /// A closed mechanism's generated functions; the reduced Jacobian and the passive map from
    /// their numerators over `det J_Cp`.
    fn mechanism_generated(
        &self,
        function: Function,
        q: &[f64],
        values: &[f64],
    ) -> Result<Evaluation> {
        let Kind::Mechanism(mech) = &self.kind else {
            unreachable!("only mechanisms come here")
        };
        self.derive()?;
        let (generated, rows) = mech.generated.get().expect("derived above");
        let m = &mech.model;
        let n = q.len();
        let (active, passive) = m.partition();
        let (na, np, no) = (active.len(), passive.len(), m.outputs.len());
        let singular = || {
            Error::NotFinite(format!(
                "J_Cp is singular at this configuration (parallel singularity of `{}`)",
                m.name
            ))
        };
        let eval = |f: Function| {
            generated
                .outputs(f, q, values)
                .ok_or_else(|| Error::Unsupported(format!("internal: no generated `{f}`")))
        };
        // J_Cp, the passive columns of the emitted J_C: singular by the one rule of
        // `trocar_model::singularity`, as the numeric runtime decides (not by `det J_Cp != 0`,
        // which rounding decides at a singular configuration).
        if matches!(function, Function::ReducedJacobian | Function::PassiveMap) {
            let j_c = eval(Function::ConstraintJacobian)?;
            let j_cp = nalgebra::DMatrix::from_fn(*rows, np, |r, c| j_c[passive[c] * rows + r]);
            let sv: Vec<f64> = j_cp.singular_values().iter().copied().collect();
            if np > 0 && trocar_model::singularity::is_singular(&sv, (*rows).min(np)) {
                return Err(singular());
            }
        }
        let out = match function {
            Function::ConstraintJacobian => {
                Evaluation::from_column_major(&eval(Function::ConstraintJacobian)?, *rows, n)
            }
            Function::ConstraintDeterminant => {
                Evaluation::from_column_major(&eval(Function::ConstraintDeterminant)?, 1, 1)
            }
            Function::TaskJacobian => {
                Evaluation::from_column_major(&eval(Function::TaskJacobian)?, no, n)
            }
            Function::ReducedJacobian | Function::PassiveMap => {
                let (numerator, count) = if function == Function::ReducedJacobian {
                    (Function::ReducedJacobianNumerator, no)
                } else {
                    (Function::PassiveMapNumerator, np)
                };
                // Column-major, row 0 of every column is det J_Cp.
                let num = eval(numerator)?;
                let stride = 1 + count;
                let mut data = vec![0.0; count * na];
                for a in 0..na {
                    let det = num[a * stride];
                    if !(det.is_finite() && det != 0.0) {
                        return Err(singular());
                    }
                    for r in 0..count {
                        data[r * na + a] = num[a * stride + 1 + r] / det;
                    }
                }
                Evaluation {
                    rows: count,
                    cols: na,
                    data,
                }
            }
            other => {
                return Err(Error::Unsupported(format!(
                    "`{}` is not defined for a closed mechanism (use jr, jc, passive or det)",
                    other.short_name()
                )))
            }
        };
        if !out.is_finite() {
            return Err(singular());
        }
        Ok(out)
    }

    /// Row and column labels of `function`'s matrix: the twist components `v_x … w_z` of the
    /// frame a Jacobian maps to, and what its columns multiply (`v0i[k]`, the free coordinates
    /// of the constrained link's twist in the basis `Λ#`; `dq_<joint>`; `dv0r[k]`, the commanded
    /// velocity in the constrained directions); a mechanism's outputs, passive and active joints.
    /// `None` for a pose or a scalar.
    pub fn labels(&self, function: Function) -> Option<(Vec<String>, Vec<String>)> {
        match &self.kind {
            Kind::Serial(s) => serial_labels(&s.desc, function),
            Kind::Mechanism(m) => mechanism_labels(&m.model, function),
        }
    }

    /// Where the Jacobian behind `function` is singular at `q` by the one rule of
    /// [`trocar_model::singularity`] (the closed form's or the numeric runtime's, as `numeric`
    /// says), a sentence saying so: `J^r` for `jr`, the task Jacobian `S J^r` for `task`,
    /// whichever defines the manipulability for `manip`, `J^B_0i` for `jb0i`. `None` where it is
    /// regular, for another function, or for a mechanism. `evaluated` is that Jacobian when the
    /// caller has it already.
    pub fn singularity(
        &self,
        function: Function,
        q: &[f64],
        params: &[(String, f64)],
        numeric: bool,
        evaluated: Option<&Evaluation>,
    ) -> Result<Option<String>> {
        let Some(desc) = self.description() else {
            return Ok(None);
        };
        let (jacobian, name) = match function {
            Function::ConstrainedJacobian => (Function::ConstrainedJacobian, "J^r"),
            Function::ConstrainedTaskJacobian => {
                (Function::ConstrainedTaskJacobian, "the task Jacobian S J^r")
            }
            Function::Manipulability if desc.task.is_some() => {
                (Function::ConstrainedTaskJacobian, "the task Jacobian S J^r")
            }
            Function::Manipulability => (Function::ConstrainedJacobian, "J^r"),
            Function::PartialBodyJacobian => (Function::PartialBodyJacobian, "J^B_0i"),
            _ => return Ok(None),
        };
        let computed;
        let m = match evaluated {
            Some(m) => m,
            None => {
                computed = if numeric {
                    self.eval_numeric(jacobian, q, params)?
                } else {
                    self.eval(jacobian, q, params)?
                };
                &computed
            }
        };
        let j = nalgebra::DMatrix::from_fn(m.rows, m.cols, |r, c| m.get(r, c));
        let sv: Vec<f64> = j.singular_values().iter().copied().collect();
        let full = m.rows.min(m.cols);
        if !trocar_model::singularity::is_singular(&sv, full) {
            return Ok(None);
        }
        let smallest = sv.iter().copied().fold(f64::INFINITY, f64::min);
        let largest = sv.iter().copied().fold(0.0_f64, f64::max);
        Ok(Some(format!(
            "{name} is singular at this configuration: rank {} of {full}, smallest singular value \
             {smallest:.3e} ≤ {:.0e} × max(largest {largest:.3e}, 1){}",
            trocar_model::singularity::rank(&sv),
            trocar_model::singularity::RELATIVE_TOLERANCE,
            if function == Function::Manipulability {
                // w = Π σ ≤ σ_min σ_max^(full − 1): at most the tolerance times σ_max^full.
                format!(
                    "; its manipulability is below {:.0e} × largest^{full}: zero at this scale, \
                     whatever value is printed",
                    trocar_model::singularity::RELATIVE_TOLERANCE
                )
            } else {
                String::new()
            }
        )))
    }

    /// The generated Rust module: a serial robot's closed forms, or a mechanism's reduced
    /// kinematics, with `options` (the real type, the runtime path).
    pub fn generate(&self, options: &trocar_codegen::ModuleOptions) -> Result<String> {
        if options.c_api && self.is_mechanism() {
            return Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: the C ABI is emitted for serial robots",
                self.name()
            )));
        }
        if !options.functions.is_empty() && self.is_mechanism() {
            return Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: fused functions are emitted for serial \
                 robots",
                self.name()
            )));
        }
        Ok(match &self.kind {
            Kind::Serial(s) => trocar_codegen::generate_module_string(&s.desc, options)?,
            Kind::Mechanism(m) => trocar_codegen::generate_mechanism_string(&m.model, options)?,
        })
    }

    /// The C header of a serial robot's C ABI (`ModuleOptions::c_api`): sizes and parameter
    /// indices as `#define`s, one prototype per function (matrices column-major).
    pub fn c_header(&self, options: &trocar_codegen::ModuleOptions) -> Result<String> {
        match &self.kind {
            Kind::Serial(s) => Ok(trocar_codegen::generate_c_header(&s.desc, options)?),
            Kind::Mechanism(m) => Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: the C ABI is emitted for serial robots",
                m.model.name
            ))),
        }
    }

    /// The C++ header over a serial robot's C ABI (`trocar.hpp`-style: RAII controller,
    /// `std::array` and pointer signatures, `enum class Status`), for a robot whose constraint
    /// frame slides along its link.
    pub fn cpp_header(&self, options: &trocar_codegen::ModuleOptions) -> Result<String> {
        let name = self.name().to_string();
        match &self.kind {
            Kind::Serial(s) => {
                trocar_codegen::generate_cpp_header(&s.desc, options)?.ok_or_else(|| {
                    Error::Unsupported(format!(
                    "`{name}` has no controller (its constraint frame does not slide along its \
                     link): its C header alone serves"
                ))
                })
            }
            Kind::Mechanism(m) => Err(Error::Unsupported(format!(
                "`{}` is a closed mechanism: the C ABI is emitted for serial robots",
                m.model.name
            ))),
        }
    }

    /// Checks a set of outputs asked for together (`what`): at least one, none twice (by the
    /// function, whichever of its names was given).
    pub fn check_outputs(functions: &[Function]) -> Result<()> {
        if functions.is_empty() {
            return Err(Error::argument(
                "what",
                "no quantity asked for; name at least one",
            ));
        }
        if let Some(k) = (1..functions.len()).find(|&k| functions[..k].contains(&functions[k])) {
            return Err(Error::argument(
                "what",
                format!("`{}` asked for twice", functions[k].short_name()),
            ));
        }
        Ok(())
    }

    /// Checks a sample count of [`Robot::verify`]: at least 1 and at most [`MAX_SAMPLES`].
    pub fn check_samples(samples: usize) -> Result<()> {
        if samples == 0 {
            return Err(Error::argument("samples", "must be at least 1"));
        }
        if samples > MAX_SAMPLES {
            return Err(Error::argument(
                "samples",
                format!("{samples} asked for; at most {MAX_SAMPLES} samples are checked"),
            ));
        }
        Ok(())
    }

    /// Checks the generated closed forms of a serial robot against the numeric runtime and
    /// finite differences at `samples` random configurations drawn from `seed`; `progress`
    /// receives the fraction done.
    pub fn verify(
        &self,
        samples: usize,
        seed: u64,
        progress: impl FnMut(f64),
    ) -> Result<trocar_check::Report> {
        let Some(desc) = self.description() else {
            let name = &self.source;
            return Err(Error::Unsupported(format!(
                "`{name}` is a closed mechanism: `verify` checks serial robots; compare its \
                 closed form `jr` with the numeric runtime's (evaluated both ways)"
            )));
        };
        Self::check_samples(samples)?;
        let generated = self.derive()?;
        trocar_check::verify::verify(
            desc,
            generated,
            samples,
            seed,
            trocar_check::Tolerances::F64,
            progress,
        )
        .map_err(self.robot_error())
    }
}

/// One function of a robot, compiled, ready to evaluate at one configuration or many
/// ([`Robot::evaluator`]).
#[derive(Clone, Copy, Debug)]
pub struct Evaluator<'a> {
    robot: &'a Robot,
    generated: &'a Generated,
    function: Function,
    compiled: &'a Compiled,
    shape: Shape,
    /// Where each output goes in the row-major result ([`Layout::row_major_positions`]).
    row_major: &'a [usize],
}

thread_local! {
    /// Register file of [`Evaluator::eval_into`], kept per thread.
    static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Configurations from which [`Evaluator::eval_many`] uses every core.
const PARALLEL_FROM: usize = 512;

impl Evaluator<'_> {
    /// The function.
    pub fn function(&self) -> Function {
        self.function
    }

    /// Rows of the result (4 for a pose, 1 for a scalar).
    pub fn rows(&self) -> usize {
        self.shape.dims().0
    }

    /// Columns of the result.
    pub fn cols(&self) -> usize {
        self.shape.dims().1
    }

    /// Entries of one result (`rows · cols`).
    pub fn len(&self) -> usize {
        let (r, c) = self.shape.dims();
        r * c
    }

    /// Whether a result has no entries.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn block(&self) -> Block<'_> {
        Block {
            robot: self.robot,
            generated: self.generated,
            compiled: self.compiled,
            row_major: self.row_major,
            len: self.len(),
            transforms: match self.shape.layout {
                Layout::Transform => &[0],
                _ => &[],
            },
        }
    }

    /// Evaluates at `q` (one value per joint) with parameter values `values` (declaration
    /// order) into `out` (`rows · cols` entries, row by row). An error if the result is not
    /// finite (what it divides by is named); lengths are the caller's to get right (checked).
    pub fn eval_into(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<()> {
        match self.block().eval_into(q, values, out)? {
            None => Ok(()),
            Some(_) => Err(not_finite(self.generated, self.function, values, None)),
        }
    }

    /// Evaluates at `count = q.len() / dof` configurations given one after the other (row-major
    /// `count × dof`) into `out` (`count × rows × cols`, each result row by row), equal to
    /// `count` calls of [`Evaluator::eval_into`]; the configurations are evaluated
    /// [`trocar_codegen::evaluate::LANES`] at a time on every core.
    pub fn eval_many(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<()> {
        match self.block().eval_many(q, values, out)? {
            None => Ok(()),
            Some(k) => Err(not_finite(
                self.generated,
                self.function,
                values,
                Some(k / self.len().max(1)),
            )),
        }
    }
}

/// Several functions of a serial robot evaluated by one compiled program that computes every
/// value they share once ([`Robot::fused_evaluator`]): the program of a fused function of these
/// outputs in the generated module (`trocar generate --function`). A result holds each
/// function's matrix row by row, one function after the other ([`FusedEvaluator::range`]).
#[derive(Clone, Debug)]
pub struct FusedEvaluator<'a> {
    robot: &'a Robot,
    generated: &'a Generated,
    fusion: Arc<Fusion>,
}

/// A fused program and where its outputs go in a result.
#[derive(Debug)]
struct Fusion {
    program: FusedProgram,
    /// Each function's `(rows, cols)`.
    dims: Vec<(usize, usize)>,
    /// Where each function's matrix starts in a result.
    starts: Vec<usize>,
    /// Where each output of the program goes in a result.
    row_major: Vec<usize>,
    /// Where each homogeneous transform starts in a result.
    transforms: Vec<usize>,
    /// Entries of one result.
    len: usize,
}

impl Fusion {
    fn new(program: FusedProgram) -> Self {
        let dims: Vec<(usize, usize)> = program
            .outputs()
            .iter()
            .map(|(_, layout)| Shape { layout: *layout }.dims())
            .collect();
        let mut starts = Vec::with_capacity(dims.len());
        let mut row_major = Vec::new();
        let mut transforms = Vec::new();
        let mut len = 0;
        for ((_, layout), (r, c)) in program.outputs().iter().zip(&dims) {
            starts.push(len);
            row_major.extend(layout.row_major_positions().into_iter().map(|k| k + len));
            if let Layout::Transform = layout {
                transforms.push(len);
            }
            len += r * c;
        }
        Fusion {
            program,
            dims,
            starts,
            row_major,
            transforms,
            len,
        }
    }
}

impl FusedEvaluator<'_> {
    /// The functions, in the order of their matrices in a result.
    pub fn functions(&self) -> Vec<Function> {
        self.fusion
            .program
            .outputs()
            .iter()
            .map(|(f, _)| *f)
            .collect()
    }

    /// Each function's `(rows, cols)` (4 × 4 for a pose, 1 × 1 for a scalar), in order.
    pub fn dims(&self) -> &[(usize, usize)] {
        &self.fusion.dims
    }

    /// The entries of a result that hold function `k`'s matrix, row by row.
    ///
    /// # Panics
    /// If `k` is not below the number of functions.
    pub fn range(&self, k: usize) -> std::ops::Range<usize> {
        let (r, c) = self.fusion.dims[k];
        let start = self.fusion.starts[k];
        start..start + r * c
    }

    /// Entries of one result: every function's `rows · cols`, summed.
    pub fn len(&self) -> usize {
        self.fusion.len
    }

    /// Whether a result has no entries (never: a fused evaluator has at least one function).
    pub fn is_empty(&self) -> bool {
        self.fusion.len == 0
    }

    fn block(&self) -> Block<'_> {
        Block {
            robot: self.robot,
            generated: self.generated,
            compiled: self.fusion.program.compiled(),
            row_major: &self.fusion.row_major,
            len: self.fusion.len,
            transforms: &self.fusion.transforms,
        }
    }

    /// The function whose matrix holds entry `k` of a result.
    fn function_at(&self, k: usize) -> Function {
        let j = (0..self.fusion.dims.len())
            .rfind(|&j| self.fusion.starts[j] <= k)
            .unwrap_or(0);
        self.fusion.program.outputs()[j].0
    }

    /// Evaluates at `q` (one value per joint) with parameter values `values` (declaration
    /// order) into `out` ([`FusedEvaluator::len`] entries: each function's matrix row by row,
    /// one after the other). Each function's values equal its own [`Evaluator`]'s to rounding.
    /// An error if a result is not finite (which function, and what it divides by).
    pub fn eval_into(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<()> {
        match self.block().eval_into(q, values, out)? {
            None => Ok(()),
            Some(k) => Err(not_finite(
                self.generated,
                self.function_at(k),
                values,
                None,
            )),
        }
    }

    /// Evaluates at `count = q.len() / dof` configurations given one after the other into
    /// `out` (`count × len` entries, each configuration's result as
    /// [`FusedEvaluator::eval_into`] writes it), on every core as [`Evaluator::eval_many`].
    pub fn eval_many(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<()> {
        let len = self.fusion.len.max(1);
        match self.block().eval_many(q, values, out)? {
            None => Ok(()),
            Some(k) => Err(not_finite(
                self.generated,
                self.function_at(k % len),
                values,
                Some(k / len),
            )),
        }
    }

    /// [`FusedEvaluator::eval_many`] with each function's results in a slice of its own:
    /// `outs[k]` receives function `k`'s matrix (row by row) for every configuration, one after
    /// the other (`count × rows · cols` entries), as separate arrays of each quantity need them.
    /// The configurations go through a small buffer, 64 at a time, on every core.
    pub fn eval_many_each(&self, q: &[f64], values: &[f64], outs: &mut [&mut [f64]]) -> Result<()> {
        let block = self.block();
        let count = block.configurations(q, values)?;
        let fusion = &self.fusion;
        if outs.len() != fusion.dims.len() {
            return Err(Error::Input(format!(
                "{} outputs given for {} functions",
                outs.len(),
                fusion.dims.len()
            )));
        }
        let sizes: Vec<usize> = fusion.dims.iter().map(|(r, c)| r * c).collect();
        for (k, (out, size)) in outs.iter().zip(&sizes).enumerate() {
            if out.len() != count * size {
                return Err(Error::Input(format!(
                    "output {k} holds {} values, not {count} × {size}",
                    out.len()
                )));
            }
        }
        let n = self.generated.joints();
        let len = fusion.len;
        let per = per_thread(count);
        // One part per thread: its configurations and its piece of every output.
        let mut pieces: Vec<std::slice::ChunksMut<'_, f64>> = outs
            .iter_mut()
            .zip(&sizes)
            .map(|(out, size)| out.chunks_mut((per * size).max(1)))
            .collect();
        let parts: Vec<(&[f64], Vec<&mut [f64]>)> = q
            .chunks(per * n)
            .map(|qs| {
                let mine = pieces
                    .iter_mut()
                    .map(|p| p.next().unwrap_or_default())
                    .collect();
                (qs, mine)
            })
            .collect();
        let finite = on_every_core(parts, |(qs, mut mine)| {
            let mut buffer = vec![0.0; CHUNK * len];
            for b in buffer.chunks_exact_mut(len.max(1)) {
                block.last_rows(b);
            }
            let mut finite = true;
            for (c, qc) in qs.chunks(CHUNK * n).enumerate() {
                let m = qc.len() / n;
                let buffer = &mut buffer[..m * len];
                finite &=
                    block
                        .compiled
                        .eval_batch_ordered(qc, values, buffer, len, block.row_major);
                for (k, piece) in mine.iter_mut().enumerate() {
                    let (start, size) = (fusion.starts[k], sizes[k]);
                    let to = &mut piece[c * CHUNK * size..][..m * size];
                    for (to, from) in to
                        .chunks_exact_mut(size.max(1))
                        .zip(buffer.chunks_exact(len.max(1)))
                    {
                        to.copy_from_slice(&from[start..start + size]);
                    }
                }
            }
            finite
        });
        if finite {
            return Ok(());
        }
        // The earliest configuration with a value that is not finite, and its function.
        let (configuration, k) = outs
            .iter()
            .zip(&sizes)
            .enumerate()
            .filter_map(|(k, (out, size))| {
                let at = out.iter().position(|v| !v.is_finite())?;
                Some((at / size.max(&1), k))
            })
            .min()
            .unwrap_or((0, 0));
        Err(not_finite(
            self.generated,
            fusion.program.outputs()[k].0,
            values,
            Some(configuration),
        ))
    }
}

/// Configurations [`FusedEvaluator::eval_many_each`] evaluates at a time into its buffer.
const CHUNK: usize = 64;

/// What both evaluators run: a compiled program whose outputs go to the positions `row_major`
/// of a result of `len` entries, in which homogeneous transforms start at `transforms`.
struct Block<'r> {
    robot: &'r Robot,
    generated: &'r Generated,
    compiled: &'r Compiled,
    row_major: &'r [usize],
    len: usize,
    transforms: &'r [usize],
}

impl Block<'_> {
    /// The constant last row of each homogeneous transform in one result, which no output
    /// writes.
    fn last_rows(&self, out: &mut [f64]) {
        for &t in self.transforms {
            out[t + 12..t + 16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
        }
    }

    /// One configuration into `out`; the first entry that is not finite, if any.
    fn eval_into(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<Option<usize>> {
        self.check_lengths(q.len(), values.len(), out.len(), 1)?;
        self.last_rows(out);
        let finite = SCRATCH.with(|s| {
            self.compiled
                .eval_into_at(q, values, &mut s.borrow_mut(), out, Some(self.row_major))
        });
        Ok((!finite).then(|| out.iter().position(|v| !v.is_finite()).unwrap_or(0)))
    }

    /// Configurations one after the other into `out`, on every core from [`PARALLEL_FROM`]
    /// configurations; the first entry that is not finite, if any.
    fn eval_many(&self, q: &[f64], values: &[f64], out: &mut [f64]) -> Result<Option<usize>> {
        let count = self.configurations(q, values)?;
        let n = self.generated.joints();
        self.check_lengths(n, values.len(), out.len(), count)?;
        let len = self.len;
        if !self.transforms.is_empty() {
            for block in out.chunks_exact_mut(len) {
                self.last_rows(block);
            }
        }
        let per = per_thread(count);
        let parts = q.chunks(per * n).zip(out.chunks_mut(per * len)).collect();
        let finite = on_every_core(parts, |(qs, outs)| {
            self.compiled
                .eval_batch_ordered(qs, values, outs, len, self.row_major)
        });
        Ok((!finite).then(|| out.iter().position(|v| !v.is_finite()).unwrap_or(0)))
    }

    /// The number of configurations in `q` (one after the other), checked: whole, finite, and
    /// `values` one per parameter.
    fn configurations(&self, q: &[f64], values: &[f64]) -> Result<usize> {
        let n = self.generated.joints();
        let count = q.len().checked_div(n).unwrap_or(0);
        if q.len() != count * n {
            return Err(Error::Input(format!(
                "the configurations hold {} values, not a multiple of the {n} joints",
                q.len()
            )));
        }
        self.check_lengths(n, values.len(), 0, 0)?;
        if let Some(k) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::Input(format!(
                "configuration {}: joint {} is not finite ({})",
                k / n,
                k % n + 1,
                q[k]
            )));
        }
        Ok(count)
    }

    fn check_lengths(&self, q: usize, values: usize, out: usize, count: usize) -> Result<()> {
        let n = self.generated.joints();
        let p = self.generated.param_count();
        if q != n {
            return Err(Error::argument(
                "q",
                format!(
                    "{q} values given, `{}` has {n} joints (give all joint values, base first)",
                    self.robot.name()
                ),
            ));
        }
        if values != p {
            return Err(Error::Input(format!(
                "{values} parameter values given, `{}` has {p}",
                self.robot.name()
            )));
        }
        if out != count * self.len {
            return Err(Error::Input(format!(
                "the output holds {out} values, not {count} × {}",
                self.len
            )));
        }
        Ok(())
    }
}

/// Configurations per thread for `count` of them: all on one thread below [`PARALLEL_FROM`],
/// otherwise shared evenly by the cores.
fn per_thread(count: usize) -> usize {
    let threads = if count >= PARALLEL_FROM {
        std::thread::available_parallelism().map_or(1, |p| p.get())
    } else {
        1
    };
    count.div_ceil(threads.max(1)).max(1)
}

/// `work` on every part, the first on this thread and each other one on a thread of its own;
/// whether every call returned `true`.
fn on_every_core<T: Send>(parts: Vec<T>, work: impl Fn(T) -> bool + Sync) -> bool {
    let mut parts = parts.into_iter();
    let Some(here) = parts.next() else {
        return true;
    };
    if parts.len() == 0 {
        return work(here);
    }
    std::thread::scope(|scope| {
        let work = &work;
        let handles: Vec<_> = parts.map(|part| scope.spawn(move || work(part))).collect();
        let first = work(here);
        handles.into_iter().fold(first, |all, h| {
            // A worker's panic is a fault of this code, not a value: it goes on as one.
            h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)) && all
        })
    })
}

/// Why `function`'s result is not finite: a parameter it divides by at zero, or an overflow.
fn not_finite(
    generated: &Generated,
    function: Function,
    values: &[f64],
    configuration: Option<usize>,
) -> Error {
    let names = generated.param_names();
    let divisors: Vec<(String, f64)> = generated
        .divisors(function)
        .into_iter()
        .filter_map(|d| {
            let k = names.iter().position(|n| *n == d)?;
            Some((d, values[k]))
        })
        .collect();
    let list = |only_zero: bool| {
        divisors
            .iter()
            .filter(|(_, v)| !only_zero || v.abs() < f64::MIN_POSITIVE)
            .map(|(d, v)| format!("`{d}` = {v:e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let at = match configuration {
        Some(k) => format!("at configuration {k}"),
        None => "at this configuration".to_string(),
    };
    let zero = list(true);
    Error::NotFinite(if !zero.is_empty() {
        format!("`{function}` is not finite {at}: it divides by {zero} (zero or subnormal)")
    } else if !divisors.is_empty() {
        format!(
            "`{function}` is not finite {at}: an intermediate value overflowed; it divides by {}",
            list(false)
        )
    } else {
        format!(
            "`{function}` is not finite {at}: an intermediate value overflowed (a joint value or a parameter too large)"
        )
    })
}

/// The error for a task Jacobian asked of a robot without a `[task]`.
fn no_task(desc: &RobotDescription) -> Error {
    Error::Unsupported(format!(
        "`{}` has no [task]: the task Jacobian needs one (select = [\"x\", \"y\", \"z\", \"rz\"], ...)",
        desc.name
    ))
}

/// The numeric runtime's differential kinematics of a closed mechanism.
fn mechanism_numeric(
    m: &MechanismModel,
    function: Function,
    q: &[f64],
    values: &[f64],
) -> Result<Evaluation> {
    let sim = |e: &dyn std::fmt::Display| Error::NotFinite(e.to_string());
    let mech = trocar_sim::closed_chain::Mechanism::from_model(m, values).map_err(|e| sim(&e))?;
    let theta = faer::ColRef::from_slice(q).to_owned();
    let d = mech.differential(&theta).map_err(|e| sim(&e))?;
    Ok(match function {
        Function::ConstraintJacobian => Evaluation::from_faer(&d.j_c),
        Function::ConstraintDeterminant if d.j_cp.nrows() == d.j_cp.ncols() => {
            Evaluation::scalar(trocar_sim::linalg::determinant(d.j_cp.as_ref()))
        }
        Function::ConstraintDeterminant => {
            return Err(Error::Unsupported(format!(
                "det: `{}` has {} structural equations and {} passive joints, so J_Cp \
                 is {} × {}, not square, and has no determinant (use jr, jc or passive)",
                m.name,
                d.j_cp.nrows(),
                d.j_cp.ncols(),
                d.j_cp.nrows(),
                d.j_cp.ncols()
            )))
        }
        Function::ReducedJacobian | Function::PassiveMap => {
            let r = mech.reduced(&theta).map_err(|e| sim(&e))?;
            if function == Function::ReducedJacobian {
                Evaluation::from_faer(&r.jacobian)
            } else {
                Evaluation::from_faer(&r.passive_map)
            }
        }
        other => {
            return Err(Error::Unsupported(format!(
                "`{}` is not defined for a closed mechanism (use jr, jc, passive or det)",
                other.short_name()
            )))
        }
    })
}

/// The components of a twist `(v, ω)`, the rows of every Jacobian.
pub const TWIST: [&str; 6] = ["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"];

fn serial_labels(
    desc: &RobotDescription,
    function: Function,
) -> Option<(Vec<String>, Vec<String>)> {
    let twist: Vec<String> = TWIST.iter().map(|s| s.to_string()).collect();
    let joints = |range: std::ops::Range<usize>| -> Vec<String> {
        desc.joints[range]
            .iter()
            .map(|j| format!("dq_{}", j.name))
            .collect()
    };
    let n = desc.joints.len();
    let constraint = desc.constraint.as_ref();
    let jr_cols = || {
        let c = constraint?;
        let mut cols: Vec<String> = (1..=6 - c.h.len()).map(|k| format!("v0i[{k}]")).collect();
        cols.extend(joints(c.link..n));
        Some(cols)
    };
    match function {
        Function::ConstrainedJacobian => Some((twist, jr_cols()?)),
        Function::ConstrainedTaskJacobian => {
            let task = desc.task.as_ref()?;
            // A row of S that selects one component is named after it.
            let rows = task
                .select
                .iter()
                .enumerate()
                .map(|(r, row)| {
                    let ones: Vec<usize> = (0..6).filter(|&c| row[c] != 0.0).collect();
                    match ones.as_slice() {
                        [c] if row[*c] == 1.0 => TWIST[*c].to_string(),
                        _ => format!("s[{}]", r + 1),
                    }
                })
                .collect();
            Some((rows, jr_cols()?))
        }
        Function::ConstraintJacobianC => Some((
            twist,
            (1..=constraint?.h.len())
                .map(|k| format!("dv0r[{k}]"))
                .collect(),
        )),
        Function::PartialBodyJacobian => Some((twist, joints(0..constraint?.link))),
        Function::BodyJacobian => Some((twist, joints(0..n))),
        _ => None,
    }
}

fn mechanism_labels(m: &MechanismModel, function: Function) -> Option<(Vec<String>, Vec<String>)> {
    let names = m.joint_names();
    let (active, passive) = m.partition();
    let rates = |idx: &[usize]| -> Vec<String> {
        idx.iter().map(|&k| format!("dq_{}", names[k])).collect()
    };
    match function {
        Function::ReducedJacobian => Some((
            m.outputs
                .iter()
                .map(|o| format!("{o:?}").to_lowercase())
                .collect(),
            rates(&active),
        )),
        Function::PassiveMap => Some((rates(&passive), rates(&active))),
        Function::ConstraintJacobian => Some((
            (1..=m.n_constraints()).map(|k| format!("c[{k}]")).collect(),
            rates(&(0..names.len()).collect::<Vec<_>>()),
        )),
        _ => None,
    }
}

/// The body ((2.55)) or spatial ((2.53)) Jacobian of the chain of `urdf` from its root to
/// `tip`, at all joint values `q` (root first).
pub fn urdf_jacobian(urdf: &Path, tip: &str, q: &[f64], spatial: bool) -> Result<Evaluation> {
    let desc = RobotDescription::from_urdf_file(urdf, tip)?;
    let robot = Robot::from_description(desc);
    robot.check_q(q)?;
    let numeric = robot.numeric()?;
    let j = if spatial {
        numeric.spatial_jacobian(q)
    } else {
        numeric.body_jacobian(q)
    }
    .map_err(robot.robot_error())?;
    Ok(Evaluation::from_faer(&j))
}
