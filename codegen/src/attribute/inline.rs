//! The structured inline form: `params(..)`, `joints(..)`, `end_effector(..)`, `constraint(..)`
//! → a [`RobotDescription`], with the span of every field so the description's own validation
//! errors land on the right token.

use super::errors::Errors;
use super::keys::InlineLists;
use proc_macro2::Span;
use quote::ToTokens;
use syn::parse::{Parse, ParseStream, Parser};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Expr, Ident, Meta, MetaList, Token};
use trocar_model::description::{
    ConstraintDesc, DescriptionError, EndEffector, JointDesc, JointKind, Linear, Origin, Parameter,
    RobotDescription, Rotation, Wrist,
};

/// Field path (as in the description's errors: `joints[3].axis`) → span.
#[derive(Default)]
pub(crate) struct Spans(Vec<(String, Span)>);

impl Spans {
    fn add(&mut self, field: impl Into<String>, span: Span) {
        self.0.push((field.into(), span));
    }

    /// The span of `field`, or of its deepest recorded prefix.
    pub(crate) fn find(&self, field: &str) -> Option<Span> {
        let mut f = field;
        loop {
            if let Some((_, s)) = self.0.iter().rev().find(|(k, _)| k == f) {
                return Some(*s);
            }
            let cut = f.rfind(['.', '['])?;
            f = &f[..cut];
        }
    }
}

/// One joint: `name: kind(args)` or `kind(args)`.
struct JointItem {
    name: Option<Ident>,
    kind: Ident,
    args: Punctuated<Meta, Token![,]>,
}

impl Parse for JointItem {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name = if input.peek(Ident) && input.peek2(Token![:]) && !input.peek2(Token![::]) {
            let n: Ident = input.parse()?;
            input.parse::<Token![:]>()?;
            Some(n)
        } else {
            None
        };
        let kind: Ident = input.parse()?;
        let content;
        syn::parenthesized!(content in input);
        let args = Punctuated::parse_terminated(&content)?;
        Ok(JointItem { name, kind, args })
    }
}

fn key_of(meta: &Meta) -> (String, Span) {
    let p = meta.path();
    (
        p.get_ident()
            .map(|i| i.to_string())
            .unwrap_or_else(|| p.to_token_stream().to_string()),
        p.span(),
    )
}

fn value_of<'a>(meta: &'a Meta, errors: &mut Errors) -> Option<&'a Expr> {
    match meta {
        Meta::NameValue(nv) => Some(&nv.value),
        _ => {
            let (k, _) = key_of(meta);
            errors.at(meta.span(), format_args!("expected `{k} = ...`"));
            None
        }
    }
}

fn text(e: &Expr) -> String {
    e.to_token_stream().to_string()
}

/// The one parser of lengths written in the attribute: the text of an expression (tokens printed
/// with spaces, e.g. `l_a + l_b`, `- 0.5 * l_8`) → a [`Linear`].
fn parse_length(text: &str) -> Result<Linear, String> {
    Linear::parse(text)
}

/// A length: a number, a parameter name or a linear combination (`l_a + l_b`, `-0.5 * l_8`).
fn scalar(e: &Expr) -> syn::Result<Linear> {
    parse_length(&text(e)).map_err(|m| {
        syn::Error::new(
            e.span(),
            format_args!("expected a number, a parameter or a linear combination: {m}"),
        )
    })
}

fn number(e: &Expr) -> syn::Result<f64> {
    match parse_length(&text(e)) {
        Ok(s) if s.is_constant() => Ok(s.constant),
        _ => Err(syn::Error::new(
            e.span(),
            format_args!("expected a number, found `{}`", text(e)),
        )),
    }
}

fn elements(e: &Expr) -> Option<Vec<&Expr>> {
    match e {
        Expr::Tuple(t) => Some(t.elems.iter().collect()),
        Expr::Array(a) => Some(a.elems.iter().collect()),
        Expr::Paren(p) => Some(vec![&*p.expr]),
        _ => None,
    }
}

fn triple<T: Default + Clone>(
    e: &Expr,
    field: &str,
    spans: &mut Spans,
    each: impl Fn(&Expr) -> syn::Result<T>,
) -> syn::Result<[T; 3]> {
    let elems = elements(e)
        .filter(|v| v.len() == 3)
        .ok_or_else(|| syn::Error::new(e.span(), "expected three values `(x, y, z)`"))?;
    let mut out: [T; 3] = Default::default();
    for (k, x) in elems.into_iter().enumerate() {
        spans.add(format!("{field}[{k}]"), x.span());
        out[k] = each(x)?;
    }
    Ok(out)
}

