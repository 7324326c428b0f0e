//! The checks of a generated module ([`crate::Builder::checks`], `checks` in
//! `#[constrained_robot(...)]`) and its evidence ([`crate::Builder::evidence`]).
//!
//! - [`items`]: behind `#[cfg(test)]` or `#[cfg(feature = "...")]` ([`ChecksGate`]), the unit
//!   struct `Checks` and its implementations of `trocar_check::Candidate` (every catalogue
//!   function of the module, evaluated as compiled, in the module's `f32` or `f64`) and
//!   `trocar_check::GeneratedModule` (robot, scalar type, description hash, generator), so that a
//!   test reads `trocar_check::assert_matches_numeric::<arm::Checks>("robots/arm.toml", 2_000)`.
//! - [`staleness_guard`]: `DESCRIPTION_HASH` and a constant assertion that the description
//!   file(s) still hash to it, so that a module whose description changed fails to build.
//! - [`evidence_doc`]: the module documentation's section with the generation-time check.

use crate::ir::{Layout, ModuleSpec, Real};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::path::{Path, PathBuf};
use trocar_model::catalogue::Function;

/// The generator's name and version, as modules record it.
pub const GENERATOR: &str = concat!("trocar-codegen ", env!("CARGO_PKG_VERSION"));

/// When the checks of a module are compiled.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ChecksGate {
    /// `#[cfg(test)]`: in the crate's own unit tests.
    Test,
    /// `#[cfg(feature = "<name>")]`: where the crate's feature `<name>` is on (for integration
    /// tests, `tests/*.rs`, which see the library built without `cfg(test)`).
    Feature(String),
}

