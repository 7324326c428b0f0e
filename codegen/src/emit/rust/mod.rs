//! The Rust backend: tokens for a robot module read from its [`ModuleSpec`] (`Params`,
//! `JointTrig`, constants, one function plus its `_trig` variant per
//! [`EmittedFunction`](crate::ir::EmittedFunction), the fused functions and their FMA entry
//! points, the controller glue of [`super::controller`]), naming the runtime crate by
//! [`Runtime`], formatted with prettyplease ([`format_file`]).
//!
//! - `ty`: the real type and the runtime path ([`Runtime`]).
//! - `body`: a program as Rust statements.
//! - `function`: one function and its `_trig` variant.
//! - `fused`: fused functions, the paired-rows walk and the FMA entry points.
//! - this module: `Params`, `JointTrig`, `pose_and_jacobians_trig` and the whole module.

mod body;
mod function;
mod fused;
mod ty;

pub(crate) use ty::Ty;
pub use ty::{Runtime, DEFAULT_RUNTIME_PATH};

use crate::emit::doc::doc_attrs;
use crate::ir::{Layout, ModuleSpec, Op, Real};
use body::{body, trig_statement, uses, Access, Body};
use function::{divides_by, divisors, function_tokens, layout_tokens};
use fused::{fma_entry_points, fused_tokens, repr_c};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;
use trocar_model::catalogue;

