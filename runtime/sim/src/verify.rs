//! Verification of generated kinematics against the numeric runtime and finite differences.
//!
//! A [`Candidate`] is any implementation of the robot's kinematics — in practice the generator's
//! closed forms, evaluated as emitted. [`verify`] draws random configurations and parameter values,
//! and compares, for every quantity the candidate offers:
//!
//! - candidate vs the numeric runtime ([`crate::robot::NumericRobot`]), relative to the matrix
//!   norm;
//! - the candidate's `J^B_0i` vs central differences of the candidate's own `g_0i`, and the
//!   numeric body Jacobian vs central differences of the candidate's `g_0e` — so an error common
//!   to the candidate and the runtime would still be caught by the finite differences.
//!
//! The result is a [`Report`] with the largest error of each check and the configuration where it
//! happened.

use crate::robot::{NumericRobot, RobotError};
use faer::Mat;
use nalgebra::{Matrix3, Vector3};
use std::fmt;
use trocar::se3::Se3;
use trocar_model::catalogue::Function;
use trocar_model::description::RobotDescription;

/// The generated functions [`verify`] checks against the numeric runtime, in report order.
pub const CHECKED: [Function; 8] = [
    Function::ForwardKinematics,
    Function::ConstrainedLinkKinematics,
    Function::PartialBodyJacobian,
    Function::ConstrainedJacobian,
    Function::ConstraintJacobianC,
    Function::ConstrainedTaskJacobian,
    Function::Manipulability,
    Function::ManipulabilitySquared,
];

/// An implementation of a robot's kinematics to be checked.
pub trait Candidate {
    /// Evaluates the generated function `function` ([`trocar_model::catalogue`]) at joints `q` (all n,
    /// base first) and parameter values `params` (every named parameter of the description, in
    /// declaration order); a transform as a 4 × 4 homogeneous matrix. `None` when the candidate
    /// does not provide this function.
    fn evaluate(&self, function: Function, q: &[f64], params: &[f64]) -> Option<Mat<f64>>;
}

/// The largest error of one check over all samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// What was compared, e.g. `jr: generated vs numeric`.
    pub name: String,
    /// Largest error, relative to the reference's norm (or absolute when the norm is below 1);
    /// for manipulability, relative to Hadamard's bound `Π‖row_k(J^r)‖`.
    pub max_error: f64,
    /// The tolerance the error is held to.
    pub tolerance: f64,
    /// Joint values where the largest error happened.
    pub worst_q: Vec<f64>,
    /// Number of comparisons.
    pub count: usize,
}

impl Check {
    /// `true` when the largest error is within tolerance (and not NaN).
    pub fn passed(&self) -> bool {
        self.max_error <= self.tolerance
    }
}

/// The outcome of [`verify`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Robot name.
    pub robot: String,
    /// Number of random samples.
    pub samples: usize,
    /// One line per check.
    pub checks: Vec<Check>,
}

impl Report {
    /// `true` when every check passed.
    pub fn passed(&self) -> bool {
        !self.checks.is_empty() && self.checks.iter().all(Check::passed)
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}: {} random samples", self.robot, self.samples)?;
        // The first column as wide as the longest check name, so the numbers align.
        let width = self
            .checks
            .iter()
            .map(|c| c.name.chars().count())
            .max()
            .unwrap_or(0)
            .max("check".len());
        writeln!(
            f,
            "{:<width$} {:>12} {:>10}  result",
            "check", "max error", "tolerance"
        )?;
        for c in &self.checks {
            writeln!(
                f,
                "{:<width$} {:>12.3e} {:>10.0e}  {}",
                c.name,
                c.max_error,
                c.tolerance,
                if c.passed() { "ok" } else { "MISMATCH" }
            )?;
        }
        Ok(())
    }
}

/// Tolerances of [`verify`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Candidate vs numeric runtime (relative).
    pub exact: f64,
    /// Finite differences vs Jacobians.
    pub finite_difference: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            exact: 1e-12,
            finite_difference: 1e-6,
        }
    }
}

