//! One generated module of one description: its options ([`ModuleOptions`]), its derivation and
//! the tokens and formatted text of its module, C header, or closed mechanism's module. The
//! [`crate::Builder`], the scene generator ([`crate::scene`]), the attribute and the command line
//! all go through here.

use crate::closed_chain;
use crate::derivation;
use crate::emit::checks::{self, ChecksGate};
use crate::emit::{self, Runtime};
use crate::error::Error;
use crate::ir::{ModuleSpec, Real};
use crate::lower;
use crate::naming::checked_module_name;
use proc_macro2::TokenStream;
use std::path::PathBuf;
use trocar_model::catalogue::Fused;
use trocar_model::closed_chain::MechanismModel;
use trocar_model::description::{DescriptionError, RobotDescription};

/// Options of one generated module.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ModuleOptions {
    /// Real type of the generated code.
    pub real: Real,
    /// Module name; default: the robot's name, snake-cased ([`crate::module_name`]).
    pub module_name: Option<String>,
    /// The path through which the generated code names the runtime crate `trocar`; default
    /// `::trocar` (see [`crate::Builder::runtime_path`]).
    pub runtime_path: Option<String>,
    /// Also emit the module's C ABI (`extern "C"` functions named `<module>_<function>`,
    /// [`crate::emit::c_api`]); see [`crate::Builder::c_api`].
    pub c_api: bool,
    /// Also emit `Checks`, the module's implementation of `trocar_check::GeneratedModule`, behind
    /// this gate ([`crate::emit::checks`]); see [`crate::Builder::checks`].
    pub checks: Option<ChecksGate>,
    /// Check the module at generation time at this many random configurations and write the
    /// largest errors into its documentation, with `DESCRIPTION_HASH` and its build-time
    /// assertion; see [`crate::Builder::evidence`].
    pub evidence: Option<usize>,
    /// Fused functions besides the defaults ([`crate::Builder::function`]): each one function computing
    /// several catalogue outputs in one program.
    pub functions: Vec<Fused>,
    /// Also emit each fused function's `f64` entry points with fused multiply-adds chosen at run
    /// time (`<name>_f64`, `<name>_trig_f64`); see [`crate::Builder::fma_at_run_time`].
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
/// Records the C symbols of one build, `(symbol, the module exporting it)`, in `seen`:
/// [`Error::CSymbolClash`] naming both modules where a symbol is already there (modules `arm` and
/// `arm_link`: `arm_link_pose_and_jacobian`).
pub(crate) fn record_c_symbols(
    seen: &mut std::collections::BTreeMap<String, String>,
    exported: impl IntoIterator<Item = (String, String)>,
) -> Result<(), Error> {
    for (symbol, module) in exported {
        if let Some(first) = seen.insert(symbol.clone(), module.clone()) {
            return Err(Error::CSymbolClash {
                symbol,
                modules: (first, module),
            });
        }
    }
    Ok(())
}

/// Rust items: a fused name that starts with `<module>_` (it could be another C function's Rust
/// name) or is the C ABI's helper `c_params` would clash; and the header's macros must be
/// distinct ([`emit::c_api::check_names`]).
pub(crate) fn c_api_names(spec: &ModuleSpec) -> Result<(), Error> {
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

/// The C++ header over a description's C ABI ([`crate::emit::cpp_header`]): `None` for a
/// module without a controller (a constraint frame that slides along its link), whose C header
/// alone serves. Fails as [`generate_c_header`] does.
pub fn generate_cpp_header(
    desc: &RobotDescription,
    options: &ModuleOptions,
) -> Result<Option<String>, Error> {
    let spec = spec_for(desc, options)?;
    c_api_names(&spec)?;
    Ok(emit::cpp_header::header(&spec, options.real))
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
pub(crate) fn module_string(
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
