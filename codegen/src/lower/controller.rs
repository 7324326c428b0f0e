//! The controller's data from a derivation: which parameter slides the constraint frame along
//! the constrained link, the task's rows, `m` and the link `i` ([`ControllerSpec`]), from which
//! the controller glue backend writes `StepKinematics`, `step_kinematics` and `Kinematics`.
//!
//! The constraint frame slides along the link when `g_ir = (R_ir, o + l_a d)` for one parameter
//! `l_a` with `R_ir` and `o` free of it and `d` a constant direction ([`shaft_parameter`]): the
//! thesis's `(I, (0, l_a, 0))` and a laparoscope's `(I, (0, 0, flange + l_a))` alike.

use crate::derivation::Derivation;
use crate::ir::ControllerSpec;
use crate::symbolic::{inverse_denominator, node_definition, Atom, Transform};

impl ControllerSpec {
    /// For a derivation with a constraint; `None` without one.
    pub fn of(d: &Derivation) -> Option<Self> {
        let c = d.constraint.as_ref()?;
        Some(ControllerSpec {
            offset: shaft_parameter(d),
            task: c.task.is_some(),
            task_rows: c.task.as_ref().map_or(6, |t| t.s.rows()),
            m: c.m,
            link: c.link,
        })
    }
}

/// The parameter that slides the constraint frame along a fixed line of the constrained link:
/// `g_ir = (R_ir, o + p d)` with `R_ir` and `o` free of `p` and `d` a nonzero constant. A
/// parameter named `l_a` is preferred; otherwise the only such parameter; `None` if there is
/// none or the choice is ambiguous.
pub fn shaft_parameter(d: &Derivation) -> Option<String> {
    let c = d.constraint.as_ref()?;
    let candidates: Vec<usize> = (0..d.params.len())
        .filter(|&k| slides_along_line(&c.g_ir, k))
        .collect();
    let k = match candidates.iter().find(|&&k| d.params[k] == "l_a") {
        Some(&k) => k,
        None if candidates.len() == 1 => candidates[0],
        None => return None,
    };
    Some(d.params[k].clone())
}

/// Whether `g` is `(R, o + p_k d)`: `R` free of parameter `k`, the translation affine in it with
/// constant coefficients, not all zero.
fn slides_along_line(g: &Transform, k: usize) -> bool {
    if g.rot.entries().iter().any(|e| e.params().contains(&k)) {
        return false;
    }
    let mut moves = false;
    for e in g.pos.entries() {
        for (m, _) in e.terms() {
            let mentions = m.factors().iter().any(|&(a, _)| match a {
                Atom::Param(p) => p as usize == k,
                Atom::Inv(id) => inverse_denominator(id).params().contains(&k),
                Atom::Node(id) => node_definition(id).params().contains(&k),
                _ => false,
            });
            if mentions {
                if m.factors() != [(Atom::Param(k as u16), 1)] {
                    return false;
                }
                moves = true;
            }
        }
    }
    moves
}
