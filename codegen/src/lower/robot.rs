//! Lowering of a serial robot's [`Derivation`] to its [`ModuleSpec`]: the constants (`N`, `I`,
//! `R`, `M`, `K`, `TASK_ROWS`), one program per catalogue function (forward kinematics (2.21),
//! body Jacobians (2.45), `J^r_0e` (3.15), `J_c` (3.33), `H`, `Λ#` (3.3), `Λ†` (3.31), the
//! constraint frame, the manipulability (3.36), the task's `S` and `S J^r_0e`), each in the
//! cheaper of its product and expanded forms, the fused functions, `pose_and_jacobians` when one
//! program is smaller than four, and the controller's data.

use super::chain::{body_jacobian_product_program, fk_product_program};
use super::form::{cheaper, graph_or_expanded, graph_or_expanded_form};
use super::fused::{fused_functions, fused_walk_program, Forms};
use super::manipulability::{manipulability_graph_or_expanded, manipulability_programs};
use super::poly::{matrix_program, transform_program};
use crate::derivation::Derivation;
use crate::error::Error;
use crate::ir::{ConstItem, ControllerSpec, EmittedFunction, ModuleSpec};
use trocar_model::catalogue::{Function as F, Fused, Size};

/// The module for a derivation: constants, `Params`, `JointTrig` and the functions
/// `forward_kinematics`, `body_jacobian` and, with a constraint, `constrained_jacobian`,
/// `constraint_jacobian_c`, `partial_body_jacobian`, `forward_kinematics_i`, `manipulability`,
/// `manipulability_squared`, with the default fused functions ([`Fused::defaults`]).
pub fn module_spec(d: &Derivation, module_name: &str) -> ModuleSpec {
    module_spec_with(d, module_name, &[]).expect("the default fused functions are valid")
}

