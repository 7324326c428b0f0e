//! The build-script API, in the style of prost-build.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), trocar_codegen::builder::Error> {
//!     trocar_codegen::builder::Builder::new()
//!         .robot("robots/arm.toml")
//!         .real(trocar_codegen::emit::Real::F64)
//!         .compile()?;
//!     Ok(())
//! }
//! ```
//! and in the crate: `include!(concat!(env!("OUT_DIR"), "/arm.rs"));` which defines `pub mod arm`.
//! Closed mechanisms are added with [`Builder::mechanism`] (`runtime/model/robots/mechanisms/*.toml`);
//! their modules hold the reduced Jacobian (8) and passive velocities (7) in closed form
//! ([`crate::closed_chain`]).
//!
//! [`Builder::generate`] returns the code without writing anything (for tests and the CLI);
//! [`Builder::compile`] writes `<robot_name>.rs` into `OUT_DIR` (or [`Builder::out_dir`]), only
//! when the content changed, and prints `cargo:rerun-if-changed=<file>` for every description
//! file. The lower-level entry points [`generate_module`] (tokens) and [`generate_module_string`]
//! (formatted file) serve the command line and the proc-macro.

use crate::closed_chain;
use crate::derivation;
use crate::emit::{self, bridge, Real};
use proc_macro2::TokenStream;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::{DescriptionError, RobotDescription};

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
    /// No output directory: neither [`Builder::out_dir`] nor the `OUT_DIR` variable.
    NoOutDir,
    /// Two robots would be written to the same file.
    DuplicateModule(String),
    /// A module name is not a Rust identifier.
    BadModuleName(String),
    /// The generated tokens did not parse as a file (a bug in the generator).
    Internal(String),
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
            Error::BadModuleName(m) => write!(f, "`{m}` is not a valid module name"),
            Error::Internal(m) => write!(f, "internal generator error: {m}"),
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

/// Options of one generated module.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ModuleOptions {
    /// Scalar type of the generated code.
    pub real: Real,
    /// Module name; default: the robot's name, snake-cased.
    pub module_name: Option<String>,
}

/// The module name for a robot name: lower snake case, a valid identifier.
pub fn module_name(robot: &str) -> String {
    let mut s = String::new();
    let mut prev_lower = false;
    for ch in robot.chars() {
        if ch.is_ascii_alphanumeric() {
            if ch.is_ascii_uppercase() && prev_lower {
                s.push('_');
            }
            prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
            s.push(ch.to_ascii_lowercase());
        } else {
            if !s.ends_with('_') {
                s.push('_');
            }
            prev_lower = false;
        }
    }
    let s = s.trim_matches('_').to_string();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        format!("robot_{s}")
    } else if syn::parse_str::<syn::Ident>(&s).is_err() {
        format!("{s}_")
    } else {
        s
    }
}

fn spec_for(desc: &RobotDescription, options: &ModuleOptions) -> Result<emit::ModuleSpec, Error> {
    let name = options
        .module_name
        .clone()
        .unwrap_or_else(|| module_name(&desc.name));
    if syn::parse_str::<syn::Ident>(&name).is_err() {
        return Err(Error::BadModuleName(name));
    }
    let d =
        derivation::derive(desc).map_err(|e| Error::Description(e.into_description_error(desc)))?;
    Ok(bridge::module_spec(&d, &name))
}

