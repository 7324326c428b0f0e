//! The build-script API, in the style of prost-build.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), trocar_codegen::Error> {
//!     trocar_codegen::Builder::new()
//!         .robot("robots/arm.toml")
//!         .real(trocar_codegen::Real::F64)
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
//! file. The lower-level entry points [`generate_module`] (tokens), [`generate_module_string`]
//! and [`generate_mechanism_string`] (formatted file) serve the command line and the attribute.

use crate::closed_chain;
use crate::derivation;
use crate::emit::checks::{self, ChecksGate};
use crate::emit::{self, Runtime};
use crate::error::Error;
use crate::ir::{ModuleSpec, Real};
use crate::lower;
use crate::naming::checked_module_name;
use proc_macro2::TokenStream;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use trocar_model::catalogue::{Function, Fused};
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::{DescriptionError, RobotDescription};
use trocar_model::scene::SceneDescription;

/// Options of one generated module.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ModuleOptions {
    /// Real type of the generated code.
    pub real: Real,
    /// Module name; default: the robot's name, snake-cased ([`crate::module_name`]).
    pub module_name: Option<String>,
    /// The path through which the generated code names the runtime crate `trocar`; default
    /// `::trocar` (see [`Builder::runtime_path`]).
    pub runtime_path: Option<String>,
    /// Also emit the module's C ABI (`extern "C"` functions named `<module>_<function>`,
    /// [`crate::emit::c_api`]); see [`Builder::c_api`].
    pub c_api: bool,
    /// Also emit `Checks`, the module's implementation of `trocar_check::GeneratedModule`, behind
    /// this gate ([`crate::emit::checks`]); see [`Builder::checks`].
    pub checks: Option<ChecksGate>,
    /// Check the module at generation time at this many random configurations and write the
    /// largest errors into its documentation, with `DESCRIPTION_HASH` and its build-time
    /// assertion; see [`Builder::evidence`].
    pub evidence: Option<usize>,
    /// Fused functions besides the defaults ([`Builder::function`]): each one function computing
    /// several catalogue outputs in one program.
    pub functions: Vec<Fused>,
    /// Also emit each fused function's `f64` entry points with fused multiply-adds chosen at run
    /// time (`<name>_f64`, `<name>_trig_f64`); see [`Builder::fma_at_run_time`].
    pub fma_at_run_time: bool,
    /// The files the description was read from (the TOML file, then the URDF it reads), relative
    /// to the package's root or absolute: their hash is the module's `DESCRIPTION_HASH`. Empty
    /// for a description given in memory.
    pub description_files: Vec<PathBuf>,
}

impl ModuleOptions {
    fn runtime(&self) -> Result<Runtime, Error> {
        match &self.runtime_path {
            None => Ok(Runtime::default()),
            Some(p) => Runtime::new(p).ok_or_else(|| Error::BadRuntimePath(p.clone())),
        }
    }
}

