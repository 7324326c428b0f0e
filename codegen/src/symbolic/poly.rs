//! Canonical polynomials over joint sines/cosines, joint values, named parameters (with negative
//! powers) and hash-consed inverses of polynomials.
//!
//! # Normal form
//! A [`Poly`] is a sum of terms `coefficient · monomial`, kept as a vector sorted by monomial,
//! with no zero coefficient and no repeated monomial. A [`Monomial`] is a sorted product of
//! [`Atom`] powers with no zero exponent. Every operation returns this normal form, built with the
//! named rules below (each applied in exactly one function, each unit-tested):
//!
//! | rule | statement | where |
//! |---|---|---|
//! | `collect_like_terms` | `a·m + b·m → (a+b)·m`, drop `0·m` | [`Poly::from_terms`] |
//! | `exponent_add` | `x^a · x^b → x^(a+b)`, drop `x^0` (so `l·l⁻¹ → 1`) | [`Monomial::mul`] |
//! | `pythagorean` | `s_k² → 1 − c_k²` (every `s_k` has degree ≤ 1) | [`Poly::from_terms`] |
//! | `inverse_of_constant` | `1/c → c⁻¹` exactly (error for 0) | [`Poly::inv`] |
//! | `inverse_of_monomial` | `1/(c·Π p_j^e_j) → c⁻¹ Π p_j^(−e_j)` for parameters `p_j` | [`Poly::inv`] |
//! | `inverse_normalise` | `1/(c·P) → c⁻¹ · Inv(P)`, `P` with leading coefficient 1, interned once | [`Poly::inv`] |
//! | `inverse_cancel` | `k·P·Inv(P) → k` when a whole sum or product is exactly that | [`Poly::mul`], [`Poly::add`] |
//!
//! Since `{s_k² + c_k² − 1}` is a Gröbner basis for any order with `s_k > c_k`, reducing every
//! `s_k` to degree ≤ 1 gives a **unique** representative of each class modulo `s_k² + c_k² = 1`:
//! two Laurent polynomials in `s, c, q` and the parameters are equal on all configurations iff
//! their normal forms are equal (`==`). `Inv` atoms are treated as independent variables (only
//! the direct `inverse_cancel` is applied), so for expressions with polynomial denominators
//! equality of normal forms is sufficient, not necessary; the derivation only creates them in
//! `Λ†` (thesis (3.33)).

use super::number::Rational;
use std::collections::{BTreeSet, HashMap};
use std::fmt;
use std::sync::{Arc, Mutex, OnceLock};

/// An indeterminate. Joint indices are 0-based positions in `q` (thesis joint `k` is index
/// `k − 1`); parameter indices are positions in the derivation's parameter list.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub enum Atom {
    /// `sin q[k]` (thesis `s_{k+1}`); degree ≤ 1 in normal form.
    Sin(u16),
    /// `cos q[k]` (thesis `c_{k+1}`).
    Cos(u16),
    /// `q[k]` itself (prismatic joints and screw pitch terms).
    Joint(u16),
    /// A named parameter; negative exponents allowed.
    Param(u16),
    /// `1 / P` for the interned polynomial `P` = [`inverse_denominator`]`(id)`; exponent ≥ 1.
    Inv(u32),
    /// A shared subexpression: the polynomial [`node_definition`]`(id)`, kept unexpanded (a node
    /// of the expression graph, see [`Poly::shared`]); exponent ≥ 1.
    Node(u32),
}

impl Atom {
    /// The joint this atom depends on, if any.
    pub fn joint(&self) -> Option<usize> {
        match *self {
            Atom::Sin(k) | Atom::Cos(k) | Atom::Joint(k) => Some(k as usize),
            _ => None,
        }
    }
}

const EXPONENT_OVERFLOW: &str = "exponent overflow in a monomial (|exponent| > i32::MAX)";

/// A product of atom powers, sorted by atom, exponents non-zero.
#[derive(Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Debug, Default)]
pub struct Monomial(Vec<(Atom, i32)>);

impl Monomial {
    /// The empty product `1`.
    pub fn one() -> Self {
        Monomial(Vec::new())
    }

    /// `atom^exp` (`1` when `exp == 0`).
    pub fn atom(atom: Atom, exp: i32) -> Self {
        if exp == 0 {
            Self::one()
        } else {
            Monomial(vec![(atom, exp)])
        }
    }

    /// The factors `(atom, exponent)`, sorted by atom.
    pub fn factors(&self) -> &[(Atom, i32)] {
        &self.0
    }

    /// Is this the empty product?
    pub fn is_one(&self) -> bool {
        self.0.is_empty()
    }

    /// Exponent of `atom` (0 if absent).
    pub fn exponent(&self, atom: Atom) -> i32 {
        self.0
            .iter()
            .find(|(a, _)| *a == atom)
            .map(|(_, e)| *e)
            .unwrap_or(0)
    }

