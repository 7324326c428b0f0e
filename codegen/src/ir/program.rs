//! Straight-line programs: a hash-consed, value-numbered DAG with its optimisation rules.
//!
//! A [`Program`] is the representation of one emitted function. Values are created through the
//! smart constructors ([`Program::add`], [`Program::mul`], …), which apply the rewrite rules below
//! **once, at construction**, and then look the resulting operation up in a hash table, so every
//! structurally equal value exists once in the whole function (common-subexpression elimination
//! over all outputs). Dead code is removed when the program is scheduled ([`Program::live`]), and
//! operation counts are taken from the live nodes only ([`Program::op_counts`]).
//!
//! # Rules
//!
//! Each rule is applied in exactly one place and has a unit test of the same name.
//!
//! | rule | statement | where |
//! |---|---|---|
//! | `hash_cons` | structurally equal operations get the same [`ValueId`] | `Program::intern` |
//! | `commutative_order` | `a + b`, `a · b` stored with operands sorted by id | [`Program::add`], [`Program::mul`] |
//! | `fold_constants` | an operation on constants is replaced by its value | each constructor |
//! | `add_zero` | `x + 0 → x`, `x − 0 → x`, `0 − x → −x` | [`Program::add`], [`Program::sub`] |
//! | `mul_zero` | `x · 0 → 0`, `0 / x → 0` | [`Program::mul`], [`Program::div`] |
//! | `mul_one` | `x · 1 → x`, `x · (−1) → −x`, `x / 1 → x` | [`Program::mul`], [`Program::div`] |
//! | `neg_neg` | `−(−x) → x` | [`Program::neg`] |
//! | `sign_out` | `(−x) · y → −(x · y)`, `(−x) / y → −(x / y)`, `x / (−y) → −(x / y)`, `(−c) · x → −(c · x)` and `x / (−c) → −(x / c)` for literals (so literals in products are positive) | [`Program::mul`], [`Program::div`] |
//! | `add_neg` | `x + (−y) → x − y`, `(−x) + y → y − x`, `x − (−y) → x + y`, `(−x) − y → −(x + y)`, `x + (−c) → x − c` for a literal `c > 0` | [`Program::add`], [`Program::sub`] |
//! | `sub_self` | `x − x → 0` | [`Program::sub`] |
//! | `div_pow2` | `x / c → x · (1/c)` when `1/c` is exact (`c` a power of two) | [`Program::div`] |
//! | `const_assoc` | `c₁ · (c₂ · x) → (c₁c₂) · x` | [`Program::mul`] |
//! | `horner` | a sum of monomials is built by factoring out, recursively, the atom that occurs in most terms (multivariate Horner), so that shared products are hoisted | [`Program::sum_of_monomials`] |
//! | `monomial_prefix` | a monomial's atoms are multiplied in a canonical order, coefficient last, so equal sub-products are shared | [`Program::monomial`] |
//! | `sign_normalise` | a sum whose terms are all negative is built as `−(sum of the negations)`; a sum whose coefficients share one magnitude `c` as `c · (sum)` | [`Program::sum_of_monomials`] |
//! | `one_inverse` | `x⁻ᵏ` is built as `(1/x)ᵏ`, with `1/x` a single shared division | [`Program::power`] |
//! | `one_trig` | `sin q_k` and `cos q_k` come from one `sin_cos` per joint, all of a function's joints in one `sin_cos_array` call | [`Program::op_counts`], emission |
//! | `dead_code` | only values reachable from the outputs are emitted and counted | [`Program::live`] |
//! | `fuse_when_it_pays` | a product used once and added to something is one fused multiply-add, in programs with at least [`MIN_FUSED_PRODUCTS`] such products | [`Program::fused_products`] |

use std::collections::{BTreeMap, HashMap};
use std::fmt;

/// Index of a value (a node) in a [`Program`].
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct ValueId(pub(crate) u32);

