//! Which form of a function is lowered: of two programs for the same values (a matrix in graph
//! form or its canonical expansion, the product form of the chain or the expanded polynomials),
//! the one with fewer live operations. The two are equal as functions (the expanded form is
//! what the derivation's symbolic tests check).

use super::poly::matrix_program;
use crate::derivation::Derivation;
use crate::ir::Program;
use crate::symbolic::{Matrix, Poly};

/// Most terms in all of a matrix in graph form that [`graph_or_expanded`] writes out to compare
/// with the graph.
pub(super) const REEXPANSION_BUDGET: usize = 1_000;

/// The program of `m`, a matrix that may hold shared subexpressions (the graph form of a long or
/// generic chain, [`crate::derivation::SHARE_TERMS`]): when its canonical expansion is small, the
/// program of that expansion is built as well and the one with fewer operations kept (a chain
/// of moderate length often factors better expanded; a long one only as a graph).
pub(super) fn graph_or_expanded(d: &Derivation, m: &Matrix) -> Program {
    graph_or_expanded_form(d, m).1
}

/// [`graph_or_expanded`] with the form it chose (`m` itself or its expansion).
pub(super) fn graph_or_expanded_form(d: &Derivation, m: &Matrix) -> (Matrix, Program) {
    let graph = matrix_program(d, m);
    if !m.entries().iter().any(Poly::has_nodes) {
        return (m.clone(), graph);
    }
    match crate::derivation::expanded_within(m, REEXPANSION_BUDGET) {
        Some(e) => {
            let expanded = matrix_program(d, &e);
            cheaper_by((m.clone(), graph), (e, expanded), |form| &form.1)
        }
        None => (m.clone(), graph),
    }
}

pub(super) fn cheaper(a: Program, b: Program) -> Program {
    cheaper_by(a, b, |p| p)
}

/// Of two forms, the one whose program (`program(form)`) has fewer live operations; `a` on a
/// tie.
pub(super) fn cheaper_by<T>(a: T, b: T, program: impl Fn(&T) -> &Program) -> T {
    if program(&b).live_len() < program(&a).live_len() {
        b
    } else {
        a
    }
}