    /// Rule `exponent_add`: merge the sorted factor lists adding exponents, dropping zeros.
    ///
    /// # Panics
    /// When an exponent leaves the `i32` range (checked, never wraps).
    pub fn mul(&self, other: &Monomial) -> Monomial {
        let (a, b) = (&self.0, &other.0);
        let mut out = Vec::with_capacity(a.len() + b.len());
        let (mut i, mut j) = (0, 0);
        while i < a.len() && j < b.len() {
            match a[i].0.cmp(&b[j].0) {
                std::cmp::Ordering::Less => {
                    out.push(a[i]);
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    out.push(b[j]);
                    j += 1;
                }
                std::cmp::Ordering::Equal => {
                    let e = a[i].1.checked_add(b[j].1).expect(EXPONENT_OVERFLOW);
                    if e != 0 {
                        out.push((a[i].0, e));
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        out.extend_from_slice(&a[i..]);
        out.extend_from_slice(&b[j..]);
        Monomial(out)
    }

    /// Total degree (sum of exponents).
    pub fn degree(&self) -> i32 {
        self.0.iter().map(|(_, e)| e).sum()
    }

    fn with_exponent(&self, atom: Atom, exp: i32) -> Monomial {
        let mut v: Vec<(Atom, i32)> = self.0.iter().copied().filter(|(a, _)| *a != atom).collect();
        if exp != 0 {
            v.push((atom, exp));
            v.sort_by_key(|x| x.0);
        }
        Monomial(v)
    }

    fn eval(&self, env: &Env<'_>) -> f64 {
        let mut v = 1.0;
        for &(a, e) in &self.0 {
            v *= env.atom(a).powi(e);
        }
        v
    }
}

/// Values at which to evaluate expressions: joint values `q` (0-based) and parameter values.
#[derive(Clone, Copy, Debug)]
pub struct Env<'a> {
    /// Joint values, base first.
    pub q: &'a [f64],
    /// Parameter values, in the derivation's parameter order.
    pub params: &'a [f64],
}

impl Env<'_> {
    /// Value of one atom (`NaN` when an index is out of range).
    pub fn atom(&self, a: Atom) -> f64 {
        let q = |k: u16| self.q.get(k as usize).copied().unwrap_or(f64::NAN);
        match a {
            Atom::Sin(k) => q(k).sin(),
            Atom::Cos(k) => q(k).cos(),
            Atom::Joint(k) => q(k),
            Atom::Param(p) => self.params.get(p as usize).copied().unwrap_or(f64::NAN),
            Atom::Inv(id) => 1.0 / inverse_denominator(id).eval(self),
            Atom::Node(id) => node_value(id, self),
        }
    }
}

/// The values of the shared subexpressions at the last `Env` they were evaluated at, so that a
/// node used many times (the graph form of a long chain) is evaluated once per point.
#[derive(Default)]
struct NodeValues {
    /// The bits of `q` and the parameters the values belong to.
    key: Vec<u64>,
    values: HashMap<u32, f64>,
}

thread_local! {
    static NODE_VALUES: std::cell::RefCell<NodeValues> = std::cell::RefCell::new(NodeValues::default());
}

/// The value of the node `id` at `env` (memoised per point, see [`NodeValues`]).
fn node_value(id: u32, env: &Env<'_>) -> f64 {
    let same_point = |k: &[u64]| {
        k.len() == env.q.len() + env.params.len() + 1
            && k[0] == env.q.len() as u64
            && env
                .q
                .iter()
                .chain(env.params)
                .zip(&k[1..])
                .all(|(x, b)| x.to_bits() == *b)
    };
    let cached = NODE_VALUES.with(|c| {
        let mut c = c.borrow_mut();
        if !same_point(&c.key) {
            c.key = std::iter::once(env.q.len() as u64)
                .chain(env.q.iter().chain(env.params).map(|x| x.to_bits()))
                .collect();
            c.values.clear();
        }
        c.values.get(&id).copied()
    });
    if let Some(v) = cached {
        return v;
    }
    // Evaluated outside the borrow: the definition refers to earlier nodes.
    let v = node_definition(id).eval(env);
    NODE_VALUES.with(|c| c.borrow_mut().values.insert(id, v));
    v
}

/// Errors of symbolic operations.
#[derive(Clone, Debug, PartialEq)]
pub enum SymbolicError {
    /// Division by an expression that is identically zero.
    DivisionByZero,
    /// An exponent or index does not fit the representation.
    Overflow,
    /// A parse error, with the byte offset.
    Parse(usize, String),
}

impl fmt::Display for SymbolicError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SymbolicError::DivisionByZero => write!(f, "division by zero"),
            SymbolicError::Overflow => write!(f, "exponent or index overflow"),
            SymbolicError::Parse(at, m) => write!(f, "parse error at byte {at}: {m}"),
        }
    }
}

impl std::error::Error for SymbolicError {}

