//! A Rust module for a closed mechanism, in the style of the serial-robot modules.
//!
//! The polynomial parts (`constraint_jacobian`, `task_jacobian`, `constraint_determinant`,
//! `reduced_jacobian_numerator`, `passive_map_numerator`) go through the shared optimiser and emitter ([`crate::emit`]: CSE,
//! Horner factoring, operation counts, `_trig` variants); the functions that divide by
//! `det J_Cp` (`reduced_jacobian`, `passive_map`, `passive_velocities`) wrap them and return
//! `None` instead of a NaN or an infinity when `det J_Cp` is zero or not finite.

use super::derive::{derive, MechanismDerivation, MechanismError};
use crate::emit::bridge::PolyBuilder;
use crate::emit::rust::Ty;
use crate::emit::{self, ConstItem, EmittedFunction, ModuleSpec, Program, Runtime, Scalar};
use crate::error::Error;
use crate::naming::checked_module_name;
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};
use trocar_model::catalogue::{Function as F, Size};
use trocar_model::closed_chain::MechanismModel;

fn program(d: &MechanismDerivation) -> Program {
    Program::new(d.params.clone())
}

fn matrix_program(d: &MechanismDerivation, m: &crate::symbolic::Matrix) -> Program {
    let mut prog = program(d);
    let outs = PolyBuilder::new(&mut prog).matrix(m);
    prog.set_outputs(outs);
    prog
}

/// The module description: constants, `Params`, `JointTrig` and the polynomial functions.
pub fn module_spec(d: &MechanismDerivation, module_name: &str) -> ModuleSpec {
    let n = d.n();
    let (na, np, no, r) = (
        d.active.len(),
        d.passive.len(),
        d.outputs.len(),
        d.j_c.rows(),
    );
    let c = |name: &str, value: usize, doc: &str| ConstItem {
        name: name.into(),
        value,
        doc: doc.into(),
    };
    let consts = vec![
        c(
            "N",
            n,
            "Number of joints `n` (length of `q`: all joints, active and passive, in the \
             description's order).",
        ),
        c("N_ACTIVE", na, "Number of active joints `n_a` (θ_a)."),
        c("N_PASSIVE", np, "Number of passive joints `n_p` (θ_p)."),
        c("N_OUTPUTS", no, "Number of task outputs `m_x`."),
        c(
            "R",
            r,
            "Number of structural equations `r = 3(m − 1)` (rows of `J_C`); equals `N_PASSIVE`.",
        ),
    ];
    let mut functions = Vec::new();
    let size = |s: Size| match s {
        Size::N => n,
        Size::NActive => na,
        Size::NPassive => np,
        Size::NOutputs => no,
        Size::R => r,
        Size::I | Size::M | Size::K | Size::TaskRows => {
            unreachable!("a mechanism module has no size {s:?}")
        }
    };
    functions.push(EmittedFunction::catalogued(
        F::ConstraintJacobian,
        "Constraint Jacobian `J_C = Ã J = ∂c/∂θ` (rows: `pose_1 − pose_k`, `(x, y, φ)` per chain \
         k = 2..m), R × N",
        "",
        matrix_program(d, &d.j_c),
        size,
    ));
    functions.push(EmittedFunction::catalogued(
        F::TaskJacobian,
        "Analytic Jacobian of the task `J_A = S_x A† J` (chain Jacobians averaged), N_OUTPUTS × N",
        "",
        matrix_program(d, &d.j_a),
        size,
    ));
    let mut det = program(d);
    let v = PolyBuilder::new(&mut det).poly(&d.det_j_cp);
    det.set_outputs(vec![v]);
    functions.push(EmittedFunction::catalogued(
        F::ConstraintDeterminant,
        "`det J_Cp`, the determinant of the passive columns of `J_C`: zero exactly at the \
         parallel (actuator) singularities, where the passive joints can move with the active \
         joints locked",
        "",
        det,
        size,
    ));
    // Each numerator with `det J_Cp` as row 0 of every column, in one program so that the
    // determinant and the adjugate share their minors.
    let numerator = |m: &crate::symbolic::Matrix| {
        let mut prog = program(d);
        let mut b = PolyBuilder::new(&mut prog);
        let det_v = b.poly(&d.det_j_cp);
        let vals = b.matrix(m);
        let rows = m.rows();
        let mut outs = Vec::with_capacity((rows + 1) * na);
        for a in 0..na {
            outs.push(det_v);
            outs.extend_from_slice(&vals[a * rows..(a + 1) * rows]);
        }
        prog.set_outputs(outs);
        prog
    };
    functions.push(EmittedFunction::catalogued(
        F::ReducedJacobianNumerator,
        "`det J_Cp` and the numerator `det(J_Cp) · J = det(J_Cp) J_Aa − J_Ap adj(J_Cp) J_Ca` of \
         the reduced Jacobian",
        &format!(
            "Row 0 of every column is `det J_Cp`; rows `1..=N_OUTPUTS` are the column of \
             `det(J_Cp) · J`. [`{}`] divides them.",
            F::ReducedJacobian.name()
        ),
        numerator(&d.reduced_numerator),
        size,
    ));
    functions.push(EmittedFunction::catalogued(
        F::PassiveMapNumerator,
        "`det J_Cp` and the numerator `−adj(J_Cp) J_Ca` of the passive map \
         `θ̇_p = −J_Cp⁻¹ J_Ca θ̇_a`",
        &format!(
            "Row 0 of every column is `det J_Cp`; rows `1..=N_PASSIVE` are the column of \
             `−adj(J_Cp) J_Ca`, in the order of [`PASSIVE`]. [`{}`] divides them.",
            F::PassiveMap.name()
        ),
        numerator(&d.passive_numerator),
        size,
    ));
    ModuleSpec {
        name: module_name.into(),
        doc: module_doc(d),
        joints: n,
        params: d
            .params
            .iter()
            .cloned()
            .zip(d.param_values.iter().copied())
            .collect(),
        consts,
        functions,
        controller: None,
        joint_limits: None,
        joint_ranges: Vec::new(),
        joint_speed_limits: Vec::new(),
        pose_and_jacobians: None,
        fused: Vec::new(),
        fma_at_run_time: false,
    }
}

