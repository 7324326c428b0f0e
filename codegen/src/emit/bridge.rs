//! From the symbolic engine's canonical polynomials ([`crate::symbolic::Poly`]) to programs, and
//! from a [`Derivation`] to a [`ModuleSpec`].
//!
//! A canonical polynomial is a sum of monomials with rational coefficients, so the bridge is
//! direct: each term becomes a [`Term`] (coefficient rounded to the nearest `f64`) and the sum is
//! built by [`Program::sum_of_monomials`] (Horner factoring, CSE). An `Inv(P)` atom becomes one
//! shared division `1 / P` per program.
//!
//! Forward kinematics is built in **product form** `T_1 ⋯ T_n g_ne` from the per-joint
//! transforms ([`Derivation::joint_transforms`]), and each body-Jacobian column
//! `Ad⁻¹_{g_ke} ξ_k = (R_keᵀ (v_k + ω_k × p_ke), R_keᵀ ω_k)` from the suffix products
//! `g_ke = T_{k+1} ⋯ T_n g_ne`, whenever that program is cheaper than the expanded polynomials
//! (both are built and the one with fewer live operations is kept); the two are equal as
//! functions (the expanded form is what the derivation's symbolic tests check). The per-joint
//! transforms are those of the turned link frames ([`Derivation::frame_turns`]): a product that
//! starts or ends at a link turns there ([`Derivation::frame_turn`],
//! [`Derivation::turned_back`]).

use super::program::{Factor, Program, Term, ValueId};
use super::rust::{ConstItem, EmittedFunction, FusedFunction, ModuleSpec};
use crate::derivation::{Derivation, ManipulabilityForm};
use crate::error::Error;
use crate::symbolic::{self, inverse_denominator, node_definition, Matrix, Poly, Transform};
use std::collections::HashMap;
use trocar_model::catalogue::{Function as F, Fused, Size};

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

    /// Outputs in the [`super::Layout::Transform`] layout: `R` column-major, then `p`.
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

fn dot(p: &mut Program, a: &[ValueId; 3], b: &[ValueId; 3]) -> ValueId {
    let mut acc = p.constant(0.0);
    for k in 0..3 {
        let m = p.mul(a[k], b[k]);
        acc = p.add(acc, m);
    }
    acc
}