/// The module `pub mod <name> { ... }` for a description, as tokens (for the proc-macro).
pub fn generate_module(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<TokenStream, Error> {
    let spec = spec_for(desc, options)?;
    Ok(emit::module_tokens(&spec, options.real))
}

/// The module as a formatted file (prettyplease), headed
/// `// This file is @generated by trocar-codegen. Do not edit.` (for the CLI and build scripts).
pub fn generate_module_string(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<String, Error> {
    let tokens = generate_module(desc, options)?;
    emit::format_file(tokens).map_err(|e| Error::Internal(e.to_string()))
}

#[derive(Clone, Debug)]
enum Source {
    File(PathBuf),
    Description(Box<RobotDescription>),
}

/// Configures and runs code generation from a build script (prost-build's `Config`).
#[derive(Clone, Debug, Default)]
pub struct Builder {
    robots: Vec<(Source, Option<String>)>,
    mechanisms: Vec<(PathBuf, Option<String>)>,
    real: Real,
    out_dir: Option<PathBuf>,
    emit_rerun: bool,
}

impl Builder {
    /// A builder with no robots, generic scalar type, output to `OUT_DIR`.
    pub fn new() -> Self {
        Builder {
            emit_rerun: true,
            ..Builder::default()
        }
    }

    /// Adds a robot description file (TOML); may be called several times.
    pub fn robot(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.robots
            .push((Source::File(path.as_ref().to_path_buf()), None));
        self
    }

    /// Adds a robot description file and names its module.
    pub fn robot_as(&mut self, path: impl AsRef<Path>, module: &str) -> &mut Self {
        self.robots.push((
            Source::File(path.as_ref().to_path_buf()),
            Some(module.to_string()),
        ));
        self
    }

    /// Adds an already-parsed description (e.g. a preset).
    pub fn description(&mut self, desc: RobotDescription) -> &mut Self {
        self.robots
            .push((Source::Description(Box::new(desc)), None));
        self
    }

    /// Adds a closed-mechanism description file (TOML, `runtime/model/robots/mechanisms/*.toml`): the
    /// module has the closed-form reduced Jacobian (8) and passive velocities (7) (see
    /// [`crate::closed_chain`]); may be called several times.
    pub fn mechanism(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.mechanisms.push((path.as_ref().to_path_buf(), None));
        self
    }

    /// Adds a closed-mechanism description file and names its module.
    pub fn mechanism_as(&mut self, path: impl AsRef<Path>, module: &str) -> &mut Self {
        self.mechanisms
            .push((path.as_ref().to_path_buf(), Some(module.to_string())));
        self
    }

    /// Scalar type of the generated code (default [`Real::Generic`]).
    pub fn real(&mut self, real: Real) -> &mut Self {
        self.real = real;
        self
    }

    /// Output directory for [`Builder::compile`] (default: the `OUT_DIR` variable).
    pub fn out_dir(&mut self, dir: impl AsRef<Path>) -> &mut Self {
        self.out_dir = Some(dir.as_ref().to_path_buf());
        self
    }

    /// Whether [`Builder::compile`] prints `cargo:rerun-if-changed` lines (default `true`).
    pub fn emit_rerun_if_changed(&mut self, on: bool) -> &mut Self {
        self.emit_rerun = on;
        self
    }

    fn load(&self) -> Result<Vec<(RobotDescription, Option<String>)>, Error> {
        self.robots
            .iter()
            .map(|(src, name)| {
                let d = match src {
                    Source::File(p) => RobotDescription::from_toml_file(p)?,
                    Source::Description(d) => (**d).clone(),
                };
                Ok((d, name.clone()))
            })
            .collect()
    }

    /// Generates every module without writing: file name (`<module>.rs`) → formatted code.
    pub fn generate(&self) -> Result<BTreeMap<String, String>, Error> {
        let mut out = BTreeMap::new();
        for (desc, name) in self.load()? {
            let options = ModuleOptions {
                real: self.real,
                module_name: name,
            };
            let module = options
                .module_name
                .clone()
                .unwrap_or_else(|| module_name(&desc.name));
            let code = generate_module_string(&desc, &options)?;
            let file = format!("{module}.rs");
            if out.insert(file, code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
        }
        for (path, name) in &self.mechanisms {
            let src = MechanismModel::from_toml_file(path)?;
            let module = closed_chain::emit::module_name_for(&src.name, name.as_deref())?;
            let code =
                closed_chain::emit::generate_mechanism_string(&src, Some(&module), self.real)?;
            let file = format!("{module}.rs");
            if out.insert(file, code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
        }
        Ok(out)
    }

    /// Generates and writes `<module>.rs` for every robot into the output directory, only the
    /// files whose content changed; prints `cargo:rerun-if-changed=<file>` for each description
    /// file. Returns the paths of the generated files.
    pub fn compile(&self) -> Result<Vec<PathBuf>, Error> {
        let dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => std::env::var_os("OUT_DIR")
                .map(PathBuf::from)
                .ok_or(Error::NoOutDir)?,
        };
        if self.emit_rerun {
            for (src, _) in &self.robots {
                if let Source::File(p) = src {
                    println!("cargo:rerun-if-changed={}", p.display());
                }
            }
            for (p, _) in &self.mechanisms {
                println!("cargo:rerun-if-changed={}", p.display());
            }
        }
        let files = self.generate()?;
        std::fs::create_dir_all(&dir).map_err(|source| Error::Io {
            path: dir.clone(),
            source,
        })?;
        let mut written = Vec::new();
        for (file, code) in files {
            let path = dir.join(file);
            write_if_changed(&path, &code)?;
            written.push(path);
        }
        Ok(written)
    }

    /// Alias of [`Builder::compile`].
    pub fn write(&self) -> Result<Vec<PathBuf>, Error> {
        self.compile()
    }
}

/// Writes `content` to `path` unless the file already holds exactly it (no needless rebuilds).
/// Returns whether the file was written.
pub fn write_if_changed(path: &Path, content: &str) -> Result<bool, Error> {
    if let Ok(old) = std::fs::read_to_string(path) {
        if old == content {
            return Ok(false);
        }
    }
    std::fs::write(path, content).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(true)
}
