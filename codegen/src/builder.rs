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
//! file. The lower-level entry points of [`crate::module`] ([`crate::generate_module`] (tokens),
//! [`crate::generate_module_string`] and [`crate::generate_mechanism_string`] (formatted file))
//! serve the command line and the attribute.

use crate::emit::checks::ChecksGate;
use crate::error::Error;
use crate::ir::Real;
use crate::module::{c_api_names, module_string, record_c_symbols, spec_for, ModuleOptions};
use crate::naming::checked_module_name;
use crate::{emit, generate_mechanism_string};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use trocar_model::catalogue::{Function, Fused};
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::RobotDescription;
use trocar_model::scene::SceneDescription;

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
    /// params, out)` (and `<module>_controller_step` and `<module>_register_port` where the
    /// module has `Kinematics`, with the controller object `<module>_controller_init`,
    /// `_update`, `_reset`) inside the module, the matching C header `<module>.h` beside
    /// `<module>.rs` ([`crate::emit::c_api`]) and, for a module with `Kinematics`, the C++
    /// header `<module>.hpp` over it ([`crate::emit::cpp_header`]). A crate built as a
    /// `staticlib` or `cdylib` then exports them. Each scene ([`Builder::scene`]) gets its C
    /// object (`<scene>_scene_init`, `_update`, ..., [`crate::emit::c_scene`]) with its arm
    /// modules' C ABIs, and the headers `<scene>.h`, `<scene>.hpp` and each arm module's.
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
            let cpp_header = self
                .c_api
                .then(|| emit::cpp_header::header(&spec, options.real))
                .flatten();
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
            record_c_symbols(
                &mut symbols,
                exported.into_iter().map(|s| (s, module.clone())),
            )?;
            if let Some(header) = header {
                out.insert(format!("{module}.h"), header);
            }
            if let Some(header) = cpp_header {
                out.insert(format!("{module}.hpp"), header);
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
            let (code, headers, exported) = if self.c_api {
                let files = crate::scene::generate_scene_c(&scene, &options)?;
                (files.code, files.headers, files.symbols)
            } else {
                let code = crate::scene::generate_scene_string(&scene, &options)?;
                (code, Vec::new(), Vec::new())
            };
            if out.insert(format!("{module}.rs"), code).is_some() {
                return Err(Error::DuplicateModule(module));
            }
            record_c_symbols(&mut symbols, exported)?;
            for (file, text) in headers {
                if out.insert(file.clone(), text).is_some() {
                    return Err(Error::DuplicateModule(file));
                }
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