fn cross(p: &mut Program, a: &[ValueId; 3], b: &[ValueId; 3]) -> [ValueId; 3] {
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
fn rot_t_apply(p: &mut Program, r: &[[ValueId; 3]; 3], x: &[ValueId; 3]) -> [ValueId; 3] {
    let mut out = [ValueId(0); 3];
    for (j, o) in out.iter_mut().enumerate() {
        *o = dot(p, &[r[0][j], r[1][j], r[2][j]], x);
    }
    out
}

fn new_program(d: &Derivation) -> Program {
    Program::new(d.params.clone())
}

/// A program with the expanded polynomials of `m` as outputs (column-major).
pub fn matrix_program(d: &Derivation, m: &Matrix) -> Program {
    let mut prog = new_program(d);
    let outs = PolyBuilder::new(&mut prog).matrix(m);
    prog.set_outputs(outs);
    prog
}

/// A rigid transform's expanded entries as a program, outputs in the [`super::Layout::Transform`]
/// layout.
pub fn transform_program(d: &Derivation, t: &Transform) -> Program {
    let mut prog = new_program(d);
    let values = PolyBuilder::new(&mut prog).transform(t);
    prog.set_outputs(values.outputs());
    prog
}

/// Forward kinematics of the first `upto` joints (then `tail`, if given), product form.
fn fk_product_program(d: &Derivation, upto: usize, tail: Option<&Transform>) -> Program {
    let mut prog = new_program(d);
    let acc = chain_product(d, &mut prog, 0..upto, tail);
    prog.set_outputs(acc.outputs());
    prog
}

/// The product `T_a ⋯ T_b` of the joints `range` (0-based), then `tail` if given (in the
/// description's frame of the last link), built into `prog` left to right (2.21); the identity
/// when both are empty. Turned link frames ([`Derivation::frame_turns`]) are turned back at both
/// ends.
fn chain_product(
    d: &Derivation,
    prog: &mut Program,
    range: std::ops::Range<usize>,
    tail: Option<&Transform>,
) -> NumTransform {
    let head = d.frame_turn(range.start).cloned();
    let end = d.turned_back(range.end, tail);
    let mut b = PolyBuilder::new(prog);
    let mut factors: Vec<NumTransform> = head.iter().map(|t| b.transform(t)).collect();
    factors.extend(d.joint_transforms[range].iter().map(|t| b.transform(t)));
    if let Some(t) = &end {
        factors.push(b.transform(t));
    }
    let mut acc = match factors.first() {
        Some(&f) => f,
        None => b.transform(&Transform::identity()),
    };
    for f in factors.iter().skip(1) {
        acc = acc.compose(f, prog);
    }
    acc
}

/// Body Jacobian of the chain `joints[..upto]` then `tail` (`J^B_0e` with `tail = g_ne`,
/// `J^B_0i` with `upto = i` and no tail), product form.
fn body_jacobian_product_program(d: &Derivation, upto: usize, tail: Option<&Transform>) -> Program {
    let mut prog = new_program(d);
    let (cols, _) = body_jacobian_walk(d, &mut prog, upto, tail);
    prog.set_outputs(cols.into_iter().flatten().collect());
    prog
}

/// The columns `Ad⁻¹_{g_ke} ξ_k` (2.45) of the body Jacobian of `joints[..upto]` then `tail`, built
/// into `prog` by walking the chain from its end: `g_ke` is the suffix product
/// `T_{k+1} ⋯ T_upto · tail`, so the walk ends with the whole product `T_1 ⋯ T_upto · tail`, which
/// is returned beside the columns (`g_0i` for `J^B_0i`).
fn body_jacobian_walk(
    d: &Derivation,
    prog: &mut Program,
    upto: usize,
    tail: Option<&Transform>,
) -> (Vec<[ValueId; 6]>, NumTransform) {
    let mut b = PolyBuilder::new(prog);
    let joints: Vec<NumTransform> = d.joint_transforms[..upto]
        .iter()
        .map(|t| b.transform(t))
        .collect();
    let twists: Vec<([ValueId; 3], [ValueId; 3])> = d.twists[..upto]
        .iter()
        .map(|x| {
            let v = [
                b.poly(x.get(0, 0)),
                b.poly(x.get(1, 0)),
                b.poly(x.get(2, 0)),
            ];
            let w = [
                b.poly(x.get(3, 0)),
                b.poly(x.get(4, 0)),
                b.poly(x.get(5, 0)),
            ];
            (v, w)
        })
        .collect();
    // In the description's frame of link `upto` (a turned frame turned back), then `tail`.
    let mut g = match d.turned_back(upto, tail) {
        Some(t) => b.transform(&t),
        None => b.transform(&Transform::identity()),
    };
    let mut cols = vec![[ValueId(0); 6]; upto];
    for k in (0..upto).rev() {
        // g = g_ke: F_k → F_e.
        let (v, w) = &twists[k];
        let wxp = cross(prog, w, &g.pos);
        let mut lin_in = [ValueId(0); 3];
        for i in 0..3 {
            lin_in[i] = prog.add(v[i], wxp[i]);
        }
        let lin = rot_t_apply(prog, &g.rot, &lin_in);
        let ang = rot_t_apply(prog, &g.rot, w);
        cols[k] = [lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]];
        g = joints[k].compose(&g, prog);
    }
    (cols, g)
}

/// The forms of `J^r_0e` and `J_c` their own functions are built from (the graph or its
/// expansion, [`graph_or_expanded_form`]), which a fused program builds again among its values.
#[derive(Default)]
struct Forms {
    jr: Option<Matrix>,
    jc: Option<Matrix>,
}

