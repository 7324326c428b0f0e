//! `trocar eval`: the constrained Jacobian and friends of a serial robot or a closed mechanism
//! at one configuration, from the generated closed forms or (`--numeric`) the numeric runtime.

use crate::args::What;
use crate::output::{CliError, MatrixOut};
use crate::params;
use crate::robot::{check_q, numeric_robot, robot_error};
use clap::ValueEnum;
use trocar_codegen::catalogue::Function;
use trocar_codegen::evaluate::Generated;
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::RobotDescription;
use trocar_model::Description;

/// `trocar eval`: loads `robot` (file or shipped name) and evaluates `what` at all joint values
/// `q`, with the parameter overrides `params` (`(name, value)`).
pub fn eval(
    robot: &str,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
    numeric: bool,
) -> Result<MatrixOut, CliError> {
    match Description::load(robot)? {
        Description::Mechanism(m) => eval_mechanism(&m, q, params, what, numeric),
        Description::Serial(desc) => eval_serial(&desc, q, params, what, numeric),
    }
}

/// `trocar eval` for a serial robot: `--what jr` (J^r_0e, (3.15)), `manip` ((3.36)), `jc`
/// ((3.33)), `jb0i` ((3.13)), `jb0e` ((2.55)) or `fk`; from the generated closed forms
/// (interpreted exactly as emitted) or, with `numeric`, the numeric runtime.
pub fn eval_serial(
    desc: &RobotDescription,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
    numeric: bool,
) -> Result<MatrixOut, CliError> {
    check_q(desc, q)?;
    let declared = desc.parameters.iter().map(|p| (p.name.as_str(), p.value));
    let values = params::resolve(declared, params, "description")?;
    if matches!(what, What::Passive | What::Det) {
        return Err(CliError(format!(
            "--what {}: only for closed mechanisms (`{}` is a serial robot)",
            what_name(what),
            desc.name
        )));
    }
    if numeric {
        finite_numeric(serial_numeric(desc, q, &values, what)?, what)
    } else {
        serial_generated(desc, q, &values, what)
    }
}

/// The numeric runtime's answer, or an error where it is not finite (never a `NaN` or `inf`
/// printed with exit code 0): a parameter at an extreme value (`l_a = 1e-200` overflows `w`), or
/// a mechanism at a configuration where the answer is undefined.
fn finite_numeric(out: MatrixOut, what: What) -> Result<MatrixOut, CliError> {
    if out.is_finite() {
        Ok(out)
    } else {
        Err(CliError(format!(
            "--what {} --numeric: the result is not finite at this configuration and these \
             parameter values (an extreme parameter value, or a singular configuration)",
            what_name(what)
        )))
    }
}

/// The generated closed forms of a serial robot, interpreted exactly as emitted.
fn serial_generated(
    desc: &RobotDescription,
    q: &[f64],
    values: &[f64],
    what: What,
) -> Result<MatrixOut, CliError> {
    let generated = crate::progress::with_spinner(
        &format!("deriving the closed forms of `{}`", desc.name),
        || Generated::new(desc),
    )
    .map_err(CliError::from_display)?;
    let function = match what {
        What::Jr => Function::ConstrainedJacobian,
        What::Manip => Function::Manipulability,
        What::Task => Function::ConstrainedTaskJacobian,
        What::Jc => Function::ConstraintJacobianC,
        What::Jb0i => Function::PartialBodyJacobian,
        What::Jb0e => Function::BodyJacobian,
        What::Fk => Function::ForwardKinematics,
        What::Passive | What::Det => unreachable!("rejected by eval_serial"),
    };
    let m = generated.evaluate(function, q, values).ok_or_else(|| {
        CliError(if what == What::Task {
            format!(
                "`{}` has no [task]: --what task needs one (select = [\"x\", \"y\", \"z\", \"rz\"], ...)",
                desc.name
            )
        } else {
            format!(
                "`{}` has no generated `{function}` (a robot without [constraint] has only fk and jb0e)",
                desc.name
            )
        })
    })?;
    if m.values.iter().any(|v| !v.is_finite()) {
        // Say which parameter it divides by is (numerically) zero, when one is.
        let names: Vec<&str> = desc.parameters.iter().map(|p| p.name.as_str()).collect();
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
        let zero = list(true);
        return Err(CliError(if !zero.is_empty() {
            format!(
                "`{function}` is not finite at this configuration: it divides by {zero} (zero or subnormal)"
            )
        } else if !divisors.is_empty() {
            format!(
                "`{function}` is not finite at this configuration: an intermediate value overflowed; it divides by {}",
                list(false)
            )
        } else {
            format!(
                "`{function}` is not finite at this configuration: an intermediate value overflowed (a joint value or a parameter too large)"
            )
        }));
    }
    Ok(MatrixOut::from_evaluated(&m))
}