/// SplitMix64: a small, seedable generator, enough for sampling configurations.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn relative_error(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    if a.shape() != b.shape() {
        return f64::INFINITY;
    }
    let diff = (a - b).norm_l2();
    let scale = b.norm_l2().max(1.0);
    if diff.is_nan() {
        f64::INFINITY
    } else {
        diff / scale
    }
}

fn se3_from_matrix(m: &Mat<f64>) -> Option<Se3<f64>> {
    if m.shape() != (4, 4) {
        return None;
    }
    let r = Matrix3::from_fn(|i, j| m[(i, j)]);
    let p = Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Some(Se3::new(r, p))
}

/// Body Jacobian of a pose function by central differences through the SE(3) log, over the
/// first `columns` joints.
fn finite_difference_jacobian(
    pose: impl Fn(&[f64]) -> Option<Se3<f64>>,
    q: &[f64],
    columns: usize,
    h: f64,
) -> Option<Mat<f64>> {
    let g = pose(q)?;
    let mut out = Mat::zeros(6, columns);
    let mut qq = q.to_vec();
    for k in 0..columns {
        qq[k] = q[k] + h;
        let plus = g.inverse_compose(&pose(&qq)?).log();
        qq[k] = q[k] - h;
        let minus = g.inverse_compose(&pose(&qq)?).log();
        qq[k] = q[k];
        let column = (plus - minus) / (2.0 * h);
        for r in 0..6 {
            out[(r, k)] = column[r];
        }
    }
    Some(out)
}

struct Tally {
    check: Check,
}

impl Tally {
    fn new(name: String, tolerance: f64) -> Self {
        Tally {
            check: Check {
                name,
                max_error: 0.0,
                tolerance,
                worst_q: Vec::new(),
                count: 0,
            },
        }
    }

    fn record(&mut self, error: f64, q: &[f64]) {
        self.check.count += 1;
        let error = if error.is_nan() { f64::INFINITY } else { error };
        if error > self.check.max_error || self.check.worst_q.is_empty() {
            self.check.max_error = error;
            self.check.worst_q = q.to_vec();
        }
    }
}