/// A polynomial in normal form (see the module documentation).
#[derive(Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Debug, Default)]
pub struct Poly {
    terms: Vec<(Monomial, Rational)>,
}

#[derive(Default)]
struct Interner {
    polys: Vec<Arc<Poly>>,
    ids: HashMap<Poly, u32>,
}

fn interner() -> &'static Mutex<Interner> {
    static INTERNER: OnceLock<Mutex<Interner>> = OnceLock::new();
    INTERNER.get_or_init(|| Mutex::new(Interner::default()))
}

/// The denominator `P` of the atom `Inv(id)` (hash-consed: one id per distinct normalised `P`).
///
/// # Panics
/// Never for ids produced by this module; an unknown id gives the zero polynomial.
pub fn inverse_denominator(id: u32) -> Arc<Poly> {
    let guard = interner().lock().unwrap_or_else(|e| e.into_inner());
    guard
        .polys
        .get(id as usize)
        .cloned()
        .unwrap_or_else(|| Arc::new(Poly::zero()))
}

/// A shared subexpression and what it depends on (computed once, when it is created).
struct Node {
    definition: Arc<Poly>,
    joints: BTreeSet<usize>,
    params: BTreeSet<usize>,
}

#[derive(Default)]
struct NodeTable {
    nodes: Vec<Node>,
    ids: HashMap<Poly, u32>,
}

fn node_table() -> &'static Mutex<NodeTable> {
    static NODES: OnceLock<Mutex<NodeTable>> = OnceLock::new();
    NODES.get_or_init(|| Mutex::new(NodeTable::default()))
}

/// The polynomial the atom `Node(id)` stands for (hash-consed: one id per distinct normalised
/// polynomial). It may itself contain earlier nodes, never later ones.
///
/// # Panics
/// Never for ids produced by this module; an unknown id gives the zero polynomial.
pub fn node_definition(id: u32) -> Arc<Poly> {
    let guard = node_table().lock().unwrap_or_else(|e| e.into_inner());
    guard
        .nodes
        .get(id as usize)
        .map_or_else(|| Arc::new(Poly::zero()), |n| n.definition.clone())
}

/// Joints or parameters of the node `id`.
fn node_dependencies(id: u32, params: bool) -> BTreeSet<usize> {
    let guard = node_table().lock().unwrap_or_else(|e| e.into_inner());
    guard
        .nodes
        .get(id as usize)
        .map_or_else(BTreeSet::new, |n| {
            if params {
                n.params.clone()
            } else {
                n.joints.clone()
            }
        })
}

fn intern_node(p: Poly) -> u32 {
    if let Some(&id) = node_table()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .ids
        .get(&p)
    {
        return id;
    }
    // Dependencies first, outside the lock (they read the table).
    let (joints, params) = (p.joints(), p.params());
    let mut guard = node_table().lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&id) = guard.ids.get(&p) {
        return id;
    }
    let id = guard.nodes.len() as u32;
    guard.nodes.push(Node {
        definition: Arc::new(p.clone()),
        joints,
        params,
    });
    guard.ids.insert(p, id);
    id
}

fn intern(p: Poly) -> u32 {
    let mut guard = interner().lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&id) = guard.ids.get(&p) {
        return id;
    }
    let id = guard.polys.len() as u32;
    guard.polys.push(Arc::new(p.clone()));
    guard.ids.insert(p, id);
    id
}

impl Poly {
    /// `0`.
    pub fn zero() -> Self {
        Poly { terms: Vec::new() }
    }

    /// `1`.
    pub fn one() -> Self {
        Self::constant(Rational::one())
    }

    /// A constant.
    pub fn constant(c: Rational) -> Self {
        Self::from_terms(vec![(Monomial::one(), c)])
    }

    /// An integer constant.
    pub fn integer(i: i64) -> Self {
        Self::constant(Rational::integer(i))
    }

    /// A single atom.
    pub fn atom(a: Atom) -> Self {
        Self::from_terms(vec![(Monomial::atom(a, 1), Rational::one())])
    }

    /// `sin q[k]`.
    pub fn sin(k: usize) -> Self {
        Self::atom(Atom::Sin(k as u16))
    }

    /// `cos q[k]`.
    pub fn cos(k: usize) -> Self {
        Self::atom(Atom::Cos(k as u16))
    }

    /// `q[k]`.
    pub fn joint(k: usize) -> Self {
        Self::atom(Atom::Joint(k as u16))
    }

    /// Parameter number `p`.
    pub fn param(p: usize) -> Self {
        Self::atom(Atom::Param(p as u16))
    }

    /// The normal form of an arbitrary list of terms: rules `pythagorean` and
    /// `collect_like_terms`.
    pub fn from_terms(terms: Vec<(Monomial, Rational)>) -> Self {
        let mut reduced = Vec::with_capacity(terms.len());
        for (m, c) in terms {
            if !c.is_zero() {
                pythagorean(m, c, &mut reduced);
            }
        }
        Poly {
            terms: collect_like_terms(reduced),
        }
    }

