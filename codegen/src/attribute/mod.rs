//! The attribute `#[constrained_robot(...)]` of the `trocar-derive` crate, on
//! [`proc_macro2`] tokens: the derive crate is one call to [`expand`] (as `pest_derive` calls
//! `pest_generator`).
//!
//! [`expand`] parses the attribute's keys (one description source: `preset = "..."`,
//! `file = "..."`, `toml = "..."` or the structured inline form `params(..)`, `joints(..)`,
//! `end_effector(..)`, `constraint(..)`; options `real`, `module`, `name`), loads and validates the
//! description, generates its module ([`crate::generate_module`]) and puts it next to the unit
//! struct, whose associated functions delegate to the module's functions. The grammar is
//! documented on `trocar_derive::constrained_robot`.
//!
//! Every problem is a `compile_error!` at the offending token, several at once; the `file` form
//! expands to `include_bytes!` of the description so that editing it rebuilds the calling crate.

mod errors;
mod inline;
mod keys;

use self::keys::Source;
use crate::module::{generate_module, ModuleOptions};
use crate::naming::module_name;
use proc_macro2::{Span, TokenStream};
use quote::{format_ident, quote};
use std::path::PathBuf;
use syn::{Fields, Ident, Item, ItemStruct, LitStr};
use trocar_model::description::{preset_names, RobotDescription};

/// The expansion of `#[constrained_robot(attr)] item`: the struct, the generated module, the
/// delegating `impl` and type aliases, or `compile_error!`s at the offending tokens.
pub fn expand(attr: TokenStream, item: TokenStream) -> TokenStream {
    try_expand(attr, item).unwrap_or_else(syn::Error::into_compile_error)
}

