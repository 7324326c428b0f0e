//! Verification of generated kinematics against the numeric runtime and finite differences.
//!
//! A [`Candidate`] is any implementation of the robot's kinematics: the generator's closed forms
//! evaluated as emitted (`trocar verify`), or a compiled generated module (its `Checks`, emitted
//! by `Builder::checks`). [`verify`] draws random configurations and parameter values
//! ([`crate::Ranges`]) and compares, for every function of the catalogue the candidate offers
//! ([`CHECKED`]):
//!
//! - candidate vs the numeric runtime ([`trocar_model::reference`]: the typed kernels of `trocar` on the
//!   description's [`NumericModel`]), relative to the matrix norm;
//! - the candidate's `J^B_0i` vs central differences of the candidate's own `g_0i`, its `J^B_0e`
//!   vs central differences of its own `g_0e`, and the numeric body Jacobian vs central
//!   differences of the candidate's `g_0e` — so an error common to the candidate and the runtime
//!   would still be caught by the finite differences.
//!
//! The result is a [`Report`] with the largest error of each check, the configuration and
//! parameters where it happened and the entries that differ there.

use crate::Ranges;
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::fmt;
use trocar::se3::Se3;
use trocar_model::catalogue::{Function, Fused};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::{NumericModel, RobotError};
use trocar_model::reference;

/// The generated functions [`verify`] checks against the numeric runtime, in report order: every
/// function of a serial robot's module ([`Function::SERIAL`]).
pub const CHECKED: [Function; 14] = Function::SERIAL;

/// The fused functions a candidate offers ([`Candidate::fused`]).
pub type FusedList = Vec<Fused>;

/// The values of a fused function's outputs, in order ([`Candidate::evaluate_fused`]).
pub type FusedValues = Vec<DMatrix<f64>>;

/// An implementation of a robot's kinematics to be checked.
pub trait Candidate {
    /// Evaluates the generated function `function` ([`trocar_model::catalogue`]) at joints `q` (all n,
    /// base first) and parameter values `params` (every named parameter of the description, in
    /// declaration order); a transform as a 4 × 4 homogeneous matrix, a scalar as 1 × 1. `None`
    /// when the candidate does not provide this function.
    fn evaluate(&self, function: Function, q: &[f64], params: &[f64]) -> Option<DMatrix<f64>>;

    /// The fused functions the candidate offers ([`Fused`]: one function computing several
    /// catalogue outputs); none unless the candidate says otherwise.
    fn fused(&self) -> FusedList {
        Vec::new()
    }

    /// Evaluates the fused function `name` at `q` and `params`: one value per output of
    /// [`Candidate::fused`]'s entry, in its order and in [`Candidate::evaluate`]'s layout. `None`
    /// when the candidate has no such function.
    fn evaluate_fused(&self, name: &str, q: &[f64], params: &[f64]) -> Option<FusedValues> {
        let _ = (name, q, params);
        None
    }
}

/// One entry of a result where the candidate and the reference differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Difference {
    /// Row (0-based).
    pub row: usize,
    /// Column (0-based).
    pub col: usize,
    /// The candidate's value.
    pub candidate: f64,
    /// The reference's value (numeric runtime or finite differences).
    pub reference: f64,
}

/// The largest error of one check over all samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// What was compared, e.g. `jr: generated vs numeric`.
    pub name: String,
    /// The catalogue function whose value is checked (for a finite-difference check, the
    /// Jacobian compared with the differences).
    pub function: Option<Function>,
    /// Largest error, relative to the reference's norm (or absolute when the norm is below 1);
    /// for manipulability, relative to Hadamard's bound `Π‖row_k(J)‖` of the matrix it is taken
    /// of (3.36).
    pub max_error: f64,
    /// The tolerance the error is held to.
    pub tolerance: f64,
    /// Joint values where the largest error happened.
    pub worst_q: Vec<f64>,
    /// Parameter values (declaration order) where the largest error happened.
    pub worst_params: Vec<f64>,
    /// At the worst sample, the entries whose difference exceeds the tolerance (relative to the
    /// same scale as the error), largest first, at most [`MAX_DIFFERENCES`]; the largest one when
    /// none does.
    pub differences: Vec<Difference>,
    /// Number of comparisons.
    pub count: usize,
}