/// An axis: `x`, `-z`, or `(0, 0, 1)`.
fn axis(e: &Expr, field: &str, spans: &mut Spans) -> syn::Result<[f64; 3]> {
    let (sign, inner) = match e {
        Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => (-1.0, &*u.expr),
        _ => (1.0, e),
    };
    if let Expr::Path(p) = inner {
        let letter = p
            .path
            .get_ident()
            .map(|i| i.to_string())
            .unwrap_or_default();
        let k = match letter.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => {
                return Err(syn::Error::new(
                    e.span(),
                    format_args!(
                        "unknown axis `{letter}` (expected x, y, z, -x, -y, -z or (x, y, z))"
                    ),
                ))
            }
        };
        let mut a = [0.0; 3];
        a[k] = sign;
        return Ok(a);
    }
    triple(e, field, spans, number)
}

fn origin_args(
    meta: &Meta,
    field: &str,
    origin: &mut Origin,
    spans: &mut Spans,
    errors: &mut Errors,
) -> bool {
    let (k, kspan) = key_of(meta);
    match k.as_str() {
        "xyz" => {
            if let Some(v) = value_of(meta, errors) {
                spans.add(format!("{field}xyz"), kspan);
                if let Some(x) = errors.ok(triple(v, &format!("{field}xyz"), spans, scalar)) {
                    origin.xyz = x;
                }
            }
            true
        }
        "rpy" => {
            if let Some(v) = value_of(meta, errors) {
                spans.add(format!("{field}rpy"), kspan);
                if let Some(x) = errors.ok(triple(v, &format!("{field}rpy"), spans, number)) {
                    origin.rotation = Rotation::Rpy(x);
                }
            }
            true
        }
        _ => false,
    }
}

fn identity() -> Origin {
    Origin {
        xyz: Default::default(),
        rotation: Rotation::Rpy([0.0; 3]),
    }
}

fn parse_list<T: Parse>(l: &MetaList) -> syn::Result<Punctuated<T, Token![,]>> {
    Punctuated::<T, Token![,]>::parse_terminated.parse2(l.tokens.clone())
}