pub(crate) fn spec_for(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<ModuleSpec, Error> {
    let name = checked_module_name(&desc.name, options.module_name.as_deref())?;
    let d =
        derivation::derive(desc).map_err(|e| Error::Description(e.into_description_error(desc)))?;
    let mut spec = lower::module_spec_with(&d, &name, &options.functions)?;
    if options.fma_at_run_time {
        if options.real != Real::Generic {
            return Err(Error::FmaNeedsGeneric(options.real.to_string()));
        }
        spec.fma_at_run_time = true;
    }
    Ok(spec)
}

/// The module `pub mod <name> { ... }` for a description, as tokens (for the attribute).
pub fn generate_module(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<TokenStream, Error> {
    module_tokens(desc, options, spec_for(desc, options)?)
}

/// [`generate_module`] of the description's derived module `spec`.
pub(crate) fn module_tokens(
    desc: &RobotDescription,
    options: &ModuleOptions,
    spec: ModuleSpec,
) -> Result<TokenStream, Error> {
    let runtime = options.runtime()?;
    if options.c_api {
        c_api_names(&spec)?;
    }
    let mut items = emit::module_items_in(&spec, options.real, &runtime);
    if options.c_api {
        items.extend(emit::c_api::items(&spec, options.real, runtime.tokens()));
    }
    let files = &options.description_files;
    let hash = checks::description_hash(files).map_err(|source| Error::Io {
        path: files.first().cloned().unwrap_or_default(),
        source,
    })?;
    if let Some(gate) = &options.checks {
        items.extend(checks::items(&spec, options.real, gate, &desc.name, hash));
    }
    let mut doc = spec.doc.clone();
    if let Some(samples) = options.evidence {
        let generated = crate::evaluate::Generated::from_spec(spec.clone());
        let report = trocar_check::verify::verify(
            desc,
            &generated,
            samples,
            trocar_check::SEED,
            trocar_check::Tolerances::F64,
            |_| {},
        )
        .map_err(|e| Error::Evidence(e.to_string()))?;
        if !report.passed() {
            return Err(Error::Evidence(format!("{report}{}", report.failures())));
        }
        doc += &checks::evidence_doc(
            &report,
            options.real,
            files.first().map(PathBuf::as_path),
            hash,
        );
        if let Some(h) = hash {
            items.extend(checks::staleness_guard(files, h));
        }
    }
    let tokens = emit::wrap_module(&spec.name, &doc, items);
    if let Some(literal) = f32_overflow(tokens.clone()) {
        return Err(Error::Description(DescriptionError {
            file: desc.source.clone(),
            line: None,
            column: None,
            field: "(closed forms)".into(),
            message: format!(
                "the closed forms need the constant {literal}, beyond the range of f32 (±3.4e38): the description's lengths are too large for an f32 module; generate it for f64"
            ),
        }));
    }
    Ok(tokens)
}

/// With the C ABI, a fused function's C function `<module>_<name>` lives beside the module's
/// Rust items: a fused name that starts with `<module>_` (it could be another C function's Rust
/// name) or is the C ABI's helper `c_params` would clash; and the header's macros must be
/// distinct ([`emit::c_api::check_names`]).
fn c_api_names(spec: &ModuleSpec) -> Result<(), Error> {
    emit::c_api::check_names(spec)?;
    let prefix = format!("{}_", spec.name);
    for f in &spec.fused {
        if f.name == "c_params" || f.name.starts_with(&prefix) {
            return Err(Error::Function {
                name: f.name.clone(),
                message: format!(
                    "with the C ABI the module's C functions are named `{prefix}<function>`, \
                     beside its Rust items, and it holds `c_params`: name the function without \
                     the prefix `{prefix}`"
                ),
            });
        }
    }
    Ok(())
}

/// The first `f32` literal of `tokens` that overflows `f32` (it would not compile), if any.
fn f32_overflow(tokens: TokenStream) -> Option<String> {
    tokens.into_iter().find_map(|tree| match tree {
        proc_macro2::TokenTree::Group(g) => f32_overflow(g.stream()),
        proc_macro2::TokenTree::Literal(l) => {
            let text = l.to_string();
            let digits = text
                .strip_suffix("_f32")
                .or_else(|| text.strip_suffix("f32"))?;
            let value: f32 = digits.replace('_', "").parse().ok()?;
            value.is_infinite().then_some(text)
        }
        _ => None,
    })
}

/// The C header of a description's module's C ABI ([`ModuleOptions::c_api`],
/// [`crate::emit::c_api`]): its sizes and parameter indices as `#define`s and one prototype per
/// function; matrices column-major. Fails with [`Error::CMacroClash`] when two of the module's names
/// give one macro, and with [`Error::Function`] for a fused name the C ABI cannot take.
pub fn generate_c_header(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<String, Error> {
    let spec = spec_for(desc, options)?;
    c_api_names(&spec)?;
    Ok(emit::c_api::header(&spec, options.real))
}

/// The module as a formatted file (prettyplease), headed
/// `// This file is @generated by trocar-codegen. Do not edit.` (for the CLI and build scripts).
pub fn generate_module_string(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<String, Error> {
    module_string(desc, options, spec_for(desc, options)?)
}

/// [`generate_module_string`] of the description's derived module `spec`.
fn module_string(
    desc: &RobotDescription,
    options: &ModuleOptions,
    spec: ModuleSpec,
) -> Result<String, Error> {
    emit::format_file(module_tokens(desc, options, spec)?)
        .map_err(|e| Error::Internal(e.to_string()))
}

/// The module of a closed mechanism as a formatted file (prettyplease, headed by the
/// `@generated` line): the closed-form reduced Jacobian (8) and passive velocities (7)
/// ([`crate::closed_chain`]).
pub fn generate_mechanism_string(
    src: &MechanismModel,
    options: &ModuleOptions,
) -> Result<String, Error> {
    let runtime = options.runtime()?;
    let d = closed_chain::derive(src).map_err(Error::Description)?;
    for (k, name) in d.params.iter().enumerate() {
        if syn::parse_str::<syn::Ident>(name).is_err() {
            return Err(Error::Description(
                closed_chain::MechanismError::new(
                    format!("parameters.{name}"),
                    format!(
                        "parameter {k} `{name}` is not a Rust identifier (a field of `Params`)"
                    ),
                )
                .into_description_error(src.file.as_deref()),
            ));
        }
    }
    let name = checked_module_name(&d.name, options.module_name.as_deref())?;
    let spec = lower::mechanism::module_spec(&d, &name);
    emit::format_file(emit::mechanism::module_tokens(
        &d,
        &spec,
        options.real,
        &runtime,
    ))
    .map_err(|e| Error::Internal(e.to_string()))
}

#[derive(Clone, Debug)]
enum SceneSource {
    File(PathBuf),
    Description(Box<SceneDescription>),
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
    scenes: Vec<(SceneSource, Option<String>)>,
    mechanisms: Vec<(PathBuf, Option<String>)>,
    real: Real,
    runtime_path: Option<String>,
    out_dir: Option<PathBuf>,
    emit_rerun: bool,
    c_api: bool,
    checks: Option<ChecksGate>,
    evidence: Option<usize>,
    functions: Vec<Fused>,
    fma_at_run_time: bool,
}

impl Builder {
    /// A builder with no robots, generic real type, output to `OUT_DIR`.
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

    /// Adds a scene file (TOML with a `[scene]` table, [`trocar_model::scene`]): its module
    /// (named after the scene) holds every arm's closed forms and the scene's step kinematics
    /// ([`crate::scene`]); may be called several times.
    pub fn scene(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.scenes
            .push((SceneSource::File(path.as_ref().to_path_buf()), None));
        self
    }

    /// Adds a scene file and names its module.
    pub fn scene_as(&mut self, path: impl AsRef<Path>, module: &str) -> &mut Self {
        self.scenes.push((
            SceneSource::File(path.as_ref().to_path_buf()),
            Some(module.to_string()),
        ));
        self
    }

    /// Adds an already-read scene (e.g. a shipped one, `SceneDescription::shipped`).
    pub fn scene_description(&mut self, scene: SceneDescription) -> &mut Self {
        self.scenes
            .push((SceneSource::Description(Box::new(scene)), None));
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

    /// Real type of the generated code (default [`Real::Generic`]).
    pub fn real(&mut self, real: Real) -> &mut Self {
        self.real = real;
        self
    }

    /// The path through which generated code names the runtime crate `trocar` (prost-build's
    /// `prost_path`), e.g. `"::my_reexport::trocar"` for a crate that depends on `trocar` only
    /// through a re-export; default `"::trocar"`. A path that is not a Rust path makes
    /// [`Builder::generate`] fail with [`Error::BadRuntimePath`].
    pub fn runtime_path(&mut self, path: impl Into<String>) -> &mut Self {
        self.runtime_path = Some(path.into());
        self
    }

    /// Also emit each serial robot's C ABI: `extern "C"` functions `<module>_<function>(q,
    /// params, out)` (and `<module>_controller_step` where the module has `Kinematics`) inside
    /// the module, and the matching C header `<module>.h` beside `<module>.rs`
    /// ([`crate::emit::c_api`]). A crate built as a `staticlib` or `cdylib` then exports them.
    /// [`Builder::generate`] fails with [`Error::CSymbolClash`] when two of its modules would
    /// export the same symbol (modules `arm` and `arm_link`: `arm_link_pose_and_jacobian`);
    /// modules generated by separate builds or attributes are not compared.
    pub fn c_api(&mut self, on: bool) -> &mut Self {
        self.c_api = on;
        self
    }

    /// Also emit, for each fused function `name` of each serial robot (the defaults and those of
    /// [`Builder::function`]), the `f64` entry points `name_f64` and `name_trig_f64` with fused
    /// multiply-adds chosen at run time (`trocar::emitted::fma`): in a build for the default x86-64
    /// target with `trocar`'s `std` feature, on a CPU with AVX2 and FMA, they run `name`
    /// compiled for those (every `mul_add` one instruction when optimised, rounded once;
    /// `name_trig_f64` compiled for AVX-512F and AVX-512VL too where the CPU has them, with the
    /// same bits); elsewhere, and always without `std`, they call `name::<f64>`. Their results' last
    /// bits then depend on the CPU. The fused functions become `#[inline(always)]`. The
    /// AVX-512 function needs Rust 1.89 or later (the AVX-512 target features became stable
    /// there) to compile the generated module; the rest of trocar needs 1.85. Needs the
    /// generic scalar ([`Real::Generic`], the default); [`Builder::generate`] fails with
    /// [`Error::FmaNeedsGeneric`] otherwise.
    pub fn fma_at_run_time(&mut self, on: bool) -> &mut Self {
        self.fma_at_run_time = on;
        self
    }

    /// Also emit, in each serial robot's module and behind `#[cfg(test)]`, `Checks`: the module's
    /// implementation of `trocar_check::GeneratedModule` (every function of the catalogue it has,
    /// evaluated as compiled, in its `f32` or `f64`), so that a unit test of the crate reads
    /// `trocar_check::assert_matches_numeric::<arm::Checks>("robots/arm.toml", 2_000)`. The crate
    /// then needs `trocar-check` among its dev-dependencies. `false` removes them again.
    pub fn checks(&mut self, on: bool) -> &mut Self {
        self.checks = on.then_some(ChecksGate::Test);
        self
    }

    /// As [`Builder::checks`], behind `#[cfg(feature = "<feature>")]` instead of `#[cfg(test)]`:
    /// for integration tests (`tests/*.rs` see the library built without `cfg(test)`); the
    /// feature enables an optional dependency on `trocar-check`.
    pub fn checks_feature(&mut self, feature: &str) -> &mut Self {
        self.checks = Some(ChecksGate::Feature(feature.into()));
        self
    }

    /// Checks each serial robot's module when it is generated, at `samples` random
    /// configurations and parameter values (seed `trocar_check::SEED`), every function evaluated
    /// as the generated `f64` code against the numeric runtime and the Jacobians against finite
    /// differences; generation fails on a mismatch. The module's documentation then opens with
    /// the evidence (generator, description hash, seed, samples, the largest error of each
    /// check), and a module generated from a file holds `DESCRIPTION_HASH` and a constant
    /// assertion that fails its build once the description file (or its URDF) has changed.
    pub fn evidence(&mut self, samples: usize) -> &mut Self {
        self.evidence = Some(samples);
        self
    }

    /// Also emit, in each serial robot's module, the function `name` (and `name_trig`, taking
    /// `JointTrig`) computing the catalogue functions `outputs` in one straight-line program
    /// that shares every value they have in common: for `function("pose_and_jacobian",
    /// [Function::ForwardKinematics, Function::BodyJacobian])`,
    /// `pose_and_jacobian(&q, &p, &mut fk, &mut jb0e)`, each output written through a `&mut`
    /// out-parameter named by its short name ([`Function::short_name`]) in the layout its own
    /// function returns. Every module already has `pose_and_jacobian` (`g_0e`, `J^B_0e`) and,
    /// with a constraint, `link_pose_and_jacobian` (`g_0i`, `J^B_0i`) ([`Fused::defaults`]); a
    /// function named like one of them replaces it. May be called several times. Generation
    /// fails with [`Error::Function`] when the name is taken, is not a snake_case identifier or
    /// ends in a suffix the module gives to variants (`_trig`, and `_f64`, `_fma`, `_avx512` of
    /// [`Builder::fma_at_run_time`]), or an output is repeated or not a function of the module
    /// (`constrained_jacobian` of a robot without a constraint).
    pub fn function(
        &mut self,
        name: &str,
        outputs: impl IntoIterator<Item = Function>,
    ) -> &mut Self {
        self.functions.push(Fused::new(name, outputs));
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

    /// Each robot's description, module name and the files it was read from.
    #[allow(clippy::type_complexity)]
    fn load(&self) -> Result<Vec<(RobotDescription, Option<String>, Vec<PathBuf>)>, Error> {
        self.robots
            .iter()
            .map(|(src, name)| {
                let (d, files) = match src {
                    Source::File(p) => (
                        RobotDescription::from_toml_file(p)?,
                        RobotDescription::files_read(p),
                    ),
                    Source::Description(d) => ((**d).clone(), Vec::new()),
                };
                Ok((d, name.clone(), files))
            })
            .collect()
    }

    /// Generates every module without writing: file name (`<module>.rs`) → formatted code.
    /// With the C ABI, also `<module>.h`, and fails with [`Error::CSymbolClash`] when two modules
    /// would export the same C symbol.
    pub fn generate(&self) -> Result<BTreeMap<String, String>, Error> {
        let mut out = BTreeMap::new();
        // C symbol → the module exporting it.
        let mut symbols: BTreeMap<String, String> = BTreeMap::new();
        for (desc, name, description_files) in self.load()? {
            let module = checked_module_name(&desc.name, name.as_deref())?;
            let options = ModuleOptions {
                real: self.real,
                module_name: Some(module.clone()),
                runtime_path: self.runtime_path.clone(),
                c_api: self.c_api,
                checks: self.checks.clone(),
                evidence: self.evidence,
                functions: self.functions.clone(),
                fma_at_run_time: self.fma_at_run_time,
                description_files,
            };
            let spec = spec_for(&desc, &options)?;
            if self.c_api {
                c_api_names(&spec)?;
            }
            let header = self.c_api.then(|| emit::c_api::header(&spec, options.real));
            let exported = if self.c_api {
                emit::c_api::symbols(&spec)
            } else {
                Vec::new()
            };
            let code = module_string(&desc, &options, spec)?;
            let file = format!("{module}.rs");
            if out.insert(file, code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
            for symbol in exported {
                if let Some(first) = symbols.insert(symbol.clone(), module.clone()) {
                    return Err(Error::CSymbolClash {
                        symbol,
                        modules: (first, module),
                    });
                }
            }
            if let Some(header) = header {
                out.insert(format!("{module}.h"), header);
            }
        }
        for (src, name) in &self.scenes {
            let scene = match src {
                SceneSource::File(p) => SceneDescription::from_toml_file(p)?,
                SceneSource::Description(d) => (**d).clone(),
            };
            let module = checked_module_name(&scene.name, name.as_deref())?;
            let options = ModuleOptions {
                real: self.real,
                module_name: Some(module.clone()),
                runtime_path: self.runtime_path.clone(),
                ..ModuleOptions::default()
            };
            let code = crate::scene::generate_scene_string(&scene, &options)?;
            if out.insert(format!("{module}.rs"), code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
        }
        for (path, name) in &self.mechanisms {
            let src = MechanismModel::from_toml_file(path)?;
            let module = checked_module_name(&src.name, name.as_deref())?;
            let options = ModuleOptions {
                real: self.real,
                module_name: Some(module.clone()),
                runtime_path: self.runtime_path.clone(),
                ..ModuleOptions::default()
            };
            let code = generate_mechanism_string(&src, &options)?;
            let file = format!("{module}.rs");
            if out.insert(file, code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
        }
        Ok(out)
    }

    /// Generates and writes `<module>.rs` for every robot and scene into the output directory, only the
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
                    // The description and the URDF its chain may come from.
                    for f in RobotDescription::files_read(p) {
                        println!("cargo:rerun-if-changed={}", f.display());
                    }
                }
            }
            for (p, _) in &self.mechanisms {
                println!("cargo:rerun-if-changed={}", p.display());
            }
            for (src, _) in &self.scenes {
                if let SceneSource::File(p) = src {
                    for f in SceneDescription::files_read(p) {
                        println!("cargo:rerun-if-changed={}", f.display());
                    }
                }
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
fn write_if_changed(path: &Path, content: &str) -> Result<bool, Error> {
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

#[cfg(test)]
mod f32_literals {
    use super::f32_overflow;
    use quote::quote;

    /// A literal beyond `f32::MAX` does not compile (`1e40_f32`): it is found, in any group.
    #[test]
    fn overflowing_literals_are_found() {
        assert_eq!(
            f32_overflow(quote!(
                fn f() -> f32 {
                    g(3.0e38_f32, [1e40_f32])
                }
            )),
            Some("1e40_f32".to_string())
        );
        assert_eq!(f32_overflow(quote!(let x = 3.4e38_f32 + 1e300_f64;)), None);
    }
}