impl ValueId {
    /// Position of the node in [`Program::ops`].
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Rule `fuse_when_it_pays`: a function writes its products added once as `Real::mul_add` (one
/// FMA instruction where the target has it) only when it has at least this many
/// ([`Program::fused_products`]). Measured (BENCHMARKS.md, "Fused multiply-add in generated code"
/// and "Peers with one pass along the chain and a frozen baseline"): dia10_like's FK + J^B_0i +
/// J^r, dozens of fusions, takes 0.84× the time fused; the presets' `J^r`, two fusions each, take
/// the same time either way, and fused they count +4, +3 and −4 instructions (register copies for
/// the destructive FMA forms where all three operands stay live): nothing to gain.
pub const MIN_FUSED_PRODUCTS: usize = 4;

/// An `f64` constant hashed and compared by its bits (`-0.0` is normalised to `0.0`).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct Const(u64);

impl Const {
    /// Wraps a finite value.
    pub fn new(x: f64) -> Self {
        let x = if x == 0.0 { 0.0 } else { x };
        Const(x.to_bits())
    }

    /// The value.
    pub fn value(self) -> f64 {
        f64::from_bits(self.0)
    }
}

/// One operation of a straight-line program.
///
/// Joint indices are 0-based positions in `q`; parameter indices are positions in
/// [`Program::params`].
#[derive(Clone, PartialEq, Eq, Hash, Debug)]
pub enum Op {
    /// A literal.
    Const(Const),
    /// A named parameter (index into [`Program::params`]).
    Param(usize),
    /// `q[k]` itself (prismatic joints).
    Joint(usize),
    /// `sin q[k]`.
    Sin(usize),
    /// `cos q[k]`.
    Cos(usize),
    /// `a + b`.
    Add(ValueId, ValueId),
    /// `a − b`.
    Sub(ValueId, ValueId),
    /// `a · b`.
    Mul(ValueId, ValueId),
    /// `−a`.
    Neg(ValueId),
    /// `a / b`.
    Div(ValueId, ValueId),
    /// `√a`.
    Sqrt(ValueId),
    /// `|a|`.
    Abs(ValueId),
}

impl Op {
    /// The operands of this operation.
    pub fn operands(&self) -> impl Iterator<Item = ValueId> {
        let (a, b) = match *self {
            Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) => (Some(a), Some(b)),
            Op::Neg(a) | Op::Sqrt(a) | Op::Abs(a) => (Some(a), None),
            _ => (None, None),
        };
        a.into_iter().chain(b)
    }
}

/// An indeterminate of a monomial, for [`Program::sum_of_monomials`].
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub enum Factor {
    /// `sin q[k]`.
    Sin(usize),
    /// `cos q[k]`.
    Cos(usize),
    /// `q[k]`.
    Joint(usize),
    /// A parameter (index into [`Program::params`]).
    Param(usize),
    /// An already-built value (e.g. the inverse of a polynomial).
    Value(ValueId),
}

/// `coefficient · Π atomᵉ`, exponents non-zero (negative exponents allowed).
#[derive(Clone, PartialEq, Debug)]
pub struct Term {
    /// The coefficient.
    pub coef: f64,
    /// `(atom, exponent)` pairs, each atom at most once.
    pub factors: Vec<(Factor, i32)>,
}

impl Term {
    /// A term from a coefficient and factors (zero exponents are dropped, repeated atoms merged).
    pub fn new(coef: f64, factors: impl IntoIterator<Item = (Factor, i32)>) -> Self {
        let mut map: BTreeMap<Factor, i32> = BTreeMap::new();
        for (a, e) in factors {
            *map.entry(a).or_insert(0) += e;
        }
        Term {
            coef,
            factors: map.into_iter().filter(|&(_, e)| e != 0).collect(),
        }
    }
}

/// Operation counts of the live part of a program.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default)]
pub struct OpCounts {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// Square roots.
    pub sqrt: usize,
    /// `sin_cos` calls (one per joint whose sine or cosine is used).
    pub trig: usize,
    /// Negations.
    pub neg: usize,
    /// Absolute values.
    pub abs: usize,
}

impl fmt::Display for OpCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} add, {} mul, {} div, {} sqrt, {} trig (sin_cos), {} neg, {} abs",
            self.add, self.mul, self.div, self.sqrt, self.trig, self.neg, self.abs
        )
    }
}

