//! The controller glue of a constrained robot's module: `Kinematics<T>`, an implementation of the
//! runtime controller's `ConstrainedKinematics` trait on the module's own closed forms, so that the
//! controller (pinv, damped least squares, filtered inverse, drift correction, moving trocar) runs
//! on generated code with no hand-written kinematics.
//!
//! One control step asks for `g_0i`, then, with the trocar offset `l_a = (p_trocar − p_0i) · y_i`
//! set as the constraint frame's parameter, `g_0e`, `J^r_0e` (3.15), `J^B_0i` (3.13), `J_c`
//! (3.33), `Λ#` (3.6) and `Λ†` (3.31): all from one [`JointTrig`](crate) per step.
//!
//! The trait's convention (the thesis's) is `g_ir = (I, (0, l_a, 0))`: the constraint frame is
//! the link's frame moved along `y_i` by one parameter. Modules whose constraint frame has that
//! form get the glue ([`trocar_offset_parameter`]); the others keep `H`, `Λ#` and `Λ†` as plain
//! functions.

use super::Real;
use crate::derivation::Derivation;
use crate::symbolic::{Matrix, Poly};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The parameter that places the constraint frame on the link, when `g_ir = (I, (0, p, 0))` for
/// one named parameter `p` (the trocar offset `l_a` of the thesis); `None` otherwise.
pub fn trocar_offset_parameter(d: &Derivation) -> Option<String> {
    let c = d.constraint.as_ref()?;
    if c.g_ir.rot != Matrix::identity(3) {
        return None;
    }
    let p = c.g_ir.pos.entries();
    if !p[0].is_zero() || !p[2].is_zero() {
        return None;
    }
    (0..d.params.len())
        .find(|&k| p[1] == Poly::param(k))
        .map(|k| d.params[k].clone())
}

/// `Kinematics<T>` and its `ConstrainedKinematics` implementation, for a module whose trocar
/// offset is the parameter `offset`.
/// `rt` is the path of the runtime crate in emitted code (`::trocar`).
pub(crate) fn tokens(rt: &TokenStream, real: Real, offset: &str) -> TokenStream {
    let offset = format_ident!("{}", offset);
    let (t, generics, args, impl_generics, ty_args) = match real {
        Real::Generic => (
            quote!(T),
            quote!(<T: #rt::Real>),
            quote!(<T>),
            quote!(<T: #rt::Real + #rt::nalgebra::RealField>),
            quote!(<T>),
        ),
        Real::F32 => (quote!(f32), quote!(), quote!(), quote!(), quote!()),
        Real::F64 => (quote!(f64), quote!(), quote!(), quote!(), quote!()),
    };
    let real = quote!(<#t as #rt::Real>);
    let struct_doc = format!(
        "The runtime controller's kinematics on this module's closed forms: \
         `{rt}::control::ConstrainedKinematics<_, N, I, R, K, M>`, so that \
         `{rt}::control::Controller` runs on generated code.\n\n\
         Every evaluation sets `params.{offset}` (the constraint frame's offset along the \
         link's `y` axis, `g_ir = (I, (0, {offset}, 0))`) to the `l_a` it is given, and computes \
         `g_0e`, `J^r_0e` (3.15), `J^B_0i` (3.13), `J_c` (3.33), `Λ#` (3.6) and `Λ†` (3.31) from \
         one [`JointTrig`]. `l_a` zero or not finite is `ControlError::Kinematics`.",
        rt = rt.to_string().replace(' ', ""),
        offset = offset,
    );
    let struct_doc = struct_doc.lines().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#[doc = #l])
    });
    quote! {
        #(#struct_doc)*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Kinematics #generics {
            /// The parameters; the trocar offset is overwritten at every evaluation.
            pub params: Params #args,
        }

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
            fn pose((r, p): ([[#t; 3]; 3], [#t; 3])) -> #rt::se3::Se3<#t> {
                #rt::se3::Se3 {
                    rotation: #rt::nalgebra::Matrix3::from_data(#rt::nalgebra::ArrayStorage(r)),
                    translation: #rt::nalgebra::Vector3::from_data(#rt::nalgebra::ArrayStorage([p])),
                }
            }

            /// The constrained state from the joints' sines and cosines and `g_0i` (which does
            /// not depend on the trocar offset).
            #[inline]
            fn state(
                &self,
                t: &JointTrig #ty_args,
                g_0i: #rt::se3::Se3<#t>,
                l_a: #t,
            ) -> ::core::result::Result<
                #rt::control::ConstrainedState<#t, I, R, K, M>,
                #rt::control::ControlError,
            > {
                if l_a == #real::ZERO || !#real::is_finite(l_a) {
                    return ::core::result::Result::Err(#rt::control::ControlError::Kinematics);
                }
                let mut p = self.params;
                p.#offset = l_a;
                ::core::result::Result::Ok(#rt::control::ConstrainedState {
                    g_0e: Self::pose(forward_kinematics_trig(t, &p)),
                    g_0i,
                    jr: #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                        constrained_jacobian_trig(t, &p),
                    )),
                    jb0i: #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                        partial_body_jacobian_trig(t, &p),
                    )),
                    jc: #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                        constraint_jacobian_c_trig(t, &p),
                    )),
                    lambda_sharp: #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                        lambda_null_space(&p),
                    )),
                    lambda_pinv: #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                        lambda_pinv(&p),
                    )),
                })
            }
        }

        impl #impl_generics #rt::control::ConstrainedKinematics<#t, N, I, R, K, M>
            for Kinematics #ty_args
        {
            #[inline]
            fn g_0i(&self, q: &#rt::nalgebra::SVector<#t, N>) -> #rt::se3::Se3<#t> {
                Self::pose(forward_kinematics_i(&q.data.0[0], &self.params))
            }

            #[inline]
            fn h(&self) -> #rt::nalgebra::SMatrix<#t, R, 6> {
                #rt::nalgebra::SMatrix::from_data(#rt::nalgebra::ArrayStorage(
                    constraint_selection(&self.params),
                ))
            }

            #[inline]
            fn evaluate(
                &self,
                q: &#rt::nalgebra::SVector<#t, N>,
                l_a: #t,
            ) -> ::core::result::Result<
                #rt::control::ConstrainedState<#t, I, R, K, M>,
                #rt::control::ControlError,
            > {
                let t = JointTrig::new(&q.data.0[0]);
                let g_0i = Self::pose(forward_kinematics_i_trig(&t, &self.params));
                self.state(&t, g_0i, l_a)
            }

            /// One `JointTrig` for `g_0i`, `l_a` and everything else.
            #[inline]
            fn evaluate_at_trocar(
                &self,
                q: &#rt::nalgebra::SVector<#t, N>,
                trocar: &#rt::nalgebra::Vector3<#t>,
            ) -> ::core::result::Result<
                (#t, #rt::control::ConstrainedState<#t, I, R, K, M>),
                #rt::control::ControlError,
            > {
                let t = JointTrig::new(&q.data.0[0]);
                let g_0i = Self::pose(forward_kinematics_i_trig(&t, &self.params));
                let l_a = #rt::control::trocar_offset(&g_0i, trocar);
                ::core::result::Result::Ok((l_a, self.state(&t, g_0i, l_a)?))
            }
        }
    }
}