/// [`module_spec`] with the fused functions `requests` besides the defaults (a request named like
/// a default replaces it); [`Error::Function`] when a request's name is taken or its outputs are
/// not functions of the module.
pub fn module_spec_with(
    d: &Derivation,
    module_name: &str,
    requests: &[Fused],
) -> Result<ModuleSpec, Error> {
    let n = d.n;
    let mut consts = vec![ConstItem {
        name: "N".into(),
        value: n,
        doc: "Number of joints `n` (length of `q`, base first).".into(),
    }];
    let mut functions = Vec::new();
    let size = |s: Size| match (s, &d.constraint) {
        (Size::N, _) => n,
        (Size::I, Some(c)) => c.link,
        (Size::R, Some(c)) => c.r,
        (Size::M, Some(c)) => c.m,
        (Size::K, Some(c)) => 6 - c.r,
        (Size::TaskRows, Some(c)) => c.task.as_ref().map_or(6, |t| t.s.rows()),
        _ => unreachable!("a serial module has no size {s:?}"),
    };

    let fk_product = fk_product_program(d, n, Some(&d.end_effector));
    let fk = match &d.fk_e {
        Some(fk_e) => cheaper(transform_program(d, fk_e), fk_product),
        None => fk_product,
    };
    let fk_len = fk.live_len();
    functions.push(EmittedFunction::catalogued(
        F::ForwardKinematics,
        "Forward kinematics `g_0e(q) = (R_0e, p_0e)` of the end effector",
        "",
        fk,
        size,
    ));
    let jb_product = body_jacobian_product_program(d, n, Some(&d.end_effector));
    let jb = match &d.body_jacobian_e {
        Some(m) => cheaper(graph_or_expanded(d, m), jb_product),
        None => jb_product,
    };
    functions.push(EmittedFunction::catalogued(
        F::BodyJacobian,
        "Body Jacobian `J^B_0e(q)` of the whole chain, 6 × N (twist order `(v, ω)`)",
        "",
        jb,
        size,
    ));

    let mut pose_and_jacobians = None;
    let mut forms = Forms::default();
    if let Some(c) = &d.constraint {
        consts.push(ConstItem {
            name: "I".into(),
            value: c.link,
            doc: "The constrained link `i` (1-based): joints `1..=I` come before the constraint."
                .into(),
        });
        consts.push(ConstItem {
            name: "R".into(),
            value: c.r,
            doc: "Number of constrained directions `r` (rows of `H`).".into(),
        });
        consts.push(ConstItem {
            name: "M".into(),
            value: c.m,
            doc: "Number of columns of `J^r_0e`: `m = 6 − r + n − i`.".into(),
        });
        consts.push(ConstItem {
            name: "K".into(),
            value: 6 - c.r,
            doc: "Number of columns of `Λ#`: `k = 6 − r`, the free directions of the constrained \
                  link's twist."
                .into(),
        });
        let basis = format!(
            "Null-space basis `Λ#` ([`lambda_null_space`]): {}. Columns: the {} components of \
             `v0i`, then joints {}..={}.",
            basis_label(c.basis),
            6 - c.r,
            c.link + 1,
            n
        );
        let (jr_form, jr) = graph_or_expanded_form(d, &c.jr);
        let (jc_form, jc) = graph_or_expanded_form(d, &c.jc);
        let step_separately = [fk_len, jr.live_len(), jc.live_len()];
        functions.push(EmittedFunction::catalogued(
            F::ConstrainedJacobian,
            "Constrained Jacobian `J^r_0e = [Ad_{g_ei} Λ# | J^B_0e2]`, 6 × M",
            &basis,
            jr,
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::ConstraintJacobianC,
            "Jacobian of the moving constraint `J_c = Ad_{g_ei} Λ†`, 6 × R",
            "",
            jc,
            size,
        ));
        let jbi = cheaper(
            graph_or_expanded(d, &c.body_jacobian_i),
            body_jacobian_product_program(d, c.link, None),
        );
        // One program for the step's g_0e, J^B_0i, J^r and J_c where it is smaller than the
        // four functions' together.
        forms = Forms {
            jr: Some(jr_form),
            jc: Some(jc_form),
        };
        let fused = fused_walk_program(
            d,
            &[
                F::ForwardKinematics,
                F::PartialBodyJacobian,
                F::ConstrainedJacobian,
                F::ConstraintJacobianC,
            ],
            &forms,
            &functions,
        );
        pose_and_jacobians = (fused.live_len()
            < step_separately.iter().sum::<usize>() + jbi.live_len())
        .then_some(fused);
        functions.push(EmittedFunction::catalogued(
            F::PartialBodyJacobian,
            "Partial body Jacobian `J^B_0i(q_1..q_i)` of the chain cut at the constrained link, 6 × I",
            "",
            jbi,
            size,
        ));
        let fki = cheaper(
            transform_program(d, &c.fk_i),
            fk_product_program(d, c.link, None),
        );
        functions.push(EmittedFunction::catalogued(
            F::ConstrainedLinkKinematics,
            "Forward kinematics `g_0i(q_1..q_i) = (R_0i, p_0i)` of the constrained link's frame",
            "",
            fki,
            size,
        ));
        // Of what the task commands: S J^r with a task, J^r without.
        let (w, w2) = match (&c.manipulability, &c.task) {
            (Some(m), _) => manipulability_programs(d, &m.form),
            (None, Some(t)) => manipulability_graph_or_expanded(d, &t.jacobian),
            (None, None) => manipulability_graph_or_expanded(d, &c.jr),
        };
        let (w_doc, w2_doc) = if c.task.is_some() {
            (
                "Manipulability `w = sqrt(det((S J^r)(S J^r)ᵀ))` of the task Jacobian \
                 ([`constrained_task_jacobian`]; `|det S J^r|` when square, the Cauchy–Binet \
                 sum of squared maximal minors with one spare column, the product of the row \
                 norms left by Gram–Schmidt when wider)",
                "Squared manipulability `w² = det((S J^r)(S J^r)ᵀ)` of the task Jacobian (no \
                 square root, for thresholds such as (3.44))",
            )
        } else {
            (
                "Manipulability `w = sqrt(det(J^r J^rᵀ))` of the constrained Jacobian (`|det J^r|` \
                 when square, the Cauchy–Binet sum of squared maximal minors with one spare \
                 column, the product of the row norms left by Gram–Schmidt when wider)",
                "Squared manipulability `w² = det(J^r J^rᵀ)` (no square root, for thresholds such as \
                 (3.44))",
            )
        };
        functions.push(EmittedFunction::catalogued(
            F::Manipulability,
            w_doc,
            "",
            w,
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::ManipulabilitySquared,
            w2_doc,
            "",
            w2,
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::ConstraintSelection,
            "The constrained directions `H`, R × 6: the constraint is `H V^B_0r = 0`",
            "",
            matrix_program(d, &c.h),
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::LambdaNullSpace,
            "Null-space basis `Λ#` of `Λ = H Ad_{g_ri}` (3.3), 6 × K: `V^B_0i = Λ# v0i`",
            "",
            matrix_program(d, &c.lambda_sharp),
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::LambdaPinv,
            "`Λ† = Λᵀ (Λ Λᵀ)⁻¹`, 6 × R",
            "",
            matrix_program(d, &c.lambda_pinv),
            size,
        ));
        functions.push(EmittedFunction::catalogued(
            F::ConstraintFrame,
            "The constraint frame `g_ir = (R_ir, p_ir)`: `F_r` in the constrained link's frame `F_i`",
            "",
            transform_program(d, &c.g_ir),
            size,
        ));
        if let Some(t) = &c.task {
            consts.push(ConstItem {
                name: "TASK_ROWS".into(),
                value: t.s.rows(),
                doc: "Number of task rows `t` (rows of `S`, the `[task]` selection).".into(),
            });
            functions.push(EmittedFunction::catalogued(
                F::TaskSelection,
                "The task selection `S`, TASK_ROWS × 6: the rows of the end-effector body twist \
                 `V^B_0e = (v, ω)` (components in the end-effector frame) that the task commands",
                "",
                matrix_program(d, &t.s),
                size,
            ));
            functions.push(EmittedFunction::catalogued(
                F::ConstrainedTaskJacobian,
                "Task Jacobian `S J^r_0e`, TASK_ROWS × M: the commanded rows of the end-effector \
                 twist per unit of `(v0i, θ̇_j..θ̇_n)`",
                "",
                graph_or_expanded(d, &t.jacobian),
                size,
            ));
        }
    }

    let fused = fused_functions(d, requests, &forms, &functions)?;
    Ok(ModuleSpec {
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
        controller: ControllerSpec::of(d),
        joint_limits: d.joint_limits.clone(),
        joint_ranges: d.joint_ranges.clone(),
        joint_speed_limits: d.joint_speed_limits.clone(),
        joint_acceleration_limits: d.joint_acceleration_limits.clone(),
        joint_jerk_limits: d.joint_jerk_limits.clone(),
        pose_and_jacobians,
        fused,
        fma_at_run_time: false,
    })
}