/// A straight-line program: hash-consed nodes, named parameters and a list of outputs.
#[derive(Clone, Debug, Default)]
pub struct Program {
    ops: Vec<Op>,
    table: HashMap<Op, ValueId>,
    params: Vec<String>,
    outputs: Vec<ValueId>,
}

impl Program {
    /// An empty program over the given parameter names.
    pub fn new(params: Vec<String>) -> Self {
        Program {
            params,
            ..Program::default()
        }
    }

    /// Parameter names, in index order.
    pub fn params(&self) -> &[String] {
        &self.params
    }

    /// All nodes (live or not), in creation order (operands always precede their users).
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The operation of a value.
    pub fn op(&self, v: ValueId) -> &Op {
        &self.ops[v.index()]
    }

    /// The outputs, in order.
    pub fn outputs(&self) -> &[ValueId] {
        &self.outputs
    }

    /// Appends an output.
    pub fn push_output(&mut self, v: ValueId) {
        self.outputs.push(v);
    }

    /// Replaces the outputs.
    pub fn set_outputs(&mut self, outputs: Vec<ValueId>) {
        self.outputs = outputs;
    }

    /// Rule `hash_cons`: returns the existing id of an equal operation, or appends it.
    fn intern(&mut self, op: Op) -> ValueId {
        if let Some(&id) = self.table.get(&op) {
            return id;
        }
        let id = ValueId(self.ops.len() as u32);
        self.ops.push(op.clone());
        self.table.insert(op, id);
        id
    }

    /// The constant value of `v`, if it is a literal.
    pub fn as_const(&self, v: ValueId) -> Option<f64> {
        match self.op(v) {
            Op::Const(c) => Some(c.value()),
            _ => None,
        }
    }

    fn as_neg(&self, v: ValueId) -> Option<ValueId> {
        match self.op(v) {
            Op::Neg(a) => Some(*a),
            _ => None,
        }
    }

    /// A literal.
    pub fn constant(&mut self, x: f64) -> ValueId {
        self.intern(Op::Const(Const::new(x)))
    }

    /// A parameter by index.
    pub fn param(&mut self, p: usize) -> ValueId {
        self.intern(Op::Param(p))
    }

    /// `q[k]`.
    pub fn joint(&mut self, k: usize) -> ValueId {
        self.intern(Op::Joint(k))
    }

    /// `sin q[k]`.
    pub fn sin(&mut self, k: usize) -> ValueId {
        self.intern(Op::Sin(k))
    }

    /// `cos q[k]`.
    pub fn cos(&mut self, k: usize) -> ValueId {
        self.intern(Op::Cos(k))
    }