/// The expansion, or the (combined) errors.
fn try_expand(attr: TokenStream, item: TokenStream) -> syn::Result<TokenStream> {
    let strukt: ItemStruct = syn::parse2(item).map_err(|e| {
        syn::Error::new(
            e.span(),
            "#[constrained_robot] applies to a unit struct, e.g. `pub struct Arm;`",
        )
    })?;
    let attr = keys::parse(attr);
    let shape = match (&strukt.fields, strukt.generics.params.is_empty()) {
        (Fields::Unit, true) => Ok(()),
        (Fields::Unit, false) => Err(syn::Error::new_spanned(
            &strukt.generics,
            "#[constrained_robot] applies to a unit struct without generic parameters",
        )),
        (fields, _) => Err(syn::Error::new_spanned(
            fields,
            "#[constrained_robot] applies to a unit struct (`struct Arm;`): the generated \
             functions are associated functions and need no fields",
        )),
    };
    let attr = match (attr, shape) {
        (Ok(a), Ok(())) => a,
        (Err(mut a), Err(s)) => {
            a.combine(s);
            return Err(a);
        }
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };

    let ident = &strukt.ident;
    if let Source::Scene(lit) = &attr.source {
        return expand_scene(&strukt, &attr, lit);
    }
    let (desc, tracked, source_span) = load(&attr.source, &ident.to_string())?;

    let module = attr.module.clone().unwrap_or_else(|| {
        let mut m = module_name(&ident.to_string());
        if *ident == m {
            m.push_str("_kinematics");
        }
        Ident::new(&m, ident.span())
    });
    let options = ModuleOptions {
        real: attr.real,
        module_name: Some(module.to_string()),
        checks: attr.checks.clone(),
        functions: attr.functions.iter().map(|(f, _)| f.clone()).collect(),
        fma_at_run_time: attr.fma_at_run_time.is_some(),
        description_files: tracked
            .as_ref()
            .map(RobotDescription::files_read)
            .unwrap_or_default(),
        ..ModuleOptions::default()
    };
    let tokens = generate_module(&desc, &options).map_err(|e| {
        // A fused function's problem at its name, anything else at the description.
        let span = match &e {
            crate::Error::Function { name, .. } => attr
                .functions
                .iter()
                .find(|(f, _)| f.name == *name)
                .map_or(source_span, |(_, s)| *s),
            crate::Error::FmaNeedsGeneric(_) => attr.fma_at_run_time.unwrap_or(source_span),
            _ => source_span,
        };
        syn::Error::new(span, format_args!("trocar-codegen: {e}"))
    })?;
    let mut module_item: syn::ItemMod = syn::parse2(tokens).map_err(|e| {
        syn::Error::new(
            source_span,
            format_args!("trocar-codegen produced tokens that do not parse (a bug): {e}"),
        )
    })?;
    module_item.vis = strukt.vis.clone();
    // The generated tokens carry the attribute's span; when the attribute spans several lines,
    // clippy's line-based heuristic reads `[a, -b]` in the generated arrays as a missing comma.
    module_item
        .attrs
        .push(syn::parse_quote!(#[allow(clippy::possible_missing_comma)]));
    module_item.ident = module.clone();

    let impl_and_aliases = delegates(&strukt, &module_item)?;
    // The description file and the URDF its chain may come from.
    let tracked: Vec<TokenStream> = tracked
        .map(RobotDescription::files_read)
        .unwrap_or_default()
        .into_iter()
        .map(|path| {
            let path = std::fs::canonicalize(&path).unwrap_or(path);
            let lit = LitStr::new(&path.display().to_string(), source_span);
            quote! {
                // Rebuild when the description file changes.
                const _: &[u8] = ::core::include_bytes!(#lit);
            }
        })
        .collect();
    Ok(quote! {
        #strukt
        #module_item
        #impl_and_aliases
        #(#tracked)*
    })
}

/// `#[constrained_robot(scene = "…")] struct S;`: the struct and the scene's module
/// ([`crate::scene`]) beside it, named after the struct (snake case) or `module`; the scene file
/// (relative to the calling crate's `CARGO_MANIFEST_DIR`, else a shipped scene's name) and its
/// arms' descriptions tracked.
fn expand_scene(strukt: &ItemStruct, attr: &keys::Attr, lit: &LitStr) -> syn::Result<TokenStream> {
    use trocar_model::scene::{shipped_scene_names, SceneDescription};
    if attr.checks.is_some() || !attr.functions.is_empty() || attr.fma_at_run_time.is_some() {
        return Err(syn::Error::new(
            lit.span(),
            "`checks`, `function` and `fma_at_run_time` apply to one robot: a scene's module has \
             its arms' closed forms and its step",
        ));
    }
    let base = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_default();
    let path = base.join(lit.value());
    let (scene, tracked) = if path.is_file() {
        let path = std::fs::canonicalize(&path).unwrap_or(path);
        let scene = SceneDescription::from_toml_file(&path)
            .map_err(|e| syn::Error::new(lit.span(), format_args!("invalid scene: {e}")))?;
        (scene, SceneDescription::files_read(&path))
    } else if shipped_scene_names().any(|n| n == lit.value()) {
        let scene = SceneDescription::shipped(&lit.value())
            .map_err(|e| syn::Error::new(lit.span(), format_args!("invalid scene: {e}")))?;
        (scene, Vec::new())
    } else {
        return Err(syn::Error::new(
            lit.span(),
            format_args!(
                "no scene file `{}` (resolved to `{}`, relative to the calling crate's \
                 CARGO_MANIFEST_DIR) and no shipped scene of that name ({})",
                lit.value(),
                path.display(),
                shipped_scene_names().collect::<Vec<_>>().join(", ")
            ),
        ));
    };
    let ident = &strukt.ident;
    let module = attr.module.clone().unwrap_or_else(|| {
        let mut m = module_name(&ident.to_string());
        if *ident == m {
            m.push_str("_scene");
        }
        Ident::new(&m, ident.span())
    });
    let options = ModuleOptions {
        real: attr.real,
        module_name: Some(module.to_string()),
        ..ModuleOptions::default()
    };
    let tokens = crate::scene::generate_scene(&scene, &options)
        .map_err(|e| syn::Error::new(lit.span(), format_args!("trocar-codegen: {e}")))?;
    let mut module_item: syn::ItemMod = syn::parse2(tokens).map_err(|e| {
        syn::Error::new(
            lit.span(),
            format_args!("trocar-codegen produced tokens that do not parse (a bug): {e}"),
        )
    })?;
    module_item.vis = strukt.vis.clone();
    module_item
        .attrs
        .push(syn::parse_quote!(#[allow(clippy::possible_missing_comma)]));
    let tracked = tracked.into_iter().map(|path| {
        let path = std::fs::canonicalize(&path).unwrap_or(path);
        let lit = LitStr::new(&path.display().to_string(), lit.span());
        quote! {
            // Rebuild when the scene or an arm's description changes.
            const _: &[u8] = ::core::include_bytes!(#lit);
        }
    });
    Ok(quote! {
        #strukt
        #module_item
        #(#tracked)*
    })
}

/// The description, the file to track (if any) and the span of the source key.
fn load(
    source: &Source,
    default_name: &str,
) -> syn::Result<(RobotDescription, Option<PathBuf>, Span)> {
    match source {
        Source::Preset(lit) => {
            let name = lit.value();
            if trocar_model::description::preset(&name).is_none() {
                return Err(syn::Error::new(
                    lit.span(),
                    format_args!(
                        "unknown preset `{name}`; the presets are: {}",
                        preset_names().collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
            let d = RobotDescription::preset(&name).map_err(|e| {
                syn::Error::new(lit.span(), format_args!("invalid preset description: {e}"))
            })?;
            Ok((d, None, lit.span()))
        }
        Source::File(lit) => {
            let base = std::env::var_os("CARGO_MANIFEST_DIR")
                .map(PathBuf::from)
                .unwrap_or_default();
            let path = base.join(lit.value());
            if let Err(e) = std::fs::metadata(&path) {
                return Err(syn::Error::new(
                    lit.span(),
                    format_args!(
                        "cannot read the description `{}`: resolved to `{}` (relative to the \
                         calling crate's CARGO_MANIFEST_DIR): {e}",
                        lit.value(),
                        path.display()
                    ),
                ));
            }
            // Canonical when it exists: messages and `include_bytes!` get a clean absolute path.
            let path = std::fs::canonicalize(&path).unwrap_or(path);
            let d = RobotDescription::from_toml_file(&path).map_err(|e| {
                syn::Error::new(lit.span(), format_args!("invalid robot description: {e}"))
            })?;
            Ok((d, Some(path), lit.span()))
        }
        Source::Toml(lit) => {
            let d = RobotDescription::from_toml_str(&lit.value(), None).map_err(|e| {
                syn::Error::new(
                    lit.span(),
                    format_args!("invalid robot description (line:column within the string): {e}"),
                )
            })?;
            Ok((d, None, lit.span()))
        }
        Source::Scene(lit) => Err(syn::Error::new(
            lit.span(),
            "a scene is expanded on its own (a bug: it reached the robot's loader)",
        )),
        Source::Inline(lists) => {
            let d = inline::build(lists, default_name)?;
            Ok((d, None, lists.first.unwrap_or_else(Span::call_site)))
        }
    }
}

/// First paragraph of the doc comments, intra-doc links turned into plain code.
fn summary(attrs: &[syn::Attribute]) -> String {
    let mut out = String::new();
    for a in attrs {
        if !a.path().is_ident("doc") {
            continue;
        }
        if let syn::Meta::NameValue(nv) = &a.meta {
            if let syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
            {
                let line = s.value();
                if line.trim().is_empty() {
                    if out.is_empty() {
                        continue;
                    }
                    break;
                }
                out.push_str(line.trim());
                out.push(' ');
            }
        }
    }
    out.replace("[`", "`").replace("`]", "`").trim().to_string()
}

/// The type aliases (`ArmParams`, ...) and the `impl` of the struct delegating to the module.
///
/// The associated functions keep the module functions' signatures as written there (`&[T; N]`,
/// `&Params<T>`), so the `impl` is written in an anonymous constant that imports the module's
/// types and constants. The struct cannot be named like one of those items when a signature
/// uses it (`struct Params;`): the import would shadow it.
/// Whether a module item is compiled only under a `#[cfg(...)]` (the module's `Checks`): the
/// struct gets no alias or delegate for it.
fn is_gated(item: &Item) -> bool {
    let attrs = match item {
        Item::Struct(s) => &s.attrs,
        Item::Const(c) => &c.attrs,
        Item::Fn(f) => &f.attrs,
        Item::Impl(i) => &i.attrs,
        _ => return false,
    };
    attrs.iter().any(|a| a.path().is_ident("cfg"))
}

fn delegates(strukt: &ItemStruct, module: &syn::ItemMod) -> syn::Result<TokenStream> {
    let ident = &strukt.ident;
    let vis = &strukt.vis;
    let m = &module.ident;
    let items: &[Item] = module.content.as_ref().map_or(&[], |(_, i)| i);
    // The names the signatures and constant types take from the module. A module item named
    // like the struct is left out, so that `impl #ident` still names the struct.
    let (named_like_struct, imported): (Vec<&Ident>, Vec<&Ident>) = items
        .iter()
        .filter(|i| !is_gated(i))
        .filter_map(|i| match i {
            Item::Struct(s) => Some(&s.ident),
            Item::Type(t) => Some(&t.ident),
            Item::Const(c) => Some(&c.ident),
            _ => None,
        })
        .partition(|name| *name == ident);
    let mut assoc = Vec::new();
    let mut aliases = Vec::new();
    let mut signatures = Vec::new();
    for item in items.iter().filter(|i| !is_gated(i)) {
        match item {
            Item::Const(c) => {
                let ty = &c.ty;
                signatures.push(quote!(#ty));
                let name = &c.ident;
                let doc = format!("{} (`{m}::{name}`)", summary(&c.attrs));
                assoc.push(quote! { #[doc = #doc] pub const #name: #ty = #m::#name; });
            }
            Item::Struct(s) => {
                let alias = format_ident!("{}{}", ident, s.ident);
                let name = &s.ident;
                let params: Vec<_> = s.generics.type_params().map(|p| &p.ident).collect();
                let doc = format!("`{m}::{name}`: {}", summary(&s.attrs));
                let generics = if params.is_empty() {
                    quote!()
                } else {
                    quote!(<#(#params),*>)
                };
                aliases.push(quote! {
                    #[doc = #doc]
                    #vis type #alias #generics = #m::#name #generics;
                });
            }
            Item::Fn(f) if matches!(f.vis, syn::Visibility::Public(_)) => {
                let sig = &f.sig;
                signatures.push(quote!(#sig));
                let name = &sig.ident;
                let args = sig.inputs.iter().filter_map(|a| match a {
                    syn::FnArg::Typed(t) => Some(&t.pat),
                    syn::FnArg::Receiver(_) => None,
                });
                let doc = format!("{}\n\nDelegates to `{m}::{name}`.", summary(&f.attrs));
                // A function that writes through out-parameters returns nothing to use.
                let returns = match &sig.output {
                    syn::ReturnType::Default => false,
                    syn::ReturnType::Type(_, ty) => {
                        !matches!(&**ty, syn::Type::Tuple(t) if t.elems.is_empty())
                    }
                };
                let must_use = returns.then(|| quote!(#[must_use]));
                assoc.push(quote! {
                    #[doc = #doc]
                    #[inline]
                    #must_use
                    pub #sig { #m::#name(#(#args),*) }
                });
            }
            _ => {}
        }
    }
    if !named_like_struct.is_empty() && signatures.into_iter().any(|t| mentions(t, ident)) {
        return Err(syn::Error::new(
            ident.span(),
            format_args!(
                "the generated module `{m}` has an item named `{ident}` that the associated \
                 functions use; rename the struct"
            ),
        ));
    }
    let params_alias = format_ident!("{}Params", ident);
    let params_ty: Option<&syn::ItemStruct> = items.iter().find_map(|i| match i {
        Item::Struct(s) if s.ident == "Params" => Some(s),
        _ => None,
    });
    let nominal = match params_ty {
        Some(s) if s.generics.type_params().next().is_some() => quote! {
            /// The description's nominal parameter values (`Params::nominal()`).
            #[inline]
            #[must_use]
            pub fn nominal_params<T: ::trocar::emitted::Real>() -> #params_alias<T> {
                #m::Params::nominal()
            }
        },
        Some(_) => quote! {
            /// The description's nominal parameter values (`Params::nominal()`).
            #[inline]
            #[must_use]
            pub fn nominal_params() -> #params_alias {
                #m::Params::nominal()
            }
        },
        None => quote!(),
    };
    Ok(quote! {
        #(#aliases)*
        const _: () = {
            #[allow(unused_imports)]
            use #m::{#(#imported),*};
            #[allow(dead_code)]
            impl #ident {
                #(#assoc)*
                #nominal
            }
        };
    })
}

/// Whether `tokens` contain the identifier `name`.
fn mentions(tokens: TokenStream, name: &Ident) -> bool {
    tokens.into_iter().any(|t| match t {
        proc_macro2::TokenTree::Ident(i) => i == *name,
        proc_macro2::TokenTree::Group(g) => mentions(g.stream(), name),
        _ => false,
    })
}

#[cfg(test)]
mod tests {
    use quote::quote;

    /// The file form puts `include_bytes!` of the canonical path in the expansion: rustc records
    /// the file in its dep-info, so editing it rebuilds the calling crate.
    #[test]
    fn file_form_tracks_the_description_file() {
        let out = super::try_expand(
            quote!(file = "../derive/tests/ui/robots/arm.toml", real = "f32"),
            quote!(
                pub struct Arm;
            ),
        )
        .expect("valid description")
        .to_string();
        let path = std::fs::canonicalize(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../derive/tests/ui/robots/arm.toml"),
        )
        .unwrap();
        let lit = format!("{:?}", path.display().to_string());
        assert!(out.contains("include_bytes"), "{out}");
        assert!(out.contains(&lit), "no {lit} in the expansion");
        assert!(out.contains("impl Arm"));
        assert!(out.contains("pub type ArmParams"));
    }

    /// A description whose chain comes from a URDF: both files are tracked, and the module has
    /// the task functions.
    #[test]
    fn file_form_tracks_the_urdf_too() {
        let out = super::try_expand(
            quote!(file = "../runtime/model/robots/panda-laparoscope.toml"),
            quote!(
                pub struct Panda;
            ),
        )
        .expect("valid description")
        .to_string();
        let urdf = std::fs::canonicalize(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../runtime/model/robots/urdf/panda.urdf"),
        )
        .unwrap();
        let lit = format!("{:?}", urdf.display().to_string());
        assert!(out.contains(&lit), "no {lit} in the expansion");
        assert_eq!(out.matches("include_bytes").count(), 2);
        assert!(out.contains("constrained_task_jacobian"));
    }

    #[test]
    fn presets_are_not_tracked_and_errors_are_collected() {
        let out = super::try_expand(
            quote!(preset = "unidirectional"),
            quote!(
                struct Uni;
            ),
        )
        .unwrap()
        .to_string();
        assert!(!out.contains("include_bytes"));
        let e = super::try_expand(
            quote!(foo = 1, real = "f16"),
            quote!(
                struct A;
            ),
        )
        .unwrap_err();
        assert_eq!(e.into_iter().count(), 2);
    }
}
