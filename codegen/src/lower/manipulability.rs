//! The manipulability `w = sqrt(det(J Jᵀ))` (3.36) and `w²` as programs: from the derivation's
//! closed form (`|det J|` or the square root of a sum of squared minors), or, without one, from
//! the program values of `J^r` (or of the task Jacobian `S J^r`) by Cauchy–Binet with memoised
//! minors or by modified Gram–Schmidt.

use super::form::{cheaper_by, REEXPANSION_BUDGET};
use super::poly::{new_program, PolyBuilder};
use crate::derivation::{Derivation, ManipulabilityForm};
use crate::ir::{Program, ValueId};
use crate::symbolic::{Matrix, Poly};
use std::collections::HashMap;

/// [`manipulability_from_jr`] of `j` and, as in [`graph_or_expanded`], of its small canonical
/// expansion; the pair with fewer operations is kept.
pub(super) fn manipulability_graph_or_expanded(d: &Derivation, j: &Matrix) -> (Program, Program) {
    let graph = manipulability_from_jr(d, j);
    if !j.entries().iter().any(Poly::has_nodes) {
        return graph;
    }
    match crate::derivation::expanded_within(j, REEXPANSION_BUDGET) {
        Some(e) => cheaper_by(graph, manipulability_from_jr(d, &e), |w| &w.0),
        None => graph,
    }
}

pub(super) fn manipulability_programs(
    d: &Derivation,
    form: &ManipulabilityForm,
) -> (Program, Program) {
    let mut w = new_program(d);
    let mut w2 = new_program(d);
    match form {
        ManipulabilityForm::AbsDet(det) => {
            let v = PolyBuilder::new(&mut w).poly(det);
            let a = w.abs(v);
            w.set_outputs(vec![a]);
            let v = PolyBuilder::new(&mut w2).poly(det);
            let s = w2.mul(v, v);
            w2.set_outputs(vec![s]);
        }
        ManipulabilityForm::SqrtSumOfSquares(minors) => {
            for prog in [&mut w, &mut w2] {
                let mut b = PolyBuilder::new(prog);
                let vals: Vec<ValueId> = minors.iter().map(|(_, m)| b.poly(m)).collect();
                let mut acc = prog.constant(0.0);
                for v in vals {
                    let s = prog.mul(v, v);
                    acc = prog.add(acc, s);
                }
                prog.set_outputs(vec![acc]);
            }
            let s = w.outputs()[0];
            let r = w.sqrt(s);
            w.set_outputs(vec![r]);
        }
    }
    (w, w2)
}

/// Manipulability when the derivation has no closed form: from the program values of `J^r`
/// (`t × m`, or the task Jacobian).
///
/// With at most one spare column ([`crate::derivation::minors_apply`]): `det(J Jᵀ) = Σ_S
/// det(J[:, S])²` over the `t`-column subsets `S` (Cauchy–Binet), each minor by Laplace expansion
/// along the rows with the sub-minors of every column subset memoised, so they are shared
/// between minors; division-free. Wider: [`manipulability_by_gram_schmidt`]. Returns the
/// programs of `w` and `w²`.
pub fn manipulability_from_jr(d: &Derivation, jr: &Matrix) -> (Program, Program) {
    if !crate::derivation::minors_apply(jr.rows(), jr.cols()) {
        return manipulability_by_gram_schmidt(d, jr);
    }
    let mut w2 = new_program(d);
    let vals = PolyBuilder::new(&mut w2).matrix(jr);
    let (rows, cols) = (jr.rows(), jr.cols());
    let entry = |r: usize, c: usize| vals[c * rows + r];
    let mut memo: HashMap<u64, ValueId> = HashMap::new();
    let mut acc = w2.constant(0.0);
    for mask in 0u64..(1u64 << cols) {
        if mask.count_ones() as usize == rows {
            let m = minor(&mut w2, &entry, &mut memo, mask);
            let sq = w2.mul(m, m);
            acc = w2.add(acc, sq);
        }
    }
    w2.set_outputs(vec![acc]);
    let mut w = w2.clone();
    let r = w.sqrt(acc);
    w.set_outputs(vec![r]);
    (w, w2)
}

/// Manipulability of a wide `t × m` Jacobian by modified Gram–Schmidt on its rows:
/// `v_k = row_k − Σ_{j<k} (q_j · row_k) q_j` (each projection removed from the running `v_k`),
/// `r_k = ‖v_k‖`, `q_k = v_k / r_k`; then `J = R Q` with `R` lower triangular and
/// `w = sqrt(det(J Jᵀ)) = Π r_k` (3.36). About `t² m` products, `t` square roots and `t`
/// divisions, against `C(m, t)` minors for Cauchy–Binet; `R` is as accurate as Householder's
/// (modified Gram–Schmidt loses only `Q`'s orthogonality). At a singular configuration an
/// `r_k` is 0 and the next `q_k` is not finite: the emitted manipulability then returns 0 (its
/// rule for values that are not finite). Returns the programs of `w` and `w²`.
pub fn manipulability_by_gram_schmidt(d: &Derivation, j: &Matrix) -> (Program, Program) {
    let mut w = new_program(d);
    let vals = PolyBuilder::new(&mut w).matrix(j);
    let (rows, cols) = (j.rows(), j.cols());
    let mut q: Vec<Vec<ValueId>> = Vec::with_capacity(rows);
    let mut product = w.constant(1.0);
    for k in 0..rows {
        let mut v: Vec<ValueId> = (0..cols).map(|c| vals[c * rows + k]).collect();
        for qj in &q {
            let mut dot = w.constant(0.0);
            for c in 0..cols {
                let t = w.mul(qj[c], v[c]);
                dot = w.add(dot, t);
            }
            for c in 0..cols {
                let t = w.mul(dot, qj[c]);
                v[c] = w.sub(v[c], t);
            }
        }
        let mut norm2 = w.constant(0.0);
        for &x in &v {
            let t = w.mul(x, x);
            norm2 = w.add(norm2, t);
        }
        let r = w.sqrt(norm2);
        product = w.mul(product, r);
        if k + 1 < rows {
            let qk = v.iter().map(|&x| w.div(x, r)).collect();
            q.push(qk);
        }
    }
    let mut w2 = w.clone();
    w.set_outputs(vec![product]);
    let sq = w2.mul(product, product);
    w2.set_outputs(vec![sq]);
    (w, w2)
}

/// Determinant of rows `0..|mask|` and the columns in `mask` (increasing), Laplace along the last
/// row, memoised by column mask.
fn minor(
    p: &mut Program,
    entry: &dyn Fn(usize, usize) -> ValueId,
    memo: &mut HashMap<u64, ValueId>,
    mask: u64,
) -> ValueId {
    if mask == 0 {
        return p.constant(1.0);
    }
    if let Some(&v) = memo.get(&mask) {
        return v;
    }
    let k = mask.count_ones() as usize;
    let row = k - 1;
    let mut acc = p.constant(0.0);
    let mut pos = 0;
    for c in 0..64 {
        if mask & (1u64 << c) == 0 {
            continue;
        }
        let sub = minor(p, entry, memo, mask & !(1u64 << c));
        let t = p.mul(entry(row, c), sub);
        // Sign of the cofactor of (row, pos) with row = k − 1.
        acc = if (row + pos) % 2 == 0 {
            p.add(acc, t)
        } else {
            p.sub(acc, t)
        };
        pos += 1;
    }
    memo.insert(mask, acc);
    acc
}