fn joint(k: usize, item: &JointItem, spans: &mut Spans, errors: &mut Errors) -> JointDesc {
    let field = format!("joints[{k}]");
    let name = item
        .name
        .as_ref()
        .map(|n| n.to_string())
        .unwrap_or_else(|| format!("joint_{}", k + 1));
    spans.add(
        &field,
        item.name.as_ref().map_or(item.kind.span(), Ident::span),
    );
    spans.add(
        format!("{field}.name"),
        item.name.as_ref().map_or(item.kind.span(), Ident::span),
    );
    spans.add(format!("{field}.type"), item.kind.span());
    let mut origin = identity();
    let mut ax: Option<[f64; 3]> = None;
    let mut v: Option<[Linear; 3]> = None;
    let mut w: Option<[f64; 3]> = None;
    let kind = item.kind.to_string();
    let twist = kind == "twist";
    let keys = if twist {
        "v, w, xyz, rpy"
    } else {
        "an axis letter, axis, xyz, rpy"
    };
    for meta in &item.args {
        if origin_args(meta, &format!("{field}."), &mut origin, spans, errors) {
            continue;
        }
        let (key, kspan) = key_of(meta);
        match (meta, key.as_str()) {
            (Meta::Path(p), "x" | "y" | "z") if !twist => {
                spans.add(format!("{field}.axis"), p.span());
                let e: Expr = syn::parse_quote!(#p);
                ax = errors.ok(axis(&e, &format!("{field}.axis"), spans));
            }
            (_, "axis") if !twist => {
                spans.add(format!("{field}.axis"), kspan);
                if let Some(e) = value_of(meta, errors) {
                    ax = errors.ok(axis(e, &format!("{field}.axis"), spans));
                }
            }
            (_, "v") if twist => {
                spans.add(format!("{field}.v"), kspan);
                if let Some(e) = value_of(meta, errors) {
                    v = errors.ok(triple(e, &format!("{field}.v"), spans, scalar));
                }
            }
            (_, "w") if twist => {
                spans.add(format!("{field}.w"), kspan);
                if let Some(e) = value_of(meta, errors) {
                    w = errors.ok(triple(e, &format!("{field}.w"), spans, number));
                }
            }
            _ => errors.at(
                kspan,
                format_args!("unknown key `{key}` for a {kind} joint (expected {keys})"),
            ),
        }
    }
    let kind = match kind.as_str() {
        "revolute" | "prismatic" => {
            let axis = ax.unwrap_or_else(|| {
                errors.at(
                    item.kind.span(),
                    format_args!(
                        "a {kind} joint needs an axis: `{kind}(z, ...)` or `axis = (x, y, z)`"
                    ),
                );
                [0.0, 0.0, 1.0]
            });
            if kind == "revolute" {
                JointKind::Revolute { axis }
            } else {
                JointKind::Prismatic { axis }
            }
        }
        "twist" => {
            if v.is_none() || w.is_none() {
                errors.at(
                    item.kind.span(),
                    "a twist joint needs `v = (..)` and `w = (..)`",
                );
            }
            JointKind::Twist {
                v: v.unwrap_or_default(),
                w: w.unwrap_or([0.0, 0.0, 1.0]),
            }
        }
        other => {
            errors.at(
                item.kind.span(),
                format_args!(
                    "unknown joint type `{other}` (expected revolute, prismatic or twist)"
                ),
            );
            JointKind::Revolute {
                axis: [0.0, 0.0, 1.0],
            }
        }
    };
    JointDesc {
        name,
        origin,
        kind,
        limits: None,
        speed_limit: None,
        acceleration_limit: None,
        jerk_limit: None,
        dynamics: Default::default(),
        location: None,
    }
}

fn constraint(l: &MetaList, spans: &mut Spans, errors: &mut Errors) -> Option<ConstraintDesc> {
    spans.add("constraint", l.path.span());
    let metas = errors.ok(parse_list::<Meta>(l))?;
    let mut origin = identity();
    let mut link = None;
    let mut h = None;
    let mut wrist = None;
    for meta in &metas {
        if origin_args(meta, "constraint.", &mut origin, spans, errors) {
            continue;
        }
        let (key, kspan) = key_of(meta);
        let Some(value) = value_of(meta, errors) else {
            continue;
        };
        match key.as_str() {
            "link" => {
                spans.add("constraint.link", value.span());
                link = errors.ok(match value {
                    Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Int(i),
                        ..
                    }) => i.base10_parse::<usize>(),
                    _ => Err(syn::Error::new(
                        value.span(),
                        "expected the link number (1-based)",
                    )),
                });
            }
            "h" => {
                spans.add("constraint.h", kspan);
                let rows = match value {
                    Expr::Tuple(_) | Expr::Array(_) => elements(value).unwrap_or_default(),
                    _ => vec![value],
                };
                let mut out = Vec::new();
                for (k, row) in rows.into_iter().enumerate() {
                    spans.add(format!("constraint.h[{k}]"), row.span());
                    let r = match row {
                        Expr::Path(p) => {
                            let letter = p.path.to_token_stream().to_string();
                            match ["x", "y", "z", "rx", "ry", "rz"].iter().position(|a| *a == letter) {
                                Some(i) => {
                                    let mut r = [0.0; 6];
                                    r[i] = 1.0;
                                    Ok(r)
                                }
                                None => Err(syn::Error::new(
                                    row.span(),
                                    format_args!(
                                        "unknown axis `{letter}` (expected x, y, z, rx, ry or rz)"
                                    ),
                                )),
                            }
                        }
                        _ => match elements(row).filter(|v| v.len() == 6) {
                            Some(v) => v
                                .into_iter()
                                .map(number)
                                .collect::<syn::Result<Vec<f64>>>()
                                .map(|v| <[f64; 6]>::try_from(v).expect("six")),
                            None => Err(syn::Error::new(
                                row.span(),
                                "a row of H is an axis letter or six numbers (vx, vy, vz, wx, wy, wz)",
                            )),
                        },
                    };
                    if let Some(r) = errors.ok(r) {
                        out.push(r);
                    }
                }
                h = Some(out);
            }
            "wrist" => {
                spans.add("constraint.wrist", value.span());
                wrist = match text(value).as_str() {
                    "unidirectional" => Some(Wrist::Unidirectional),
                    "zy" => Some(Wrist::Zy),
                    "zx" => Some(Wrist::Zx),
                    other => {
                        errors.at(
                            value.span(),
                            format_args!(
                                "unknown wrist `{other}` (expected unidirectional, zy or zx)"
                            ),
                        );
                        None
                    }
                };
            }
            _ => errors.at(
                kspan,
                format_args!(
                    "unknown key `{key}` in constraint (expected link, xyz, rpy, h, wrist)"
                ),
            ),
        }
    }
    if link.is_none() {
        errors.at(
            l.path.span(),
            "the constraint needs `link = i` (the constrained link, 1-based)",
        );
    }
    if h.is_none() {
        errors.at(
            l.path.span(),
            "the constraint needs `h = (..)`, e.g. `h = (x, z)`",
        );
    }
    Some(ConstraintDesc {
        link: link?,
        origin,
        h: h?,
        wrist,
    })
}