/// The finite differences of a fused function's poses are taken at every this many samples (each
/// costs `2 n` evaluations of the whole function); its outputs are compared with the numeric
/// runtime at every sample.
pub const FUSED_DIFFERENCES_EVERY: usize = 4;

/// The most entries a [`Check`] lists in [`Check::differences`].
pub const MAX_DIFFERENCES: usize = 8;

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
    /// The seed the samples were drawn from.
    pub seed: u64,
    /// The parameters' names, in declaration order (the order of [`Check::worst_params`]).
    pub parameters: Vec<String>,
    /// One line per check.
    pub checks: Vec<Check>,
}

impl Report {
    /// `true` when every check passed.
    pub fn passed(&self) -> bool {
        !self.checks.is_empty() && self.checks.iter().all(Check::passed)
    }

    /// Each failed check in full: the function, the largest error and the tolerance, the worst
    /// configuration and parameters, and the entries that differ there. Empty when every check
    /// passed.
    pub fn failures(&self) -> String {
        let mut out = String::new();
        for c in self.checks.iter().filter(|c| !c.passed()) {
            let function = c.function.map_or(String::new(), |f| format!(" (`{f}`)"));
            out += &format!(
                "MISMATCH {}{function}: max error {:.3e} > tolerance {:.0e}\n",
                c.name, c.max_error, c.tolerance
            );
            out += &format!("  worst q = {:?}\n", c.worst_q);
            if !self.parameters.is_empty() {
                let params: Vec<String> = self
                    .parameters
                    .iter()
                    .zip(&c.worst_params)
                    .map(|(n, v)| format!("{n} = {v:?}"))
                    .collect();
                out += &format!("  parameters: {}\n", params.join(", "));
            }
            for d in &c.differences {
                out += &format!(
                    "  entry ({}, {}): generated {:.9e}, reference {:.9e}, difference {:.3e}\n",
                    d.row,
                    d.col,
                    d.candidate,
                    d.reference,
                    d.candidate - d.reference
                );
            }
        }
        out
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
    /// Candidate vs numeric runtime (relative to the matrix norm or 1, manipulability to its
    /// Hadamard bound).
    pub exact: f64,
    /// Finite differences vs Jacobians (relative).
    pub finite_difference: f64,
    /// The step `h` of the central differences (rad or m).
    pub step: f64,
}

impl Tolerances {
    /// For a candidate computing in `f64`: `1e-12` against the numeric runtime, `1e-6` against
    /// central differences of step `1e-5`.
    pub const F64: Tolerances = Tolerances {
        exact: 1e-12,
        finite_difference: 1e-6,
        step: 1e-5,
    };

