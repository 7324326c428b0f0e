//! Fused functions: several catalogue outputs ([`Fused`]) as one program, walking the chain once
//! where the outputs allow (`g_0i` (2.21) at the end of the walk that builds `J^B_0i`, `g_0e` at
//! the end of the one that builds `J^B_0e`), or the outputs' own programs merged when that is
//! smaller; values the outputs share exist once (rule `hash_cons`).

use super::chain::{body_jacobian_walk, chain_product, paired_heads};
use super::form::cheaper;
use super::poly::{new_program, PolyBuilder};
use crate::derivation::Derivation;
use crate::error::Error;
use crate::ir::{EmittedFunction, FusedFunction, Program, ValueId};
use crate::symbolic::Matrix;
use trocar_model::catalogue::{Function as F, Fused};

/// The forms of `J^r_0e` and `J_c` their own functions are built from (the graph or its
/// expansion, [`graph_or_expanded_form`]), which a fused program builds again among its values.
#[derive(Default)]
pub(super) struct Forms {
    pub(super) jr: Option<Matrix>,
    pub(super) jc: Option<Matrix>,
}

/// Several catalogue outputs (`outputs`, in that order, each in its function's layout) as one
/// program, walking the chain once where the outputs allow: the walk that builds `J^B_0i` from
/// the constrained link's end ends with `g_0i` (2.21), the walk that builds `J^B_0e` ends with
/// `g_0e`, and `g_0e = g_0i · g_ie` takes one product more after the first; `J^r_0e` and `J_c`
/// are built from `forms` into the same program, every other output from its function's own
/// program (`functions`). Values the outputs share exist once (rule `hash_cons`).
pub(super) fn fused_walk_program(
    d: &Derivation,
    outputs: &[F],
    forms: &Forms,
    functions: &[EmittedFunction],
) -> Program {
    let mut prog = new_program(d);
    let want = |f: F| outputs.contains(&f);
    let mut values: Vec<(F, Vec<ValueId>)> = Vec::new();
    let mut g_0i = None;
    if let Some(c) = &d.constraint {
        if want(F::PartialBodyJacobian) || want(F::ConstrainedLinkKinematics) {
            let (cols, g) = body_jacobian_walk(d, &mut prog, c.link, None);
            values.push((F::PartialBodyJacobian, cols.into_iter().flatten().collect()));
            values.push((F::ConstrainedLinkKinematics, g.outputs()));
            g_0i = Some((c.link, g));
        }
    }
    let mut g_0e = None;
    if want(F::BodyJacobian) {
        let (cols, g) = body_jacobian_walk(d, &mut prog, d.n, Some(&d.end_effector));
        values.push((F::BodyJacobian, cols.into_iter().flatten().collect()));
        g_0e = Some(g);
    }
    if want(F::ForwardKinematics) {
        let g = match (g_0e, g_0i) {
            (Some(g), _) => g,
            (None, Some((link, g_0i))) => {
                let g_ie = chain_product(d, &mut prog, link..d.n, Some(&d.end_effector));
                g_0i.compose(&g_ie, &mut prog)
            }
            (None, None) => chain_product(d, &mut prog, 0..d.n, Some(&d.end_effector)),
        };
        values.push((F::ForwardKinematics, g.outputs()));
    }
    let mut b = PolyBuilder::new(&mut prog);
    for (f, form) in [
        (F::ConstrainedJacobian, &forms.jr),
        (F::ConstraintJacobianC, &forms.jc),
    ] {
        if let (true, Some(m)) = (want(f), form) {
            values.push((f, b.matrix(m)));
        }
    }
    for &f in outputs {
        if values.iter().all(|(g, _)| *g != f) {
            let v = prog.import(&function_of(functions, f).program);
            values.push((f, v));
        }
    }
    let outs = outputs
        .iter()
        .flat_map(|f| {
            let (_, v) = values.iter().find(|(g, _)| g == f).expect("built above");
            v.iter().copied()
        })
        .collect();
    prog.set_outputs(outs);
    prog
}

/// The emitted function `f` among `functions`.
fn function_of(functions: &[EmittedFunction], f: F) -> &EmittedFunction {
    functions
        .iter()
        .find(|x| x.name == f.name())
        .expect("a fused output is a function of the module")
}

/// The fused program of `outputs`: [`fused_walk_program`], or the outputs' own programs built
/// into one when that is smaller.
fn fused_program(
    d: &Derivation,
    outputs: &[F],
    forms: &Forms,
    functions: &[EmittedFunction],
) -> Program {
    let walked = fused_walk_program(d, outputs, forms, functions);
    let mut merged = new_program(d);
    let mut outs = Vec::new();
    for &f in outputs {
        outs.extend(merged.import(&function_of(functions, f).program));
    }
    merged.set_outputs(outs);
    cheaper(walked, merged)
}

/// The fused functions of a module: `defaults` with `requests` (a request named like a default
/// replaces it), each checked: its name free ([`Fused::check_name`]), its outputs functions of
/// the module, none twice.
pub(super) fn fused_functions(
    d: &Derivation,
    requests: &[Fused],
    forms: &Forms,
    functions: &[EmittedFunction],
) -> Result<Vec<FusedFunction>, Error> {
    let mut list: Vec<Fused> = Fused::defaults(d.constraint.is_some())
        .into_iter()
        .filter(|f| requests.iter().all(|r| r.name != f.name))
        .collect();
    for (k, r) in requests.iter().enumerate() {
        let error = |message: String| Error::Function {
            name: r.name.clone(),
            message,
        };
        Fused::check_name(&r.name).map_err(error)?;
        if requests[..k].iter().any(|x| x.name == r.name) {
            return Err(error("requested twice".into()));
        }
        if r.outputs.is_empty() {
            return Err(error(
                "no outputs: name at least one catalogue function".into(),
            ));
        }
        for (j, f) in r.outputs.iter().enumerate() {
            if r.outputs[..j].contains(f) {
                return Err(error(format!("output `{}` given twice", f.short_name())));
            }
            if functions.iter().all(|x| x.name != f.name()) {
                let have: Vec<String> = functions
                    .iter()
                    .map(|x| {
                        let g = F::from_name(&x.name).expect("catalogued");
                        format!("{} ({})", g.short_name(), g.name())
                    })
                    .collect();
                return Err(error(format!(
                    "output `{}` ({}) is not a function of this module; its functions are: {}",
                    f.short_name(),
                    f.name(),
                    have.join(", ")
                )));
            }
        }
        list.push(r.clone());
    }
    Ok(list
        .iter()
        .map(|r| {
            let outputs: Vec<&EmittedFunction> = r
                .outputs
                .iter()
                .map(|&f| function_of(functions, f))
                .collect();
            let mut f = FusedFunction::new(
                &r.name,
                &outputs,
                fused_program(d, &r.outputs, forms, functions),
            );
            let link_pose_and_jacobian = r.outputs.len() == 2
                && r.outputs.contains(&F::ConstrainedLinkKinematics)
                && r.outputs.contains(&F::PartialBodyJacobian);
            if let (true, Some(c)) = (link_pose_and_jacobian, &d.constraint) {
                f.paired_heads = paired_heads(d, c.link);
            }
            f
        })
        .collect())
}
