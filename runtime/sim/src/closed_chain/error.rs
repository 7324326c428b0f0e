//! Errors and singularity kinds of the closed-chain computations.

use std::fmt;
use trocar_model::description::DescriptionError;

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