/// Compares `candidate` with the numeric runtime and with finite differences at `samples` random
/// configurations (`q_k` uniform in `[−π, π]`, prismatic joints in `[−0.5, 0.5]`, parameters
/// uniform within ±20 % of their nominal values). `progress` is called with the fraction done.
pub fn verify(
    description: &RobotDescription,
    candidate: &dyn Candidate,
    samples: usize,
    seed: u64,
    tolerances: Tolerances,
    mut progress: impl FnMut(f64),
) -> Result<Report, RobotError> {
    let mut rng = SplitMix64::new(seed);
    let n = description.joints.len();
    let link = description.constraint.as_ref().map(|c| c.link);
    let mut tallies: Vec<(Function, Tally)> = Vec::new();
    let mut fd_numeric = Tally::new(
        "jb0e: numeric vs finite differences of fk".into(),
        tolerances.finite_difference,
    );
    let mut fd_candidate = Tally::new(
        "jb0i: generated vs finite differences of fk0i".into(),
        tolerances.finite_difference,
    );
    let h = 1e-5;
    let mut any_fd_candidate = false;
    for s in 0..samples {
        let q: Vec<f64> = description
            .joints
            .iter()
            .map(|j| match j.kind {
                trocar_model::description::JointKind::Prismatic { .. } => rng.uniform(-0.5, 0.5),
                _ => rng.uniform(-core::f64::consts::PI, core::f64::consts::PI),
            })
            .collect();
        let params: Vec<(String, f64)> = description
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value * rng.uniform(0.8, 1.2)))
            .collect();
        let values: Vec<f64> = params.iter().map(|(_, v)| *v).collect();
        let robot = NumericRobot::<f64>::from_description(description, &params)?;
        for quantity in CHECKED {
            let Some(got) = candidate.evaluate(quantity, &q, &values) else {
                continue;
            };
            let reference = match quantity {
                Function::ConstrainedJacobian => robot.constrained_jacobian(&q)?,
                Function::ConstraintJacobianC => robot.constraint_jacobian_c(&q)?,
                Function::ConstrainedTaskJacobian => robot.constrained_task_jacobian(&q)?,
                Function::PartialBodyJacobian => robot.partial_body_jacobian(&q)?,
                Function::ForwardKinematics => robot.forward_kinematics_matrix(&q)?,
                Function::ConstrainedLinkKinematics => {
                    let Some(i) = link else { continue };
                    let m = robot.link_frame(i, &q)?.to_homogeneous();
                    Mat::from_fn(4, 4, |r, c| m[(r, c)])
                }
                Function::Manipulability => Mat::full(1, 1, robot.manipulability(&q)?),
                Function::ManipulabilitySquared => {
                    Mat::full(1, 1, robot.manipulability(&q)?.powi(2))
                }
                _ => continue,
            };
            let tally = match tallies.iter_mut().find(|(k, _)| *k == quantity) {
                Some((_, t)) => t,
                None => {
                    tallies.push((
                        quantity,
                        Tally::new(
                            format!("{}: generated vs numeric", quantity.short_name()),
                            tolerances.exact,
                        ),
                    ));
                    &mut tallies.last_mut().expect("just pushed").1
                }
            };
            let error = match quantity {
                // Manipulability is a product of singular values: its error is measured
                // relative to Hadamard's bound Π‖row_k(J)‖ (squared for the squared value),
                // the natural scale of a determinant, as matrices are measured relative to
                // their norm; J is S J^r with a task, J^r without.
                Function::Manipulability | Function::ManipulabilitySquared => {
                    let jr = match robot.task_selection() {
                        Some(_) => robot.constrained_task_jacobian(&q)?,
                        None => robot.constrained_jacobian(&q)?,
                    };
                    let mut bound: f64 = jr.row_iter().map(|r| r.norm_l2()).product();
                    if quantity == Function::ManipulabilitySquared {
                        bound *= bound;
                    }
                    let diff = (got[(0, 0)] - reference[(0, 0)]).abs();
                    if got.shape() != (1, 1) || diff.is_nan() {
                        f64::INFINITY
                    } else {
                        diff / bound.max(1.0)
                    }
                }
                _ => relative_error(&got, &reference),
            };
            tally.record(error, &q);
        }
        // Finite differences of the candidate's forward kinematics.
        let fk = |qq: &[f64]| {
            candidate
                .evaluate(Function::ForwardKinematics, qq, &values)
                .and_then(|m| se3_from_matrix(&m))
        };
        if fk(&q).is_some() {
            if let Some(fd) = finite_difference_jacobian(fk, &q, n, h) {
                fd_numeric.record(relative_error(&fd, &robot.body_jacobian(&q)?), &q);
            }
        }
        if let Some(i) = link {
            let fk0i = |qq: &[f64]| {
                candidate
                    .evaluate(Function::ConstrainedLinkKinematics, qq, &values)
                    .and_then(|m| se3_from_matrix(&m))
            };
            let jb0i = candidate.evaluate(Function::PartialBodyJacobian, &q, &values);
            if let (Some(jb0i), Some(fd)) = (jb0i, finite_difference_jacobian(fk0i, &q, i, h)) {
                any_fd_candidate = true;
                fd_candidate.record(relative_error(&fd, &jb0i), &q);
            }
        }
        progress((s + 1) as f64 / samples.max(1) as f64);
    }
    tallies.sort_by_key(|(k, _)| CHECKED.iter().position(|a| a == k));
    let mut checks: Vec<Check> = tallies.into_iter().map(|(_, t)| t.check).collect();
    if fd_numeric.check.count > 0 {
        checks.push(fd_numeric.check);
    }
    if any_fd_candidate {
        checks.push(fd_candidate.check);
    }
    Ok(Report {
        robot: description.name.clone(),
        samples,
        checks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_aligns_with_any_check_name() {
        let check = |name: &str| Check {
            name: name.into(),
            max_error: 1.5e-16,
            tolerance: 1e-12,
            worst_q: vec![],
            count: 1,
        };
        let report = Report {
            robot: "arm".into(),
            samples: 3,
            checks: vec![
                check("fk: generated vs numeric"),
                check("jb0i: generated vs finite differences of fk0i, a long name"),
            ],
        };
        let text = report.to_string();
        let lines: Vec<&str> = text.lines().skip(1).collect();
        let column = |l: &str, word: &str| l.find(word).map(|i| i + word.len());
        let end = column(lines[0], "max error").unwrap();
        for l in &lines[1..] {
            assert_eq!(column(l, "1.500e-16"), Some(end), "{text}");
        }
    }

    /// A candidate that is the numeric runtime itself, optionally with one entry perturbed.
    struct Numeric {
        description: RobotDescription,
        perturb: f64,
    }

    impl Candidate for Numeric {
        fn evaluate(&self, quantity: Function, q: &[f64], params: &[f64]) -> Option<Mat<f64>> {
            let overrides: Vec<(String, f64)> = self
                .description
                .parameters
                .iter()
                .zip(params)
                .map(|(p, v)| (p.name.clone(), *v))
                .collect();
            let robot =
                NumericRobot::<f64>::from_description(&self.description, &overrides).ok()?;
            let mut m = match quantity {
                Function::ConstrainedJacobian => robot.constrained_jacobian(q).ok()?,
                Function::ForwardKinematics => robot.forward_kinematics_matrix(q).ok()?,
                Function::PartialBodyJacobian => robot.partial_body_jacobian(q).ok()?,
                Function::ConstrainedLinkKinematics => {
                    let i = self.description.constraint.as_ref()?.link;
                    let g = robot.link_frame(i, q).ok()?.to_homogeneous();
                    Mat::from_fn(4, 4, |r, c| g[(r, c)])
                }
                _ => return None,
            };
            m[(0, 0)] += self.perturb;
            Some(m)
        }
    }

    #[test]
    fn a_faithful_candidate_passes_and_a_perturbed_one_fails() {
        let description = RobotDescription::preset("bidirectional-zy").unwrap();
        let good = Numeric {
            description: description.clone(),
            perturb: 0.0,
        };
        let report = verify(&description, &good, 20, 7, Tolerances::default(), |_| {}).unwrap();
        assert!(report.passed(), "{report}");
        assert!(report
            .checks
            .iter()
            .any(|c| c.name.starts_with("jb0e: numeric vs finite")));
        assert!(report
            .checks
            .iter()
            .any(|c| c.name.starts_with("jb0i: generated vs finite")));

        let bad = Numeric {
            description: description.clone(),
            perturb: 1e-9,
        };
        let report = verify(&description, &bad, 5, 7, Tolerances::default(), |_| {}).unwrap();
        assert!(!report.passed());
        let jr = report
            .checks
            .iter()
            .find(|c| c.name.starts_with("jr:"))
            .unwrap();
        assert!(!jr.passed() && jr.max_error > 1e-10, "{report}");
        assert_eq!(jr.worst_q.len(), 8);
    }

    #[test]
    fn generator_is_uniform_and_reproducible() {
        let mut a = SplitMix64::new(3);
        let mut b = SplitMix64::new(3);
        let xs: Vec<f64> = (0..1000).map(|_| a.uniform(-1.0, 1.0)).collect();
        let ys: Vec<f64> = (0..1000).map(|_| b.uniform(-1.0, 1.0)).collect();
        assert_eq!(xs, ys);
        let mean = xs.iter().sum::<f64>() / 1000.0;
        assert!(mean.abs() < 0.1 && xs.iter().all(|x| (-1.0..1.0).contains(x)));
        assert_ne!(SplitMix64::new(4).next_u64(), SplitMix64::new(3).next_u64());
    }
}