impl ChecksGate {
    fn attribute(&self) -> TokenStream {
        match self {
            ChecksGate::Test => quote!(#[cfg(test)]),
            ChecksGate::Feature(name) => quote!(#[cfg(feature = #name)]),
        }
    }
}

/// [`trocar_check::fnv1a`] of the files, in order, from [`trocar_check::FNV_OFFSET`]; `None`
/// when there are none.
pub fn description_hash(files: &[PathBuf]) -> std::io::Result<Option<u64>> {
    if files.is_empty() {
        return Ok(None);
    }
    let mut state = trocar_check::FNV_OFFSET;
    for f in files {
        state = trocar_check::fnv1a(state, &std::fs::read(f)?);
    }
    Ok(Some(state))
}

/// The checks of a serial robot's module (see the module documentation); `hash` is
/// [`description_hash`] of its description file(s).
pub fn items(
    spec: &ModuleSpec,
    real: Real,
    gate: &ChecksGate,
    robot: &str,
    hash: Option<u64>,
) -> TokenStream {
    let cfg = gate.attribute();
    let (params_ty, scalar) = match real {
        Real::F32 => (quote!(Params), quote!(F32)),
        Real::F64 => (quote!(Params), quote!(F64)),
        Real::Generic => (quote!(Params::<f64>), quote!(F64)),
    };
    // The inputs rounded to `f32` for an `f32` module, as they are for `f64` ones.
    let (q_init, cast) = if real == Real::F32 {
        (
            quote!(let q: [f32; N] = ::core::array::from_fn(|k| q[k] as f32);),
            quote!(as f32),
        )
    } else {
        (
            quote!(let q: [f64; N] = <[f64; N]>::try_from(q).ok()?;),
            quote!(),
        )
    };
    let p_count = Literal::usize_unsuffixed(spec.params.len());
    let params_init = if spec.params.is_empty() {
        quote!(#params_ty::nominal())
    } else {
        let fields = spec.params.iter().enumerate().map(|(k, (name, _))| {
            let id = format_ident!("{}", name);
            let k = Literal::usize_unsuffixed(k);
            quote!(#id: params[#k] #cast,)
        });
        quote!(#params_ty { #(#fields)* })
    };
    let arms = spec.functions.iter().filter_map(|f| {
        let entry = Function::from_name(&f.name)?;
        if entry.is_mechanism() {
            return None;
        }
        let name = format_ident!("{}", f.name);
        let variant = format_ident!("{}", format!("{entry:?}"));
        let call = if f.takes_joints {
            quote!(#name(&q, &p))
        } else {
            quote!(#name(&p))
        };
        let convert = match f.layout {
            Layout::Scalar => quote!(::trocar_check::from_scalar(#call)),
            Layout::Matrix { .. } => quote!(::trocar_check::from_columns(&#call)),
            Layout::Transform => quote!(::trocar_check::from_transform(&#call)),
        };
        Some(quote!(::trocar_check::Function::#variant => #convert,))
    });
    // The fused functions: each output into a zeroed out-parameter, then converted as above.
    let float = if real == Real::F32 {
        quote!(f32)
    } else {
        quote!(f64)
    };
    let fused_list = spec.fused.iter().map(|f| {
        let name = &f.name;
        let variants = f.outputs.iter().map(|o| {
            let v = format_ident!("{}", format!("{:?}", o.function));
            quote!(::trocar_check::Function::#v)
        });
        quote!(::trocar_check::Fused::new(#name, [#(#variants),*]))
    });
    let fused_arms = spec.fused.iter().map(|f| {
        let name = &f.name;
        let call = format_ident!("{}", f.name);
        let outs: Vec<_> = f
            .outputs
            .iter()
            .map(|o| format_ident!("{}", o.function.short_name()))
            .collect();
        let decls = f.outputs.iter().zip(&outs).map(|(o, id)| {
            let (ty, zero) = match o.layout {
                Layout::Scalar => (quote!(#float), quote!(0.0)),
                Layout::Transform => (
                    quote!(([[#float; 3]; 3], [#float; 3])),
                    quote!(([[0.0; 3]; 3], [0.0; 3])),
                ),
                Layout::Matrix { rows, cols } => {
                    let r = Literal::usize_unsuffixed(rows);
                    let c = Literal::usize_unsuffixed(cols);
                    (quote!([[#float; #r]; #c]), quote!([[0.0; #r]; #c]))
                }
            };
            quote!(let mut #id: #ty = #zero;)
        });
        let converts = f.outputs.iter().zip(&outs).map(|(o, id)| match o.layout {
            Layout::Scalar => quote!(::trocar_check::from_scalar(#id)),
            Layout::Matrix { .. } => quote!(::trocar_check::from_columns(&#id)),
            Layout::Transform => quote!(::trocar_check::from_transform(&#id)),
        });
        quote! {
            #name => {
                #(#decls)*
                #call(&q, &p, #(&mut #outs),*);
                ::core::iter::IntoIterator::into_iter([#(#converts),*]).collect()
            }
        }
    });
    let hash = match hash {
        Some(h) => {
            let h = hex(h);
            quote!(::core::option::Option::Some(#h))
        }
        None => quote!(::core::option::Option::None),
    };
    let doc = format!(
        " The checks of this module: `trocar_check::assert_matches_numeric::<Checks>(description, \
         samples)` compares every function of the module, as compiled (in `{}`), with the numeric \
         runtime and finite differences.",
        if real == Real::F32 { "f32" } else { "f64" }
    );
    quote! {
        #[doc = #doc]
        #cfg
        #[derive(Clone, Copy, Debug, Default)]
        pub struct Checks;

        #cfg
        impl ::trocar_check::GeneratedModule for Checks {
            const ROBOT: &'static str = #robot;
            const SCALAR: ::trocar_check::Scalar = ::trocar_check::Scalar::#scalar;
            const DESCRIPTION_HASH: ::core::option::Option<u64> = #hash;
            const GENERATOR: &'static str = #GENERATOR;
        }

        #cfg
        impl ::trocar_check::Candidate for Checks {
            fn evaluate(
                &self,
                function: ::trocar_check::Function,
                q: &[f64],
                params: &[f64],
            ) -> ::core::option::Option<::trocar_check::DMatrix<f64>> {
                if q.len() != N || params.len() != #p_count {
                    return ::core::option::Option::None;
                }
                #q_init
                let p = #params_init;
                ::core::option::Option::Some(match function {
                    #(#arms)*
                    _ => return ::core::option::Option::None,
                })
            }

            fn fused(&self) -> ::trocar_check::FusedList {
                ::core::iter::IntoIterator::into_iter([#(#fused_list),*]).collect()
            }

            fn evaluate_fused(
                &self,
                name: &str,
                q: &[f64],
                params: &[f64],
            ) -> ::core::option::Option<::trocar_check::FusedValues> {
                if q.len() != N || params.len() != #p_count {
                    return ::core::option::Option::None;
                }
                #q_init
                let p = #params_init;
                ::core::option::Option::Some(match name {
                    #(#fused_arms)*
                    _ => return ::core::option::Option::None,
                })
            }
        }
    }
}

/// A `u64` literal in hexadecimal, as hashes are written.
fn hex(x: u64) -> syn::LitInt {
    syn::LitInt::new(&format!("0x{x:016x}"), proc_macro2::Span::call_site())
}

/// How the module names a description file in `include_bytes!`: a relative path from the
/// package's root (`CARGO_MANIFEST_DIR`, the working directory of build scripts), so that the
/// module builds on any machine; an absolute one as it is.
fn include_path(path: &Path) -> TokenStream {
    let text = path.display().to_string();
    if path.is_absolute() {
        quote!(::core::include_bytes!(#text))
    } else {
        let rel = format!("/{text}");
        quote!(::core::include_bytes!(
            ::core::concat!(::core::env!("CARGO_MANIFEST_DIR"), #rel)
        ))
    }
}

/// `DESCRIPTION_HASH` and the constant assertion that `files` (the description and the URDF it
/// reads) still hash to it: a module whose description changed since it was generated fails to
/// build, naming the file.
pub fn staleness_guard(files: &[PathBuf], hash: u64) -> TokenStream {
    let h = hex(hash);
    let offset = hex(trocar_check::FNV_OFFSET);
    let reads = files.iter().map(|f| {
        let bytes = include_path(f);
        quote!(state = fnv1a(state, #bytes);)
    });
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    let message = format!(
        "{} changed since this module was generated (DESCRIPTION_HASH): regenerate the module",
        names.join(" or ")
    );
    quote! {
        /// FNV-1a (64 bits) of the description's bytes (then of the URDF it reads, if any) when
        /// the module was generated; the build fails when they no longer hash to it.
        pub const DESCRIPTION_HASH: u64 = #h;

        const _: () = {
            const fn fnv1a(mut state: u64, bytes: &[u8]) -> u64 {
                let mut k = 0;
                while k < bytes.len() {
                    state ^= bytes[k] as u64;
                    state = state.wrapping_mul(0x0000_0100_0000_01b3);
                    k += 1;
                }
                state
            }
            let mut state: u64 = #offset;
            #(#reads)*
            assert!(state == DESCRIPTION_HASH, #message);
        };
    }
}

/// The module documentation's section "Evidence": the generator, the description and its hash,
/// the seed and samples, and the table of the largest errors of `report` (every function
/// against the numeric runtime, the Jacobians against finite differences).
pub fn evidence_doc(
    report: &trocar_check::Report,
    real: Real,
    source: Option<&Path>,
    hash: Option<u64>,
) -> String {
    let mut out = String::from("\n\n# Evidence\n\n");
    let from = match (source, hash) {
        (Some(p), Some(h)) => format!(" from `{}` (description hash `{h:#018x}`)", p.display()),
        _ => String::new(),
    };
    out += &format!(
        "Checked when generated by {GENERATOR}{from}: {} random configurations and parameter \
         values (seed {}), every function evaluated operation for operation as the generated \
         `f64` code against the numeric runtime (`trocar_check`), and the Jacobians against \
         central differences of the generated poses.",
        report.samples, report.seed
    );
    if real == Real::F32 {
        out += " This module computes the same programs in `f32`, within `2e-6` of them.";
    }
    out += "\n\n| check | function | largest error | tolerance |\n|---|---|---|---|\n";
    for c in &report.checks {
        let function = c.function.map_or(String::new(), |f| format!("`{f}`"));
        out += &format!(
            "| {} | {function} | {:.1e} | {:.0e} |\n",
            c.name, c.max_error, c.tolerance
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Compiles `source` as a library with rustc (metadata only); the compiler's messages on
    /// failure.
    fn compiles(dir: &Path, source: &str) -> Result<(), String> {
        let file = dir.join("guard.rs");
        std::fs::write(&file, source).unwrap();
        let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
        let out = std::process::Command::new(rustc)
            .args([
                "--crate-type=lib",
                "--emit=metadata",
                "--edition=2021",
                "--out-dir",
            ])
            .arg(dir)
            .arg(&file)
            .output()
            .unwrap();
        if out.status.success() {
            Ok(())
        } else {
            Err(String::from_utf8_lossy(&out.stderr).into_owned())
        }
    }

    #[test]
    fn the_guard_builds_with_its_description_and_fails_once_it_changes() {
        let dir = std::env::temp_dir().join(format!("trocar-guard-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let description = dir.join("arm.toml");
        std::fs::write(&description, "[robot]\nname = \"arm\"\n").unwrap();
        let files = vec![description.clone()];
        let hash = description_hash(&files).unwrap().unwrap();
        let source = staleness_guard(&files, hash).to_string();
        assert_eq!(compiles(&dir, &source), Ok(()));
        std::fs::write(&description, "[robot]\nname = \"arm2\"\n").unwrap();
        let err = compiles(&dir, &source).unwrap_err();
        assert!(
            err.contains("changed since this module was generated") && err.contains("arm.toml"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn the_hash_is_fnv1a_of_the_files_in_order() {
        let dir = std::env::temp_dir().join(format!("trocar-hash-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a"), dir.join("b"));
        std::fs::write(&a, "fo").unwrap();
        std::fs::write(&b, "obar").unwrap();
        // FNV-1a 64 of "foobar" (Fowler, Noll, Vo's test vectors).
        assert_eq!(
            description_hash(&[a, b]).unwrap(),
            Some(0x8594_4171_f739_67e8)
        );
        assert_eq!(description_hash(&[]).unwrap(), None);
        std::fs::remove_dir_all(&dir).ok();
    }
}