    /// The terms `(monomial, coefficient)`, sorted by monomial.
    pub fn terms(&self) -> &[(Monomial, Rational)] {
        &self.terms
    }

    /// Number of terms.
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// Has this no term (is it `0`)?
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// Is this `0`?
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// The value if this is a constant.
    pub fn as_constant(&self) -> Option<Rational> {
        match self.terms.as_slice() {
            [] => Some(Rational::zero()),
            [(m, c)] if m.is_one() => Some(c.clone()),
            _ => None,
        }
    }

    /// Is this the constant `1`?
    pub fn is_one(&self) -> bool {
        self.as_constant().is_some_and(|c| c.is_one())
    }

    /// Sum (with rule `inverse_cancel`).
    pub fn add(&self, other: &Poly) -> Poly {
        let mut v = Vec::with_capacity(self.len() + other.len());
        v.extend(self.terms.iter().cloned());
        v.extend(other.terms.iter().cloned());
        inverse_cancel(Poly {
            terms: collect_like_terms(v),
        })
    }

    /// Difference.
    pub fn sub(&self, other: &Poly) -> Poly {
        self.add(&other.neg())
    }

    /// Negation.
    pub fn neg(&self) -> Poly {
        Poly {
            terms: self.terms.iter().map(|(m, c)| (m.clone(), -c)).collect(),
        }
    }

    /// Multiplication by a constant.
    pub fn scale(&self, k: &Rational) -> Poly {
        if k.is_zero() {
            return Poly::zero();
        }
        Poly {
            terms: self.terms.iter().map(|(m, c)| (m.clone(), c * k)).collect(),
        }
    }

    /// Product (with rule `inverse_cancel` when one factor is an interned denominator).
    pub fn mul(&self, other: &Poly) -> Poly {
        if self.is_zero() || other.is_zero() {
            return Poly::zero();
        }
        if let Some(c) = self.as_constant() {
            return other.scale(&c);
        }
        if let Some(c) = other.as_constant() {
            return self.scale(&c);
        }
        let mut v = Vec::with_capacity(self.len() * other.len());
        for (ma, ca) in &self.terms {
            for (mb, cb) in &other.terms {
                v.push((ma.mul(mb), ca * cb));
            }
        }
        inverse_cancel(Poly::from_terms(v))
    }

    /// `self^n`.
    pub fn pow(&self, n: u32) -> Poly {
        let mut r = Poly::one();
        for _ in 0..n {
            r = r.mul(self);
        }
        r
    }

    /// `1/self`: rules `inverse_of_constant`, `inverse_of_monomial`, `inverse_normalise`.
    pub fn inv(&self) -> Result<Poly, SymbolicError> {
        match self.terms.as_slice() {
            [] => Err(SymbolicError::DivisionByZero),
            [(m, c)] if m.factors().iter().all(|(a, _)| matches!(a, Atom::Param(_))) => {
                // inverse_of_constant / inverse_of_monomial
                let c = c.checked_recip().ok_or(SymbolicError::DivisionByZero)?;
                let mut f = Vec::with_capacity(m.factors().len());
                for &(a, e) in m.factors() {
                    f.push((a, e.checked_neg().ok_or(SymbolicError::Overflow)?));
                }
                Ok(Poly {
                    terms: vec![(Monomial(f), c)],
                })
            }
            _ => {
                // inverse_normalise: leading (last) coefficient 1
                let lead = self.terms[self.terms.len() - 1].1.clone();
                let inv_lead = lead.checked_recip().ok_or(SymbolicError::DivisionByZero)?;
                let normal = self.scale(&inv_lead);
                let id = intern(normal);
                Ok(Poly {
                    terms: vec![(Monomial::atom(Atom::Inv(id), 1), inv_lead)],
                })
            }
        }
    }

    /// `self`, or a shared subexpression standing for it when it has more than `max_terms`
    /// terms: `c · Node(P)` with `P = self / c` normalised to a leading coefficient 1 (so `P` and
    /// `−2 P` share one node). The node is not expanded again by later products, which is what
    /// keeps a long or generic chain linear in size: `g_0k = g_0(k−1) T_k` multiplies nodes by
    /// the few terms of `T_k` instead of expanding the product of all sums before it.
    ///
    /// A polynomial with nodes is still exact, but no longer canonical: two equal functions
    /// may have different forms, so [`Poly::is_zero`] may miss a zero hidden inside nodes.
    pub fn shared(&self, max_terms: usize) -> Poly {
        if self.terms.len() <= max_terms {
            return self.clone();
        }
        let lead = self.terms[self.terms.len() - 1].1.clone();
        let normal = match lead.checked_recip() {
            Some(inv) => self.scale(&inv),
            None => return self.clone(),
        };
        let id = intern_node(normal);
        Poly {
            terms: vec![(Monomial::atom(Atom::Node(id), 1), lead)],
        }
    }