    /// For a candidate computing in `f32` (its inputs rounded to `f32`): `2e-6` against the
    /// numeric runtime, the bound `docs/generated-code.md` gives `f32` code (relative to the
    /// matrix norm, manipulability to its Hadamard bound); `1e-3` against central differences of
    /// step `3e-3` (the rounding of `q ± h` to `f32` alone is `≈ 1e-7 / h`).
    pub const F32: Tolerances = Tolerances {
        exact: 2e-6,
        finite_difference: 1e-3,
        step: 3e-3,
    };
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances::F64
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

/// The relative error of `a` against `b`: `‖a − b‖ / max(‖b‖, 1)` (Frobenius), `∞` for a shape
/// mismatch or NaN.
fn relative_error(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    if a.shape() != b.shape() {
        return f64::INFINITY;
    }
    let diff = (a - b).norm();
    let scale = b.norm().max(1.0);
    if diff.is_nan() {
        f64::INFINITY
    } else {
        diff / scale
    }
}

fn se3_from_matrix(m: &DMatrix<f64>) -> Option<Se3<f64>> {
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
) -> Option<DMatrix<f64>> {
    let g = pose(q)?;
    let mut out = DMatrix::zeros(6, columns);
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

/// The entries of `got` that differ from `reference` by more than `tolerance · scale`, largest
/// first (at most [`MAX_DIFFERENCES`]), or the largest one when none does.
fn differences(
    got: &DMatrix<f64>,
    reference: &DMatrix<f64>,
    tolerance: f64,
    scale: f64,
) -> Vec<Difference> {
    if got.shape() != reference.shape() {
        return Vec::new();
    }
    let mut all: Vec<(f64, Difference)> = (0..got.ncols())
        .flat_map(|c| (0..got.nrows()).map(move |r| (r, c)))
        .map(|(r, c)| {
            let d = (got[(r, c)] - reference[(r, c)]).abs();
            let d = if d.is_nan() { f64::INFINITY } else { d };
            (
                d,
                Difference {
                    row: r,
                    col: c,
                    candidate: got[(r, c)],
                    reference: reference[(r, c)],
                },
            )
        })
        .collect();
    all.sort_by(|a, b| b.0.total_cmp(&a.0));
    let over = all.iter().filter(|(d, _)| *d > tolerance * scale).count();
    all.into_iter()
        .take(over.clamp(1, MAX_DIFFERENCES))
        .map(|(_, d)| d)
        .collect()
}

struct Tally {
    check: Check,
}

impl Tally {
    fn new(name: String, function: Option<Function>, tolerance: f64) -> Self {
        Tally {
            check: Check {
                name,
                function,
                max_error: 0.0,
                tolerance,
                worst_q: Vec::new(),
                worst_params: Vec::new(),
                differences: Vec::new(),
                count: 0,
            },
        }
    }

    /// Records one comparison: `error`, and at a new worst sample the entries of `got` against
    /// `reference` (the error's scale is `scale`).
    fn record(
        &mut self,
        error: f64,
        q: &[f64],
        params: &[f64],
        got: &DMatrix<f64>,
        reference: &DMatrix<f64>,
        scale: f64,
    ) {
        self.check.count += 1;
        let error = if error.is_nan() { f64::INFINITY } else { error };
        if error > self.check.max_error || self.check.worst_q.is_empty() {
            self.check.max_error = error;
            self.check.worst_q = q.to_vec();
            self.check.worst_params = params.to_vec();
            self.check.differences = differences(got, reference, self.check.tolerance, scale);
        }
    }
}

/// The error of a candidate's value `got` of `quantity` against the reference `expected`, and
/// the scale it is relative to.
fn compare(
    model: &NumericModel<f64>,
    quantity: Function,
    q: &[f64],
    got: &DMatrix<f64>,
    expected: &DMatrix<f64>,
) -> Result<(f64, f64), RobotError> {
    Ok(match quantity {
        // Manipulability is a product of singular values: its error is measured relative to
        // Hadamard's bound Π‖row_k(J)‖ (squared for the squared value), the natural scale of a
        // determinant, as matrices are measured relative to their norm; J is S J^r with a task,
        // J^r without.
        Function::Manipulability | Function::ManipulabilitySquared => {
            let j = reference::manipulated_jacobian(model, q)?;
            let mut bound: f64 = j.row_iter().map(|r| r.norm()).product();
            if quantity == Function::ManipulabilitySquared {
                bound *= bound;
            }
            let scale = bound.max(1.0);
            let diff = if got.shape() == (1, 1) {
                (got[(0, 0)] - expected[(0, 0)]).abs()
            } else {
                f64::NAN
            };
            if diff.is_nan() {
                (f64::INFINITY, scale)
            } else {
                (diff / scale, scale)
            }
        }
        _ => (relative_error(got, expected), expected.norm().max(1.0)),
    })
}

/// The value of `f` among a sample's values by function.
fn value_of(values: &[(Function, DMatrix<f64>)], f: Function) -> Option<&DMatrix<f64>> {
    values.iter().find(|(g, _)| *g == f).map(|(_, m)| m)
}

/// The tallies of one fused function ([`Candidate::fused`]): each output against the numeric
/// runtime, and its Jacobians against central differences of its own poses.
struct FusedTallies {
    fused: Fused,
    outputs: Vec<Tally>,
    /// `(Jacobian's position, pose's position, columns, tally)`: `J^B_0e` against differences of
    /// `g_0e`, `J^B_0i` against those of `g_0i`, where the function computes both.
    differences: Vec<(usize, usize, usize, Tally)>,
}

impl FusedTallies {
    fn new(fused: Fused, n: usize, link: Option<usize>, tolerances: Tolerances) -> Self {
        let outputs = fused
            .outputs
            .iter()
            .map(|f| {
                Tally::new(
                    format!("{}.{}: generated vs numeric", fused.name, f.short_name()),
                    Some(*f),
                    tolerances.exact,
                )
            })
            .collect();
        let at = |f: Function| fused.outputs.iter().position(|g| *g == f);
        let mut differences = Vec::new();
        for (jacobian, pose, columns) in [
            (Function::BodyJacobian, Function::ForwardKinematics, Some(n)),
            (
                Function::PartialBodyJacobian,
                Function::ConstrainedLinkKinematics,
                link,
            ),
        ] {
            if let (Some(j), Some(g), Some(columns)) = (at(jacobian), at(pose), columns) {
                differences.push((
                    j,
                    g,
                    columns,
                    Tally::new(
                        format!(
                            "{}.{}: generated vs finite differences of {}",
                            fused.name,
                            jacobian.short_name(),
                            pose.short_name()
                        ),
                        Some(jacobian),
                        tolerances.finite_difference,
                    ),
                ));
            }
        }
        FusedTallies {
            fused,
            outputs,
            differences,
        }
    }

    /// Records the candidate's fused values at `q` against the reference (`references`: the
    /// sample's reference values already computed, by function), and with a step `h` its
    /// Jacobians against central differences of its poses.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        candidate: &dyn Candidate,
        model: &NumericModel<f64>,
        references: &[(Function, DMatrix<f64>)],
        q: &[f64],
        values: &[f64],
        h: Option<f64>,
    ) -> Result<(), RobotError> {
        let name = self.fused.name.clone();
        let Some(got) = candidate.evaluate_fused(&name, q, values) else {
            // A fused function the candidate lists but cannot evaluate here fails every check.
            for t in &mut self.outputs {
                let nan = DMatrix::from_element(1, 1, f64::NAN);
                t.record(f64::INFINITY, q, values, &nan, &nan, 1.0);
            }
            return Ok(());
        };
        for (k, &f) in self.fused.outputs.iter().enumerate() {
            let computed;
            let expected = match value_of(references, f) {
                Some(m) => m,
                None => match reference::evaluate(model, f, q)? {
                    Some(m) => {
                        computed = m;
                        &computed
                    }
                    None => continue,
                },
            };
            let Some(value) = got.get(k) else {
                let nan = DMatrix::from_element(1, 1, f64::NAN);
                self.outputs[k].record(f64::INFINITY, q, values, &nan, expected, 1.0);
                continue;
            };
            let (error, scale) = compare(model, f, q, value, expected)?;
            self.outputs[k].record(error, q, values, value, expected, scale);
        }
        let Some(h) = h else {
            return Ok(());
        };
        for (j, g, columns, tally) in &mut self.differences {
            let pose = |qq: &[f64]| {
                candidate
                    .evaluate_fused(&name, qq, values)
                    .and_then(|v| v.get(*g).and_then(se3_from_matrix))
            };
            if let (Some(fd), Some(jac)) = (
                finite_difference_jacobian(pose, q, *columns, h),
                got.get(*j),
            ) {
                let scale = fd.norm().max(1.0);
                tally.record(relative_error(jac, &fd), q, values, jac, &fd, scale);
            }
        }
        Ok(())
    }

    fn checks(self) -> impl Iterator<Item = Check> {
        self.outputs
            .into_iter()
            .chain(self.differences.into_iter().map(|(_, _, _, t)| t))
            .map(|t| t.check)
            .filter(|c| c.count > 0)
    }
}

/// Compares `candidate` with the numeric runtime and with finite differences at `samples` random
/// configurations drawn from `seed` over [`crate::Ranges`] of the description (joints within
/// their limits, else `[−π, π]` or `[−0.5, 0.5]` m; parameters within ±20 % of their nominal
/// values). `progress` is called with the fraction done.
pub fn verify(
    description: &RobotDescription,
    candidate: &dyn Candidate,
    samples: usize,
    seed: u64,
    tolerances: Tolerances,
    mut progress: impl FnMut(f64),
) -> Result<Report, RobotError> {
    let mut rng = SplitMix64::new(seed);
    let ranges = Ranges::of(description);
    let n = description.joints.len();
    let link = description.constraint.as_ref().map(|c| c.link);
    let mut tallies: Vec<(Function, Tally)> = Vec::new();
    let fd = |name: &str, function| Tally::new(name.into(), function, tolerances.finite_difference);
    let mut fd_numeric = fd("jb0e: numeric vs finite differences of fk", None);
    let mut fd_jb0e = fd(
        "jb0e: generated vs finite differences of fk",
        Some(Function::BodyJacobian),
    );
    let mut fd_candidate = fd(
        "jb0i: generated vs finite differences of fk0i",
        Some(Function::PartialBodyJacobian),
    );
    let h = tolerances.step;
    let mut fused: Vec<FusedTallies> = candidate
        .fused()
        .into_iter()
        .map(|f| FusedTallies::new(f, n, link, tolerances))
        .collect();
    for s in 0..samples {
        let (q, values) = ranges.sample(&mut rng);
        let params: Vec<(String, f64)> = ranges
            .parameters
            .iter()
            .zip(&values)
            .map(|((name, _), v)| (name.clone(), *v))
            .collect();
        let model = NumericModel::<f64>::from_description(description, &params)?;
        // The reference values of this sample, for the fused functions' outputs too.
        let mut references: Vec<(Function, DMatrix<f64>)> = Vec::new();
        // The candidate's values of this sample, for the finite differences.
        let mut generated: Vec<(Function, DMatrix<f64>)> = Vec::new();
        for quantity in CHECKED {
            let Some(got) = candidate.evaluate(quantity, &q, &values) else {
                continue;
            };
            let Some(expected) = reference::evaluate(&model, quantity, &q)? else {
                continue;
            };
            let tally = match tallies.iter_mut().position(|(k, _)| *k == quantity) {
                Some(k) => &mut tallies[k].1,
                None => {
                    tallies.push((
                        quantity,
                        Tally::new(
                            format!("{}: generated vs numeric", quantity.short_name()),
                            Some(quantity),
                            tolerances.exact,
                        ),
                    ));
                    &mut tallies.last_mut().expect("just pushed").1
                }
            };
            let (error, scale) = compare(&model, quantity, &q, &got, &expected)?;
            tally.record(error, &q, &values, &got, &expected, scale);
            references.push((quantity, expected));
            generated.push((quantity, got));
        }
        // Finite differences of the candidate's forward kinematics.
        let at = &values;
        let pose = |function: Function| {
            move |qq: &[f64]| {
                candidate
                    .evaluate(function, qq, at)
                    .and_then(|m| se3_from_matrix(&m))
            }
        };
        let fk = pose(Function::ForwardKinematics);
        if let Some(fd) = finite_difference_jacobian(fk, &q, n, h) {
            let computed;
            let jb0e = match value_of(&references, Function::BodyJacobian) {
                Some(m) => m,
                None => {
                    computed = reference::body_jacobian(&model, &q)?;
                    &computed
                }
            };
            let scale = jb0e.norm().max(1.0);
            fd_numeric.record(relative_error(&fd, jb0e), &q, &values, &fd, jb0e, scale);
            if let Some(got) = value_of(&generated, Function::BodyJacobian) {
                let scale = fd.norm().max(1.0);
                fd_jb0e.record(relative_error(got, &fd), &q, &values, got, &fd, scale);
            }
        }
        if let Some(i) = link {
            let fk0i = pose(Function::ConstrainedLinkKinematics);
            let jb0i = value_of(&generated, Function::PartialBodyJacobian);
            if let (Some(jb0i), Some(fd)) = (jb0i, finite_difference_jacobian(fk0i, &q, i, h)) {
                let scale = fd.norm().max(1.0);
                fd_candidate.record(relative_error(jb0i, &fd), &q, &values, jb0i, &fd, scale);
            }
        }
        // Every output of every fused function, and its Jacobians against its own poses.
        for f in &mut fused {
            let h = (s % FUSED_DIFFERENCES_EVERY == 0).then_some(h);
            f.record(candidate, &model, &references, &q, &values, h)?;
        }
        progress((s + 1) as f64 / samples.max(1) as f64);
    }
    tallies.sort_by_key(|(k, _)| CHECKED.iter().position(|a| a == k));
    let mut checks: Vec<Check> = tallies.into_iter().map(|(_, t)| t.check).collect();
    for t in [fd_numeric, fd_jb0e, fd_candidate] {
        if t.check.count > 0 {
            checks.push(t.check);
        }
    }
    for f in fused {
        checks.extend(f.checks());
    }
    Ok(Report {
        robot: description.name.clone(),
        samples,
        seed,
        parameters: ranges.parameters.iter().map(|(n, _)| n.clone()).collect(),
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
            function: None,
            max_error: 1.5e-16,
            tolerance: 1e-12,
            worst_q: vec![],
            worst_params: vec![],
            differences: vec![],
            count: 1,
        };
        let report = Report {
            robot: "arm".into(),
            samples: 3,
            seed: 1,
            parameters: vec![],
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

    /// A candidate written here by hand with plain 3 × 3 rotations (not the typed kernels the
    /// reference uses): the forward kinematics of [`TWO_JOINTS`], optionally with one entry of
    /// `g_0e` perturbed.
    struct TwoJoints {
        perturb: f64,
    }

    /// Joint `a` about `z` at `(0, 0, 0.3)`, joint `b` about `y` at `(0.2, 0, 0)` from it.
    const TWO_JOINTS: &str = "[robot]\nname = \"zy\"\n\
        [[joints]]\nname = \"a\"\ntype = \"revolute\"\nxyz = [0, 0, 0.3]\nrpy = [0, 0, 0]\naxis = [0, 0, 1]\n\
        [[joints]]\nname = \"b\"\ntype = \"revolute\"\nxyz = [0.2, 0, 0]\nrpy = [0, 0, 0]\naxis = [0, 1, 0]\n\
        [end_effector]\nxyz = [0, 0, 0]\n";

    impl Candidate for TwoJoints {
        fn evaluate(&self, quantity: Function, q: &[f64], _params: &[f64]) -> Option<DMatrix<f64>> {
            if quantity != Function::ForwardKinematics {
                return None;
            }
            let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), q[0]);
            let ry = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), q[1]);
            let r = (rz * ry).into_inner();
            let p = Vector3::new(0.0, 0.0, 0.3) + rz * Vector3::new(0.2, 0.0, 0.0);
            let mut m = DMatrix::identity(4, 4);
            m.view_mut((0, 0), (3, 3)).copy_from(&r);
            m.view_mut((0, 3), (3, 1)).copy_from(&p);
            m[(0, 3)] += self.perturb;
            Some(m)
        }
    }

