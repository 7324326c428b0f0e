//! What one control step of a constrained robot needs, emitted into its module:
//!
//! - `StepKinematics`, caller-owned storage for `g_0e`, `g_0i` (2.21), `J^B_0i` (3.13),
//!   `J^r_0e` (3.15), `J_c` (3.33), `Λ#` (3.6), `Λ†` (3.31) and, with a task, `S J^r_0e`;
//! - `step_kinematics`, which fills it from one `JointTrig` (and, when the constraint frame
//!   slides along the link, from the trocar point: the offset `l_a` is computed first);
//! - when the constraint frame slides along the link, `Kinematics<T>`: an implementation of the
//!   runtime controller's `ConstrainedKinematics` trait on those closed forms, so that the
//!   controller (pinv, damped least squares, filtered inverse, drift correction, moving trocar,
//!   null-space objectives) runs on generated code with no hand-written kinematics.
//!
//! The constraint frame slides along the link when `g_ir = (R_ir, o + l_a d)` for one parameter
//! `l_a` with `R_ir` and `o` free of it and `d` a constant direction (`lower::shaft_parameter`): the
//! thesis's `(I, (0, l_a, 0))` and a laparoscope's `(I, (0, 0, flange + l_a))` alike. Every step
//! puts `F_r` at the point of that line nearest to the trocar,
//! `l_a = ((p_t − p_0i − R_0i o) · R_0i d) / |d|²`.