    /// `self` with every shared subexpression written out, back in canonical form, or `None`
    /// when that takes more than `budget` terms at any step (a long chain's nodes expand
    /// exponentially; a short chain's back into the small canonical polynomials that prove its
    /// closed forms).
    pub fn expanded(&self, budget: usize) -> Option<Poly> {
        self.expanded_with(budget, &mut HashMap::new())
    }

    /// [`Poly::expanded`] with the expansions of nodes already met (`None`: over budget).
    fn expanded_with(&self, budget: usize, memo: &mut HashMap<u32, Option<Poly>>) -> Option<Poly> {
        if !self.has_nodes() {
            return (self.len() <= budget).then(|| self.clone());
        }
        let mut out = Poly::zero();
        for (m, c) in &self.terms {
            let mut term = Poly::constant(c.clone());
            for &(a, e) in m.factors() {
                if e < 0 {
                    return None;
                }
                let factor = match a {
                    Atom::Node(id) => {
                        if !memo.contains_key(&id) {
                            let x = node_definition(id).expanded_with(budget, memo);
                            memo.insert(id, x);
                        }
                        memo.get(&id).cloned().flatten()?
                    }
                    _ => Poly::atom(a),
                };
                for _ in 0..e {
                    // The product's size is at most the product of the sizes: refuse early.
                    if term.len().saturating_mul(factor.len()) > budget.saturating_mul(4) {
                        return None;
                    }
                    term = term.mul(&factor);
                    if term.len() > budget {
                        return None;
                    }
                }
            }
            out = out.add(&term);
            if out.len() > budget {
                return None;
            }
        }
        Some(out)
    }

    /// Whether any term contains a shared subexpression ([`Atom::Node`]).
    pub fn has_nodes(&self) -> bool {
        self.terms
            .iter()
            .any(|(m, _)| m.factors().iter().any(|(a, _)| matches!(a, Atom::Node(_))))
    }

    /// `self / other`.
    pub fn div(&self, other: &Poly) -> Result<Poly, SymbolicError> {
        Ok(self.mul(&other.inv()?))
    }

    /// Numeric value.
    pub fn eval(&self, env: &Env<'_>) -> f64 {
        self.terms
            .iter()
            .map(|(m, c)| c.to_f64() * m.eval(env))
            .sum()
    }

    /// Joints (0-based) this expression depends on, including through `Inv` atoms.
    pub fn joints(&self) -> BTreeSet<usize> {
        let mut s = BTreeSet::new();
        for (m, _) in &self.terms {
            for (a, _) in m.factors() {
                if let Some(k) = a.joint() {
                    s.insert(k);
                } else if let Atom::Inv(id) = a {
                    s.extend(inverse_denominator(*id).joints());
                } else if let Atom::Node(id) = a {
                    s.extend(node_dependencies(*id, false));
                }
            }
        }
        s
    }

    /// Parameters (indices) this expression depends on.
    pub fn params(&self) -> BTreeSet<usize> {
        let mut s = BTreeSet::new();
        for (m, _) in &self.terms {
            for (a, _) in m.factors() {
                if let Atom::Param(p) = a {
                    s.insert(*p as usize);
                } else if let Atom::Inv(id) = a {
                    s.extend(inverse_denominator(*id).params());
                } else if let Atom::Node(id) = a {
                    s.extend(node_dependencies(*id, true));
                }
            }
        }
        s
    }

    /// Does any coefficient have a denominator other than a power of 2 and 5 (i.e. is not a
    /// finite decimal)? Useful to see where exactness was lost; informational only.
    pub fn max_coefficient_digits(&self) -> usize {
        self.terms
            .iter()
            .map(|(_, c)| {
                let (n, d) = c.to_parts();
                n.len().max(d.len())
            })
            .max()
            .unwrap_or(0)
    }

    /// A printable form using the given parameter names (`s7` is `sin q[6]`, thesis style).
    pub fn display<'a>(&'a self, names: &'a [String]) -> PolyDisplay<'a> {
        PolyDisplay { poly: self, names }
    }

    /// Parses an expression such as `-c8*(l_8 + l_b*c7)/l_a + 2^-1*s7^2` with the
    /// [length-expression grammar](trocar_model::expr) (`+ - * / ^`, parentheses, numbers, `pi`)
    /// where a name is one of the given parameter names or `sK`/`cK`/`qK` (thesis joint `K`,
    /// 1-based). Intended for tests and hand-written reference matrices.
    pub fn parse(text: &str, names: &[&str]) -> Result<Poly, SymbolicError> {
        let expr = trocar_model::expr::Expr::parse(text)
            .map_err(|e| SymbolicError::Parse(e.at, e.message))?;
        Poly::from_expr(&expr, &|id| {
            if let Some(p) = names.iter().position(|n| *n == id) {
                return Some(Poly::param(p));
            }
            let (head, num) = id.split_at(1);
            let k: usize = num.parse().ok().filter(|k| *k >= 1)?;
            match head {
                "s" => Some(Poly::sin(k - 1)),
                "c" => Some(Poly::cos(k - 1)),
                "q" => Some(Poly::joint(k - 1)),
                _ => None,
            }
        })
    }

