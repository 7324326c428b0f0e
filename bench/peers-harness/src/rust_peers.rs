//! The peers that emit Rust, compiled here with the harness's flags: wrenfold's `RustGenerator`
//! (generic over the `wrenfold-traits` spans) and SymForce's Rust backend (nalgebra `SMatrix`),
//! written by `bench/peers_rust_gen.py` into `bench/out/` (a module per case in each file) from the
//! same chains as the C peers. Same layout as [`super::eval`]: the pose block is the 3 × 4 matrix
//! [R | p] and every Jacobian a 6 × n matrix, all column-major.
//!
//! Each case has two functions: from the joint values (the tool's own `sin`/`cos`, i.e. std's,
//! glibc's), and `_trig` given the sines and cosines ([`Trig`]). Both are called as
//! [`super::ours::eval_fn`] calls ours: through a function pointer chosen before the timed loop,
//! inputs borrowed in place, outputs written into the caller's slice.

use super::{Case, EvalFn};
use nalgebra::{SMatrix, SVector};
use wrenfold_traits::{OutputSpan2D, Span2D};

/// The generated wrenfold code (`wrenfold_peers.rs`).
#[allow(missing_docs, clippy::all, unused_imports)]
pub mod wrenfold_gen {
    include!(concat!(env!("TROCAR_PEERS_RUST_DIR"), "/wrenfold_peers.rs"));
}

/// The generated SymForce code (`symforce_peers.rs`).
#[allow(missing_docs, clippy::all, unused_imports, unused_variables)]
pub mod symforce_gen {
    include!(concat!(env!("TROCAR_PEERS_RUST_DIR"), "/symforce_peers.rs"));
}

/// Which Rust-emitting peer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RustPeer {
    /// wrenfold 0.5 (`RustGenerator`).
    Wrenfold,
    /// SymForce 0.12 (`RustConfig`).
    Symforce,
}

impl RustPeer {
    /// Both.
    pub const ALL: [RustPeer; 2] = [RustPeer::Wrenfold, RustPeer::Symforce];
    /// Short name (bench ids, `cg_driver`).
    pub fn name(self) -> &'static str {
        match self {
            RustPeer::Wrenfold => "wrenfold",
            RustPeer::Symforce => "symforce",
        }
    }
    /// Parses [`RustPeer::name`].
    pub fn from_name(s: &str) -> Option<RustPeer> {
        RustPeer::ALL.into_iter().find(|p| p.name() == s)
    }
    /// The case's function from the joint values, as an [`EvalFn`].
    pub fn eval_fn(self, case: Case) -> EvalFn {
        match self {
            RustPeer::Wrenfold => {
                per_case!(wrenfold_eval, case; Uni, Bzy, Bzx, DiaZy, Panda, PandaI, Oblique7, PandaRcm)
            }
            RustPeer::Symforce => {
                per_case!(symforce_eval, case; Uni, Bzy, Bzx, DiaZy, Panda, PandaI, Oblique7, PandaRcm)
            }
        }
    }
    /// The case's `_trig` function (given the sines and cosines).
    pub fn eval_trig_fn(self, case: Case) -> TrigFn {
        match self {
            RustPeer::Wrenfold => per_case_trig!(wrenfold_eval_trig, case),
            RustPeer::Symforce => per_case_trig!(symforce_eval_trig, case),
        }
    }
}

/// The sines and cosines of a case's joints (the first [`Case::nq`] entries used).
#[derive(Clone, Copy, Debug)]
pub struct Trig {
    /// sin q_k.
    pub s: [f64; 8],
    /// cos q_k.
    pub c: [f64; 8],
}

impl Trig {
    /// `sin_cos` (std) of each joint value.
    pub fn new(q: &[f64]) -> Trig {
        let mut t = Trig {
            s: [0.0; 8],
            c: [0.0; 8],
        };
        for (k, &x) in q.iter().take(8).enumerate() {
            (t.s[k], t.c[k]) = x.sin_cos();
        }
        t
    }
}

/// A case's `_trig` function with the case fixed.
pub type TrigFn = fn(&Trig, &[f64], &mut [f64]);

