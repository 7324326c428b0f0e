//! Evaluation of the generated programs: the closed-form path of `trocar eval` and what
//! `trocar verify` checks.
//!
//! An interpreter of the IR beside the backends: it lowers a derivation as the generator does
//! (`lower`) and runs the module's programs (`ir`); neither imports it. The programs evaluated
//! here are exactly those the emitter turns into Rust (after CSE, constant folding and
//! factoring), compiled once ([`Compiled`]) and evaluated in `f64` operation for
//! operation as the generated `f64` code evaluates them (the same `sin_cos`, the same fused
//! multiply-adds), so the answers are bit for bit the generated code's; the generated-code test
//! crate checks that. Functions are named by the catalogue ([`trocar_model::catalogue::Function`]),
//! as the emitter names them.

mod compiled;

pub use compiled::{Compiled, LANES};

use crate::closed_chain::MechanismDerivation;
use crate::derivation::{self, Derivation};
use crate::error::Error;
use crate::ir::{Layout, ModuleSpec};
use crate::lower;
use crate::naming::module_name;
use std::sync::Arc;
use trocar_model::catalogue::{Function, Fused};
use trocar_model::description::RobotDescription;

/// A robot's or a mechanism's generated functions, ready to evaluate.
#[derive(Clone, Debug)]
pub struct Generated {
    spec: ModuleSpec,
    /// Every function's program, compiled, in the order of `spec.functions`.
    compiled: Vec<Compiled>,
    /// The catalogue entry of each of `spec.functions` (`None` for a function it does not name).
    entries: Vec<Option<Function>>,
    /// Each function's [`Layout::row_major_positions`].
    row_major: Vec<Vec<usize>>,
    /// Every fused function's program, compiled, in the order of `spec.fused`.
    fused: Vec<Compiled>,
    /// A serial robot's derivation, from which [`Generated::fuse`] builds programs of outputs
    /// asked for later (`None` for a mechanism).
    derivation: Option<Arc<Derivation>>,
}

impl Generated {
    /// Derives and optimises the module of a description (nothing is formatted or written).
    pub fn new(description: &RobotDescription) -> Result<Self, Error> {
        let d = derivation::derive(description)
            .map_err(|e| Error::Description(e.into_description_error(description)))?;
        let mut g = Generated::from_spec(lower::module_spec(&d, &module_name(&description.name)));
        g.derivation = Some(Arc::new(d));
        Ok(g)
    }

    /// The polynomial functions of a closed mechanism's module ([`Function::is_program`]:
    /// `constraint_jacobian`, `task_jacobian`, `constraint_determinant` and the numerators);
    /// `q` holds all joints, active and passive.
    pub fn mechanism(derivation: &MechanismDerivation) -> Self {
        Generated::from_spec(lower::mechanism::module_spec(
            derivation,
            &module_name(&derivation.name),
        ))
    }

    pub(crate) fn from_spec(spec: ModuleSpec) -> Self {
        let compiled = spec
            .functions
            .iter()
            .map(|f| Compiled::new(&f.program, spec.joints))
            .collect();
        let entries = spec
            .functions
            .iter()
            .map(|f| Function::from_name(&f.name))
            .collect();
        let row_major = spec
            .functions
            .iter()
            .map(|f| f.layout.row_major_positions())
            .collect();
        let fused = spec
            .fused
            .iter()
            .map(|f| Compiled::new(&f.program, spec.joints))
            .collect();
        Generated {
            spec,
            compiled,
            entries,
            row_major,
            fused,
            derivation: None,
        }
    }

    fn position(&self, function: Function) -> Option<usize> {
        self.entries.iter().position(|e| *e == Some(function))
    }

    /// Number of parameters.
    pub fn param_count(&self) -> usize {
        self.spec.params.len()
    }

    /// The compiled program of `function`, if the module has it.
    pub fn compiled(&self, function: Function) -> Option<&Compiled> {
        Some(&self.compiled[self.position(function)?])
    }

    /// Where each output of `function` goes in its result written row by row
    /// ([`Layout::row_major_positions`]), if the module has it.
    pub fn row_major_positions(&self, function: Function) -> Option<&[usize]> {
        Some(&self.row_major[self.position(function)?])
    }