    /// The polynomial of a parsed [length expression](trocar_model::expr::Expr): numbers exactly
    /// as their decimal reading ([`Rational::from_f64_decimal`]), `pi` as that of its `f64` value,
    /// each symbol as `symbol(name)` (`None`: an unknown identifier, reported at its offset),
    /// `/` and negative powers through [`Poly::div`] and [`Poly::inv`].
    pub fn from_expr(
        expr: &trocar_model::expr::Expr,
        symbol: &dyn Fn(&str) -> Option<Poly>,
    ) -> Result<Poly, SymbolicError> {
        use trocar_model::expr::{BinOp, Expr};
        let number = |x: f64, at: usize| {
            Rational::from_f64_decimal(x)
                .map(Poly::constant)
                .map_err(|_| SymbolicError::Parse(at, "bad number".into()))
        };
        Ok(match expr {
            Expr::Number { value, at } => number(*value, *at)?,
            Expr::Pi { at } => number(std::f64::consts::PI, *at)?,
            Expr::Symbol { name, at } => symbol(name)
                .ok_or_else(|| SymbolicError::Parse(*at, format!("unknown identifier `{name}`")))?,
            Expr::Neg { operand, .. } => Poly::from_expr(operand, symbol)?.neg(),
            Expr::Binary { op, lhs, rhs, .. } => {
                let a = Poly::from_expr(lhs, symbol)?;
                let b = Poly::from_expr(rhs, symbol)?;
                match op {
                    BinOp::Add => a.add(&b),
                    BinOp::Sub => a.sub(&b),
                    BinOp::Mul => a.mul(&b),
                    BinOp::Div => a.div(&b)?,
                }
            }
            Expr::Pow { base, exponent, .. } => {
                let p = Poly::from_expr(base, symbol)?.pow(exponent.unsigned_abs());
                if *exponent < 0 {
                    p.inv()?
                } else {
                    p
                }
            }
        })
    }
}

/// Rule `pythagorean`: `s_k^e → s_k^(e−2) (1 − c_k²)` until every sine has degree ≤ 1.
fn pythagorean(m: Monomial, c: Rational, out: &mut Vec<(Monomial, Rational)>) {
    let high = m
        .factors()
        .iter()
        .find(|(a, e)| matches!(a, Atom::Sin(_)) && *e >= 2)
        .copied();
    match high {
        None => out.push((m, c)),
        Some((Atom::Sin(k), e)) => {
            let base = m.with_exponent(Atom::Sin(k), e - 2);
            let cos2 = base.mul(&Monomial::atom(Atom::Cos(k), 2));
            pythagorean(base, c.clone(), out);
            pythagorean(cos2, -&c, out);
        }
        Some(_) => out.push((m, c)),
    }
}

/// Rule `collect_like_terms`: sort by monomial, add coefficients of equal monomials, drop zeros.
///
/// With floating coefficients (rule "float stays float" of [`super::number`]: a summand longer
/// than [`FLOATING_BITS`]) a sum that cancels to within [`CANCELLATION`] of its largest summand is
/// rounding noise and is dropped as zero, as the exact sum would have been: otherwise identities
/// such as `s² + c² = 1` or a vanishing determinant minor would leave terms of size `1e-17`.
/// Short (exact) coefficients are never affected.
fn collect_like_terms(mut v: Vec<(Monomial, Rational)>) -> Vec<(Monomial, Rational)> {
    v.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out: Vec<(Monomial, Rational)> = Vec::with_capacity(v.len());
    // Of the group being summed (the last of `out`): the largest |summand| and whether any
    // summand is floating.
    let mut largest = 0.0f64;
    let mut floating = false;
    let close = |out: &mut Vec<(Monomial, Rational)>, largest: f64, floating: bool| {
        if let Some((_, lc)) = out.last() {
            if lc.is_zero() || (floating && lc.to_f64().abs() <= CANCELLATION * largest) {
                out.pop();
            }
        }
    };
    for (m, c) in v {
        match out.last_mut() {
            Some((lm, lc)) if *lm == m => {
                largest = largest.max(c.to_f64().abs());
                floating |= c.bits() > FLOATING_BITS;
                *lc = &*lc + &c;
            }
            _ => {
                close(&mut out, largest, floating);
                largest = c.to_f64().abs();
                floating = c.bits() > FLOATING_BITS;
                out.push((m, c));
            }
        }
    }
    close(&mut out, largest, floating);
    out
}

