//! From the symbolic engine's canonical polynomials ([`crate::symbolic::Poly`]) to program
//! values.
//!
//! A canonical polynomial is a sum of monomials with rational coefficients, so the step is
//! direct: each term becomes a [`Term`] (coefficient rounded to the nearest `f64`) and the sum is
//! built by [`Program::sum_of_monomials`] (Horner factoring, CSE). An `Inv(P)` atom becomes one
//! shared division `1 / P` per program, a `Node` atom (a shared subexpression) one value.
//! Rigid transforms become [`NumTransform`]s, composed as (2.21).

use crate::derivation::Derivation;
use crate::ir::{Factor, Program, Term, ValueId};
use crate::symbolic::{self, inverse_denominator, node_definition, Matrix, Poly, Transform};
use std::collections::HashMap;

/// Builds polynomials into one program, sharing `1/P` for each `Inv` atom and one value for each
/// shared subexpression (`Node` atom).
pub struct PolyBuilder<'a> {
    prog: &'a mut Program,
    inverses: HashMap<u32, ValueId>,
    nodes: HashMap<u32, ValueId>,
}

impl<'a> PolyBuilder<'a> {
    /// A builder writing into `prog` (whose parameter indices are the derivation's).
    pub fn new(prog: &'a mut Program) -> Self {
        PolyBuilder {
            prog,
            inverses: HashMap::new(),
            nodes: HashMap::new(),
        }
    }

    /// The program.
    pub fn program(&mut self) -> &mut Program {
        self.prog
    }

    fn atom(&mut self, a: symbolic::Atom) -> Factor {
        match a {
            symbolic::Atom::Sin(k) => Factor::Sin(k as usize),
            symbolic::Atom::Cos(k) => Factor::Cos(k as usize),
            symbolic::Atom::Joint(k) => Factor::Joint(k as usize),
            symbolic::Atom::Param(p) => Factor::Param(p as usize),
            symbolic::Atom::Inv(id) => {
                if let Some(&v) = self.inverses.get(&id) {
                    return Factor::Value(v);
                }
                let den = inverse_denominator(id);
                let d = self.poly(&den);
                let one = self.prog.constant(1.0);
                let v = self.prog.div(one, d);
                self.inverses.insert(id, v);
                Factor::Value(v)
            }
            symbolic::Atom::Node(id) => {
                if let Some(&v) = self.nodes.get(&id) {
                    return Factor::Value(v);
                }
                let v = self.poly(&node_definition(id));
                self.nodes.insert(id, v);
                Factor::Value(v)
            }
        }
    }

    /// One polynomial as a value.
    pub fn poly(&mut self, p: &Poly) -> ValueId {
        let terms: Vec<Term> = p
            .terms()
            .iter()
            .map(|(m, c)| {
                let factors: Vec<(Factor, i32)> = m
                    .factors()
                    .iter()
                    .map(|&(a, e)| (self.atom(a), e))
                    .collect();
                Term::new(c.to_f64(), factors)
            })
            .collect();
        self.prog.sum_of_monomials(&terms)
    }

    /// A matrix as values, **column-major**.
    pub fn matrix(&mut self, m: &Matrix) -> Vec<ValueId> {
        let mut out = Vec::with_capacity(m.rows() * m.cols());
        for c in 0..m.cols() {
            for r in 0..m.rows() {
                out.push(self.poly(m.get(r, c)));
            }
        }
        out
    }

    /// A transform as values: `R` row-major `[[v; 3]; 3]` and `p`.
    pub fn transform(&mut self, t: &Transform) -> NumTransform {
        let mut rot = [[ValueId(0); 3]; 3];
        let mut pos = [ValueId(0); 3];
        for (i, row) in rot.iter_mut().enumerate() {
            for (j, e) in row.iter_mut().enumerate() {
                *e = self.poly(t.rot.get(i, j));
            }
            pos[i] = self.poly(t.pos.get(i, 0));
        }
        NumTransform { rot, pos }
    }
}

/// A rigid transform whose entries are program values (`rot[row][col]`).
#[derive(Clone, Copy, Debug)]
pub struct NumTransform {
    /// `R`, row-major.
    pub rot: [[ValueId; 3]; 3],
    /// `p`.
    pub pos: [ValueId; 3],
}

impl NumTransform {
    /// `g h = (R_g R_h, R_g p_h + p_g)` (2.21).
    pub fn compose(&self, h: &NumTransform, p: &mut Program) -> NumTransform {
        let mut rot = [[ValueId(0); 3]; 3];
        let mut pos = [ValueId(0); 3];
        for (i, row) in rot.iter_mut().enumerate() {
            for (j, e) in row.iter_mut().enumerate() {
                let col = [h.rot[0][j], h.rot[1][j], h.rot[2][j]];
                *e = dot(p, &self.rot[i], &col);
            }
            let d = dot(p, &self.rot[i], &h.pos);
            pos[i] = p.add(d, self.pos[i]);
        }
        NumTransform { rot, pos }
    }

    /// Outputs in the layout [`Transform`](crate::ir::Layout::Transform): `R` column-major,
    /// then `p`.
    pub fn outputs(&self) -> Vec<ValueId> {
        let mut v = Vec::with_capacity(12);
        for j in 0..3 {
            for i in 0..3 {
                v.push(self.rot[i][j]);
            }
        }
        v.extend_from_slice(&self.pos);
        v
    }
}

/// `a · b`.
fn dot(p: &mut Program, a: &[ValueId; 3], b: &[ValueId; 3]) -> ValueId {
    let mut acc = p.constant(0.0);
    for k in 0..3 {
        let m = p.mul(a[k], b[k]);
        acc = p.add(acc, m);
    }
    acc
}

/// `a × b`.
pub(super) fn cross(p: &mut Program, a: &[ValueId; 3], b: &[ValueId; 3]) -> [ValueId; 3] {
    let mut out = [ValueId(0); 3];
    for (i, o) in out.iter_mut().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let x = p.mul(a[j], b[k]);
        let y = p.mul(a[k], b[j]);
        *o = p.sub(x, y);
    }
    out
}

/// Rᵀ x.
pub(super) fn rot_t_apply(
    p: &mut Program,
    r: &[[ValueId; 3]; 3],
    x: &[ValueId; 3],
) -> [ValueId; 3] {
    let mut out = [ValueId(0); 3];
    for (j, o) in out.iter_mut().enumerate() {
        *o = dot(p, &[r[0][j], r[1][j], r[2][j]], x);
    }
    out
}

/// An empty program over the derivation's parameters (their indices are the program's).
pub(super) fn new_program(d: &Derivation) -> Program {
    Program::new(d.params.clone())
}

/// A program with the expanded polynomials of `m` as outputs (column-major).
pub fn matrix_program(d: &Derivation, m: &Matrix) -> Program {
    let mut prog = new_program(d);
    let outs = PolyBuilder::new(&mut prog).matrix(m);
    prog.set_outputs(outs);
    prog
}

/// A rigid transform's expanded entries as a program, outputs in the layout
/// [`Transform`](crate::ir::Layout::Transform).
pub fn transform_program(d: &Derivation, t: &Transform) -> Program {
    let mut prog = new_program(d);
    let values = PolyBuilder::new(&mut prog).transform(t);
    prog.set_outputs(values.outputs());
    prog
}