fn module_doc(d: &MechanismDerivation) -> String {
    let joints: Vec<String> = d
        .joint_names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            format!(
                "`q[{k}]` = `{name}` ({}, {})",
                if d.active.contains(&k) {
                    "active"
                } else {
                    "passive"
                },
                if d.joint_is_linear[k] {
                    "prismatic, m"
                } else {
                    "revolute, rad"
                }
            )
        })
        .collect();
    let outputs: Vec<&str> = d.outputs.iter().map(|o| o.name()).collect();
    let passive: Vec<&str> = d
        .passive
        .iter()
        .map(|&k| d.joint_names[k].as_str())
        .collect();
    let active: Vec<&str> = d
        .active
        .iter()
        .map(|&k| d.joint_names[k].as_str())
        .collect();
    format!(
        "Closed-form reduced kinematics of the closed mechanism `{}`, derived symbolically by \
         trocar-codegen (equations of Freitas, Leite & Lizarralde, CBA 2010).\n\n\
         With `J_C = [J_Ca J_Cp]`, `J_A = [J_Aa J_Ap]` (5)–(6) and `J_Cp` invertible:\n\
         `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca = (det(J_Cp) J_Aa − J_Ap adj(J_Cp) J_Ca) / det(J_Cp)` (8) \
         and `θ̇_p = −adj(J_Cp) J_Ca θ̇_a / det(J_Cp)` (7), numerators and `det J_Cp` as \
         expanded polynomials.\n\n\
         Joints: {}.\n\n\
         Active columns: {}; passive rows of the passive map: {}; task outputs (rows of `J`): {}.\n\n\
         Every function takes **all** joint values `q`, active and passive: solve the passive \
         joints first (closed form where there is one, e.g. \
         `trocar_sim::closed_chain::four_bar::FourBar::passive`, or Newton's method, \
         `trocar_sim::closed_chain::Mechanism::solve_passive`). The functions that divide by \
         `det J_Cp` return `None` when it is zero or not finite, and never a NaN.\n\n\
         **Array order:** matrices are column-major, `[[T; rows]; cols]` (`a[col][row]`), \
         which is nalgebra's `ArrayStorage`.",
        d.name,
        joints.join(", "),
        active.join(", "),
        passive.join(", "),
        outputs.join(", "),
    )
}

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
        Scalar::Generic => quote!(<T: #rt::emitted::Real, const IN: usize, const OUT: usize>),
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
    real: Scalar,
    runtime: &Runtime,
) -> TokenStream {
    let items = emit::module_items_in(spec, real, runtime);
    let wrappers = wrapper_tokens(d, &Ty::new(real, runtime));
    quote! {
        #items
        #wrappers
    }
}

/// The whole module `pub mod <name> { ... }` with its documentation and lint attributes
/// ([`emit::wrap_module`]).
pub fn module_tokens(
    d: &MechanismDerivation,
    module_name: &str,
    real: Scalar,
    runtime: &Runtime,
) -> TokenStream {
    let spec = module_spec(d, module_name);
    emit::wrap_module(
        module_name,
        &spec.doc,
        module_items(d, &spec, real, runtime),
    )
}

/// The formatted module file (prettyplease, headed by the `@generated` line) of a mechanism,
/// named `module` or after the mechanism.
pub fn generate_mechanism_string(
    model: &MechanismModel,
    module: Option<&str>,
    real: Scalar,
    runtime: &Runtime,
) -> Result<String, Error> {
    let d = derive(model).map_err(Error::Description)?;
    for (k, name) in d.params.iter().enumerate() {
        if syn::parse_str::<Ident>(name).is_err() {
            return Err(Error::Description(
                MechanismError::new(
                    format!("parameters.{name}"),
                    format!(
                        "parameter {k} `{name}` is not a Rust identifier (a field of `Params`)"
                    ),
                )
                .into_description_error(model.file.as_deref()),
            ));
        }
    }
    let name = checked_module_name(&d.name, module)?;
    emit::format_file(module_tokens(&d, &name, real, runtime))
        .map_err(|e| Error::Internal(e.to_string()))
}
