//! One emitted function and its `_trig` variant ([`EmittedFunction`]): signature from its
//! [`Layout`] (column-major matrices, transforms), documentation (summary, equation, the
//! parameters it divides by) and body.

use super::body::{body, uses, Access, Body};
use super::ty::Ty;
use crate::emit::doc::doc_attrs;
use crate::ir::{EmittedFunction, Layout, Op, Program};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;

pub(super) fn layout_tokens(
    layout: Layout,
    ty: &Ty,
    outs: &[TokenStream],
) -> (TokenStream, TokenStream) {
    let t = ty.t();
    match layout {
        Layout::Scalar => (quote!(#t), outs[0].clone()),
        Layout::Matrix { rows, cols } => {
            let r = Literal::usize_unsuffixed(rows);
            let c = Literal::usize_unsuffixed(cols);
            let columns = outs.chunks(rows.max(1)).map(|col| quote!([#(#col),*]));
            (quote!([[#t; #r]; #c]), quote!([#(#columns),*]))
        }
        Layout::Transform => {
            let columns = outs[..9].chunks(3).map(|col| quote!([#(#col),*]));
            let p = &outs[9..12];
            (
                quote!(([[#t; 3]; 3], [#t; 3])),
                quote!(([#(#columns),*], [#(#p),*])),
            )
        }
    }
}

pub(super) fn dims_tokens(f: &EmittedFunction, ty: &Ty) -> Option<TokenStream> {
    let (r, c) = f.dims.as_ref()?;
    let t = ty.t();
    let r: TokenStream = r.parse().ok()?;
    let c: TokenStream = c.parse().ok()?;
    Some(match f.layout {
        Layout::Matrix { .. } => quote!([[#t; #r]; #c]),
        _ => return None,
    })
}

pub(super) fn layout_doc(layout: Layout, dims: Option<&(String, String)>, t: &str) -> String {
    match layout {
        Layout::Scalar => String::new(),
        Layout::Matrix { rows, cols } => {
            let (r, c) = dims
                .cloned()
                .unwrap_or_else(|| (rows.to_string(), cols.to_string()));
            format!(
                "Returns the {rows} × {cols} matrix **column-major**: `[[{t}; {r}]; {c}]` holds {c} \
                 columns of {r} entries, `a[col][row]`. The conversion to nalgebra is free: \
                 `SMatrix::<{t}, {rows}, {cols}>::from_data(ArrayStorage(a))`."
            )
        }
        Layout::Transform => "Returns `(R, p)`: the rotation **column-major** (`r[col][row]`, \
             nalgebra: `Matrix3::from_data(ArrayStorage(r))`) and the position."
            .to_string(),
    }
}

/// The parameters `prog` divides by, as "`a`, `b`" (empty when none).
pub(super) fn divisors(prog: &Program) -> String {
    prog.divisor_params()
        .iter()
        .map(|p| format!("`{p}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The documentation's note on the parameters a function divides by ([`divisors`]).
pub(super) fn divides_by(divisors: &str) -> String {
    format!(
        "Divides by {divisors}: the result is not finite where that is 0 (nor, in general, with a \
         NaN or infinite input); test it with `is_finite` where that can happen."
    )
}

pub(super) fn function_tokens(f: &EmittedFunction, ty: &Ty, n: usize) -> TokenStream {
    let t = ty.t();
    let counts = f.program.op_counts();
    let name = format_ident!("{}", f.name);
    let name_trig = format_ident!("{}_trig", f.name);
    let mut doc = String::new();
    let _ = writeln!(doc, "{}, thesis {}.", f.summary, f.equation);
    if !f.details.is_empty() {
        let _ = writeln!(doc, "\n{}", f.details);
    }
    let layout = layout_doc(f.layout, f.dims.as_ref(), &t.to_string());
    if !layout.is_empty() {
        let _ = writeln!(doc, "\n{layout}");
    }
    let guard = f.zero_when_not_finite && f.layout == Layout::Scalar;
    // A function that tests its value needs `Real`; a straight-line one runs on lanes (`Arith`).
    let generics = if guard {
        ty.real_generics()
    } else {
        ty.generics()
    };
    let args = ty.args();
    let divisors = divisors(&f.program);
    let not_finite = if guard {
        let by = if divisors.is_empty() {
            String::new()
        } else {
            format!(" at a parameter it divides by equal to 0 ({divisors}), or")
        };
        format!(
            "Returns 0 where the closed form is not finite:{by} where a NaN or infinite input makes it so. \
             0 reads as singular to a controller that damps when the manipulability is small; \
             `+∞` would read as far from singular."
        )
    } else {
        String::new()
    };
    if guard {
        let _ = writeln!(doc, "\n{not_finite}");
    } else if !divisors.is_empty() {
        let _ = writeln!(doc, "\n{}", divides_by(&divisors));
    }
    let _ = writeln!(doc, "\nOperations: {counts}.");
    let doc_q = doc_attrs(&doc);
    let doc_t = doc_attrs(&format!(
        "[`{}`] from precomputed joint sines and cosines ([`JointTrig`]), thesis {}.\n\n{}{}\
         Operations: {} (the `sin_cos` calls are done once in [`JointTrig::new`]).",
        f.name,
        f.equation,
        if layout.is_empty() {
            String::new()
        } else {
            format!("{layout}\n\n")
        },
        if guard {
            format!("{not_finite}\n\n")
        } else {
            String::new()
        },
        crate::ir::OpCounts { trig: 0, ..counts }
    ));
    let Body {
        stmts: stmts_q,
        outs: outs_q,
        ..
    } = body(&f.program, ty, Access::Q);
    let Body {
        stmts: stmts_t,
        outs: outs_t,
        ..
    } = body(&f.program, ty, Access::Trig);
    let (ret, value_q) = layout_tokens(f.layout, ty, &outs_q);
    let ret = dims_tokens(f, ty).unwrap_or(ret);
    let (_, value_t) = layout_tokens(f.layout, ty, &outs_t);
    let (value_q, value_t) = if guard {
        let r = ty.real_trait_path();
        let wrap = |v: TokenStream| {
            quote! {{
                let w = #v;
                if #r::is_finite(w) { w } else { #r::ZERO }
            }}
        };
        (wrap(value_q), wrap(value_t))
    } else {
        (value_q, value_t)
    };
    let uses_q = uses(&f.program, |op| {
        matches!(op, Op::Joint(_) | Op::Sin(_) | Op::Cos(_))
    });
    let uses_p = uses(&f.program, |op| matches!(op, Op::Param(_)));
    let q = if uses_q { quote!(q) } else { quote!(_q) };
    let tt = if uses_q { quote!(t) } else { quote!(_t) };
    let p = if uses_p { quote!(p) } else { quote!(_p) };
    let n_ty = if n > 0 { quote!(N) } else { quote!(0) };
    if !f.takes_joints {
        assert!(
            !uses_q,
            "`{}` is catalogued as independent of the joints",
            f.name
        );
        return quote! {
            #doc_q
            #[inline]
            #[must_use]
            pub fn #name #generics (#p: &Params #args) -> #ret {
                #(#stmts_q)*
                #value_q
            }
        };
    }
    quote! {
        #doc_q
        #[inline]
        #[must_use]
        pub fn #name #generics (#q: &[#t; #n_ty], #p: &Params #args) -> #ret {
            #(#stmts_q)*
            #value_q
        }

        #doc_t
        #[inline]
        #[must_use]
        pub fn #name_trig #generics (#tt: &JointTrig #args, #p: &Params #args) -> #ret {
            #(#stmts_t)*
            #value_t
        }
    }
}