    /// `a + b` with rules `fold_constants`, `add_zero`, `add_neg`, `commutative_order`.
    pub fn add(&mut self, a: ValueId, b: ValueId) -> ValueId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x + y),
            (Some(0.0), None) => return b,
            (None, Some(0.0)) => return a,
            (Some(x), None) if x < 0.0 => {
                let c = self.constant(-x);
                return self.sub(b, c);
            }
            (None, Some(y)) if y < 0.0 => {
                let c = self.constant(-y);
                return self.sub(a, c);
            }
            _ => {}
        }
        match (self.as_neg(a), self.as_neg(b)) {
            (Some(x), Some(y)) => {
                let s = self.add(x, y);
                return self.neg(s);
            }
            (None, Some(y)) => return self.sub(a, y),
            (Some(x), None) => return self.sub(b, x),
            (None, None) => {}
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.intern(Op::Add(a, b))
    }

    /// `a − b` with rules `fold_constants`, `add_zero`, `add_neg`, `sub_self`.
    pub fn sub(&mut self, a: ValueId, b: ValueId) -> ValueId {
        if a == b {
            return self.constant(0.0);
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x - y),
            (None, Some(0.0)) => return a,
            (Some(0.0), None) => return self.neg(b),
            _ => {}
        }
        if let Some(y) = self.as_neg(b) {
            return self.add(a, y);
        }
        if let Some(x) = self.as_neg(a) {
            let s = self.add(x, b);
            return self.neg(s);
        }
        self.intern(Op::Sub(a, b))
    }

    /// `−a` with rules `fold_constants`, `neg_neg`.
    pub fn neg(&mut self, a: ValueId) -> ValueId {
        if let Some(x) = self.as_const(a) {
            return self.constant(-x);
        }
        if let Some(x) = self.as_neg(a) {
            return x;
        }
        self.intern(Op::Neg(a))
    }

    /// `a · b` with rules `fold_constants`, `mul_zero`, `mul_one`, `sign_out`, `const_assoc`,
    /// `commutative_order`.
    pub fn mul(&mut self, a: ValueId, b: ValueId) -> ValueId {
        // Constants first, so that `c · x` has a canonical shape.
        let (a, b) = match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x * y),
            (None, Some(_)) => (b, a),
            _ => (a, b),
        };
        if let Some(x) = self.as_const(a) {
            if x == 0.0 {
                return self.constant(0.0);
            }
            if x == 1.0 {
                return b;
            }
            if x == -1.0 {
                return self.neg(b);
            }
            if x < 0.0 {
                let c = self.constant(-x);
                let m = self.mul(c, b);
                return self.neg(m);
            }
            if let Op::Mul(c2, y) = *self.op(b) {
                if let Some(x2) = self.as_const(c2) {
                    let c = self.constant(x * x2);
                    return self.mul(c, y);
                }
            }
        }
        match (self.as_neg(a), self.as_neg(b)) {
            (Some(x), Some(y)) => return self.mul(x, y),
            (Some(x), None) => {
                let m = self.mul(x, b);
                return self.neg(m);
            }
            (None, Some(y)) => {
                let m = self.mul(a, y);
                return self.neg(m);
            }
            (None, None) => {}
        }
        let (a, b) = if self.as_const(a).is_some() || a <= b {
            (a, b)
        } else {
            (b, a)
        };
        self.intern(Op::Mul(a, b))
    }

    /// `a / b` with rules `fold_constants`, `mul_zero`, `mul_one`, `sign_out`, `div_pow2`.
    ///
    /// Division by a literal zero is kept as written (it is the caller's error, and folding it
    /// would hide it).
    pub fn div(&mut self, a: ValueId, b: ValueId) -> ValueId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) if y != 0.0 => return self.constant(x / y),
            (Some(0.0), _) => return self.constant(0.0),
            (_, Some(1.0)) => return a,
            (_, Some(-1.0)) => return self.neg(a),
            (_, Some(y)) if y != 0.0 && is_power_of_two(y) => {
                let c = self.constant(1.0 / y);
                return self.mul(c, a);
            }
            _ => {}
        }
        if let Some(x) = self.as_neg(a) {
            let d = self.div(x, b);
            return self.neg(d);
        }
        if let Some(y) = self.as_neg(b) {
            let d = self.div(a, y);
            return self.neg(d);
        }
        if let Some(y) = self.as_const(b) {
            if y < 0.0 {
                let c = self.constant(-y);
                let d = self.div(a, c);
                return self.neg(d);
            }
        }
        self.intern(Op::Div(a, b))
    }

    /// `√a` with rule `fold_constants` (for non-negative literals).
    pub fn sqrt(&mut self, a: ValueId) -> ValueId {
        if let Some(x) = self.as_const(a) {
            if x >= 0.0 {
                return self.constant(x.sqrt());
            }
        }
        self.intern(Op::Sqrt(a))
    }

    /// `|a|` with rules `fold_constants` and `|−x| → |x|`, `||x|| → |x|`.
    pub fn abs(&mut self, a: ValueId) -> ValueId {
        if let Some(x) = self.as_const(a) {
            return self.constant(x.abs());
        }
        if let Some(x) = self.as_neg(a) {
            return self.abs(x);
        }
        if let Op::Abs(_) = self.op(a) {
            return a;
        }
        self.intern(Op::Abs(a))
    }

    /// The value of an atom (`1/x` for rule `one_inverse` is built by [`Program::power`]).
    pub fn atom(&mut self, atom: Factor) -> ValueId {
        match atom {
            Factor::Sin(k) => self.sin(k),
            Factor::Cos(k) => self.cos(k),
            Factor::Joint(k) => self.joint(k),
            Factor::Param(p) => self.param(p),
            Factor::Value(v) => v,
        }
    }

    /// `atomᵉ`, rule `one_inverse`: a negative power is a power of the single shared `1/atom`.
    pub fn power(&mut self, atom: Factor, e: i32) -> ValueId {
        let mut base = self.atom(atom);
        if e < 0 {
            let one = self.constant(1.0);
            base = self.div(one, base);
        }
        let mut acc = base;
        for _ in 1..e.unsigned_abs() {
            acc = self.mul(acc, base);
        }
        if e == 0 {
            self.constant(1.0)
        } else {
            acc
        }
    }

    /// One monomial, rule `monomial_prefix`: factors in canonical order (atom order, negative
    /// powers as shared inverses), multiplied left to right, the coefficient last.
    pub fn monomial(&mut self, term: &Term) -> ValueId {
        let mut factors = term.factors.clone();
        factors.sort();
        let mut acc: Option<ValueId> = None;
        for &(a, e) in &factors {
            let p = self.power(a, e);
            acc = Some(match acc {
                None => p,
                Some(x) => self.mul(x, p),
            });
        }
        let c = self.constant(term.coef);
        match acc {
            None => c,
            Some(x) => self.mul(c, x),
        }
    }

    /// A sum of monomials, with rules `horner` and `sign_normalise`.
    ///
    /// Repeatedly factors out the atom power (`a` or `1/a`) that occurs in most terms (ties
    /// broken by atom order, so the result is deterministic):
    /// `Σ = a · Σ_with + Σ_without`. When no atom occurs in two terms, the terms are added
    /// in a canonical order.
    pub fn sum_of_monomials(&mut self, terms: &[Term]) -> ValueId {
        let terms: Vec<Term> = terms.iter().filter(|t| t.coef != 0.0).cloned().collect();
        self.horner(terms)
    }

    fn horner(&mut self, mut terms: Vec<Term>) -> ValueId {
        match terms.len() {
            0 => return self.constant(0.0),
            1 => return self.monomial(&terms[0]),
            _ => {}
        }
        // sign_normalise: all negative → −(Σ −t).
        if terms.iter().all(|t| t.coef < 0.0) {
            for t in &mut terms {
                t.coef = -t.coef;
            }
            let s = self.horner(terms);
            return self.neg(s);
        }
        // sign_normalise: one common magnitude c ≠ 1 → c · Σ(±t/c).
        let c = terms[0].coef.abs();
        if c != 1.0 && terms.iter().all(|t| t.coef.abs() == c) {
            for t in &mut terms {
                t.coef = t.coef.signum();
            }
            let s = self.horner(terms);
            let k = self.constant(c);
            return self.mul(k, s);
        }
        // horner: the most frequent (atom, sign of exponent).
        let mut counts: BTreeMap<(Factor, bool), usize> = BTreeMap::new();
        for t in &terms {
            for &(a, e) in &t.factors {
                *counts.entry((a, e > 0)).or_insert(0) += 1;
            }
        }
        let best = counts
            .iter()
            .filter(|(_, &n)| n >= 2)
            .max_by(|x, y| x.1.cmp(y.1).then_with(|| y.0.cmp(x.0)))
            .map(|(k, _)| *k);
        let Some((atom, positive)) = best else {
            return self.leaf_sum(terms);
        };
        let step = if positive { 1 } else { -1 };
        let (mut with, without): (Vec<Term>, Vec<Term>) = terms.into_iter().partition(|t| {
            t.factors
                .iter()
                .any(|&(a, e)| a == atom && (e > 0) == positive)
        });
        for t in &mut with {
            for f in &mut t.factors {
                if f.0 == atom {
                    f.1 -= step;
                }
            }
            t.factors.retain(|&(_, e)| e != 0);
        }
        let inner = self.horner(with);
        let factor = self.power(atom, step);
        let prod = self.mul(factor, inner);
        let rest = self.horner(without);
        self.add(prod, rest)
    }

    fn leaf_sum(&mut self, mut terms: Vec<Term>) -> ValueId {
        // Canonical order: positive coefficients first, then by factors.
        terms.sort_by(|x, y| {
            (x.coef < 0.0)
                .cmp(&(y.coef < 0.0))
                .then_with(|| x.factors.cmp(&y.factors))
                .then_with(|| x.coef.total_cmp(&y.coef))
        });
        let mut acc: Option<ValueId> = None;
        for t in &terms {
            let m = self.monomial(t);
            acc = Some(match acc {
                None => m,
                Some(x) => self.add(x, m),
            });
        }
        acc.unwrap_or_else(|| self.constant(0.0))
    }

    /// Builds the live values of `other` (a program over the same parameters) into this one
    /// through the smart constructors, so that the values both compute are shared (rule
    /// `hash_cons`); returns `other`'s outputs as values of this program.
    pub fn import(&mut self, other: &Program) -> Vec<ValueId> {
        debug_assert_eq!(self.params, other.params);
        let live = other.live();
        let mut map: Vec<ValueId> = Vec::with_capacity(other.ops.len());
        for (op, &l) in other.ops.iter().zip(&live) {
            if !l {
                // Never read: only live values are operands of live values.
                map.push(ValueId(0));
                continue;
            }
            let m = |v: &ValueId| map[v.index()];
            let v = match op {
                Op::Const(c) => self.constant(c.value()),
                Op::Param(k) => self.param(*k),
                Op::Joint(k) => self.joint(*k),
                Op::Sin(k) => self.sin(*k),
                Op::Cos(k) => self.cos(*k),
                Op::Add(a, b) => {
                    let (a, b) = (m(a), m(b));
                    self.add(a, b)
                }
                Op::Sub(a, b) => {
                    let (a, b) = (m(a), m(b));
                    self.sub(a, b)
                }
                Op::Mul(a, b) => {
                    let (a, b) = (m(a), m(b));
                    self.mul(a, b)
                }
                Op::Div(a, b) => {
                    let (a, b) = (m(a), m(b));
                    self.div(a, b)
                }
                Op::Neg(a) => {
                    let a = m(a);
                    self.neg(a)
                }
                Op::Sqrt(a) => {
                    let a = m(a);
                    self.sqrt(a)
                }
                Op::Abs(a) => {
                    let a = m(a);
                    self.abs(a)
                }
            };
            map.push(v);
        }
        other.outputs.iter().map(|o| map[o.index()]).collect()
    }

    /// The parameters that a live division's divisor depends on: where the program can divide
    /// by zero (a parameter at 0), in the order of [`Program::params`].
    pub fn divisor_params(&self) -> Vec<String> {
        let live = self.live();
        let mut seen = vec![false; self.ops.len()];
        let mut found = vec![false; self.params.len()];
        let mut stack: Vec<ValueId> = self
            .ops
            .iter()
            .zip(&live)
            .filter_map(|(op, &l)| match *op {
                Op::Div(_, b) if l => Some(b),
                _ => None,
            })
            .collect();
        while let Some(v) = stack.pop() {
            let i = v.0 as usize;
            if std::mem::replace(&mut seen[i], true) {
                continue;
            }
            if let Op::Param(k) = self.ops[i] {
                found[k] = true;
            }
            stack.extend(self.ops[i].operands());
        }
        self.params
            .iter()
            .zip(found)
            .filter(|&(_, f)| f)
            .map(|(name, _)| name.clone())
            .collect()
    }

    /// Rule `dead_code`: `live[v]` is `true` when `v` is reachable from an output.
    pub fn live(&self) -> Vec<bool> {
        let mut live = vec![false; self.ops.len()];
        for &o in &self.outputs {
            live[o.index()] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if live[i] {
                for a in self.ops[i].operands() {
                    live[a.index()] = true;
                }
            }
        }
        live
    }

    /// Joints whose sine or cosine is live, ascending (one `sin_cos` each, rule `one_trig`).
    pub fn trig_joints(&self) -> Vec<usize> {
        let live = self.live();
        let mut joints: Vec<usize> = self
            .ops
            .iter()
            .zip(&live)
            .filter(|(_, &l)| l)
            .filter_map(|(op, _)| match op {
                Op::Sin(k) | Op::Cos(k) => Some(*k),
                _ => None,
            })
            .collect();
        joints.sort_unstable();
        joints.dedup();
        joints
    }

    /// Operation counts of the live nodes.
    pub fn op_counts(&self) -> OpCounts {
        let live = self.live();
        let mut c = OpCounts {
            trig: self.trig_joints().len(),
            ..OpCounts::default()
        };
        for (op, _) in self.ops.iter().zip(&live).filter(|(_, &l)| l) {
            match op {
                Op::Add(..) | Op::Sub(..) => c.add += 1,
                Op::Mul(..) => c.mul += 1,
                Op::Div(..) => c.div += 1,
                Op::Sqrt(_) => c.sqrt += 1,
                Op::Neg(_) => c.neg += 1,
                Op::Abs(_) => c.abs += 1,
                _ => {}
            }
        }
        c
    }

    /// How many live operations use each value (an output counts as a use).
    pub fn use_counts(&self) -> Vec<usize> {
        let live = self.live();
        let mut uses = vec![0usize; self.ops.len()];
        for (op, _) in self.ops.iter().zip(&live).filter(|(_, &l)| l) {
            for a in op.operands() {
                uses[a.index()] += 1;
            }
        }
        for o in &self.outputs {
            uses[o.index()] += 1;
        }
        uses
    }

    /// Rule `fuse_when_it_pays`: `fused[v]` is `true` when the product `v` is written into the
    /// one addition or subtraction that uses it as a fused multiply-add (`Real::mul_add`: one
    /// FMA instruction where the target has it). A product is fusable when it is used once and
    /// added to something; a program fuses its fusable products only when it has at least
    /// [`MIN_FUSED_PRODUCTS`] of them, and none otherwise. In `a + b` (or `a − b`) with both
    /// operands fusable, `a` is the one fused and `b` is an ordinary product. The emitter and the evaluator both follow this plan, so
    /// the evaluator rounds exactly as the compiled code.
    pub fn fused_products(&self) -> Vec<bool> {
        let live = self.live();
        let uses = self.use_counts();
        let in_place = |v: ValueId| uses[v.index()] <= 1 && matches!(self.op(v), Op::Mul(..));
        let fusable = self
            .ops
            .iter()
            .zip(&live)
            .filter(|(_, &l)| l)
            .filter(|(op, _)| match **op {
                Op::Add(a, b) | Op::Sub(a, b) => in_place(a) || in_place(b),
                _ => false,
            })
            .count();
        let mut fused = vec![false; self.ops.len()];
        if fusable < MIN_FUSED_PRODUCTS {
            return fused;
        }
        for (op, _) in self.ops.iter().zip(&live).filter(|(_, &l)| l) {
            if let Op::Add(a, b) | Op::Sub(a, b) = *op {
                if in_place(a) {
                    fused[a.index()] = true;
                } else if in_place(b) {
                    fused[b.index()] = true;
                }
            }
        }
        fused
    }

    /// Number of live nodes.
    pub fn live_len(&self) -> usize {
        self.live().iter().filter(|&&l| l).count()
    }
}

fn is_power_of_two(y: f64) -> bool {
    let y = y.abs();
    y.is_finite() && y != 0.0 && {
        let (m, _) = frexp(y);
        m == 0.5
    }
}

/// Mantissa in `[0.5, 1)` and exponent, for finite non-zero normal `x`.
fn frexp(x: f64) -> (f64, i32) {
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    if exp == 0 {
        // Subnormal: scale up first.
        let (m, e) = frexp(x * f64::from_bits(0x4350_0000_0000_0000)); // 2^54
        return (m, e - 54);
    }
    let m = f64::from_bits((bits & !(0x7ff << 52)) | (1022 << 52));
    (m, exp - 1022)
}
