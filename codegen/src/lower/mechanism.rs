//! Lowering of a closed mechanism ([`MechanismDerivation`], Freitas, Leite & Lizarralde, CBA
//! 2010) to a [`ModuleSpec`]: constants `N`, `N_ACTIVE`, `N_PASSIVE`, `N_OUTPUTS`, `R` and the
//! polynomial functions `J_C` (17)–(19), `J_A`, `det J_Cp` and the numerators of the reduced
//! Jacobian (8) and of the passive map (7), each with `det J_Cp` as row 0 of every column, as
//! programs ([`PolyBuilder`]: CSE, Horner factoring). The Rust backend adds the wrappers that
//! divide by `det J_Cp`.

use super::poly::PolyBuilder;
use crate::closed_chain::MechanismDerivation;
use crate::ir::{ConstItem, EmittedFunction, ModuleSpec, Program};
use crate::symbolic::Matrix;
use trocar_model::catalogue::{Function as F, Size};

fn program(d: &MechanismDerivation) -> Program {
    Program::new(d.params.clone())
}

fn matrix_program(d: &MechanismDerivation, m: &Matrix) -> Program {
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
    let numerator = |m: &Matrix| {
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
        joint_acceleration_limits: Vec::new(),
        joint_jerk_limits: Vec::new(),
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