    #[test]
    fn a_faithful_candidate_passes_and_a_perturbed_one_fails_with_its_entry() {
        let description = RobotDescription::from_toml_str(TWO_JOINTS, None).unwrap();
        let good = TwoJoints { perturb: 0.0 };
        let report = verify(&description, &good, 20, 7, Tolerances::F64, |_| {}).unwrap();
        assert!(report.passed(), "{report}");
        assert_eq!(report.checks.len(), 2, "{report}");
        assert!(report.failures().is_empty());

        let bad = TwoJoints { perturb: 1e-9 };
        let report = verify(&description, &bad, 5, 7, Tolerances::F64, |_| {}).unwrap();
        assert!(!report.passed());
        let fk = &report.checks[0];
        assert_eq!(fk.function, Some(Function::ForwardKinematics));
        assert!(!fk.passed() && fk.max_error > 4e-10, "{report}"); // 1e-9 over ‖g‖ ≈ 2
        assert_eq!(fk.worst_q.len(), 2);
        assert_eq!(fk.differences.len(), 1);
        assert_eq!((fk.differences[0].row, fk.differences[0].col), (0, 3));
        let text = report.failures();
        assert!(
            text.contains("MISMATCH fk: generated vs numeric (`forward_kinematics`)"),
            "{text}"
        );
        assert!(text.contains("entry (0, 3)"), "{text}");
    }