/// Builds the description; `default_name` is the struct's name. On success, the description's
/// own validation has run and every problem was reported at its field's span.
pub(crate) fn build(lists: &InlineLists, default_name: &str) -> syn::Result<RobotDescription> {
    let mut errors = Errors::default();
    let mut spans = Spans::default();
    let whole = lists.first.unwrap_or_else(Span::call_site);
    spans.add("robot", whole);
    let name = match &lists.name {
        Some(n) => {
            spans.add("robot.name", n.span());
            n.value()
        }
        None => default_name.to_string(),
    };

    let mut parameters = Vec::new();
    if let Some(l) = &lists.params {
        spans.add("parameters", l.path.span());
        if let Some(metas) = errors.ok(parse_list::<Meta>(l)) {
            for meta in &metas {
                let (key, kspan) = key_of(meta);
                spans.add(format!("parameters.{key}"), kspan);
                if let Some(v) = value_of(meta, &mut errors).and_then(|e| errors.ok(number(e))) {
                    parameters.push(Parameter {
                        name: key,
                        value: v,
                    });
                }
            }
        }
    }

    let mut joints = Vec::new();
    if let Some(l) = &lists.joints {
        spans.add("joints", l.path.span());
        if let Some(items) = errors.ok(parse_list::<JointItem>(l)) {
            for (k, item) in items.iter().enumerate() {
                joints.push(joint(k, item, &mut spans, &mut errors));
            }
        }
    }

    let mut end_effector = EndEffector {
        name: "end_effector".into(),
        origin: identity(),
    };
    if let Some(l) = &lists.end_effector {
        spans.add("end_effector", l.path.span());
        if let Some(metas) = errors.ok(parse_list::<Meta>(l)) {
            for meta in &metas {
                if origin_args(
                    meta,
                    "end_effector.",
                    &mut end_effector.origin,
                    &mut spans,
                    &mut errors,
                ) {
                    continue;
                }
                let (key, kspan) = key_of(meta);
                if key == "name" {
                    if let Some(Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Str(s),
                        ..
                    })) = value_of(meta, &mut errors)
                    {
                        spans.add("end_effector.name", s.span());
                        end_effector.name = s.value();
                    } else {
                        errors.at(kspan, "expected `name = \"...\"`");
                    }
                } else {
                    errors.at(
                        kspan,
                        format_args!(
                            "unknown key `{key}` in end_effector (expected name, xyz, rpy)"
                        ),
                    );
                }
            }
        }
    }

    let constraint = match &lists.constraint {
        Some(l) => constraint(l, &mut spans, &mut errors),
        None => None,
    };

    // Format errors first: validation of a half-read description would only add noise.
    errors.finish()?;
    let desc = RobotDescription {
        name,
        parameters,
        joints,
        end_effector,
        constraint,
        task: None,
        instrument: None,
        source: None,
    };
    let mut errors = Errors::default();
    for p in desc.problems() {
        let span = spans.find(&p.field).unwrap_or(whole);
        errors.at(span, describe(&p));
    }
    errors.finish()?;
    Ok(desc)
}

/// `invalid description: field `x`: message` (no file or line: the span says where).
fn describe(e: &DescriptionError) -> String {
    format!(
        "invalid robot description: field `{}`: {}",
        e.field, e.message
    )
}
