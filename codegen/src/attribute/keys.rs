//! The attribute's top-level keys.

use super::errors::Errors;
use crate::emit::checks::ChecksGate;
use crate::ir::Real;
use proc_macro2::{Span, TokenStream};
use syn::parse::Parser;
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Expr, ExprLit, Lit, LitStr, Meta, MetaList, Token};
use trocar_model::catalogue::{Function, Fused};

/// Every key the attribute accepts (for "unknown key" messages).
pub(crate) const KEYS: &str = "preset, file, toml, scene, real, module, checks, function, \
     fma_at_run_time, name, params, joints, end_effector, constraint";

/// Where the description comes from.
pub(crate) enum Source {
    Preset(LitStr),
    File(LitStr),
    Toml(LitStr),
    /// A scene file, or a shipped scene's name.
    Scene(LitStr),
    /// The structured form: the lists, by key.
    Inline(Box<InlineLists>),
}

/// The lists of the structured inline form.
#[derive(Default)]
pub(crate) struct InlineLists {
    pub name: Option<LitStr>,
    pub params: Option<MetaList>,
    pub joints: Option<MetaList>,
    pub end_effector: Option<MetaList>,
    pub constraint: Option<MetaList>,
    /// The first inline key, for errors about the whole description.
    pub first: Option<Span>,
}

/// The parsed attribute.
pub(crate) struct Attr {
    pub source: Source,
    pub real: Real,
    pub module: Option<syn::Ident>,
    /// `checks` (behind `#[cfg(test)]`) or `checks = "feature"`.
    pub checks: Option<ChecksGate>,
    /// `function(name(output, ...), ...)`: fused functions, each with the span of its name.
    pub functions: Vec<(Fused, Span)>,
    /// `fma_at_run_time`: the fused functions' `f64` entry points with FMA chosen at run time;
    /// the key's span.
    pub fma_at_run_time: Option<Span>,
}