macro_rules! per_case_trig {
    ($f:ident, $case:expr) => {
        match $case {
            Case::Uni => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::Uni, t, p, out),
            Case::Bzy => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::Bzy, t, p, out),
            Case::Bzx => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::Bzx, t, p, out),
            Case::DiaZy => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::DiaZy, t, p, out),
            Case::Panda => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::Panda, t, p, out),
            Case::PandaI => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::PandaI, t, p, out),
            Case::Oblique7 => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::Oblique7, t, p, out),
            Case::PandaRcm => |t: &Trig, p: &[f64], out: &mut [f64]| $f(Case::PandaRcm, t, p, out),
        }
    };
}
use per_case_trig;

/// The first `N` values of `x`, borrowed in place.
#[inline(always)]
fn head<const N: usize>(x: &[f64]) -> &[f64; N] {
    x[..N].try_into().expect("enough inputs")
}

/// `x[..R * C]` as `C` columns of `R`.
#[inline(always)]
fn block<const R: usize, const C: usize>(x: &mut [f64]) -> &mut [[f64; R]; C] {
    let (chunks, _) = x.as_chunks_mut::<R>();
    (&mut chunks[..C]).try_into().expect("out holds the block")
}

/// A column vector input for wrenfold's code.
pub struct In<'a, const N: usize>(&'a [f64; N]);

impl<const N: usize> Span2D<N, 1> for In<'_, N> {
    type ValueType = f64;
    #[inline(always)]
    fn get(&self, i: usize, _j: usize) -> f64 {
        self.0[i]
    }
}

/// A column-major output block for wrenfold's code.
pub struct Out<'a, const R: usize, const C: usize>(&'a mut [[f64; R]; C]);

impl<const R: usize, const C: usize> OutputSpan2D<R, C> for Out<'_, R, C> {
    type ValueType = f64;
    #[inline(always)]
    fn set(&mut self, i: usize, j: usize, val: f64) {
        self.0[j][i] = val;
    }
}

/// `&[f64; N]` as nalgebra's column vector, in place.
#[inline(always)]
fn nv<const N: usize>(x: &[f64; N]) -> &SVector<f64, N> {
    // SAFETY: `Matrix` is `repr(C)` around its storage (and zero-sized markers), `ArrayStorage`
    // is `repr(transparent)` around `[[f64; N]; 1]`: the same layout and alignment as `[f64; N]`.
    unsafe { &*(x as *const [f64; N]).cast::<SVector<f64, N>>() }
}

/// A column-major block as nalgebra's matrix, in place.
#[inline(always)]
fn nm<const R: usize, const C: usize>(x: &mut [[f64; R]; C]) -> &mut SMatrix<f64, R, C> {
    // SAFETY: as in `nv`: `SMatrix<f64, R, C>` has the layout of `[[f64; R]; C]`.
    unsafe { &mut *(x as *mut [[f64; R]; C]).cast::<SMatrix<f64, R, C>>() }
}

/// Calls `$m::$f` of the wrenfold module with the inputs `$ins` (each `&[f64; N]`) and the output
/// blocks of the given shapes, in order, in `$out`.
macro_rules! wf {
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal)) => {
        $f($(&In($in),)* &mut Out(block::<$r0, $c0>($out)))
    };
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal), ($r1:literal, $c1:literal)) => {{
        let (a, b) = $out.split_at_mut($r0 * $c0);
        $f($(&In($in),)* &mut Out(block::<$r0, $c0>(a)), &mut Out(block::<$r1, $c1>(b)))
    }};
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal), ($r1:literal, $c1:literal), ($r2:literal, $c2:literal)) => {{
        let (a, rest) = $out.split_at_mut($r0 * $c0);
        let (b, c) = rest.split_at_mut($r1 * $c1);
        $f(
            $(&In($in),)*
            &mut Out(block::<$r0, $c0>(a)),
            &mut Out(block::<$r1, $c1>(b)),
            &mut Out(block::<$r2, $c2>(c)),
        )
    }};
}