    /// [`TwoJoints`] with a fused function `pose` of its forward kinematics, perturbed by
    /// `perturb` in the fused value only.
    struct FusedTwoJoints {
        perturb: f64,
    }

    impl Candidate for FusedTwoJoints {
        fn evaluate(&self, quantity: Function, q: &[f64], params: &[f64]) -> Option<DMatrix<f64>> {
            TwoJoints { perturb: 0.0 }.evaluate(quantity, q, params)
        }

        fn fused(&self) -> FusedList {
            vec![Fused::new("pose", [Function::ForwardKinematics])]
        }

        fn evaluate_fused(&self, name: &str, q: &[f64], params: &[f64]) -> Option<FusedValues> {
            (name == "pose").then(|| {
                vec![TwoJoints {
                    perturb: self.perturb,
                }
                .evaluate(Function::ForwardKinematics, q, params)
                .unwrap()]
            })
        }
    }

    #[test]
    fn every_output_of_a_fused_function_is_checked() {
        let description = RobotDescription::from_toml_str(TWO_JOINTS, None).unwrap();
        let report = verify(
            &description,
            &FusedTwoJoints { perturb: 0.0 },
            20,
            7,
            Tolerances::F64,
            |_| {},
        )
        .unwrap();
        assert!(report.passed(), "{report}");
        assert_eq!(report.checks.len(), 3, "{report}");
        let report = verify(
            &description,
            &FusedTwoJoints { perturb: 1e-9 },
            5,
            7,
            Tolerances::F64,
            |_| {},
        )
        .unwrap();
        assert!(!report.passed());
        let failed: Vec<&str> = report
            .checks
            .iter()
            .filter(|c| !c.passed())
            .map(|c| c.name.as_str())
            .collect();
        assert_eq!(failed, ["pose.fk: generated vs numeric"], "{report}");
    }

    #[test]
    fn differences_list_the_entries_over_tolerance_largest_first() {
        let reference = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 3.0, 4.0]);
        let got = DMatrix::from_row_slice(2, 2, &[1.0, 2.5, 3.0, 3.0]);
        let d = differences(&got, &reference, 0.1, 1.0);
        assert_eq!(d.len(), 2);
        assert_eq!((d[0].row, d[0].col, d[0].candidate), (1, 1, 3.0));
        assert_eq!((d[1].row, d[1].col, d[1].reference), (0, 1, 2.0));
        // None over tolerance: the largest alone.
        assert_eq!(differences(&got, &reference, 10.0, 1.0).len(), 1);
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