/// The fused functions of one `function(name(output, ...), ...)` key, each with the span of its
/// name; errors are collected.
fn functions(list: &MetaList, errors: &mut Errors) -> Vec<(Fused, Span)> {
    let Some(items) =
        errors.ok(list.parse_args_with(Punctuated::<Meta, Token![,]>::parse_terminated))
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for item in &items {
        let (Meta::List(l), Some(name)) = (item, item.path().get_ident()) else {
            errors.at(
                item.span(),
                "expected `name(output, ...)`, e.g. `function(pose_and_jacobian(fk, jb0e))`",
            );
            continue;
        };
        if let Err(e) = Fused::check_name(&name.to_string()) {
            errors.at(name.span(), format_args!("function `{name}`: {e}"));
            continue;
        }
        let Some(names) =
            errors.ok(l.parse_args_with(Punctuated::<syn::Ident, Token![,]>::parse_terminated))
        else {
            continue;
        };
        let mut outputs = Vec::new();
        for n in &names {
            match Function::resolve(&n.to_string(), false) {
                Some(f) => outputs.push(f),
                None => errors.at(
                    n.span(),
                    format_args!(
                        "function `{name}`: unknown output `{n}` (expected one of: {})",
                        Function::SERIAL
                            .iter()
                            .map(|f| format!("{} ({})", f.name(), f.short_name()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ),
            }
        }
        out.push((Fused::new(name.to_string(), outputs), name.span()));
    }
    out
}

/// The key of `meta` (`file` in `file = "..."`), empty for a path that is not one identifier.
fn key(meta: &Meta) -> String {
    meta.path()
        .get_ident()
        .map(|i| i.to_string())
        .unwrap_or_default()
}

fn string(meta: &Meta, errors: &mut Errors) -> Option<LitStr> {
    match meta {
        Meta::NameValue(nv) => match &nv.value {
            Expr::Lit(ExprLit {
                lit: Lit::Str(s), ..
            }) => Some(s.clone()),
            other => {
                errors.at(
                    other.span(),
                    format_args!("`{}` takes a string literal", key(meta)),
                );
                None
            }
        },
        _ => {
            errors.at(
                meta.span(),
                format_args!("expected `{} = \"...\"`", key(meta)),
            );
            None
        }
    }
}

fn list(meta: &Meta, errors: &mut Errors) -> Option<MetaList> {
    match meta {
        Meta::List(l) => Some(l.clone()),
        _ => {
            errors.at(meta.span(), format_args!("expected `{}(...)`", key(meta)));
            None
        }
    }
}

/// Parses the attribute's arguments; errors are collected.
pub(crate) fn parse(tokens: TokenStream) -> syn::Result<Attr> {
    let metas = Punctuated::<Meta, Token![,]>::parse_terminated.parse2(tokens)?;
    let mut errors = Errors::default();
    let mut source: Option<(String, Span, Source)> = None;
    let mut inline = InlineLists::default();
    let mut real = Real::Generic;
    let mut module = None;
    let mut checks = None;
    let mut fused = Vec::new();
    let mut fma_at_run_time = None;

    fn set_source(
        source: &mut Option<(String, Span, Source)>,
        errors: &mut Errors,
        key: &str,
        span: Span,
        s: Source,
    ) {
        if let Some((prev, _, _)) = source {
            errors.at(
                span,
                format_args!(
                    "`{key}` conflicts with `{prev}`: give exactly one description source \
                     (preset, file, toml, scene, or the inline joints(...))"
                ),
            );
        } else {
            *source = Some((key.to_string(), span, s));
        }
    }

    for meta in &metas {
        let Some(ident) = meta.path().get_ident() else {
            errors.at(
                meta.path().span(),
                format_args!("unknown key (expected one of: {KEYS})"),
            );
            continue;
        };
        let key = ident.to_string();
        let span = ident.span();
        match key.as_str() {
            "preset" => {
                if let Some(s) = string(meta, &mut errors) {
                    set_source(&mut source, &mut errors, &key, span, Source::Preset(s));
                }
            }
            "file" => {
                if let Some(s) = string(meta, &mut errors) {
                    set_source(&mut source, &mut errors, &key, span, Source::File(s));
                }
            }
            "toml" => {
                if let Some(s) = string(meta, &mut errors) {
                    set_source(&mut source, &mut errors, &key, span, Source::Toml(s));
                }
            }
            "scene" => {
                if let Some(s) = string(meta, &mut errors) {
                    set_source(&mut source, &mut errors, &key, span, Source::Scene(s));
                }
            }
            "real" => {
                if let Some(s) = string(meta, &mut errors) {
                    match s.value().as_str() {
                        "f32" => real = Real::F32,
                        "f64" => real = Real::F64,
                        "generic" => real = Real::Generic,
                        other => errors.at(
                            s.span(),
                            format_args!(
                                "unknown real type `{other}` (expected \"f32\", \"f64\" or \"generic\")"
                            ),
                        ),
                    }
                }
            }
            "module" => {
                if let Some(s) = string(meta, &mut errors) {
                    match syn::parse_str::<syn::Ident>(&s.value()) {
                        Ok(id) => module = Some(syn::Ident::new(&id.to_string(), s.span())),
                        Err(_) => errors.at(
                            s.span(),
                            format_args!("`{}` is not a valid module name", s.value()),
                        ),
                    }
                }
            }
            "checks" => match meta {
                Meta::Path(_) => checks = Some(ChecksGate::Test),
                _ => {
                    if let Some(s) = string(meta, &mut errors) {
                        checks = Some(ChecksGate::Feature(s.value()));
                    }
                }
            },
            "function" => {
                if let Some(l) = list(meta, &mut errors) {
                    fused.extend(functions(&l, &mut errors));
                }
            }
            "fma_at_run_time" => match meta {
                Meta::Path(_) => fma_at_run_time = Some(span),
                _ => errors.at(
                    meta.span(),
                    "`fma_at_run_time` takes no value: write `fma_at_run_time` alone",
                ),
            },
            "name" | "params" | "joints" | "end_effector" | "constraint" => {
                inline.first.get_or_insert(span);
                match key.as_str() {
                    "name" => inline.name = string(meta, &mut errors),
                    "params" => inline.params = list(meta, &mut errors),
                    "joints" => inline.joints = list(meta, &mut errors),
                    "end_effector" => inline.end_effector = list(meta, &mut errors),
                    _ => inline.constraint = list(meta, &mut errors),
                }
            }
            _ => errors.at(
                span,
                format_args!("unknown key `{key}` (expected one of: {KEYS})"),
            ),
        }
    }

    if let Some(first) = inline.first {
        if inline.joints.is_none() && source.is_none() {
            errors.at(
                first,
                "the inline description needs `joints(...)` (or use preset, file or toml)",
            );
        } else {
            let key = if inline.joints.is_some() {
                "joints"
            } else {
                "name/params/end_effector/constraint"
            };
            set_source(
                &mut source,
                &mut errors,
                key,
                first,
                Source::Inline(Box::new(inline)),
            );
        }
    }
    let source = match source {
        Some((_, _, s)) => Some(s),
        None => {
            if errors.is_empty() {
                errors.at(
                    Span::call_site(),
                    "missing description: write `preset = \"...\"`, `file = \"...\"`, \
                     `toml = \"...\"` or an inline `joints(...)`",
                );
            }
            None
        }
    };
    errors.finish()?;
    Ok(Attr {
        source: source.expect("checked above"),
        real,
        module,
        checks,
        functions: fused,
        fma_at_run_time,
    })
}