/// `pose_and_jacobians_trig` of a constrained robot: `g_0e`, `J^B_0i`, `J^r_0e` and `J_c` from one
/// [`JointTrig`], written from [`ModuleSpec::pose_and_jacobians`] when there is one (the chain
/// walked once), from the four `_trig` functions otherwise.
fn pose_and_jacobians_tokens(spec: &ModuleSpec, ty: &Ty) -> Option<TokenStream> {
    spec.function(catalogue::Function::ConstrainedJacobian)?;
    let size = |name: &str| {
        spec.consts
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.value)
            .unwrap_or_else(|| panic!("a constrained module has the constant {name}"))
    };
    let (i, m, r) = (size("I"), size("M"), size("R"));
    let t = ty.t();
    let generics = ty.generics();
    let args = ty.args();
    let tuple = quote!((([[#t; 3]; 3], [#t; 3]), [[#t; 6]; I], [[#t; 6]; M], [[#t; 6]; R]));
    let ret = quote!(PoseAndJacobians #args);
    let mut doc = String::from(
        "`(g_0e, J^B_0i, J^r_0e, J_c)` from one [`JointTrig`]: the values of \
         [`forward_kinematics_trig`], [`partial_body_jacobian_trig`], \
         [`constrained_jacobian_trig`] and [`constraint_jacobian_c_trig`], what a control step \
         needs, thesis (2.21), (3.13), (3.15) and (3.33).\n\n",
    );
    let (p, value) = match &spec.pose_and_jacobians {
        Some(prog) => {
            let Body { stmts, outs, .. } = body(prog, ty, Access::Trig);
            let (_, g) = layout_tokens(Layout::Transform, ty, &outs[..12]);
            let mat = |range: std::ops::Range<usize>, cols: usize| {
                layout_tokens(Layout::Matrix { rows: 6, cols }, ty, &outs[range]).1
            };
            let jbi = mat(12..12 + 6 * i, i);
            let jr = mat(12 + 6 * i..12 + 6 * (i + m), m);
            let jc = mat(12 + 6 * (i + m)..12 + 6 * (i + m + r), r);
            let _ = writeln!(
                doc,
                "One pass along the chain: the walk that builds `J^B_0i` ends with `g_0i`, so \
                 `g_0e = g_0i g_ie` costs one product more, and the four share their common \
                 values.\n"
            );
            let divisors = divisors(prog);
            if !divisors.is_empty() {
                let _ = writeln!(doc, "{}\n", divides_by(&divisors));
            }
            let _ = write!(
                doc,
                "Operations: {} (the `sin_cos` calls are done once in [`JointTrig::new`]).",
                crate::ir::OpCounts {
                    trig: 0,
                    ..prog.op_counts()
                }
            );
            let p = if uses(prog, |op| matches!(op, Op::Param(_))) {
                quote!(p)
            } else {
                quote!(_p)
            };
            (p, quote! { #(#stmts)* (#g, #jbi, #jr, #jc) })
        }
        None => {
            doc.push_str(
                "The four functions called in turn (one program for all four is no smaller).",
            );
            (
                quote!(p),
                quote! {
                    (
                        forward_kinematics_trig(t, p),
                        partial_body_jacobian_trig(t, p),
                        constrained_jacobian_trig(t, p),
                        constraint_jacobian_c_trig(t, p),
                    )
                },
            )
        }
    };
    let doc = doc_attrs(&doc);
    // Always inlined: called once per step, its four results then go straight into the caller's
    // storage instead of through a returned copy (measured: dia10_like 93 ns out of line, see
    // BENCHMARKS.md).
    Some(quote! {
        /// `(g_0e, J^B_0i, J^r_0e, J_c)` as [`pose_and_jacobians_trig`] returns them: `(R, p)` with
        /// `R` column-major, then the three matrices column-major.
        pub type PoseAndJacobians #args = #tuple;

        #doc
        #[inline(always)]
        #[must_use]
        pub fn pose_and_jacobians_trig #generics (t: &JointTrig #args, #p: &Params #args) -> #ret {
            #value
        }
    })
}

fn params_tokens(spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let t = ty.t();
    let generics = ty.generics();
    let args = ty.args();
    let doc_struct = doc_attrs(&format!(
        "The named parameters of `{}`: runtime inputs of every function.",
        spec.name
    ));
    let rt = ty.runtime();
    let repr = repr_c(spec);
    if spec.params.is_empty() {
        return match ty.real {
            Real::Generic => quote! {
                #doc_struct
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                #repr
                pub struct Params<T>(::core::marker::PhantomData<T>);

                impl<T: #rt::emitted::Arith> Params<T> {
                    /// The description's nominal values (this robot has no parameters).
                    #[inline]
                    #[must_use]
                    pub fn nominal() -> Self {
                        Params(::core::marker::PhantomData)
                    }
                }
            },
            _ => quote! {
                #doc_struct
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                pub struct Params;

                impl Params {
                    /// The description's nominal values (this robot has no parameters).
                    #[inline]
                    #[must_use]
                    pub fn nominal() -> Self {
                        Params
                    }
                }
            },
        };
    }
    let fields = spec.params.iter().map(|(name, value)| {
        let id = format_ident!("{}", name);
        let d = format!(" `{name}` (nominal value {value:?}).");
        quote!(#[doc = #d] pub #id: #t,)
    });
    let inits = spec.params.iter().map(|(name, value)| {
        let id = format_ident!("{}", name);
        let v = ty.lit(*value);
        quote!(#id: #v,)
    });
    quote! {
        #doc_struct
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        #repr
        pub struct Params #generics {
            #(#fields)*
        }

        impl #generics Params #args {
            /// The description's nominal values.
            #[inline]
            #[must_use]
            pub fn nominal() -> Self {
                Params { #(#inits)* }
            }
        }
    }
}

fn trig_tokens(spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let t = ty.t();
    let r = ty.real_path();
    let generics = ty.generics();
    let args = ty.args();
    let n = spec.joints;
    let mut used = vec![false; n];
    for f in &spec.functions {
        for k in f.program.trig_joints() {
            if k < n {
                used[k] = true;
            }
        }
    }
    let joints: Vec<usize> = (0..n).filter(|&k| used[k]).collect();
    let stmts = trig_statement(&r, &joints, |_| true, |_| true);
    let mut sins = Vec::new();
    let mut coss = Vec::new();
    for (k, &u) in used.iter().enumerate() {
        if u {
            let s = format_ident!("s{}", k + 1);
            let c = format_ident!("c{}", k + 1);
            sins.push(quote!(#s));
            coss.push(quote!(#c));
        } else {
            sins.push(quote!(#r::ZERO));
            coss.push(quote!(#r::ONE));
        }
    }
    let joints_doc = used
        .iter()
        .enumerate()
        .filter(|(_, &u)| u)
        .map(|(k, _)| (k + 1).to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let doc = doc_attrs(&format!(
        "Joint values with the sine and cosine of every joint the functions use (joints \
         {joints_doc}, 1-based), computed once per control step and shared by the `_trig` \
         functions.\n\nUnused entries hold `sin = 0`, `cos = 1`."
    ));
    let q = if n > 0 { quote!(q) } else { quote!(_q) };
    let repr = repr_c(spec);
    quote! {
        #doc
        #[derive(Clone, Copy, Debug, PartialEq)]
        #repr
        pub struct JointTrig #generics {
            /// The joint values `q`, base first.
            pub q: [#t; N],
            /// `sin q[k]`.
            pub sin: [#t; N],
            /// `cos q[k]`.
            pub cos: [#t; N],
        }

        impl #generics JointTrig #args {
            /// The sines and cosines of the used joints, in one `sin_cos_array` call.
            // Always inlined: out of line (merged with every identical `new` of the program)
            // its sines and cosines went to the caller through memory (the Panda with an RCM:
            // 65 ns a step instead of 56, BENCHMARKS.md).
            #[inline(always)]
            #[must_use]
            pub fn new(#q: &[#t; N]) -> Self {
                #stmts
                JointTrig { q: *#q, sin: [#(#sins),*], cos: [#(#coss),*] }
            }
        }
    }
}

/// The items of a robot module (without the `mod` wrapper), naming the runtime `::trocar`.
pub fn module_items(spec: &ModuleSpec, real: Real) -> TokenStream {
    module_items_in(spec, real, &Runtime::default())
}

/// The items of a robot module (without the `mod` wrapper), naming the runtime by `runtime`.
pub fn module_items_in(spec: &ModuleSpec, real: Real, runtime: &Runtime) -> TokenStream {
    let ty = Ty::new(real, runtime);
    let consts = spec.consts.iter().map(|c| {
        let id = format_ident!("{}", c.name);
        let v = Literal::usize_unsuffixed(c.value);
        let d = doc_attrs(&c.doc);
        quote!(#d pub const #id: usize = #v;)
    });
    let params = params_tokens(spec, &ty);
    let limits = spec.joint_limits.as_ref().map(|limits| {
        let rows = limits.iter().map(|[lo, hi]| quote!([#lo, #hi]));
        quote! {
            /// Joint limits `[lower, upper]` (rad for revolute joints, m for prismatic ones),
            /// base first, from the description (its URDF's `<limit>` or `limits = [lo, hi]`).
            pub const JOINT_LIMITS: [[f64; 2]; N] = [#(#rows),*];
        }
    });
    // A robot whose joints have limits except some (`continuous` ones): each joint's bounds,
    // typed, instead of no constant at all.
    let partial = spec.joint_ranges.iter().any(Option::is_some)
        && spec.joint_ranges.iter().any(Option::is_none);
    let ranges = partial.then(|| {
        let rows = spec.joint_ranges.iter().map(|r| match r {
            Some([lo, hi]) => quote!(Some([#lo, #hi])),
            None => quote!(None),
        });
        quote! {
            /// Each joint's limits `[lower, upper]` (rad for revolute joints, m for prismatic
            /// ones), base first, from the description; `None` for a joint without (a URDF
            /// `continuous` joint): its range is unbounded, `(−∞, ∞)`. Emitted when some
            /// joints have limits and others do not; `JOINT_LIMITS` when all have them.
            pub const JOINT_RANGES: [Option<[f64; 2]>; N] = [#(#rows),*];
        }
    });
    let trig = trig_tokens(spec, &ty);
    let fns = spec
        .functions
        .iter()
        .map(|f| function_tokens(f, &ty, spec.joints));
    let fused = spec.fused.iter().map(|f| {
        let mut items = fused_tokens(f, &ty, spec.joints, spec.fma_at_run_time);
        if spec.fma_at_run_time {
            items.extend(fma_entry_points(f, spec, &ty));
        }
        items
    });
    let step = pose_and_jacobians_tokens(spec, &ty);
    let controller = spec
        .controller
        .as_ref()
        .map(|c| super::controller::tokens(ty.runtime(), real, c));
    quote! {
        #(#consts)*
        #limits
        #ranges
        #params
        #trig
        #(#fns)*
        #(#fused)*
        #step
        #controller
    }
}

/// The whole module `pub mod <name> { ... }`, with its documentation and lint attributes, naming
/// the runtime `::trocar`.
pub fn module_tokens(spec: &ModuleSpec, real: Real) -> TokenStream {
    module_tokens_in(spec, real, &Runtime::default())
}

/// The whole module `pub mod <name> { ... }`, naming the runtime by `runtime`.
pub fn module_tokens_in(spec: &ModuleSpec, real: Real, runtime: &Runtime) -> TokenStream {
    wrap_module(&spec.name, &spec.doc, module_items_in(spec, real, runtime))
}

/// The module wrapper of every generated module, serial or mechanism: `pub mod <name> { ... }`
/// with `doc` (markdown, one `#![doc]` a line) and the lint attributes, around `items`.
pub fn wrap_module(name: &str, doc: &str, items: TokenStream) -> TokenStream {
    let name = Ident::new(name, Span::call_site());
    let doc = doc.lines().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#![doc = #l])
    });
    quote! {
        pub mod #name {
            #(#doc)*
            // Literals are the description's values written in full: they may look like
            // well-known constants (e.g. 1/√2) or carry more digits than f32 holds; rustc rounds
            // them correctly.
            #![allow(
                clippy::approx_constant,
                clippy::excessive_precision,
                clippy::unreadable_literal,
                clippy::too_many_lines,
                clippy::doc_markdown
            )]
            #items
        }
    }
}

/// Formats tokens of a file with prettyplease, headed by the `@generated` line.
pub fn format_file(tokens: TokenStream) -> Result<String, syn::Error> {
    let file: syn::File = syn::parse2(tokens)?;
    Ok(format!(
        "// This file is @generated by trocar-codegen. Do not edit.\n\n{}",
        prettyplease::unparse(&file)
    ))
}