/// The same for SymForce's (inputs `&SVector`, outputs `Option<&mut SMatrix>`).
macro_rules! sf {
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal)) => {
        $f($(nv($in),)* Some(nm(block::<$r0, $c0>($out))))
    };
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal), ($r1:literal, $c1:literal)) => {{
        let (a, b) = $out.split_at_mut($r0 * $c0);
        $f($(nv($in),)* Some(nm(block::<$r0, $c0>(a))), Some(nm(block::<$r1, $c1>(b))))
    }};
    ($f:path; $($in:expr),*; $out:expr; ($r0:literal, $c0:literal), ($r1:literal, $c1:literal), ($r2:literal, $c2:literal)) => {{
        let (a, rest) = $out.split_at_mut($r0 * $c0);
        let (b, c) = rest.split_at_mut($r1 * $c1);
        $f(
            $(nv($in),)*
            Some(nm(block::<$r0, $c0>(a))),
            Some(nm(block::<$r1, $c1>(b))),
            Some(nm(block::<$r2, $c2>(c))),
        )
    }};
}

/// Every case's call: `$call!($g::<case>::$f; inputs; out; shapes)`, with the case's joint and
/// parameter counts as the constants `$nq` and `$np`.
macro_rules! dispatch {
    ($call:ident, $g:ident, $case:expr, $out:expr, $nq:ident, $np:ident => [$($in:expr),*], $f:ident) => {
        match $case {
            Case::Uni => { const $nq: usize = 2; const $np: usize = 3; $call!($g::uni::$f; $($in),*; $out; (6, 7)) }
            Case::Bzy => { const $nq: usize = 2; const $np: usize = 3; $call!($g::bzy::$f; $($in),*; $out; (6, 6)) }
            Case::Bzx => { const $nq: usize = 2; const $np: usize = 3; $call!($g::bzx::$f; $($in),*; $out; (6, 6)) }
            Case::DiaZy => { const $nq: usize = 8; const $np: usize = 1; $call!($g::dia_zy::$f; $($in),*; $out; (3, 4), (6, 6), (6, 6)) }
            Case::Panda => { const $nq: usize = 7; const $np: usize = 1; $call!($g::panda::$f; $($in),*; $out; (3, 4), (6, 7)) }
            Case::PandaI => { const $nq: usize = 7; const $np: usize = 1; $call!($g::panda_i::$f; $($in),*; $out; (3, 4), (6, 7)) }
            Case::Oblique7 => { const $nq: usize = 7; const $np: usize = 1; $call!($g::oblique7::$f; $($in),*; $out; (3, 4), (6, 6), (6, 5)) }
            Case::PandaRcm => { const $nq: usize = 7; const $np: usize = 1; $call!($g::panda_rcm::$f; $($in),*; $out; (3, 4), (6, 6), (6, 5)) }
        }
    };
}

/// wrenfold's function of `case` from the joint values.
#[inline(always)]
pub fn wrenfold_eval(case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
    dispatch!(wf, wrenfold_gen, case, out, NQ, NP => [head::<NQ>(q), head::<NP>(p)], eval)
}

/// SymForce's function of `case` from the joint values.
#[inline(always)]
pub fn symforce_eval(case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
    dispatch!(sf, symforce_gen, case, out, NQ, NP => [head::<NQ>(q), head::<NP>(p)], eval)
}

/// wrenfold's `_trig` function of `case`.
#[inline(always)]
pub fn wrenfold_eval_trig(case: Case, t: &Trig, p: &[f64], out: &mut [f64]) {
    dispatch!(wf, wrenfold_gen, case, out, NQ, NP => [head::<NQ>(&t.s), head::<NQ>(&t.c), head::<NP>(p)], eval_trig)
}

/// SymForce's `_trig` function of `case`.
#[inline(always)]
pub fn symforce_eval_trig(case: Case, t: &Trig, p: &[f64], out: &mut [f64]) {
    dispatch!(sf, symforce_gen, case, out, NQ, NP => [head::<NQ>(&t.s), head::<NQ>(&t.c), head::<NP>(p)], eval_trig)
}