/// The numeric runtime's kinematics of a serial robot.
fn serial_numeric(
    desc: &RobotDescription,
    q: &[f64],
    values: &[f64],
    what: What,
) -> Result<MatrixOut, CliError> {
    let robot = numeric_robot(desc, values)?;
    let err = robot_error(desc);
    let needs_constraint = matches!(
        what,
        What::Jr | What::Manip | What::Jc | What::Jb0i | What::Task
    );
    if needs_constraint && desc.constraint.is_none() {
        return Err(CliError(format!(
            "`{}` has no [constraint]: only --what jb0e and fk apply",
            desc.name
        )));
    }
    Ok(match what {
        What::Jr => MatrixOut::from_faer(&robot.constrained_jacobian(q).map_err(err)?),
        What::Manip => MatrixOut::scalar(robot.manipulability(q).map_err(err)?),
        What::Task => {
            if desc.task.is_none() {
                return Err(CliError(format!(
                    "`{}` has no [task]: --what task needs one (select = [\"x\", \"y\", \"z\", \"rz\"], ...)",
                    desc.name
                )));
            }
            MatrixOut::from_faer(&robot.task_jacobian(q).map_err(err)?)
        }
        What::Jc => MatrixOut::from_faer(&robot.moving_rcm_jacobian(q).map_err(err)?),
        What::Jb0i => MatrixOut::from_faer(&robot.partial_body_jacobian(q).map_err(err)?),
        What::Jb0e => MatrixOut::from_faer(&robot.body_jacobian(q).map_err(err)?),
        What::Fk => MatrixOut::from_faer(&robot.forward_kinematics_matrix(q).map_err(err)?),
        What::Passive | What::Det => unreachable!("rejected by eval_serial"),
    })
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
    if let Err((k, problem)) = trocar_model::validity::check_all(q) {
        return Err(CliError(format!(
            "--q: value {} ({}, {:e}) {problem}",
            k + 1,
            names[k],
            q[k]
        )));
    }
    let declared = m.parameter_names().into_iter().zip(m.nominal_values());
    let values = params::resolve(declared, params, "mechanism")?;
    if numeric {
        finite_numeric(mechanism_numeric(m, q, &values, what)?, what)
    } else {
        mechanism_generated(m, q, &values, what)
    }
}

/// The numeric runtime's differential kinematics of a closed mechanism.
fn mechanism_numeric(
    m: &MechanismModel,
    q: &[f64],
    values: &[f64],
    what: What,
) -> Result<MatrixOut, CliError> {
    let mech = trocar_sim::closed_chain::Mechanism::from_model(m, values)
        .map_err(CliError::from_display)?;
    let theta = trocar::nalgebra::DVector::from_row_slice(q);
    let d = mech.differential(&theta).map_err(CliError::from_display)?;
    Ok(match what {
        What::Jc => MatrixOut::from_nalgebra(&d.j_c),
        What::Det if d.j_cp.is_square() => {
            MatrixOut::scalar(trocar_sim::closed_chain::linalg::determinant(&d.j_cp))
        }
        What::Det => {
            return Err(CliError(format!(
                "--what det: `{}` has {} structural equations and {} passive joints, so J_Cp \
                 is {} × {}, not square, and has no determinant (use jr, jc or passive)",
                m.name,
                d.j_cp.nrows(),
                d.j_cp.ncols(),
                d.j_cp.nrows(),
                d.j_cp.ncols()
            )))
        }
        What::Jr | What::Passive => {
            let r = mech.reduced(&theta).map_err(CliError::from_display)?;
            if what == What::Jr {
                MatrixOut::from_nalgebra(&r.jacobian)
            } else {
                MatrixOut::from_nalgebra(&r.passive_map)
            }
        }
        _ => return Err(unsupported_for_mechanism(what)),
    })
}

