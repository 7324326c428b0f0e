//! The one error type of the library: what went wrong and where (file, line, field for a
//! description; the argument for a value given by the caller).

use std::fmt;
use std::path::PathBuf;
use trocar_model::description::DescriptionError;

/// Why a library call failed. Every variant displays as one message that says what is wrong and
/// where, the message the command line prints after `error: ` and Python raises as `ValueError`.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A description that cannot be read or is not valid; the message names the file, the line
    /// and the field (`robot.toml:23:1: field joints[3].axis: ...`).
    Description(DescriptionError),
    /// The closed forms could not be derived or emitted.
    Generation(trocar_codegen::Error),
    /// A value given by the caller is not acceptable, or one is missing: `argument` is the
    /// library's name of it (`q`, `params`, `what`, `samples`, `q0`, `trocar`, `trajectory`,
    /// `method`, ... as [`Robot`](crate::Robot)'s methods, [`RunRequest`](crate::RunRequest) and
    /// Python name them), `problem` says what is wrong with it. Displays as
    /// `argument: problem`; the command line prints its own flag for `argument`.
    Argument {
        /// The argument's name in the library.
        argument: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// A value given by the caller is not acceptable (a file it names, a combination of
    /// values); the message says which and where.
    Input(String),
    /// The quantity asked for does not exist for this robot, or not on this path.
    Unsupported(String),
    /// A result is not finite, or undefined at this configuration (a singularity).
    NotFinite(String),
    /// The numeric robot could not be built or evaluated; `file` is the description's.
    Robot {
        /// The description's file, when it has one.
        file: Option<PathBuf>,
        /// What the numeric runtime said.
        message: String,
    },
    /// A simulation could not be run or did not finish.
    Simulation(String),
    /// An output (CSV, figure, animation) could not be written; the message names the option
    /// and the file.
    Output(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Description(e) => write!(f, "{e}"),
            Error::Generation(e) => write!(f, "{e}"),
            Error::Input(m)
            | Error::Unsupported(m)
            | Error::NotFinite(m)
            | Error::Simulation(m)
            | Error::Output(m) => f.write_str(m),
            Error::Argument { argument, problem } => write!(f, "{argument}: {problem}"),
            Error::Robot { file, message } => match file {
                Some(p) => write!(f, "{}: {message}", p.display()),
                None => f.write_str(message),
            },
        }
    }
}

impl Error {
    /// An [`Error::Argument`]: `argument` (the library's name) and what is wrong with it.
    pub fn argument(argument: &'static str, problem: impl Into<String>) -> Self {
        Error::Argument {
            argument,
            problem: problem.into(),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Description(e) => Some(e),
            Error::Generation(e) => Some(e),
            _ => None,
        }
    }
}

impl From<DescriptionError> for Error {
    fn from(e: DescriptionError) -> Self {
        Error::Description(e)
    }
}

impl From<trocar_codegen::Error> for Error {
    fn from(e: trocar_codegen::Error) -> Self {
        Error::Generation(e)
    }
}

/// A `Result` whose error is [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