fn module_doc(d: &Derivation) -> String {
    let mut s = format!(
        "Closed-form kinematics of `{}` ({} joints), derived symbolically by trocar-codegen.\n\n\
         Every function takes the joint values `q` (base first, radians or metres) and the \
         named parameters ([`Params`]); each has a `_trig` variant taking a [`JointTrig`] so \
         one set of `sin_cos` calls serves a whole control step.\n\n\
         **Array order:** matrices are column-major, `[[T; rows]; cols]` (`a[col][row]`), \
         which is nalgebra's `ArrayStorage`: \
         `SMatrix::<T, rows, cols>::from_data(ArrayStorage(a))` is free.",
        d.name, d.n
    );
    if let Some(c) = &d.constraint {
        s.push_str(&format!(
            "\n\nConstraint at link {} with r = {} constrained direction(s); `J^r_0e` is 6 × {}.",
            c.link, c.r, c.m
        ));
        if let Some(t) = &c.task {
            s.push_str(&format!(
                " The task commands {} row(s) of the end-effector twist (`S J^r_0e` is {} × {}).",
                t.s.rows(),
                t.s.rows(),
                c.m
            ));
        }
    }
    s
}

/// The basis's name in the emitted documentation (the names the generator used before the basis
/// type moved to `trocar::constraint`; kept so that emitted code stays byte-identical).
fn basis_label(b: crate::derivation::NullSpaceBasis) -> &'static str {
    use crate::derivation::NullSpaceBasis;
    match b {
        NullSpaceBasis::Unidirectional => "the thesis's (3.23), `ω_z = v_x / l_a`",
        NullSpaceBasis::Bidirectional => {
            "the thesis's (3.27), `ω_x = −v_z / l_a`, `ω_z = v_x / l_a`"
        }
        NullSpaceBasis::Computed => {
            "`Ad_{g_ir} N_H`, `N_H` the null basis of `H` from its reduced row echelon form (one \
             column per free coordinate, increasing)"
        }
    }
}
