//! Evaluation of the generated programs: the closed-form path of `trocar eval` and what
//! `trocar verify` checks.
//!
//! The programs evaluated here are exactly those the emitter turns into Rust (after CSE, constant
//! folding and factoring), interpreted in `f64`; the compiled form is checked separately by the
//! generated-code test crate.

use crate::builder::{module_name, Error};
use crate::derivation;
use crate::emit::{bridge, Function, ModuleSpec, Shape};
use trocar_model::description::RobotDescription;

/// A robot's generated functions, ready to evaluate.
#[derive(Clone, Debug)]
pub struct Generated {
    spec: ModuleSpec,
}

impl Generated {
    /// Derives and optimises the module of a description (nothing is formatted or written).
    pub fn new(description: &RobotDescription) -> Result<Self, Error> {
        let d = derivation::derive(description)
            .map_err(|e| Error::Description(e.into_description_error(description)))?;
        Ok(Generated {
            spec: bridge::module_spec(&d, &module_name(&description.name)),
        })
    }

    /// The module as emitted.
    pub fn spec(&self) -> &ModuleSpec {
        &self.spec
    }

    /// The function called `name`, if the module has one.
    pub fn function(&self, name: &str) -> Option<&Function> {
        self.spec.functions.iter().find(|f| f.name == name)
    }

    /// Evaluates the function `name` at `q` with parameter values in declaration order; a
    /// transform comes back as a 4×4 homogeneous matrix. `None` when there is no such function
    /// or the argument lengths are wrong.
    pub fn evaluate(&self, name: &str, q: &[f64], params: &[f64]) -> Option<Evaluated> {
        let f = self.function(name)?;
        if q.len() != self.spec.joints || params.len() != self.spec.params.len() {
            return None;
        }
        let out = f.program.eval(q, params);
        Some(match f.shape {
            Shape::Scalar => Evaluated {
                rows: 1,
                cols: 1,
                values: vec![out[0]],
            },
            Shape::Matrix { rows, cols } => Evaluated {
                rows,
                cols,
                values: out[..rows * cols].to_vec(),
            },
            Shape::Transform => {
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
        })
    }

    /// Nominal parameter values, in declaration order.
    pub fn nominal_params(&self) -> Vec<f64> {
        self.spec.params.iter().map(|(_, v)| *v).collect()
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
