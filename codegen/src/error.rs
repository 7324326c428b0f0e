//! The generator's error type.

use std::fmt;
use std::path::PathBuf;
use trocar_model::description::DescriptionError;

/// Why generation failed.
#[derive(Debug)]
pub enum Error {
    /// The description is unreadable, invalid or cannot be derived; names file, line and field.
    Description(DescriptionError),
    /// Reading or writing a file.
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// No output directory: neither [`crate::Builder::out_dir`] nor the `OUT_DIR` variable.
    NoOutDir,
    /// Two robots would be written to the same file.
    DuplicateModule(String),
    /// With the C ABI ([`crate::Builder::c_api`]), two modules of one build export the same C
    /// symbol (`<module>_<function>`: module `arm` and module `arm_link` both give
    /// `arm_link_pose_and_jacobian`), which would not link.
    CSymbolClash {
        /// The symbol.
        symbol: String,
        /// The two modules that export it.
        modules: (String, String),
    },
    /// With the C ABI, two names of one module give the same macro in its C header (C macros are
    /// the names in upper case: the parameters `l_b` and `L_B` both give `<MODULE>_PARAM_L_B`),
    /// which C would define twice ([`crate::emit::c_api::check_names`]).
    CMacroClash {
        /// The macro.
        name: String,
        /// What gives it first (`"the parameter `l_b`"`).
        first: String,
        /// What gives it again.
        second: String,
    },
    /// A module name is not a Rust identifier.
    BadModuleName(String),
    /// The runtime path ([`crate::Builder::runtime_path`]) is not a Rust path.
    BadRuntimePath(String),
    /// The generated tokens did not parse as a file (a bug in the generator).
    Internal(String),
    /// A fused function ([`crate::Builder::function`]) cannot be emitted: its name is taken or
    /// not an identifier, or an output is unknown, repeated or not in the module.
    Function {
        /// The fused function's name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// [`crate::Builder::fma_at_run_time`] asked of a module that is not generic over the
    /// scalar (its entry points run the generic functions on `trocar::emitted::fma::FusedF64`); the
    /// scalar asked for.
    FmaNeedsGeneric(String),
    /// The generation-time check of [`crate::Builder::evidence`] failed: the report, with the
    /// functions that do not match the numeric runtime.
    Evidence(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Description(e) => write!(f, "{e}"),
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::NoOutDir => write!(
                f,
                "no output directory: call `Builder::out_dir` or run from a build script (OUT_DIR)"
            ),
            Error::DuplicateModule(m) => write!(f, "two robots generate the module `{m}`"),
            Error::CSymbolClash {
                symbol,
                modules: (a, b),
            } => write!(
                f,
                "with the C ABI the modules `{a}` and `{b}` both export the C symbol `{symbol}`, \
                 which would not link: rename one of them (Builder::robot_as)"
            ),
            Error::CMacroClash {
                name,
                first,
                second,
            } => write!(
                f,
                "with the C ABI {first} and {second} both give the C header's macro `{name}` \
                 (C macros are the names in upper case): rename one of them"
            ),
            Error::BadModuleName(m) => write!(f, "`{m}` is not a valid module name"),
            Error::BadRuntimePath(p) => write!(
                f,
                "`{p}` is not a valid runtime path (expected a Rust path such as `::trocar`)"
            ),
            Error::Internal(m) => write!(f, "internal generator error: {m}"),
            Error::Function { name, message } => write!(f, "function `{name}`: {message}"),
            Error::FmaNeedsGeneric(real) => write!(
                f,
                "fma_at_run_time needs a module generic over the scalar (real = generic), not \
                 real = {real}: its `_f64` entry points run the generic functions on \
                 trocar::emitted::fma::FusedF64"
            ),
            Error::Evidence(m) => write!(
                f,
                "the generated module does not match the numeric runtime (evidence):\n{m}"
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Description(e) => Some(e),
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl From<DescriptionError> for Error {
    fn from(e: DescriptionError) -> Self {
        Error::Description(e)
    }
}