/// A coefficient longer than this (bits of numerator plus denominator) is taken as floating by
/// [`collect_like_terms`]: a 17-digit decimal or a rounded `f64`, never a short exact rational.
const FLOATING_BITS: u64 = 64;

/// Relative size under which a sum of floating coefficients is rounding noise (`2⁻⁴²`, about
/// `2.3e-13`, a few hundred times the rounding of one `f64` operation).
const CANCELLATION: f64 = 2.273_736_754_432_320_6e-13;

/// Rule `inverse_cancel`: a product `Inv(P)^a · (P · R)` where the polynomial factor is exactly
/// `P` times the atom is recognised when the whole sum divided by the atom equals `P · k`.
/// Applied to the simple and common case of `P · Inv(P)` (all terms share `Inv(P)` with
/// exponent 1 and the cofactor is a constant multiple of `P`).
fn inverse_cancel(p: Poly) -> Poly {
    let Some((first, _)) = p.terms.first() else {
        return p;
    };
    let Some(&(Atom::Inv(id), 1)) = first
        .factors()
        .iter()
        .find(|(a, _)| matches!(a, Atom::Inv(_)))
    else {
        return p;
    };
    let atom = Atom::Inv(id);
    if !p.terms.iter().all(|(m, _)| m.exponent(atom) == 1) {
        return p;
    }
    let cof = Poly::from_terms(
        p.terms
            .iter()
            .map(|(m, c)| (m.with_exponent(atom, 0), c.clone()))
            .collect(),
    );
    let den = inverse_denominator(id);
    if den.is_zero() || cof.len() != den.len() {
        return p;
    }
    let k = &cof.terms[cof.len() - 1].1 * &Rational::one();
    if cof == den.scale(&k) {
        Poly::constant(k)
    } else {
        p
    }
}

/// Display helper returned by [`Poly::display`].
pub struct PolyDisplay<'a> {
    poly: &'a Poly,
    names: &'a [String],
}

fn atom_name(a: Atom, names: &[String]) -> String {
    match a {
        Atom::Sin(k) => format!("s{}", k + 1),
        Atom::Cos(k) => format!("c{}", k + 1),
        Atom::Joint(k) => format!("q{}", k + 1),
        Atom::Param(p) => names
            .get(p as usize)
            .cloned()
            .unwrap_or_else(|| format!("p{p}")),
        Atom::Inv(id) => format!("1/({})", inverse_denominator(id).display(names)),
        // A node is shown by its number: written out, a chain's nodes are exponentially long.
        Atom::Node(id) => format!("n{id}"),
    }
}

