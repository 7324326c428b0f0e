//! Evaluation of the generated programs: the closed-form path of `trocar eval` and the candidate
//! that `trocar verify` checks.
//!
//! The programs evaluated here are exactly those the emitter turns into Rust (after CSE, constant
//! folding and factoring), interpreted in `f64`; the compiled form is checked separately by the
//! generated-code test crate.

use crate::builder::{module_name, Error};
use crate::derivation;
use crate::emit::{bridge, Function, ModuleSpec, Shape};
use trocar::nalgebra::DMatrix;
use trocar_model::description::RobotDescription;
use trocar_model::verify::{Candidate, Quantity};

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
    pub fn evaluate(&self, name: &str, q: &[f64], params: &[f64]) -> Option<DMatrix<f64>> {
        let f = self.function(name)?;
        if q.len() != self.spec.joints || params.len() != self.spec.params.len() {
            return None;
        }
        let out = f.program.eval(q, params);
        Some(match f.shape {
            Shape::Scalar => DMatrix::from_element(1, 1, out[0]),
            Shape::Matrix { rows, cols } => DMatrix::from_column_slice(rows, cols, &out),
            Shape::Transform => {
                let mut m = DMatrix::identity(4, 4);
                for c in 0..3 {
                    for r in 0..3 {
                        m[(r, c)] = out[c * 3 + r];
                    }
                    m[(c, 3)] = out[9 + c];
                }
                m
            }
        })
    }

    /// Nominal parameter values, in declaration order.
    pub fn nominal_params(&self) -> Vec<f64> {
        self.spec.params.iter().map(|(_, v)| *v).collect()
    }
}

/// The generated function that computes a quantity.
pub fn function_name(quantity: Quantity) -> &'static str {
    match quantity {
        Quantity::ConstrainedJacobian => "constrained_jacobian",
        Quantity::ConstraintJacobianC => "constraint_jacobian_c",
        Quantity::PartialBodyJacobian => "partial_body_jacobian",
        Quantity::ForwardKinematics => "forward_kinematics",
        Quantity::ConstrainedLinkKinematics => "forward_kinematics_i",
        Quantity::Manipulability => "manipulability",
        Quantity::ManipulabilitySquared => "manipulability_squared",
    }
}

impl Candidate for Generated {
    fn evaluate(&self, quantity: Quantity, q: &[f64], params: &[f64]) -> Option<DMatrix<f64>> {
        Generated::evaluate(self, function_name(quantity), q, params)
    }
}