    /// The layout of `function`'s outputs, if the module has it.
    pub fn shape(&self, function: Function) -> Option<Layout> {
        Some(self.spec.functions[self.position(function)?].layout)
    }

    /// Number of joint values the functions take.
    pub fn joints(&self) -> usize {
        self.spec.joints
    }

    /// The parameters' names, in declaration order.
    pub fn param_names(&self) -> Vec<&str> {
        self.spec.params.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// Whether the module has the function `function`.
    pub fn has(&self, function: Function) -> bool {
        self.spec.function(function).is_some()
    }

    /// The parameters `function` divides by ([`Program::divisor_params`](crate::ir::Program::divisor_params)):
    /// where its result is not finite when one of them is 0. Empty when the module has no
    /// such function.
    pub fn divisors(&self, function: Function) -> Vec<String> {
        self.spec
            .function(function)
            .map_or_else(Vec::new, |f| f.program.divisor_params())
    }

    /// Nominal parameter values, in declaration order.
    pub fn nominal_params(&self) -> Vec<f64> {
        self.spec.params.iter().map(|(_, v)| *v).collect()
    }

    /// The outputs of `function` at `q` with parameter values in declaration order, in the
    /// emitted layout (matrices column-major; a transform as `R` column-major then `p`). `None`
    /// when the module has no such function or the argument lengths are wrong.
    pub fn outputs(&self, function: Function, q: &[f64], params: &[f64]) -> Option<Vec<f64>> {
        let c = self.compiled(function)?;
        if q.len() != self.spec.joints || params.len() != self.spec.params.len() {
            return None;
        }
        Some(c.eval(q, params))
    }

    /// The fused functions of the module ([`trocar_model::catalogue::Fused`]: the defaults and
    /// those requested).
    pub fn fused(&self) -> Vec<Fused> {
        self.spec
            .fused
            .iter()
            .map(|f| Fused::new(f.name.clone(), f.functions()))
            .collect()
    }

    /// Evaluates the fused function `name` at `q` with parameter values in declaration order:
    /// one value per output, in order, as [`Generated::evaluate`] gives it. `None` when the
    /// module has no such function or the argument lengths are wrong.
    pub fn evaluate_fused(&self, name: &str, q: &[f64], params: &[f64]) -> Option<Vec<Evaluated>> {
        let k = self.spec.fused.iter().position(|f| f.name == name)?;
        if q.len() != self.spec.joints || params.len() != self.spec.params.len() {
            return None;
        }
        let out = self.fused[k].eval(q, params);
        let f = &self.spec.fused[k];
        Some(
            f.outputs
                .iter()
                .enumerate()
                .map(|(j, o)| shaped(o.layout, &out[f.range(j)]))
                .collect(),
        )
    }

    /// One program computing the catalogue functions `outputs` of a serial robot's module, in
    /// that order, with every value they have in common computed once: the program of a fused
    /// function of these outputs (`Builder::function`, `trocar generate --function`), compiled,
    /// for callers that ask for a set of outputs at run time (`trocar_api`'s
    /// `Robot::fused_evaluator`, Python's `Robot.eval(q, what=("fk0i", "jb0i"))`). Each output
    /// equals its own function's to rounding (the shared values may be formed in another order).
    ///
    /// Builds the module's programs again with this request (about as long as `trocar
    /// generate`: tens of milliseconds on a 7-joint arm), so a caller keeps the result.
    /// [`Error::Function`] (named by the outputs' short names) when `outputs` is empty, names a
    /// function twice, or names one the module does not have, or the module keeps no derivation
    /// (a closed mechanism's).
    pub fn fuse(&self, outputs: &[Function]) -> Result<FusedProgram, Error> {
        let label = outputs
            .iter()
            .map(|f| f.short_name())
            .collect::<Vec<_>>()
            .join(",");
        let Some(d) = &self.derivation else {
            return Err(Error::Function {
                name: label,
                message: "several outputs in one program are built from a serial robot's \
                          derivation, which this module does not keep (a closed mechanism's, or \
                          one built from a module spec); evaluate its functions one by one"
                    .into(),
            });
        };
        // A name no default and no catalogue function has; errors are renamed after the outputs.
        const NAME: &str = "requested_outputs";
        let request = Fused::new(NAME, outputs.iter().copied());
        let spec =
            lower::module_spec_with(d, &self.spec.name, &[request]).map_err(|e| match e {
                Error::Function { message, .. } => Error::Function {
                    name: label.clone(),
                    message,
                },
                e => e,
            })?;
        let f = spec
            .fused
            .into_iter()
            .find(|f| f.name == NAME)
            .ok_or_else(|| Error::Internal(format!("{label}: the fused program was not built")))?;
        Ok(FusedProgram {
            compiled: Compiled::new(&f.program, spec.joints),
            outputs: f.outputs.iter().map(|o| (o.function, o.layout)).collect(),
        })
    }

    /// Evaluates `function` at `q` with parameter values in declaration order; a transform comes
    /// back as a 4×4 homogeneous matrix. `None` when the module has no such function or the
    /// argument lengths are wrong.
    pub fn evaluate(&self, function: Function, q: &[f64], params: &[f64]) -> Option<Evaluated> {
        let out = self.outputs(function, q, params)?;
        let shape = self.spec.function(function)?.layout;
        Some(shaped(shape, &out))
    }
}

/// Several catalogue functions of a module computed by one compiled program
/// ([`Generated::fuse`]); the program's outputs are each function's in its emitted layout, one
/// function after the other.
#[derive(Clone, Debug)]
pub struct FusedProgram {
    compiled: Compiled,
    outputs: Vec<(Function, Layout)>,
}

impl FusedProgram {
    /// The compiled program.
    pub fn compiled(&self) -> &Compiled {
        &self.compiled
    }

