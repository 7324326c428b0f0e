//! The Rust module of a closed mechanism, in the style of the serial-robot modules: the Rust
//! backend's items for the polynomial functions of its [`ModuleSpec`] (`constraint_jacobian`,
//! `task_jacobian`, `constraint_determinant`, `reduced_jacobian_numerator`,
//! `passive_map_numerator`, lowered by `lower::mechanism`), and the hand-written wrappers that
//! divide by `det J_Cp` (`reduced_jacobian`, `passive_map`, `passive_velocities`, (7)–(8) of
//! Freitas, Leite & Lizarralde 2010), which return `None` instead of a NaN or an infinity when
//! `det J_Cp` is zero or not finite.

use super::rust::{module_items_in, wrap_module, Runtime, Ty};
use crate::closed_chain::MechanismDerivation;
use crate::ir::{ModuleSpec, Real};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use trocar_model::catalogue::Function as F;

/// The hand-written wrappers that divide by `det J_Cp`.
fn wrapper_tokens(d: &MechanismDerivation, ty: &Ty) -> TokenStream {
    let t = ty.t();
    // These wrappers test their values (`is_finite`, `det != 0`): `Real`, not `Arith`.
    let (generics, args) = (ty.real_generics(), ty.args());
    let rl = ty.real_trait_path();
    let rt = ty.runtime();
    let active: Vec<TokenStream> = d
        .active
        .iter()
        .map(|&k| {
            let l = proc_macro2::Literal::usize_unsuffixed(k);
            quote!(#l)
        })
        .collect();
    let passive: Vec<TokenStream> = d
        .passive
        .iter()
        .map(|&k| {
            let l = proc_macro2::Literal::usize_unsuffixed(k);
            quote!(#l)
        })
        .collect();
    let quotient_generics = match ty.real {
        Real::Generic => quote!(<T: #rt::emitted::Real, const IN: usize, const OUT: usize>),
        _ => quote!(<const IN: usize, const OUT: usize>),
    };
    let reduced = format_ident!("{}", F::ReducedJacobian.name());
    let reduced_trig = format_ident!("{}", F::ReducedJacobian.trig_name());
    let reduced_num = format_ident!("{}", F::ReducedJacobianNumerator.name());
    let reduced_num_trig = format_ident!("{}", F::ReducedJacobianNumerator.trig_name());
    let passive_map = format_ident!("{}", F::PassiveMap.name());
    let passive_map_trig = format_ident!("{}", F::PassiveMap.trig_name());
    let passive_num = format_ident!("{}", F::PassiveMapNumerator.name());
    let passive_num_trig = format_ident!("{}", F::PassiveMapNumerator.trig_name());
    let velocities = format_ident!("{}", F::PassiveVelocities.name());
    quote! {
        /// Indices in `q` of the active joints θ_a (the columns of `J`).
        pub const ACTIVE: [usize; N_ACTIVE] = [#(#active),*];
        /// Indices in `q` of the passive joints θ_p (the rows of the passive map).
        pub const PASSIVE: [usize; N_PASSIVE] = [#(#passive),*];

        /// Rows `1..` of every column of `a` divided by row 0 (`det J_Cp`); `None` when the
        /// determinant is zero or any value is not finite.
        #[inline]
        fn quotient #quotient_generics (
            a: &[[#t; IN]; N_ACTIVE],
        ) -> Option<[[#t; OUT]; N_ACTIVE]> {
            let mut out = [[#rl::ZERO; OUT]; N_ACTIVE];
            for (o, col) in out.iter_mut().zip(a.iter()) {
                let det = col[0];
                if !(#rl::is_finite(det) && det != #rl::ZERO) {
                    return None;
                }
                for (x, v) in o.iter_mut().zip(col.iter().skip(1)) {
                    let y = *v / det;
                    if !#rl::is_finite(y) {
                        return None;
                    }
                    *x = y;
                }
            }
            Some(out)
        }

        /// The reduced Jacobian `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8) of Freitas, Leite & Lizarralde
        /// (2010): `ẋ = J θ̇_a`, N_OUTPUTS × N_ACTIVE, **column-major** (`a[col][row]`).
        ///
        /// `q` holds all joints (passive ones solved by the caller). `None` when `det J_Cp` is
        /// zero or not finite (parallel singularity) or the result is not finite.
        /// Computed as [`reduced_jacobian_numerator`] divided by `det J_Cp`.
        #[inline]
        #[must_use]
        pub fn #reduced #generics (
            q: &[#t; N],
            p: &Params #args,
        ) -> Option<[[#t; N_OUTPUTS]; N_ACTIVE]> {
            quotient(&#reduced_num(q, p))
        }

        /// [`reduced_jacobian`] from precomputed joint sines and cosines ([`JointTrig`]).
        #[inline]
        #[must_use]
        pub fn #reduced_trig #generics (
            t: &JointTrig #args,
            p: &Params #args,
        ) -> Option<[[#t; N_OUTPUTS]; N_ACTIVE]> {
            quotient(&#reduced_num_trig(t, p))
        }

        /// The passive map `−J_Cp⁻¹ J_Ca` (7) of Freitas, Leite & Lizarralde (2010):
        /// `θ̇_p = passive_map · θ̇_a`, N_PASSIVE × N_ACTIVE, **column-major**; rows in the
        /// order of [`PASSIVE`]. `None` when `det J_Cp` is zero or not finite.
        #[inline]
        #[must_use]
        pub fn #passive_map #generics (
            q: &[#t; N],
            p: &Params #args,
        ) -> Option<[[#t; N_PASSIVE]; N_ACTIVE]> {
            quotient(&#passive_num(q, p))
        }

        /// [`passive_map`] from precomputed joint sines and cosines ([`JointTrig`]).
        #[inline]
        #[must_use]
        pub fn #passive_map_trig #generics (
            t: &JointTrig #args,
            p: &Params #args,
        ) -> Option<[[#t; N_PASSIVE]; N_ACTIVE]> {
            quotient(&#passive_num_trig(t, p))
        }

        /// Passive velocities `θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a` (7) of Freitas, Leite & Lizarralde
        /// (2010), in the order of [`PASSIVE`], for the active velocities `qd_active` (in the
        /// order of [`ACTIVE`]). `None` when `det J_Cp` is zero or not finite, or a result is
        /// not finite.
        #[inline]
        #[must_use]
        pub fn #velocities #generics (
            q: &[#t; N],
            qd_active: &[#t; N_ACTIVE],
            p: &Params #args,
        ) -> Option<[#t; N_PASSIVE]> {
            let m = #passive_map(q, p)?;
            let mut v = [#rl::ZERO; N_PASSIVE];
            for (col, w) in m.iter().zip(qd_active.iter()) {
                for (x, e) in v.iter_mut().zip(col.iter()) {
                    *x += *e * *w;
                }
            }
            if v.iter().all(|x| #rl::is_finite(*x)) {
                Some(v)
            } else {
                None
            }
        }
    }
}

/// The items of a mechanism module (without the `mod` wrapper).
pub fn module_items(
    d: &MechanismDerivation,
    spec: &ModuleSpec,
    real: Real,
    runtime: &Runtime,
) -> TokenStream {
    let items = module_items_in(spec, real, runtime);
    let wrappers = wrapper_tokens(d, &Ty::new(real, runtime));
    quote! {
        #items
        #wrappers
    }
}

/// The whole module `pub mod <name> { ... }` of the mechanism `d` lowered to `spec`, with its
/// documentation and lint attributes ([`wrap_module`]).
pub fn module_tokens(
    d: &MechanismDerivation,
    spec: &ModuleSpec,
    real: Real,
    runtime: &Runtime,
) -> TokenStream {
    wrap_module(&spec.name, &spec.doc, module_items(d, spec, real, runtime))
}
