//! Fused functions ([`FusedFunction`]): several catalogue outputs from one program, each written
//! through a `&mut` out-parameter; the walk of `trocar::emitted::paired_rows` for `g_0i` and `J^B_0i` on
//! chains of right-angle joints (2.21), (2.45); and the `f64` entry points with FMA chosen at run
//! time (`trocar::emitted::fma`).

use super::body::{body, trig_statement, uses, Access};
use super::function::{divides_by, divisors};
use super::ty::Ty;
use crate::emit::doc::doc_attrs;
use crate::ir::{FusedFunction, FusedOutput, Layout, ModuleSpec, Op, Real};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};
use std::fmt::Write as _;
use trocar_model::catalogue;

/// The statements that write a program's output values `outs` (in `layout`) through the
/// out-parameter `out`: entry by entry, so that each value is stored where the caller wants it
/// (no temporary of the whole result and no copy).
pub(super) fn store_tokens(
    layout: Layout,
    out: &Ident,
    outs: &[TokenStream],
    guard: Option<&TokenStream>,
) -> Vec<TokenStream> {
    match layout {
        Layout::Scalar => {
            let v = &outs[0];
            match guard {
                Some(r) => vec![quote! {
                    let w = #v;
                    *#out = if #r::is_finite(w) { w } else { #r::ZERO };
                }],
                None => vec![quote!(*#out = #v;)],
            }
        }
        Layout::Matrix { rows, .. } => outs
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let c = Literal::usize_unsuffixed(k / rows);
                let r = Literal::usize_unsuffixed(k % rows);
                quote!(#out[#c][#r] = #v;)
            })
            .collect(),
        Layout::Transform => outs
            .iter()
            .enumerate()
            .map(|(k, v)| {
                if k < 9 {
                    let c = Literal::usize_unsuffixed(k / 3);
                    let r = Literal::usize_unsuffixed(k % 3);
                    quote!(#out.0[#c][#r] = #v;)
                } else {
                    let r = Literal::usize_unsuffixed(k - 9);
                    quote!(#out.1[#r] = #v;)
                }
            })
            .collect(),
    }
}

/// The type of a fused output's out-parameter (without `&mut`).
pub(super) fn out_type(o: &FusedOutput, ty: &Ty) -> TokenStream {
    let t = ty.t();
    match o.layout {
        Layout::Scalar => quote!(#t),
        Layout::Transform => quote!(([[#t; 3]; 3], [#t; 3])),
        Layout::Matrix { rows, cols } => match &o.dims {
            Some((r, c)) => {
                let r: TokenStream = r.parse().expect("a dimension");
                let c: TokenStream = c.parse().expect("a dimension");
                quote!([[#t; #r]; #c])
            }
            None => {
                let r = Literal::usize_unsuffixed(rows);
                let c = Literal::usize_unsuffixed(cols);
                quote!([[#t; #r]; #c])
            }
        },
    }
}

/// A fused function's out-parameters: their names (the outputs' short names) and `name: &mut type`.
pub(super) fn out_params(f: &FusedFunction, ty: &Ty) -> (Vec<Ident>, Vec<TokenStream>) {
    let outs: Vec<Ident> = f
        .outputs
        .iter()
        .map(|o| format_ident!("{}", o.function.short_name()))
        .collect();
    let params = f
        .outputs
        .iter()
        .zip(&outs)
        .map(|(o, id)| {
            let t = out_type(o, ty);
            quote!(#id: &mut #t)
        })
        .collect();
    (outs, params)
}

/// A fused function ([`FusedFunction`]) and its `_trig` variant, writing into out-parameters.
///
/// With `fma_at_run_time` both are `#[inline(always)]`, so that the entry points of
/// [`fma_entry_points`] compile their whole program for AVX2 and FMA.
pub(super) fn fused_tokens(
    f: &FusedFunction,
    ty: &Ty,
    n: usize,
    fma_at_run_time: bool,
) -> TokenStream {
    let guarded = |o: &FusedOutput| o.zero_when_not_finite && o.layout == Layout::Scalar;
    // An output that is tested (`is_finite`) needs `Real`; otherwise the program runs on lanes.
    let generics = if f.outputs.iter().any(guarded) {
        ty.real_generics()
    } else {
        ty.generics()
    };
    let args = ty.args();
    let t_str = ty.t().to_string();
    let name = format_ident!("{}", f.name);
    let name_trig = format_ident!("{}_trig", f.name);
    let functions: Vec<catalogue::Function> = f.functions();
    let links = functions
        .iter()
        .map(|g| format!("[`{}`]", g.name()))
        .collect::<Vec<_>>();
    let links = match links.len() {
        1 => links[0].clone(),
        k => format!("{} and {}", links[..k - 1].join(", "), links[k - 1]),
    };
    let quantities = functions
        .iter()
        .map(|g| format!("`{}`", g.quantity()))
        .collect::<Vec<_>>()
        .join(", ");
    let mut equations: Vec<&str> = functions.iter().map(|g| g.equation()).collect();
    equations.dedup();
    let mut doc = format!(
        "{quantities} in one program: the values of {links}, thesis {}, computed together so \
         that they share every common value.\n\n",
        equations.join(", ")
    );
    for o in &f.outputs {
        let what = match o.layout {
            Layout::Scalar => String::new(),
            Layout::Transform => " as `(R, p)`, `R` column-major (`r[col][row]`)".to_string(),
            Layout::Matrix { rows, cols } => {
                let (r, c) = o
                    .dims
                    .clone()
                    .unwrap_or_else(|| (rows.to_string(), cols.to_string()));
                format!(", {r} × {c}, column-major (`[[{t_str}; {r}]; {c}]`, `a[col][row]`)")
            }
        };
        let zero = if o.zero_when_not_finite {
            " (0 where the closed form is not finite)"
        } else {
            ""
        };
        let _ = writeln!(
            doc,
            "- `{}`: `{}`{what}{zero}",
            o.function.short_name(),
            o.function.quantity()
        );
    }
    let divisors = divisors(&f.program);
    if !divisors.is_empty() {
        let _ = writeln!(doc, "\n{}", divides_by(&divisors));
    }
    let counts = f.program.op_counts();
    let doc_q = doc_attrs(&format!("{doc}\nOperations: {counts}."));
    let doc_t = doc_attrs(&format!(
        "[`{}`] from precomputed joint sines and cosines ([`JointTrig`]).\n\nOperations: {} \
         (the `sin_cos` calls are done once in [`JointTrig::new`]).",
        f.name,
        crate::ir::OpCounts { trig: 0, ..counts }
    ));
    let r = ty.real_trait_path();
    let (outs, params) = out_params(f, ty);
    let stores = |values: &[TokenStream]| -> Vec<TokenStream> {
        f.outputs
            .iter()
            .enumerate()
            .flat_map(|(k, o)| {
                let guard = guarded(o).then_some(&r);
                store_tokens(o.layout, &outs[k], &values[f.range(k)], guard)
            })
            .collect()
    };
    let body_q = body(&f.program, ty, Access::Q);
    let body_t = body(&f.program, ty, Access::Trig);
    let stores_q = stores(&body_q.outs);
    let stores_t = stores(&body_t.outs);
    let mut stmts_q = body_q.interleaved(stores_q);
    let mut stmts_t = body_t.interleaved(stores_t);
    let mut doc_q = doc_q;
    let mut doc_t = doc_t;
    if let (Some(heads), false) = (&f.paired_heads, fma_at_run_time) {
        let walk_doc = doc_attrs(&format!(
            "\nOn x86-64 with SSE2 and without AVX (the default target), the chain is walked \
             instead with the rows of the homogeneous transform as pairs \
             (`{}::emitted::paired_rows`): one SSE2 register per pair for `f64` and `f32`, one operation \
             per lane for the lane types (so that they stay, lane by lane, the scalar walk); \
             the same values to rounding. The operation counts above are the program's.",
            ty.runtime().to_string().replace(' ', "")
        ));
        doc_q.extend(walk_doc.clone());
        doc_t.extend(walk_doc);
        let at = |g: catalogue::Function| {
            let k = f
                .outputs
                .iter()
                .position(|o| o.function == g)
                .expect("paired heads are set for g_0i and J^B_0i");
            outs[k].clone()
        };
        let (g, jb) = (
            at(catalogue::Function::ConstrainedLinkKinematics),
            at(catalogue::Function::PartialBodyJacobian),
        );
        for (stmts, access) in [(&mut stmts_q, Access::Q), (&mut stmts_t, Access::Trig)] {
            let walk = paired_walk(heads, ty, access, &g, &jb);
            let program = std::mem::take(stmts);
            stmts.push(quote! {
                if cfg!(all(
                    target_arch = "x86_64",
                    target_feature = "sse2",
                    not(target_feature = "avx")
                )) {
                    #(#walk)*
                } else {
                    #(#program)*
                }
            });
        }
    }
    let uses_q = uses(&f.program, |op| {
        matches!(op, Op::Joint(_) | Op::Sin(_) | Op::Cos(_))
    });
    let uses_p = uses(&f.program, |op| matches!(op, Op::Param(_)));
    let q = if uses_q { quote!(q) } else { quote!(_q) };
    let tt = if uses_q { quote!(t) } else { quote!(_t) };
    let p = if uses_p { quote!(p) } else { quote!(_p) };
    let t = ty.t();
    let n_ty = if n > 0 { quote!(N) } else { quote!(0) };
    let inline = if fma_at_run_time {
        quote!(#[inline(always)] #[allow(clippy::inline_always)])
    } else {
        quote!(#[inline])
    };
    quote! {
        #doc_q
        #inline
        pub fn #name #generics (#q: &[#t; #n_ty], #p: &Params #args, #(#params),*) {
            #(#stmts_q)*
        }

        #doc_t
        #inline
        pub fn #name_trig #generics (#tt: &JointTrig #args, #p: &Params #args, #(#params),*) {
            #(#stmts_t)*
        }
    }
}

/// The statements of `g_0i` and `J^B_0i` written into `g` and `jb` by the walk of
/// `trocar::emitted::paired_rows` over the joints with heads `heads` (base first,
/// [`FusedFunction::paired_heads`]): from link `i` towards the base, each joint's column of
/// `J^B_0i` from the rows reached before it (2.45), `g_0i` at the end.
pub(super) fn paired_walk(
    heads: &[(i8, [f64; 3])],
    ty: &Ty,
    access: Access,
    g: &Ident,
    jb: &Ident,
) -> Vec<TokenStream> {
    let rt = ty.runtime();
    let r = ty.real_path();
    let i = heads.len();
    let mut stmts = Vec::new();
    let joints: Vec<usize> = (0..i).collect();
    let trig = |k: usize| match access {
        Access::Q => {
            let (s, c) = (format_ident!("s{}", k + 1), format_ident!("c{}", k + 1));
            (quote!(#s), quote!(#c))
        }
        Access::Trig => {
            let k = Literal::usize_unsuffixed(k);
            (quote!(t.sin[#k]), quote!(t.cos[#k]))
        }
    };
    if access == Access::Q {
        stmts.extend(trig_statement(&r, &joints, |_| true, |_| true));
    }
    let last = Literal::usize_unsuffixed(i - 1);
    stmts.push(quote!(#jb[#last] = [#r::ZERO, #r::ZERO, #r::ZERO, #r::ZERO, #r::ZERO, #r::ONE];));
    for k in (0..i).rev() {
        let (roll, o) = heads[k];
        let roll = match roll {
            0 => quote!(#rt::emitted::paired_rows::Roll::Zero),
            1 => quote!(#rt::emitted::paired_rows::Roll::Quarter),
            _ => quote!(#rt::emitted::paired_rows::Roll::MinusQuarter),
        };
        let o = o.map(|x| {
            let l = Literal::f64_unsuffixed(x.abs());
            if x < 0.0 {
                quote!(-#l)
            } else {
                quote!(#l)
            }
        });
        let (s, c) = trig(k);
        stmts.push(if k == i - 1 {
            quote!(let rows = #rt::emitted::paired_rows::Rows::first(#s, #c, #roll, [#(#o),*]);)
        } else {
            quote!(let rows = rows.joint(#s, #c, #roll, [#(#o),*]);)
        });
        stmts.push(if k == 0 {
            quote!(rows.pose(#g);)
        } else {
            let col = Literal::usize_unsuffixed(k - 1);
            quote!(rows.column(&mut #jb[#col]);)
        });
    }
    stmts
}

/// The `f64` entry points of a fused function with FMA chosen at run time (`trocar::emitted::fma`):
/// `<name>_f64` and `<name>_trig_f64`, each taking the private `<name>_fma` /
/// `<name>_trig_fma` (the fused function on `FusedF64`, compiled for AVX2 and FMA) where
/// `trocar::emitted::fma::available()` holds, and `<name>::<f64>` otherwise; `<name>_trig_f64` takes
/// `<name>_trig_avx512` (the same, compiled for AVX-512F and AVX-512VL too) instead where
/// `trocar::emitted::fma::path()` is `Avx512`. From `q` the AVX2 function stays: compiled for
/// AVX-512 it was slower there (BENCHMARKS.md, "The fused functions on AVX-512, given the sines
/// and cosines").
pub(super) fn fma_entry_points(f: &FusedFunction, spec: &ModuleSpec, ty: &Ty) -> TokenStream {
    let rt = ty.runtime();
    let f64_ty = Ty {
        real: Real::F64,
        runtime: rt.clone(),
    };
    let n_ty = if spec.joints > 0 {
        quote!(N)
    } else {
        quote!(0)
    };
    let (outs, params) = out_params(f, &f64_ty);
    // Each output seen as `FusedF64` storage: matrices and scalars in place, the pose through a
    // local (a tuple's layout is not guaranteed to follow its fields' types), copied out after.
    let mut locals = Vec::new();
    let mut copies = Vec::new();
    let views: Vec<TokenStream> = f
        .outputs
        .iter()
        .zip(&outs)
        .map(|(o, id)| match o.layout {
            Layout::Scalar => quote!(#rt::emitted::fma::FusedF64::scalar_mut(#id)),
            Layout::Matrix { .. } => quote!(#rt::emitted::fma::FusedF64::matrix_mut(#id)),
            Layout::Transform => {
                let local = format_ident!("{}_fused", id);
                locals.push(quote! {
                    let mut #local = ([[F(0.0); 3]; 3], [F(0.0); 3]);
                });
                copies.push(quote! {
                    *#id = (#local.0.map(|c| c.map(|v| v.0)), #local.1.map(|v| v.0));
                });
                quote!(&mut #local)
            }
        })
        .collect();
    // The casts are sound (the `_fma` function's doc, which the generated code carries, says
    // why): `Params` and `JointTrig` are `#[repr(C)]` ([`repr_c`]) over `T` fields only.
    let params_fused =
        quote!(unsafe { &*::core::ptr::from_ref::<Params<f64>>(p).cast::<Params<F>>() });
    // The functions are called through `self::`: the entry points' parameters (`q`, `t`, `p`,
    // the outputs' short names) and locals (`fk_fused`) would shadow a function named like one.
    let mut items = TokenStream::new();
    for trig in [false, true] {
        let base = if trig {
            format!("{}_trig", f.name)
        } else {
            f.name.clone()
        };
        let name = format_ident!("{}", base);
        let name_f64 = format_ident!("{}_f64", base);
        let name_fma = format_ident!("{}_fma", base);
        let (input, input_fused, arg) = if trig {
            (
                quote!(t: &JointTrig<f64>),
                quote!(unsafe {
                    &*::core::ptr::from_ref::<JointTrig<f64>>(t).cast::<JointTrig<F>>()
                }),
                quote!(t),
            )
        } else {
            (quote!(q: &[f64; #n_ty]), quote!(F::array(q)), quote!(q))
        };
        let doc = doc_attrs(&format!(
            "[`{base}`] in `f64` with fused multiply-adds chosen at run time (`{rt}::emitted::fma`): \
             on an x86-64 CPU with AVX2 and FMA, in a build with `trocar`'s `std` feature \
             whose target lacks FMA, [`{base}`] compiled for them{avx512}, every `mul_add` \
             rounded once (bit for bit [`{base}`] built with FMA); [`{base}`]`::<f64>` \
             otherwise (without `std`, always). The last bits of the results therefore depend \
             on the CPU: call [`{base}`] where they must not. Fast when optimised: at \
             opt-level 0 each `mul_add` is a call.",
            rt = rt.to_string().replace(' ', ""),
            avx512 = if trig {
                " (and for AVX-512F and AVX-512VL too where the CPU has them, with the same bits)"
            } else {
                ""
            }
        ));
        let doc_fma = doc_attrs(&format!(
            "[`{base}_f64`] on a CPU with AVX2 and FMA: [`{base}`] on `FusedF64`, compiled for \
             them (it is `#[inline(always)]`, so its whole program is).\n\n# Safety\n\nThe CPU \
             must have AVX2 and FMA: [`{base}_f64`] calls this function only when \
             `fma::path()` is `Fma` or `Avx512`, which it is only on such a CPU.\n\nThe views \
             of the arguments as `FusedF64` are sound: `Params` and `JointTrig` are \
             `#[repr(C)]` with fields `f64`, `[f64; N]` (or one `PhantomData`) only, and \
             `FusedF64` is `#[repr(transparent)]` over `f64`, so `Params<f64>` and \
             `Params<FusedF64>` (and the same for `JointTrig`) have one layout and every value \
             of one is a value of the other; the views borrow the arguments for no longer than \
             the call."
        ));
        let body = quote! {
            use #rt::emitted::fma::FusedF64 as F;
            #(#locals)*
            self::#name::<F>(#input_fused, #params_fused, #(#views),*);
            #(#copies)*
        };
        // Given the sines and cosines, the AVX-512 function where the CPU has it (one load of
        // the kept answer either way).
        let (dispatch, avx512_fn) = if trig {
            let name_avx512 = format_ident!("{}_avx512", base);
            let doc_avx512 = doc_attrs(&format!(
                "[`{base}_fma`] compiled for AVX-512F and AVX-512VL too (thirty-two vector \
                 registers): the same operations, so the same bits.\n\n# Safety\n\nThe CPU \
                 must have AVX2, FMA, AVX-512F and AVX-512VL: [`{base}_f64`] calls this \
                 function only when `fma::path()` is `Avx512`, which it is only on such a CPU. \
                 The views of the arguments are sound as in [`{base}_fma`]."
            ));
            (
                quote! {
                    #[cfg(target_arch = "x86_64")]
                    match #rt::emitted::fma::path() {
                        #rt::emitted::fma::Path::Avx512 => {
                            unsafe { self::#name_avx512(#arg, p, #(#outs),*) };
                            return;
                        }
                        #rt::emitted::fma::Path::Fma => {
                            unsafe { self::#name_fma(#arg, p, #(#outs),*) };
                            return;
                        }
                        _ => {}
                    }
                },
                quote! {
                    #doc_avx512
                    #[cfg(target_arch = "x86_64")]
                    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
                    unsafe fn #name_avx512(#input, p: &Params<f64>, #(#params),*) {
                        #body
                    }
                },
            )
        } else {
            (
                quote! {
                    #[cfg(target_arch = "x86_64")]
                    if #rt::emitted::fma::available() {
                        unsafe { self::#name_fma(#arg, p, #(#outs),*) };
                        return;
                    }
                },
                TokenStream::new(),
            )
        };
        // `#[inline]`, not `always`: `name` is `#[inline(always)]` here, so `always` would copy
        // the fallback `name::<f64>` into every caller, and with `path()` one load the entry
        // points inline where they pay anyway (BENCHMARKS.md, "The fused functions on AVX-512,
        // …": the same instruction counts either way).
        items.extend(quote! {
            #doc
            #[inline]
            pub fn #name_f64(#input, p: &Params<f64>, #(#params),*) {
                #dispatch
                self::#name::<f64>(#arg, p, #(#outs),*);
            }

            #doc_fma
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            unsafe fn #name_fma(#input, p: &Params<f64>, #(#params),*) {
                #body
            }

            #avx512_fn
        });
    }
    items
}

/// `#[repr(C)]` for `Params` and `JointTrig` in a module with `fma_at_run_time`: their fields are
/// all `T` (or arrays of `T`), so with a fixed field order `Params<f64>` and `JointTrig<f64>` have
/// the layout of `Params<FusedF64>` and `JointTrig<FusedF64>`, and the `_fma` functions read the
/// caller's values in place ([`fma_entry_points`]).
pub(super) fn repr_c(spec: &ModuleSpec) -> Option<TokenStream> {
    spec.fma_at_run_time.then(|| quote!(#[repr(C)]))
}
