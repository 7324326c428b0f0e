//! A program written as Rust statements: the trig prelude (rule `one_trig`: one `sin_cos_array`
//! call for a function's joints) and one `let` per live value, with operators and parentheses
//! by precedence, fused multiply-adds where [`Program::fused_products`] says so, and the output
//! expressions.

use super::ty::Ty;
use crate::ir::{Op, Program, ValueId};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

pub(super) const PREC_SUM: u8 = 1;
pub(super) const PREC_PROD: u8 = 2;
pub(super) const PREC_NEG: u8 = 3;
pub(super) const PREC_ATOM: u8 = 4;

/// How joint and parameter values are reached in a function body.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Access {
    /// `q: &[T; N]`, trig computed in the body.
    Q,
    /// `t: &JointTrig<T>`.
    Trig,
}

struct BodyWriter<'a> {
    prog: &'a Program,
    ty: &'a Ty,
    access: Access,
    /// Name of a let-bound value.
    bound: Vec<Option<Ident>>,
    inline: Vec<bool>,
    /// The products written into their one addition as `Real::mul_add`
    /// ([`Program::fused_products`]).
    fused: Vec<bool>,
}

impl BodyWriter<'_> {
    fn expr(&self, v: ValueId) -> (TokenStream, u8) {
        if let Some(id) = &self.bound[v.index()] {
            return (quote!(#id), PREC_ATOM);
        }
        let r = self.ty.real_path();
        let op = self.prog.op(v);
        match *op {
            Op::Const(c) => {
                let x = c.value();
                if x < 0.0 {
                    let l = self.ty.lit(-x);
                    (quote!(-#l), PREC_NEG)
                } else {
                    (self.ty.lit(x), PREC_ATOM)
                }
            }
            Op::Param(p) => {
                let name = format_ident!("{}", self.prog.params()[p]);
                (quote!(p.#name), PREC_ATOM)
            }
            Op::Joint(k) => {
                let k = Literal::usize_unsuffixed(k);
                match self.access {
                    Access::Q => (quote!(q[#k]), PREC_ATOM),
                    Access::Trig => (quote!(t.q[#k]), PREC_ATOM),
                }
            }
            Op::Sin(k) | Op::Cos(k) => {
                let sin = matches!(op, Op::Sin(_));
                match self.access {
                    Access::Q => {
                        let id = format_ident!("{}{}", if sin { "s" } else { "c" }, k + 1);
                        (quote!(#id), PREC_ATOM)
                    }
                    Access::Trig => {
                        let k = Literal::usize_unsuffixed(k);
                        if sin {
                            (quote!(t.sin[#k]), PREC_ATOM)
                        } else {
                            (quote!(t.cos[#k]), PREC_ATOM)
                        }
                    }
                }
            }
            Op::Add(a, b) => match (self.product(a), self.product(b)) {
                (Some((x, y)), _) => self.mul_add(x, y, self.expr(b).0),
                (None, Some((x, y))) => self.mul_add(x, y, self.expr(a).0),
                (None, None) => self.binary(a, b, quote!(+), PREC_SUM),
            },
            Op::Sub(a, b) => match (self.product(a), self.product(b)) {
                // x y − b = fma(x, y, −b); a − x y = fma(−x, y, a).
                (Some((x, y)), _) => {
                    let nb = self.operand(b, PREC_NEG);
                    self.mul_add(x, y, quote!(-#nb))
                }
                (None, Some((x, y))) => {
                    let nx = self.operand(x, PREC_NEG);
                    let y = self.expr(y).0;
                    let a = self.expr(a).0;
                    (quote!(#r::mul_add(-#nx, #y, #a)), PREC_ATOM)
                }
                (None, None) => self.binary(a, b, quote!(-), PREC_SUM),
            },
            Op::Mul(a, b) => self.binary(a, b, quote!(*), PREC_PROD),
            Op::Div(a, b) => self.binary(a, b, quote!(/), PREC_PROD),
            Op::Neg(a) => {
                let x = self.operand(a, PREC_NEG);
                (quote!(-#x), PREC_NEG)
            }
            Op::Sqrt(a) => {
                let (x, _) = self.expr(a);
                (quote!(#r::sqrt(#x)), PREC_ATOM)
            }
            Op::Abs(a) => {
                let (x, _) = self.expr(a);
                (quote!(#r::abs(#x)), PREC_ATOM)
            }
        }
    }

    /// The factors of `v` when it is a product written in place (not a `let`-bound value): an
    /// addition of it is then one fused multiply-add (`Real::mul_add`).
    fn product(&self, v: ValueId) -> Option<(ValueId, ValueId)> {
        if !self.fused[v.index()] {
            return None;
        }
        match *self.prog.op(v) {
            Op::Mul(x, y) => Some((x, y)),
            _ => None,
        }
    }

    /// `x · y + c` as `Real::mul_add(x, y, c)`.
    fn mul_add(&self, x: ValueId, y: ValueId, c: TokenStream) -> (TokenStream, u8) {
        let r = self.ty.real_path();
        let (x, _) = self.expr(x);
        let (y, _) = self.expr(y);
        (quote!(#r::mul_add(#x, #y, #c)), PREC_ATOM)
    }

    /// `v` as an operand that needs precedence at least `min`.
    fn operand(&self, v: ValueId, min: u8) -> TokenStream {
        let (x, p) = self.expr(v);
        if p < min {
            quote!((#x))
        } else {
            x
        }
    }

    fn binary(&self, a: ValueId, b: ValueId, op: TokenStream, prec: u8) -> (TokenStream, u8) {
        // Left-associative: the right operand must bind tighter to keep the evaluation order.
        let x = self.operand(a, prec);
        let y = self.operand(b, prec + 1);
        (quote!(#x #op #y), prec)
    }
}

/// A program written as Rust: the statements (trig prelude and `let` bindings) and the output
/// expressions.
pub(super) struct Body {
    pub(super) stmts: Vec<TokenStream>,
    pub(super) outs: Vec<TokenStream>,
    /// For each output, how many of `stmts` must precede it: the position just after the last
    /// statement its expression reads (0 when it reads none, e.g. a constant).
    pub(super) ready: Vec<usize>,
}

impl Body {
    /// `stmts` with each of `stores` (one per output, in output order) placed right after the
    /// last statement its value reads, stores that become ready together in their own order.
    ///
    /// Written at the end instead, every output value stays live (in a register, or spilled)
    /// from its computation to the end of the function; placed early, its register is free for
    /// the rest of the walk. On SSE2's two-operand instructions this removes register copies and
    /// spills: the Panda's `link_pose_and_jacobian_trig` compiles to 333 instructions instead of
    /// 388 at the default x86-64 target, and runs in 0.87× the time with AVX-512
    /// (BENCHMARKS.md, "Stores where their values are ready").
    pub(super) fn interleaved(self, stores: Vec<TokenStream>) -> Vec<TokenStream> {
        debug_assert_eq!(stores.len(), self.ready.len());
        let mut after: Vec<Vec<TokenStream>> = vec![Vec::new(); self.stmts.len() + 1];
        for (store, &r) in stores.into_iter().zip(&self.ready) {
            after[r].push(store);
        }
        let mut after = after.into_iter();
        let mut out: Vec<TokenStream> = after.next().unwrap_or_default();
        for (stmt, group) in self.stmts.into_iter().zip(after) {
            out.push(stmt);
            out.extend(group);
        }
        out
    }
}

/// A program written as Rust ([`Body`]).
pub(super) fn body(prog: &Program, ty: &Ty, access: Access) -> Body {
    let live = prog.live();
    let n = prog.ops().len();
    let uses = prog.use_counts();
    let mut w = BodyWriter {
        prog,
        ty,
        access,
        bound: vec![None; n],
        inline: vec![false; n],
        fused: prog.fused_products(),
    };
    let mut stmts = Vec::new();
    if access == Access::Q {
        let r = ty.real_path();
        let mut used_sin = std::collections::BTreeSet::new();
        let mut used_cos = std::collections::BTreeSet::new();
        for (i, op) in prog.ops().iter().enumerate() {
            if live[i] {
                match *op {
                    Op::Sin(k) => {
                        used_sin.insert(k);
                    }
                    Op::Cos(k) => {
                        used_cos.insert(k);
                    }
                    _ => {}
                }
            }
        }
        stmts.extend(trig_statement(
            &r,
            &prog.trig_joints(),
            |k| used_sin.contains(&k),
            |k| used_cos.contains(&k),
        ));
    }
    // How many statements precede the point where each value can be written: the trig prelude
    // for a joint's sine, cosine or value read from `q`, a value's own `let`, or the latest of
    // its operands' for a value written in place.
    let prelude = stmts.len();
    let mut ready = vec![0usize; n];
    let mut counter = 0usize;
    for (i, op) in prog.ops().iter().enumerate() {
        if !live[i] {
            continue;
        }
        ready[i] = match op {
            Op::Joint(_) | Op::Sin(_) | Op::Cos(_) => prelude,
            _ => op.operands().map(|a| ready[a.index()]).max().unwrap_or(0),
        };
        let atom = matches!(
            op,
            Op::Const(_) | Op::Param(_) | Op::Joint(_) | Op::Sin(_) | Op::Cos(_)
        );
        if atom || uses[i] <= 1 {
            w.inline[i] = true;
            continue;
        }
        let (e, _) = w.expr(ValueId(i as u32));
        let id = format_ident!("x{}", counter);
        counter += 1;
        stmts.push(quote!(let #id = #e;));
        w.bound[i] = Some(id);
        ready[i] = stmts.len();
    }
    let outs = prog.outputs().iter().map(|&o| w.expr(o).0).collect();
    let ready = prog.outputs().iter().map(|o| ready[o.index()]).collect();
    Body { stmts, outs, ready }
}

/// Whether a live operation of `prog` matches `f` (joint values, parameters ...).
pub(super) fn uses(prog: &Program, f: impl Fn(&Op) -> bool) -> bool {
    prog.ops().iter().zip(prog.live()).any(|(op, l)| l && f(op))
}

/// `let ([s.., ..], [c.., ..]) = R::sin_cos_array(&[q[k], ..]);`: the sines and cosines of the
/// joints `ks` (0-based, ascending) in one call (rule `one_trig`: one `sin_cos` per joint, batched
/// so that the runtime can compute them side by side), binding `s{k+1}` and `c{k+1}` where
/// `bind_sin(k)` and `bind_cos(k)` hold and `_` elsewhere. Nothing when `ks` is empty.
pub(super) fn trig_statement(
    r: &TokenStream,
    ks: &[usize],
    bind_sin: impl Fn(usize) -> bool,
    bind_cos: impl Fn(usize) -> bool,
) -> Option<TokenStream> {
    if ks.is_empty() {
        return None;
    }
    let bind = |k: usize, yes: bool, letter: &str| {
        if yes {
            let id = format_ident!("{}{}", letter, k + 1);
            quote!(#id)
        } else {
            quote!(_)
        }
    };
    let sins = ks.iter().map(|&k| bind(k, bind_sin(k), "s"));
    let coss = ks.iter().map(|&k| bind(k, bind_cos(k), "c"));
    let args = ks.iter().map(|&k| {
        let kk = Literal::usize_unsuffixed(k);
        quote!(q[#kk])
    });
    Some(quote!(let ([#(#sins),*], [#(#coss),*]) = #r::sin_cos_array(&[#(#args),*]);))
}