/// Several catalogue outputs (`outputs`, in that order, each in its function's layout) as one
/// program, walking the chain once where the outputs allow: the walk that builds `J^B_0i` from
/// the constrained link's end ends with `g_0i` (2.21), the walk that builds `J^B_0e` ends with
/// `g_0e`, and `g_0e = g_0i · g_ie` takes one product more after the first; `J^r_0e` and `J_c`
/// are built from `forms` into the same program, every other output from its function's own
/// program (`functions`). Values the outputs share exist once (rule `hash_cons`).
fn fused_walk_program(
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
fn fused_functions(
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

/// The heads `Trans(o_k) R_x(roll_k)` of joints `1..=upto`, base first, as `(roll in quarter
/// turns, o)`, when the chain up to link `upto` is one of right-angle joints: every joint turns
/// about the `z` axis of its link frame, `T_k = Trans(o_k) R_x(roll_k) R_z(q_k)` with a constant
/// `o_k` and `roll_k` one of `0`, `+π/2`, `−π/2` (modified Denavit–Hartenberg with right-angle
/// twists, as the Panda), and no frame up to link `upto` is turned. `None` otherwise.
///
/// Such a chain's `g_0i` and `J^B_0i` can be walked with the rows of the homogeneous transform
/// as pairs (`trocar::emitted::paired_rows`). A joint about `−z` (twist `(0, −ẑ)`) is not taken.
pub fn paired_heads(d: &Derivation, upto: usize) -> Option<Vec<(i8, [f64; 3])>> {
    if upto == 0 || d.turned_back(upto, None).is_some() {
        return None;
    }
    let z_twist: Vec<Poly> = [0, 0, 0, 0, 0, 1].map(Poly::integer).to_vec();
    (0..upto)
        .map(|k| {
            if d.joint_is_linear[k]
                || d.frame_turns[k].is_some()
                || d.twists[k].entries() != z_twist.as_slice()
            {
                return None;
            }
            let t = &d.joint_transforms[k];
            let (c, s) = (Poly::cos(k), Poly::sin(k));
            let (zero, one) = (Poly::zero(), Poly::one());
            // Row 1 of R_x(roll) R_z(q) is (c, −s, 0) for every roll; rows 2 and 3 tell it.
            let rz = [
                [c.clone(), s.neg(), zero.clone()],
                [s.clone(), c.clone(), zero.clone()],
                [zero.clone(), zero.clone(), one.clone()],
            ];
            let neg = |r: &[Poly; 3]| [r[0].neg(), r[1].neg(), r[2].neg()];
            let candidates = [
                (0i8, [rz[0].clone(), rz[1].clone(), rz[2].clone()]),
                (1, [rz[0].clone(), neg(&rz[2]), rz[1].clone()]),
                (-1, [rz[0].clone(), rz[2].clone(), neg(&rz[1])]),
            ];
            let roll = candidates.into_iter().find_map(|(roll, rows)| {
                let fits = (0..3).all(|i| (0..3).all(|j| t.rot.get(i, j) == &rows[i][j]));
                fits.then_some(roll)
            })?;
            let mut o = [0.0; 3];
            for (i, x) in o.iter_mut().enumerate() {
                *x = t.pos.get(i, 0).as_constant()?.to_f64();
            }
            Some((roll, o))
        })
        .collect()
}

/// Most terms in all of a matrix in graph form that [`graph_or_expanded`] writes out to compare
/// with the graph.
const REEXPANSION_BUDGET: usize = 1_000;

/// The program of `m`, a matrix that may hold shared subexpressions (the graph form of a long or
/// generic chain, [`crate::derivation::SHARE_TERMS`]): when its canonical expansion is small, the
/// program of that expansion is built as well and the one with fewer operations kept (a chain
/// of moderate length often factors better expanded; a long one only as a graph).
fn graph_or_expanded(d: &Derivation, m: &Matrix) -> Program {
    graph_or_expanded_form(d, m).1
}

/// [`graph_or_expanded`] with the form it chose (`m` itself or its expansion).
fn graph_or_expanded_form(d: &Derivation, m: &Matrix) -> (Matrix, Program) {
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

/// [`manipulability_from_jr`] of `j` and, as in [`graph_or_expanded`], of its small canonical
/// expansion; the pair with fewer operations is kept.
fn manipulability_graph_or_expanded(d: &Derivation, j: &Matrix) -> (Program, Program) {
    let graph = manipulability_from_jr(d, j);
    if !j.entries().iter().any(Poly::has_nodes) {
        return graph;
    }
    match crate::derivation::expanded_within(j, REEXPANSION_BUDGET) {
        Some(e) => cheaper_by(graph, manipulability_from_jr(d, &e), |w| &w.0),
        None => graph,
    }
}

fn cheaper(a: Program, b: Program) -> Program {
    cheaper_by(a, b, |p| p)
}

/// Of two forms, the one whose program (`program(form)`) has fewer live operations; `a` on a
/// tie.
fn cheaper_by<T>(a: T, b: T, program: impl Fn(&T) -> &Program) -> T {
    if program(&b).live_len() < program(&a).live_len() {
        b
    } else {
        a
    }
}

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
        controller: super::controller::ControllerSpec::of(d),
        joint_limits: d.joint_limits.clone(),
        joint_ranges: d.joint_ranges.clone(),
        joint_speed_limits: d.joint_speed_limits.clone(),
        pose_and_jacobians,
        fused,
        fma_at_run_time: false,
    })
}

fn manipulability_programs(d: &Derivation, form: &ManipulabilityForm) -> (Program, Program) {
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