use crate::emit::doc::doc_attrs;
use crate::ir::{ControllerSpec, Real};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The step storage, the step function and, with a sliding constraint frame, the controller
/// glue. `rt` is the path of the runtime crate in emitted code (`::trocar`).
pub(crate) fn tokens(rt: &TokenStream, real: Real, spec: &ControllerSpec) -> TokenStream {
    let (t, generics, args) = match real {
        Real::Generic => (quote!(T), quote!(<T: #rt::emitted::Real>), quote!(<T>)),
        Real::F32 => (quote!(f32), quote!(), quote!()),
        Real::F64 => (quote!(f64), quote!(), quote!()),
    };
    let r = quote!(<#t as #rt::emitted::Real>);
    let (task_field, task_zero, task_fill, task_check) = if spec.task {
        (
            quote! {
                /// `S J^r_0e`, TASK_ROWS × M (`constrained_task_jacobian`).
                pub task_jacobian: [[#t; TASK_ROWS]; M],
            },
            quote!(task_jacobian: [[z; TASK_ROWS]; M],),
            quote!(out.task_jacobian = constrained_task_jacobian_trig(t, p);),
            quote!(&&finite(out.task_jacobian.as_flattened())),
        )
    } else {
        (quote!(), quote!(), quote!(), quote!())
    };
    let (offset_field, offset_zero, offset_doc) = match &spec.offset {
        Some(name) => (
            {
                let doc = format!(
                    " The trocar offset `{name}` of this step: the constraint frame's position \
                     along the link."
                );
                quote! {
                    #[doc = #doc]
                    pub offset: #t,
                }
            },
            quote!(offset: z,),
            format!(
                "\n\nThe constraint frame slides along the link with `params.{name}`: \
                 [`step_kinematics`] sets it to the trocar's offset first."
            ),
        ),
        None => (quote!(), quote!(), String::new()),
    };
    let struct_doc = doc_attrs(&format!(
        "What one control step needs, in storage the caller owns (matrices column-major): \
         filled by [`step_kinematics`].{offset_doc}"
    ));
    // Everything after g_0i, at the parameters `p`: one place for the step's contents.
    let fill_fn = quote! {
        /// Fills everything but `g_0i` (and the offset) at the parameters `p`.
        #[inline]
        fn fill_step #generics (t: &JointTrig #args, p: &Params #args, out: &mut StepKinematics #args) {
            (out.g_0e, out.jb0i, out.jr, out.jc) = pose_and_jacobians_trig(t, p);
            out.lambda_sharp = lambda_null_space(p);
            out.lambda_pinv = lambda_pinv(p);
            #task_fill
        }

        /// Whether every output of a filled step is finite.
        #[inline]
        fn step_is_finite #generics (out: &StepKinematics #args) -> bool {
            let finite = |x: &[#t]| x.iter().all(|&v| #r::is_finite(v));
            finite(&out.g_0e.1)
                && finite(&out.g_0i.1)
                && finite(out.g_0e.0.as_flattened())
                && finite(out.g_0i.0.as_flattened())
                && finite(out.jb0i.as_flattened())
                && finite(out.jr.as_flattened())
                && finite(out.jc.as_flattened())
                && finite(out.lambda_sharp.as_flattened())
                && finite(out.lambda_pinv.as_flattened())
                #task_check
        }
    };
    let step_fn = match &spec.offset {
        Some(name) => {
            let offset = format_ident!("{}", name);
            let doc_offset = format!(
                " `{name}` of the point of the line `g_ir(l) = (R_ir, o + l d)` nearest to \
                 `trocar` (base coordinates) with the link at `g_0i`: \
                 `((p_t − p_0i − R_0i o) · R_0i d) / |d|²`, with `o` and `d` from \
                 [`constraint_frame`] at `{name} = 0` and `1`."
            );
            quote! {
                #[doc = #doc_offset]
                #[inline]
                #[must_use]
                pub fn trocar_offset #generics (
                    g_0i: &([[#t; 3]; 3], [#t; 3]),
                    trocar: &[#t; 3],
                    params: &Params #args,
                ) -> #t {
                    let mut p = *params;
                    p.#offset = #r::ZERO;
                    let o = constraint_frame(&p).1;
                    p.#offset = #r::ONE;
                    let o1 = constraint_frame(&p).1;
                    let d = [o1[0] - o[0], o1[1] - o[1], o1[2] - o[2]];
                    let (rot, pos) = g_0i;
                    let mut num = #r::ZERO;
                    for i in 0..3 {
                        // Row i of R_0i applied to o and d.
                        let ro = rot[0][i] * o[0] + rot[1][i] * o[1] + rot[2][i] * o[2];
                        let rd = rot[0][i] * d[0] + rot[1][i] * d[1] + rot[2][i] * d[2];
                        num += (trocar[i] - pos[i] - ro) * rd;
                    }
                    num / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                }

                /// One control step's kinematics from one `JointTrig`: `g_0i`, the trocar
                /// offset at `trocar` ([`trocar_offset`], stored in `out.offset`), then
                /// everything else at that offset. Returns `false` if an output is not finite
                /// (e.g. a null-space basis that divides by the offset, at offset 0); `out` is
                /// then not meaningful.
                #[inline]
                pub fn step_kinematics #generics (
                    t: &JointTrig #args,
                    trocar: &[#t; 3],
                    params: &Params #args,
                    out: &mut StepKinematics #args,
                ) -> bool {
                    fill_at_trocar(t, trocar, params, out);
                    #r::is_finite(out.offset) && step_is_finite(out)
                }

                /// [`step_kinematics`] without the finiteness check.
                #[inline]
                fn fill_at_trocar #generics (
                    t: &JointTrig #args,
                    trocar: &[#t; 3],
                    params: &Params #args,
                    out: &mut StepKinematics #args,
                ) {
                    out.g_0i = forward_kinematics_i_trig(t, params);
                    out.offset = trocar_offset(&out.g_0i, trocar, params);
                    let mut p = *params;
                    p.#offset = out.offset;
                    fill_step(t, &p, out);
                }
            }
        }
        None => quote! {
            /// One control step's kinematics from one `JointTrig`, at the parameters given.
            /// Returns `false` if an output is not finite; `out` is then not meaningful.
            #[inline]
            pub fn step_kinematics #generics (
                t: &JointTrig #args,
                params: &Params #args,
                out: &mut StepKinematics #args,
            ) -> bool {
                out.g_0i = forward_kinematics_i_trig(t, params);
                fill_step(t, params, out);
                step_is_finite(out)
            }
        },
    };
    let glue = spec
        .offset
        .as_deref()
        .map(|name| glue_tokens(rt, real, name, spec));
    // The fixed-size solves of a step: the task Jacobian when square, J^B_0i when 6 × 6 or
    // 6 × 7.
    let mut sizes = Vec::new();
    if spec.task_rows == spec.m {
        sizes.push(spec.m);
    }
    if spec.link == 6 && !sizes.contains(&6) {
        sizes.push(6);
    }
    let mut solvers: Vec<TokenStream> = sizes
        .iter()
        .map(|&d| lu_solve_tokens(rt, real, d))
        .collect();
    // J^B_0i with one redundant joint (6 × 7): the minimum-norm solve.
    if spec.link == 7 {
        solvers.push(min_norm_solve_tokens(rt, real, 6));
    }
    quote! {
        #struct_doc
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct StepKinematics #generics {
            #offset_field
            /// `g_0e = (R_0e, p_0e)` of the end effector.
            pub g_0e: ([[#t; 3]; 3], [#t; 3]),
            /// `g_0i = (R_0i, p_0i)` of the constrained link.
            pub g_0i: ([[#t; 3]; 3], [#t; 3]),
            /// `J^B_0i`, 6 × I.
            pub jb0i: [[#t; 6]; I],
            /// `J^r_0e`, 6 × M.
            pub jr: [[#t; 6]; M],
            /// `J_c = Ad_{g_ei} Λ†`, 6 × R.
            pub jc: [[#t; 6]; R],
            /// `Λ#`, 6 × K.
            pub lambda_sharp: [[#t; 6]; K],
            /// `Λ†`, 6 × R.
            pub lambda_pinv: [[#t; 6]; R],
            #task_field
        }

        impl #generics StepKinematics #args {
            /// All zeros (storage to be filled by [`step_kinematics`]).
            #[inline]
            #[must_use]
            pub fn zeroed() -> Self {
                let z = #r::ZERO;
                StepKinematics {
                    #offset_zero
                    g_0e: ([[z; 3]; 3], [z; 3]),
                    g_0i: ([[z; 3]; 3], [z; 3]),
                    jb0i: [[z; 6]; I],
                    jr: [[z; 6]; M],
                    jc: [[z; 6]; R],
                    lambda_sharp: [[z; 6]; K],
                    lambda_pinv: [[z; 6]; R],
                    #task_zero
                }
            }
        }

        #fill_fn
        #step_fn
        #(#solvers)*
        #glue
    }
}

/// `Kinematics<T>` and its `ConstrainedKinematics` implementation, for a module whose
/// constraint frame slides along the link with the parameter `offset`.
fn glue_tokens(rt: &TokenStream, real: Real, offset: &str, spec: &ControllerSpec) -> TokenStream {
    let task = spec.task;
    let offset = format_ident!("{}", offset);
    let (t, generics, args, impl_generics, ty_args) = match real {
        Real::Generic => (
            quote!(T),
            quote!(<T: #rt::emitted::Real>),
            quote!(<T>),
            quote!(<T: #rt::emitted::Real + #rt::emitted::nalgebra::RealField>),
            quote!(<T>),
        ),
        Real::F32 => (quote!(f32), quote!(), quote!(), quote!(), quote!()),
        Real::F64 => (quote!(f64), quote!(), quote!(), quote!(), quote!()),
    };
    let real = quote!(<#t as #rt::emitted::Real>);
    let (p_const, selection) = if task {
        (
            quote!(TASK_ROWS),
            quote! {
                #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(
                    task_selection(&self.params),
                ))
            },
        )
    } else {
        (
            quote!(6),
            quote!(#rt::emitted::nalgebra::SMatrix::identity()),
        )
    };
    let struct_doc = format!(
        "The runtime controller's kinematics on this module's closed forms: \
         `{rt}::control::ConstrainedKinematics<_, N, I, R, K, M, {p}>`, so that \
         `{rt}::control::Controller` runs on generated code.\n\n\
         The constraint frame slides along the link with `params.{offset}` \
         (`g_ir = (R_ir, o + {offset} d)`, [`constraint_frame`]); a step computes \
         everything from one [`JointTrig`] as [`step_kinematics`] does. A non-finite offset is \
         `ControlError::Kinematics`; other non-finite outputs (e.g. a basis that divides by the \
         offset, at offset 0) reach the joint rates, which the controller rejects \
         (`ControlError::NonFinite`).",
        rt = rt.to_string().replace(' ', ""),
        p = if task { "TASK_ROWS" } else { "6" },
        offset = offset,
    );
    let struct_doc = doc_attrs(&struct_doc);
    let controller_doc = doc_attrs(&format!(
        "The runtime controller sized for this robot: `{rt}::control::Controller` with this \
         module's sizes `<_, N, I, R, K, M, {p}>` in one name, run on [`Kinematics`].",
        rt = rt.to_string().replace(' ', ""),
        p = if task { "TASK_ROWS" } else { "6" },
    ));
    let state_ty = quote!(#rt::emitted::ConstrainedState<#t, I, R, K, M>);
    let solve_task = (spec.task_rows == spec.m).then(|| {
        let name = format_ident!("lu_solve_{}", spec.m);
        quote! {
            /// The square task Jacobian solved by the straight-line elimination emitted for
            /// this size.
            #[inline]
            fn solve_task(
                &self,
                j: &#rt::emitted::nalgebra::SMatrix<#t, #p_const, M>,
                b: &#rt::emitted::nalgebra::SVector<#t, #p_const>,
            ) -> ::core::option::Option<(#rt::emitted::nalgebra::SVector<#t, M>, #t)> {
                let (x, det) = #name(&j.data.0, &b.data.0[0]);
                ::core::option::Option::Some((#rt::emitted::nalgebra::SVector::from(x), det))
            }
        }
    });
    // J^B_0i through the straight-line solve emitted for its size: 6 × 6 (x, det J), or 6 × 7
    // with one redundant joint (the minimum-norm x, w = sqrt(det(J Jᵀ))).
    let jb0i_solver = match spec.link {
        6 => Some((
            format_ident!("lu_solve_6"),
            " `J^B_0i` (6 × 6) solved by the straight-line elimination emitted for this size.",
        )),
        7 => Some((
            format_ident!("min_norm_solve_6"),
            " `J^B_0i` (6 × 7, one redundant joint): the minimum-norm solution and \
             `w = sqrt(det(J Jᵀ))` from the straight-line solve emitted for this size (`w = 0` \
             where it does not apply; the controller then factors `J` itself).",
        )),
        _ => None,
    };
    let solve_jb0i = jb0i_solver.map(|(name, doc)| {
        quote! {
            #[doc = #doc]
            #[inline]
            fn solve_jb0i(
                &self,
                j: &#rt::emitted::nalgebra::SMatrix<#t, 6, I>,
                b: &#rt::emitted::nalgebra::SVector<#t, 6>,
            ) -> ::core::option::Option<(#rt::emitted::nalgebra::SVector<#t, I>, #t)> {
                let (x, det_or_w) = #name(&j.data.0, &b.data.0[0]);
                ::core::option::Option::Some((#rt::emitted::nalgebra::SVector::from(x), det_or_w))
            }
        }
    });
    quote! {
        #struct_doc
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Kinematics #generics {
            /// The parameters; the trocar offset is overwritten at every evaluation.
            pub params: Params #args,
        }

        #controller_doc
        pub type Controller #args = #rt::emitted::Controller<#t, N, I, R, K, M, #p_const>;

        impl #generics Kinematics #args {
            /// With the description's nominal parameters.
            #[inline]
            #[must_use]
            pub fn nominal() -> Self {
                Kinematics { params: Params::nominal() }
            }
        }

        impl #impl_generics Kinematics #ty_args {
            /// A pose from the generated `(R column-major, p)`.
            #[inline]
            fn pose((r, p): ([[#t; 3]; 3], [#t; 3])) -> #rt::emitted::Se3<#t> {
                #rt::emitted::Se3 {
                    rotation: #rt::emitted::nalgebra::Matrix3::from_data(#rt::emitted::nalgebra::ArrayStorage(r)),
                    translation: #rt::emitted::nalgebra::Vector3::from_data(#rt::emitted::nalgebra::ArrayStorage([p])),
                }
            }

            /// The runtime's state from a filled [`StepKinematics`].
            #[inline]
            fn state(s: &StepKinematics #ty_args) -> #state_ty {
                #rt::emitted::ConstrainedState {
                    g_0e: Self::pose(s.g_0e),
                    g_0i: Self::pose(s.g_0i),
                    jr: #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(s.jr)),
                    jb0i: #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(s.jb0i)),
                    jc: #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(s.jc)),
                    lambda_sharp: #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(
                        s.lambda_sharp,
                    )),
                    lambda_pinv: #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(
                        s.lambda_pinv,
                    )),
                }
            }
        }

        impl #impl_generics #rt::emitted::ConstrainedKinematics<#t, N, I, R, K, M, #p_const>
            for Kinematics #ty_args
        {
            #[inline]
            fn g_0i(&self, q: &#rt::emitted::nalgebra::SVector<#t, N>) -> #rt::emitted::Se3<#t> {
                Self::pose(forward_kinematics_i(&q.data.0[0], &self.params))
            }

            /// The forward kinematics alone, at the offset 0 as the trait's default takes it
            /// from `evaluate`.
            #[inline]
            fn g_0e(
                &self,
                q: &#rt::emitted::nalgebra::SVector<#t, N>,
            ) -> ::core::result::Result<#rt::emitted::Se3<#t>, #rt::emitted::ControlError> {
                let mut p = self.params;
                p.#offset = #real::ZERO;
                let (r, x) = forward_kinematics(&q.data.0[0], &p);
                if !r.as_flattened().iter().chain(&x).all(|&v| #real::is_finite(v)) {
                    return ::core::result::Result::Err(#rt::emitted::ControlError::Kinematics);
                }
                ::core::result::Result::Ok(Self::pose((r, x)))
            }

            #[inline]
            fn h(&self) -> #rt::emitted::nalgebra::SMatrix<#t, R, 6> {
                #rt::emitted::nalgebra::SMatrix::from_data(#rt::emitted::nalgebra::ArrayStorage(
                    constraint_selection(&self.params),
                ))
            }

            #[inline]
            fn shaft(&self) -> #rt::emitted::Shaft<#t> {
                let mut p = self.params;
                p.#offset = #real::ZERO;
                let at_zero = Self::pose(constraint_frame(&p));
                p.#offset = #real::ONE;
                let at_one = Self::pose(constraint_frame(&p));
                #rt::emitted::Shaft::from_frames(&at_zero, &at_one)
            }

            #[inline]
            fn task_selection(&self) -> #rt::emitted::nalgebra::SMatrix<#t, #p_const, 6> {
                #selection
            }

            #[inline]
            fn evaluate(
                &self,
                q: &#rt::emitted::nalgebra::SVector<#t, N>,
                l_a: #t,
            ) -> ::core::result::Result<#state_ty, #rt::emitted::ControlError> {
                let t = JointTrig::new(&q.data.0[0]);
                let mut p = self.params;
                p.#offset = l_a;
                let mut s = StepKinematics::zeroed();
                s.g_0i = forward_kinematics_i_trig(&t, &p);
                s.offset = l_a;
                fill_step(&t, &p, &mut s);
                if !#real::is_finite(l_a) || !step_is_finite(&s) {
                    return ::core::result::Result::Err(#rt::emitted::ControlError::Kinematics);
                }
                ::core::result::Result::Ok(Self::state(&s))
            }

            #solve_task
            #solve_jb0i

            /// One `JointTrig` for `g_0i`, `l_a` and everything else.
            #[inline]
            fn evaluate_at_trocar(
                &self,
                q: &#rt::emitted::nalgebra::SVector<#t, N>,
                trocar: &#rt::emitted::nalgebra::Vector3<#t>,
            ) -> ::core::result::Result<(#t, #state_ty), #rt::emitted::ControlError> {
                // As `step_kinematics`, without checking every output: the controller checks
                // the joint rates it computes from them.
                let t = JointTrig::new(&q.data.0[0]);
                let mut s = StepKinematics::zeroed();
                fill_at_trocar(&t, &trocar.data.0[0], &self.params, &mut s);
                if !#real::is_finite(s.offset) {
                    return ::core::result::Result::Err(#rt::emitted::ControlError::Kinematics);
                }
                ::core::result::Result::Ok((s.offset, Self::state(&s)))
            }
        }

    }
}

/// `lu_solve_{d}`: `J x = b` for a square `d × d` matrix (column-major `[col][row]`) by Gaussian
/// elimination with partial pivoting, written out for this size: every entry a local variable,
/// each row exchange of the pivot search a branch (predicted in a control loop, whose consecutive
/// matrices pivot alike: dia10_like's control step measured 298 ns against 391 ns with the
/// exchanges as selects), `b` eliminated alongside. Returns `x` and
/// `det J` (`x` is not meaningful when `det J` is 0 or not finite).
pub(crate) fn lu_solve_tokens(rt: &TokenStream, real: Real, d: usize) -> TokenStream {
    let (t, generics) = real_generics(rt, real);
    let name = format_ident!("lu_solve_{}", d);
    let mut body = elimination_tokens(rt, real, d, 1);
    let xs = back_substitution(&mut body, d, 0);
    let doc = format!(
        " `J x = b` for a square {d} × {d} `J` (column-major `j[col][row]`): Gaussian elimination \
         with partial pivoting written out for this size. Returns `(x, det J)`; `x` is not \
         meaningful when `det J` is 0 or not finite."
    );
    quote! {
        #[doc = #doc]
        #[inline]
        #[must_use]
        #[allow(unused_mut, unused_assignments, clippy::many_single_char_names, clippy::too_many_lines)]
        pub fn #name #generics (j: &[[#t; #d]; #d], b: &[#t; #d]) -> ([#t; #d], #t) {
            #(#body)*
            ([#(#xs),*], det)
        }
    }
}

/// The largest `1 + a·a` [`min_norm_solve_tokens`]' function accepts: the unit null vector's
/// component on the last column is at least 10⁻².
const MIN_NORM_MAX_NN: f64 = 1e4;

/// `min_norm_solve_{d}`: the minimum-norm solution `x = J⁺ b` of a `J = [A c] ∈ R^{d×(d+1)}`
/// with one redundant column (a 7-joint `J^B_0i`), from the elimination of its leading block `A`
/// with both right-hand sides `b` and `c`:
///
/// `y = A⁻¹ b`, `a = A⁻¹ c`; `n = [a; −1]` spans the null space of `J`, so
/// `x = [y − s a; s]` with `s = (a·y) / (1 + a·a)` (the particular solution `[y; 0]` less its
/// component along `n`), and `w = sqrt(det(J Jᵀ)) = |det A| sqrt(1 + a·a)` (3.36), since
/// `J Jᵀ = A Aᵀ + c cᵀ` (the matrix determinant lemma).
///
/// `A` is conditioned like `J` unless the last column carries `J`'s rank (`A` nearly singular,
/// `a` large): the function then returns `w = 0` (`1 + a·a > 10⁴`, or `det A` zero or not
/// finite) and the controller factors `J` itself.
pub(crate) fn min_norm_solve_tokens(rt: &TokenStream, real: Real, d: usize) -> TokenStream {
    let (t, generics) = real_generics(rt, real);
    let r = quote!(<#t as #rt::emitted::Real>);
    let name = format_ident!("min_norm_solve_{}", d);
    let mut body = elimination_tokens(rt, real, d, 2);
    let ys = back_substitution(&mut body, d, 0);
    let as_ = back_substitution(&mut body, d, 1);
    let cols = d + 1;
    let max_nn = MIN_NORM_MAX_NN;
    let xs = ys.iter().zip(&as_).map(|(y, a)| quote!(#y - s * #a));
    body.push(quote! {
        let nn = #r::ONE #(+ #as_ * #as_)*;
        let s = (#(#as_ * #ys)+*) / nn;
        let w = if nn <= #r::lit(#max_nn) { #r::abs(det) * #r::sqrt(nn) } else { #r::ZERO };
    });
    let doc = format!(
        " The minimum-norm solution `x = J⁺ b` of `J x = b` for a {d} × {cols} `J` \
         (column-major `j[col][row]`) with one redundant column: with `A` its leading {d} × {d} \
         block and `c` its last column, `y = A⁻¹ b`, `a = A⁻¹ c` (one elimination with partial \
         pivoting, written out for this size), `x = [y − s a; s]`, `s = (a·y) / (1 + a·a)`. \
         Returns `(x, w)` with `w = sqrt(det(J Jᵀ)) = |det A| sqrt(1 + a·a)` (3.36); `w = 0` \
         where this does not apply (`A` singular, or `1 + a·a > {max_nn:e}`: the last column \
         carries `J`'s rank and `A` is badly conditioned), and then `x` is not meaningful."
    );
    quote! {
        #[doc = #doc]
        #[inline]
        #[must_use]
        #[allow(unused_mut, unused_assignments, clippy::many_single_char_names, clippy::too_many_lines)]
        pub fn #name #generics (j: &[[#t; #d]; #cols], b: &[#t; #d]) -> ([#t; #cols], #t) {
            #(#body)*
            ([#(#xs,)* s], w)
        }
    }
}

/// The element type and generics of an emitted solve.
fn real_generics(rt: &TokenStream, real: Real) -> (TokenStream, TokenStream) {
    match real {
        Real::Generic => (quote!(T), quote!(<T: #rt::emitted::Real>)),
        Real::F32 => (quote!(f32), quote!()),
        Real::F64 => (quote!(f64), quote!()),
    }
}

/// Variable names of the written-out elimination: `a{row}_{col}` for the leading block, and
/// `b{rhs}_{row}` for right-hand side `rhs` (the first is the argument `b`, a second one is the
/// last column of `j`).
fn elim_a(row: usize, col: usize) -> proc_macro2::Ident {
    format_ident!("a{}_{}", row, col)
}

fn elim_b(rhs: usize, row: usize) -> proc_macro2::Ident {
    format_ident!("b{}_{}", rhs, row)
}

/// Gaussian elimination with partial pivoting of the leading `d × d` block of `j`, written out,
/// carrying `rhs` right-hand sides: `b`, then (if 2) column `d` of `j`. Leaves `U` in the `a`
/// variables, the eliminated right-hand sides in the `b` variables, `1 / U_cc` in `inv{c}` and
/// `det` = the block's determinant.
fn elimination_tokens(rt: &TokenStream, real: Real, d: usize, rhs: usize) -> Vec<TokenStream> {
    let (t, _) = real_generics(rt, real);
    let r = quote!(<#t as #rt::emitted::Real>);
    let a = elim_a;
    let mut body = Vec::new();
    for row in 0..d {
        for col in 0..d {
            let v = a(row, col);
            body.push(quote!(let mut #v = j[#col][#row];));
        }
        let v = elim_b(0, row);
        body.push(quote!(let mut #v = b[#row];));
        for k in 1..rhs {
            let v = elim_b(k, row);
            let col = d + k - 1;
            body.push(quote!(let mut #v = j[#col][#row];));
        }
    }
    body.push(quote!(let mut det = #r::ONE;));
    let inv = |c: usize| format_ident!("inv{}", c);
    for c in 0..d {
        // Pivot: bring the largest |a_rc| (r ≥ c) to row c, one compare-and-exchange per row,
        // as a branch: a controller's consecutive matrices pivot alike, so the branches are
        // predicted and the comparisons leave the chain of dependent operations.
        for row in c + 1..d {
            let (pc, pr) = (a(c, c), a(row, c));
            let mut swaps = Vec::new();
            for col in c..d {
                let (x, y) = (a(c, col), a(row, col));
                swaps.push(quote!(::core::mem::swap(&mut #x, &mut #y);));
            }
            for k in 0..rhs {
                let (bx, by) = (elim_b(k, c), elim_b(k, row));
                swaps.push(quote!(::core::mem::swap(&mut #bx, &mut #by);));
            }
            body.push(quote! {
                if #r::abs(#pr) > #r::abs(#pc) {
                    #(#swaps)*
                    det = -det;
                }
            });
        }
        let p = a(c, c);
        let iv = inv(c);
        body.push(quote! {
            det *= #p;
            let #iv = #r::ONE / #p;
        });
        for row in c + 1..d {
            let l = a(row, c);
            let mut upd = Vec::new();
            for col in c + 1..d {
                let (x, y) = (a(row, col), a(c, col));
                upd.push(quote!(#x -= l * #y;));
            }
            for k in 0..rhs {
                let (brow, bc) = (elim_b(k, row), elim_b(k, c));
                upd.push(quote!(#brow -= l * #bc;));
            }
            body.push(quote! {
                let l = #l * #iv;
                #(#upd)*
            });
        }
    }
    body
}

/// Back substitution `x_c = (b_c − Σ_{k>c} a_ck x_k) / a_cc` of right-hand side `k` after
/// [`elimination_tokens`]; returns the names of the solution's entries.
fn back_substitution(body: &mut Vec<TokenStream>, d: usize, k: usize) -> Vec<proc_macro2::Ident> {
    let x = |c: usize| {
        if k == 0 {
            format_ident!("x{}", c)
        } else {
            format_ident!("x{}_{}", k, c)
        }
    };
    let inv = |c: usize| format_ident!("inv{}", c);
    for c in (0..d).rev() {
        let (xc, bc, iv) = (x(c), elim_b(k, c), inv(c));
        let terms = (c + 1..d).map(|j| {
            let (acj, xj) = (elim_a(c, j), x(j));
            quote!(- #acj * #xj)
        });
        body.push(quote!(let #xc = (#bc #(#terms)*) * #iv;));
    }
    (0..d).map(x).collect()
}