/// The generated closed forms of a closed mechanism, interpreted exactly as emitted.
fn mechanism_generated(
    m: &MechanismModel,
    q: &[f64],
    values: &[f64],
    what: What,
) -> Result<MatrixOut, CliError> {
    let n = q.len();
    let (active, passive) = m.partition();
    let (na, np, no) = (active.len(), passive.len(), m.outputs.len());
    let singular = || {
        CliError(format!(
            "J_Cp is singular at this configuration (parallel singularity of `{}`)",
            m.name
        ))
    };
    let d = trocar_codegen::closed_chain::derive(m)?;
    let generated = Generated::mechanism(&d);
    let eval = |f: Function| {
        generated
            .outputs(f, q, values)
            .ok_or_else(|| CliError(format!("internal: no generated `{f}`")))
    };
    // J_Cp, the passive columns of the emitted J_C: singular by the one rule of
    // `trocar_model::singularity`, as the numeric runtime decides (not by `det J_Cp != 0`,
    // which rounding decides at a singular configuration).
    if matches!(what, What::Jr | What::Passive) {
        let j_c = eval(Function::ConstraintJacobian)?;
        let rows = d.j_c.rows();
        let j_cp = trocar::nalgebra::DMatrix::from_fn(rows, np, |r, c| j_c[passive[c] * rows + r]);
        let sv: Vec<f64> = j_cp.singular_values().iter().copied().collect();
        if np > 0 && trocar_model::singularity::is_singular(&sv, rows.min(np)) {
            return Err(singular());
        }
    }
    let out = match what {
        What::Jc => MatrixOut::column_major(&eval(Function::ConstraintJacobian)?, d.j_c.rows(), n),
        What::Det => MatrixOut::column_major(&eval(Function::ConstraintDeterminant)?, 1, 1),
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
    if !out.is_finite() {
        return Err(singular());
    }
    Ok(out)
}

fn unsupported_for_mechanism(what: What) -> CliError {
    CliError(format!(
        "--what {}: not defined for a closed mechanism (use jr, jc, passive or det)",
        what_name(what)
    ))
}

/// The command-line spelling of `what`.
fn what_name(what: What) -> String {
    what.to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default()
}

/// The components of a twist `(v, ω)`, the rows of every Jacobian `eval` prints.
pub(crate) const TWIST: [&str; 6] = ["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"];

/// Row and column labels of `what` for a serial robot, for text output: the twist components
/// of the frame a Jacobian maps to, and what its columns multiply (`v0i[k]`, the free
/// coordinates of the constrained link's twist in the basis `Λ#`; `dq_<joint>`; `dv0r[k]`, the
/// commanded velocity in the constrained directions). `None` for `fk`, `manip` (no labels).
pub fn serial_labels(desc: &RobotDescription, what: What) -> Option<(Vec<String>, Vec<String>)> {
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
    match what {
        What::Jr => Some((twist, jr_cols()?)),
        What::Task => {
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
        What::Jc => Some((
            twist,
            (1..=constraint?.h.len())
                .map(|k| format!("dv0r[{k}]"))
                .collect(),
        )),
        What::Jb0i => Some((twist, joints(0..constraint?.link))),
        What::Jb0e => Some((twist, joints(0..n))),
        _ => None,
    }
}

/// Row and column labels of `what` for a closed mechanism (`jr`: the task components by the
/// active joints; `passive`: passive joints by active joints; `jc`: the structural equations by
/// all joints).
pub fn mechanism_labels(m: &MechanismModel, what: What) -> Option<(Vec<String>, Vec<String>)> {
    let names = m.joint_names();
    let (active, passive) = m.partition();
    let rates = |idx: &[usize]| -> Vec<String> {
        idx.iter().map(|&k| format!("dq_{}", names[k])).collect()
    };
    match what {
        What::Jr => Some((
            m.outputs
                .iter()
                .map(|o| format!("{o:?}").to_lowercase())
                .collect(),
            rates(&active),
        )),
        What::Passive => Some((rates(&passive), rates(&active))),
        What::Jc => Some((
            (1..=m.n_constraints()).map(|k| format!("c[{k}]")).collect(),
            rates(&(0..names.len()).collect::<Vec<_>>()),
        )),
        _ => None,
    }
}

/// Runs `trocar eval`: prints the matrix as JSON or aligned text.
pub(crate) fn run(
    robot: &str,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
    json: bool,
    numeric: bool,
) -> Result<i32, CliError> {
    match Description::load(robot)? {
        Description::Mechanism(m) => {
            eval_mechanism(&m, q, params, what, numeric)?.print(json, mechanism_labels(&m, what))?
        }
        Description::Serial(desc) => {
            let out = eval_serial(&desc, q, params, what, numeric)?;
            out.print(json, serial_labels(&desc, what))?;
            // The answer is the Jacobian to test, unless it is the manipulability.
            let shown = (what != What::Manip).then_some(&out);
            if let Some(note) = serial_singularity(&desc, q, params, what, numeric, shown)? {
                eprintln!("note: {note}");
            }
        }
    }
    Ok(0)
}

/// Where the Jacobian behind `what` is singular at `q` by the one rule of
/// [`trocar_model::singularity`] (the closed form's or the numeric runtime's, as `numeric`
/// says), what `trocar eval` says about it: `J^r` for `jr`, the task Jacobian `S J^r` for `task`,
/// whichever defines the manipulability for `manip`, `J^B_0i` for `jb0i`. `None` where it is
/// regular, or for another `what`. `evaluated` is that Jacobian when the caller has it already
/// (`trocar eval --what jr` prints it), so it is not evaluated twice.
pub fn serial_singularity(
    desc: &RobotDescription,
    q: &[f64],
    params: &[(String, f64)],
    what: What,
    numeric: bool,
    evaluated: Option<&MatrixOut>,
) -> Result<Option<String>, CliError> {
    let (jacobian, name) = match what {
        What::Jr => (What::Jr, "J^r"),
        What::Task => (What::Task, "the task Jacobian S J^r"),
        What::Manip if desc.task.is_some() => (What::Task, "the task Jacobian S J^r"),
        What::Manip => (What::Jr, "J^r"),
        What::Jb0i => (What::Jb0i, "J^B_0i"),
        _ => return Ok(None),
    };
    let computed;
    let m = match evaluated {
        Some(m) => m,
        None => {
            computed = eval_serial(desc, q, params, jacobian, numeric)?;
            &computed
        }
    };
    let j = trocar::nalgebra::DMatrix::from_fn(m.rows, m.cols, |r, c| m.data[r][c]);
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
        if what == What::Manip {
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
