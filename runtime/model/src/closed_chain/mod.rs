//! Closed kinematic chains and cooperating arms (second source).
//!
//! Equation numbers refer to G. M. Freitas, A. C. Leite, F. Lizarralde, *Controle de sistemas
//! robóticos com restrições cinemáticas*, CBA 2010 (SPEC §4).
//!
//! - [`mechanism`]: planar mechanisms made of open chains joined by structural equations; the
//!   active/passive partition; `J_C = Ã J`, `J_A = A† J` (17)–(19), (29)–(31); passive velocities
//!   (7); the reduced Jacobian `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8); forward kinematics by Newton's
//!   method; singularity classification (§4.5).
//! - [`linalg`]: ranks, pseudo-inverses, annihilators and the SVD analysis of §5.4.
//! - [`description`]: the TOML description of mechanisms; shipped files in
//!   `runtime/model/robots/mechanisms/` ([`description::shipped`]).
//! - [`four_bar`], [`stewart`], [`cooperative`]: the source's three examples (closed-form passive
//!   joints of the four-bar linkage, inverse kinematics of the planar Gough–Stewart platform,
//!   contact models by selection `H` (35)–(42)).
//! - [`redundancy`]: `u = J†(ẋ_d + K e) + (I − J†J) u_0`, `u_0 = K ∂f/∂θ_a` (44)–(46).
//!
//! ```
//! use trocar_model::closed_chain::{description, four_bar::FourBar};
//! let mech = description::shipped("four-bar").unwrap();
//! let fb = FourBar::from_mechanism(&mech).unwrap();
//! let theta = fb.configuration(1.2).unwrap();       // θ = (θ1, θ3, θ2, θ4)
//! let red = mech.reduced(&theta).unwrap();          // J of (8): dφ/dθ1
//! assert_eq!(red.jacobian.shape(), (1, 1));
//! ```

pub mod cooperative;
pub mod description;
pub mod four_bar;
pub mod linalg;
pub mod mechanism;
pub mod redundancy;
pub mod stewart;

pub use mechanism::{
    Chain, Differential, JointType, Mechanism, Output, PlanarJoint, Pose2, Reduced,
    SingularityReport,
};

use crate::description::DescriptionError;
use std::fmt;

/// The kinds of singular configurations of §4.5 (Gosselin and Angeles, 1990).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SingularityKind {
    /// End-effector (serial) singularity: the task loses degrees of freedom (`rank J < m`).
    Serial,
    /// Actuator (parallel, "unstable") singularity: `J_Cp` loses rank, passive joints move with
    /// the active joints locked.
    Parallel,
    /// Both at once.
    Structural,
}

impl fmt::Display for SingularityKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SingularityKind::Serial => "serial (end-effector)",
            SingularityKind::Parallel => "parallel (actuator)",
            SingularityKind::Structural => "structural (serial and parallel)",
        })
    }
}

/// Errors of the closed-chain module. No function of this module panics on user input or returns
/// NaN: non-finite input or results are reported.
#[derive(Clone, Debug, PartialEq)]
pub enum ClosedChainError {
    /// An invalid or unreadable mechanism description (names the file, line and field).
    Description(DescriptionError),
    /// A vector or matrix of the wrong size.
    Dimension {
        /// What was passed.
        what: String,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A NaN or infinite input or intermediate result.
    NonFinite {
        /// What was not finite.
        what: String,
    },
    /// A singular matrix where an invertible one is needed.
    Singular {
        /// Which kind of singularity.
        kind: SingularityKind,
        /// Which matrix.
        what: String,
        /// Its smallest singular value.
        sigma_min: f64,
    },
    /// Newton's method did not converge.
    NoConvergence {
        /// Which equations.
        what: String,
        /// Final residual norm.
        residual: f64,
    },
    /// Unknown simulation scenario.
    UnknownScenario {
        /// The name given.
        name: String,
        /// Known names.
        known: Vec<&'static str>,
    },
    /// An invalid option.
    Option {
        /// Which option.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Writing a file (CSV, plot) failed.
    Io {
        /// The path.
        path: String,
        /// The error.
        message: String,
    },
}

impl ClosedChainError {
    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        ClosedChainError::Description(DescriptionError {
            file: None,
            line: None,
            column: None,
            field: field.into(),
            message: message.into(),
        })
    }
}

impl fmt::Display for ClosedChainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClosedChainError::Description(e) => write!(f, "{e}"),
            ClosedChainError::Dimension {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected {expected} values, got {got}"),
            ClosedChainError::NonFinite { what } => write!(f, "{what} is not finite"),
            ClosedChainError::Singular {
                kind,
                what,
                sigma_min,
            } => write!(
                f,
                "{kind} singularity: {what} is singular (smallest singular value {sigma_min:.3e})"
            ),
            ClosedChainError::NoConvergence { what, residual } => write!(
                f,
                "Newton's method did not converge on {what} (residual {residual:.3e})"
            ),
            ClosedChainError::UnknownScenario { name, known } => {
                write!(f, "unknown scenario `{name}`; known: {}", known.join(", "))
            }
            ClosedChainError::Option { field, message } => {
                write!(f, "option `{field}`: {message}")
            }
            ClosedChainError::Io { path, message } => write!(f, "{path}: {message}"),
        }
    }
}

impl std::error::Error for ClosedChainError {}

impl From<DescriptionError> for ClosedChainError {
    fn from(e: DescriptionError) -> Self {
        ClosedChainError::Description(e)
    }
}