    /// The functions computed and the layout of each one's outputs, in order.
    pub fn outputs(&self) -> &[(Function, Layout)] {
        &self.outputs
    }
}

/// Outputs in `shape`'s layout as an [`Evaluated`] value (a transform as its 4 × 4 homogeneous
/// matrix).
fn shaped(shape: Layout, out: &[f64]) -> Evaluated {
    match shape {
        Layout::Scalar => Evaluated {
            rows: 1,
            cols: 1,
            values: vec![out[0]],
        },
        Layout::Matrix { rows, cols } => Evaluated {
            rows,
            cols,
            values: out[..rows * cols].to_vec(),
        },
        Layout::Transform => {
            let mut values = vec![0.0; 16];
            for c in 0..3 {
                for r in 0..3 {
                    values[c * 4 + r] = out[c * 3 + r];
                }
                values[12 + c] = out[9 + c];
            }
            values[15] = 1.0;
            Evaluated {
                rows: 4,
                cols: 4,
                values,
            }
        }
    }
}

/// The value of a generated function: a `rows`×`cols` matrix (1×1 for a scalar, 4×4 homogeneous
/// for a transform), entries in column-major order.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluated {
    /// Row count.
    pub rows: usize,
    /// Column count.
    pub cols: usize,
    /// The `rows × cols` entries, column by column.
    pub values: Vec<f64>,
}

impl Evaluated {
    /// The entry at row `r`, column `c`.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        self.values[c * self.rows + r]
    }
}

/// The generated functions as [`trocar_check::verify`] checks them against the numeric runtime
/// (`trocar verify`, the evidence of [`crate::Builder::evidence`]): evaluated as the generated
/// `f64` code evaluates them.
impl trocar_check::Candidate for Generated {
    fn evaluate(
        &self,
        function: Function,
        q: &[f64],
        params: &[f64],
    ) -> Option<trocar_check::DMatrix<f64>> {
        let m = Generated::evaluate(self, function, q, params)?;
        Some(trocar_check::DMatrix::from_column_slice(
            m.rows, m.cols, &m.values,
        ))
    }

    fn fused(&self) -> Vec<Fused> {
        Generated::fused(self)
    }

    fn evaluate_fused(
        &self,
        name: &str,
        q: &[f64],
        params: &[f64],
    ) -> Option<Vec<trocar_check::DMatrix<f64>>> {
        let values = Generated::evaluate_fused(self, name, q, params)?;
        Some(
            values
                .into_iter()
                .map(|m| trocar_check::DMatrix::from_column_slice(m.rows, m.cols, &m.values))
                .collect(),
        )
    }
}