impl fmt::Display for PolyDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.poly.is_zero() {
            return write!(f, "0");
        }
        for (i, (m, c)) in self.poly.terms.iter().enumerate() {
            let neg = c.is_negative();
            if i == 0 {
                if neg {
                    write!(f, "-")?;
                }
            } else {
                write!(f, "{}", if neg { " - " } else { " + " })?;
            }
            let a = c.abs();
            let mut parts: Vec<String> = Vec::new();
            if !a.is_one() || m.is_one() {
                parts.push(a.to_string());
            }
            for &(atom, e) in m.factors() {
                let n = atom_name(atom, self.names);
                parts.push(if e == 1 { n } else { format!("{n}^{e}") });
            }
            write!(f, "{}", parts.join("*"))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(t: &str) -> Poly {
        Poly::parse(t, &["la", "lb"]).unwrap()
    }

    #[test]
    fn rule_collect_like_terms() {
        assert_eq!(p("2*c1 + 3*c1"), p("5*c1"));
        assert!(p("c1*la - la*c1").is_zero());
        assert_eq!(p("c1 + 0*s2").len(), 1);
    }

    #[test]
    fn rule_exponent_add() {
        assert_eq!(p("la*la"), p("la^2"));
        assert_eq!(p("la*(1/la)"), Poly::one());
        assert_eq!(p("c3^2*c3"), p("c3^3"));
    }

    #[test]
    fn rule_shared_subexpression() {
        let long = p("c1*c2 + s1*s2 + c1*s2 + s1*c2 + la*c1 + la*s1 + 2*c2");
        assert_eq!(long.len(), 7);
        // Short enough: unchanged.
        assert_eq!(long.shared(7), long);
        // Longer than the bound: one node times the leading coefficient, shared by multiples.
        let a = long.shared(4);
        let b = long.scale(&Rational::integer(-2)).shared(4);
        assert_eq!(a.len(), 1);
        assert!(a.has_nodes() && !long.has_nodes());
        assert_eq!(a.terms()[0].0, b.terms()[0].0, "one node for P and −2P");
        // Same values, joints and parameters.
        let env = Env {
            q: &[0.3, -0.7],
            params: &[0.11, 0.2],
        };
        assert!((a.eval(&env) - long.eval(&env)).abs() < 1e-15);
        assert!((b.eval(&env) + 2.0 * long.eval(&env)).abs() < 1e-14);
        assert_eq!(a.joints(), long.joints());
        assert_eq!(a.params(), long.params());
        // A node of nodes, written out again: the canonical form, or None over the budget.
        let sq = a.mul(&a).add(&p("lb")).shared(0);
        assert_eq!(sq.expanded(1000).unwrap(), long.mul(&long).add(&p("lb")));
        assert!(sq.expanded(5).is_none());
        // Evaluation is memoised per point: a new point gives new values.
        let env2 = Env {
            q: &[1.1, 0.4],
            params: &[0.11, 0.2],
        };
        let want = long.eval(&env2) * long.eval(&env2) + 0.2;
        assert!((sq.eval(&env2) - want).abs() < 1e-14);
    }

    #[test]
    fn rule_floating_cancellation() {
        // One product of floating coefficients, rounded along two paths: the two differ in the
        // last bit, as the coefficients of s² and c² of a float geometry do.
        let f = |v: f64| Rational::from_f64_decimal(v).unwrap();
        let (x, y, z) = (f(0.1f64.sin()), f(0.37f64.cos()), f(1.53f64.sin()));
        let k1 = &(&x * &y) * &z;
        let k2 = &x * &(&y * &z);
        assert_ne!(k1, k2, "the two roundings differ");
        // k1 s² + k2 c² = k1 + (k2 − k1) c²: the c² term is rounding noise and is dropped.
        let s2 = Poly::sin(0).mul(&Poly::sin(0)).scale(&k1);
        let c2 = Poly::cos(0).mul(&Poly::cos(0)).scale(&k2);
        assert_eq!(s2.add(&c2), Poly::constant(k1.clone()));
        // A true difference, even small, is kept.
        let d = Poly::constant(k1.clone()).sub(&Poly::constant(
            &k1 - &Rational::new(1, 1_000_000_000).unwrap(),
        ));
        assert!(!d.is_zero());
    }

    #[test]
    fn rule_pythagorean() {
        assert_eq!(p("s1^2 + c1^2"), Poly::one());
        assert_eq!(p("s2^2"), p("1 - c2^2"));
        assert_eq!(p("s2^3"), p("s2 - s2*c2^2"));
        // sin(a)^2 cos(b)^2 + ... mixed joints
        assert_eq!(p("(s1*s2)^2"), p("(1 - c1^2)*(1 - c2^2)"));
        // the normal form is unique: every sine has degree at most 1
        for (m, _) in p("(s1 + s2 + c1)^4").terms() {
            assert!(m.exponent(Atom::Sin(0)) <= 1 && m.exponent(Atom::Sin(1)) <= 1);
        }
    }

    #[test]
    fn rule_inverse_of_constant() {
        assert_eq!(p("1/4"), Poly::constant(Rational::new(1, 4).unwrap()));
        assert_eq!(Poly::zero().inv(), Err(SymbolicError::DivisionByZero));
    }

    #[test]
    fn rule_inverse_of_monomial() {
        let x = p("1/(2*la^2*lb)");
        assert_eq!(x.terms().len(), 1);
        assert_eq!(x.terms()[0].0.exponent(Atom::Param(0)), -2);
        assert_eq!(x.mul(&p("la^2*lb")), p("1/2"));
    }

    #[test]
    fn rule_inverse_normalise() {
        let a = p("1/(1 + la^2)");
        let b = p("3/(3 + 3*la^2)");
        assert_eq!(a, b);
        let c = p("-2/(-2 - 2*la^2)");
        assert_eq!(a, c);
        let env = Env {
            q: &[],
            params: &[0.5, 0.0],
        };
        assert!((a.eval(&env) - 1.0 / 1.25).abs() < 1e-15);
    }

    #[test]
    fn rule_inverse_cancel() {
        assert_eq!(p("(1 + la^2) / (1 + la^2)"), Poly::one());
        assert_eq!(p("(2 + 2*la^2) / (1 + la^2)"), Poly::integer(2));
        assert_eq!(p("1/(1 + la^2) + la^2/(1 + la^2)"), Poly::one());
        assert_ne!(p("1/(1 + la^2) + la/(1 + la^2)"), Poly::one());
    }

    #[test]
    fn eval_and_display() {
        let x = p("-c8*(2 + lb*c7)/la + s1");
        let names = vec!["la".to_string(), "lb".to_string()];
        let q = [0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.7, -0.2];
        let env = Env {
            q: &q,
            params: &[0.15, 0.18],
        };
        let want = -(-0.2f64).cos() * (2.0 + 0.18 * 0.7f64.cos()) / 0.15 + 0.3f64.sin();
        assert!((x.eval(&env) - want).abs() < 1e-14);
        assert_eq!(p(&x.display(&names).to_string()), x);
        assert_eq!(x.joints().into_iter().collect::<Vec<_>>(), vec![0, 6, 7]);
    }
}
