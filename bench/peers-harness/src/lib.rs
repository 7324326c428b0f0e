//! Bench-only harness: the peers' generated C behind safe wrappers, and an f64 reference of the same
//! kinematics written independently in Rust (checked against the thesis's closed forms and against
//! finite differences in `tests/check.rs`).
//!
//! Cases (inputs `q`, parameters `p`, outputs column-major):
//! - `uni`, `bzy`, `bzx`: J^r of the presets (SPEC 3.1); `q = (θ7, θ8)`, `p = (l_a, l_b, l_8)`;
//!   6×7, 6×6, 6×6.
//! - `dia_zy`: dia10_like (SPEC 3.2) with the zy wrist; `q = θ1..θ8`, `p = (l_a)`; outputs FK
//!   (R column-major then p, 12), J^B_0i (6×6), J^r (6×6).

use core::ffi::c_int;

/// The preset cases.
pub const PRESETS: [Case; 3] = [Case::Uni, Case::Bzy, Case::Bzx];

/// One function that both peers generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// Unidirectional preset J^r (6×7).
    Uni,
    /// Bidirectional zy preset J^r (6×6).
    Bzy,
    /// Bidirectional zx preset J^r (6×6).
    Bzx,
    /// dia10_like zy: FK + J^B_0i + J^r.
    DiaZy,
}

impl Case {
    /// Short name used in file and bench names.
    pub fn name(self) -> &'static str {
        match self {
            Case::Uni => "uni",
            Case::Bzy => "bzy",
            Case::Bzx => "bzx",
            Case::DiaZy => "dia_zy",
        }
    }
    /// Parses [`Case::name`].
    pub fn from_name(s: &str) -> Option<Case> {
        [Case::Uni, Case::Bzy, Case::Bzx, Case::DiaZy].into_iter().find(|c| c.name() == s)
    }
    /// Output sizes (column-major blocks).
    pub fn outs(self) -> &'static [usize] {
        match self {
            Case::Uni => &[42],
            Case::Bzy | Case::Bzx => &[36],
            Case::DiaZy => &[12, 36, 36],
        }
    }
    /// Total output length.
    pub fn out_len(self) -> usize {
        self.outs().iter().sum()
    }
    /// Typical inputs (q, p).
    pub fn inputs(self) -> (Vec<f64>, Vec<f64>) {
        match self {
            Case::DiaZy => (vec![0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3], vec![0.15]),
            _ => (vec![0.5, 0.3], vec![0.15, 0.18, 0.21]),
        }
    }
}

type CasadiFn = unsafe extern "C" fn(
    arg: *const *const f64,
    res: *const *mut f64,
    iw: *mut i64,
    w: *mut f64,
    mem: c_int,
) -> c_int;

extern "C" {
    fn casadi_uni(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_bzy(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_bzx(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_dia_zy(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_cse_uni(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_cse_bzy(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_cse_bzx(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;
    fn casadi_cse_dia_zy(a: *const *const f64, r: *const *mut f64, iw: *mut i64, w: *mut f64, m: c_int) -> c_int;

    fn sympy_uni(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_bzy(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_bzx(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_dia_zy(q: *const f64, p: *const f64, fk: *mut f64, jb0i: *mut f64, jr: *mut f64);

    fn casadi_uni_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_bzy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_bzx_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_dia_zy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_uni_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_bzy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_bzx_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_dia_zy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;

    fn floor_two_sincos(q: *const f64, out: *mut f64);
    fn floor_eight_sincos(q: *const f64, out: *mut f64);
}

/// Which implementation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Peer {
    /// `casadi.Function` (SX, default options) + `CodeGenerator`.
    Casadi,
    /// The same with the `cse` option.
    CasadiCse,
    /// `sympy.cse` + `ccode`.
    Sympy,
    /// The Rust f64 reference of this crate ([`reference`]).
    RustReference,
}

impl Peer {
    /// Every implementation.
    pub const ALL: [Peer; 4] = [Peer::Casadi, Peer::CasadiCse, Peer::Sympy, Peer::RustReference];
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Peer::Casadi => "casadi",
            Peer::CasadiCse => "casadi_cse",
            Peer::Sympy => "sympy",
            Peer::RustReference => "rust_reference",
        }
    }
    /// Parses [`Peer::name`].
    pub fn from_name(s: &str) -> Option<Peer> {
        Peer::ALL.into_iter().find(|p| p.name() == s)
    }
}

type CasadiWorkFn = unsafe extern "C" fn(*mut i64, *mut i64, *mut i64, *mut i64) -> c_int;

/// The generated CasADi function of `peer` for `case` and its `*_work` size query.
fn casadi_fn(peer: Peer, case: Case) -> (CasadiFn, CasadiWorkFn) {
    match (peer, case) {
        (Peer::Casadi, Case::Uni) => (casadi_uni, casadi_uni_work),
        (Peer::Casadi, Case::Bzy) => (casadi_bzy, casadi_bzy_work),
        (Peer::Casadi, Case::Bzx) => (casadi_bzx, casadi_bzx_work),
        (Peer::Casadi, Case::DiaZy) => (casadi_dia_zy, casadi_dia_zy_work),
        (Peer::CasadiCse, Case::Uni) => (casadi_cse_uni, casadi_cse_uni_work),
        (Peer::CasadiCse, Case::Bzy) => (casadi_cse_bzy, casadi_cse_bzy_work),
        (Peer::CasadiCse, Case::Bzx) => (casadi_cse_bzx, casadi_cse_bzx_work),
        (Peer::CasadiCse, Case::DiaZy) => (casadi_cse_dia_zy, casadi_cse_dia_zy_work),
        _ => panic!("{peer:?} is not a CasADi peer"),
    }
}

/// CasADi's work sizes `(sz_arg, sz_res, sz_iw, sz_w)` of `peer` (CasADi) for `case`, from the
/// generated `*_work` function.
pub fn casadi_work_sizes(peer: Peer, case: Case) -> [i64; 4] {
    let (_, f) = casadi_fn(peer, case);
    let mut sz = [0i64; 4];
    let [a, r, iw, w] = &mut sz;
    // SAFETY: the generated `*_work` functions write one casadi_int through each non-null pointer.
    unsafe { f(a, r, iw, w) };
    sz
}

/// Evaluates `case` with implementation `peer` into `out` (length [`Case::out_len`]).
#[inline(always)]
pub fn eval(peer: Peer, case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
    assert!(out.len() >= case.out_len());
    assert!(q.len() >= if case == Case::DiaZy { 8 } else { 2 });
    assert!(p.len() >= if case == Case::DiaZy { 1 } else { 3 });
    let o = out.as_mut_ptr();
    match peer {
        Peer::Casadi | Peer::CasadiCse => {
            let (f, _) = casadi_fn(peer, case);
            let arg = [q.as_ptr(), p.as_ptr()];
            // Output blocks; only the first `outs().len()` are used by the callee.
            let res: [*mut f64; 3] = [o, o.wrapping_add(12), o.wrapping_add(48)];
            // SAFETY: SX-generated code reads arg[0..2] and writes res[0..n_out]. Its work sizes
            // sz_iw and sz_w are 0 (checked in tests: `casadi_work_sizes`), so it never touches
            // iw or w, and null is a valid work pointer (no per-call scratch to zero).
            unsafe { f(arg.as_ptr(), res.as_ptr(), core::ptr::null_mut(), core::ptr::null_mut(), 0) };
        }
        // SAFETY: the SymPy functions read q[0..nq], p[0..np] and write the output blocks.
        Peer::Sympy => unsafe {
            match case {
                Case::Uni => sympy_uni(q.as_ptr(), p.as_ptr(), o),
                Case::Bzy => sympy_bzy(q.as_ptr(), p.as_ptr(), o),
                Case::Bzx => sympy_bzx(q.as_ptr(), p.as_ptr(), o),
                Case::DiaZy => sympy_dia_zy(q.as_ptr(), p.as_ptr(), o, o.add(12), o.add(48)),
            }
        },
        Peer::RustReference => reference::eval(case, q, p, out),
    }
}

/// `out = (sin q0, cos q0, sin q1, cos q1)` in C (glibc), compiled like the peers.
pub fn floor_two(q: &[f64; 2], out: &mut [f64; 4]) {
    // SAFETY: reads 2, writes 4.
    unsafe { floor_two_sincos(q.as_ptr(), out.as_mut_ptr()) }
}

/// The same for eight joints (the floor of dia10_like).
pub fn floor_eight(q: &[f64; 8], out: &mut [f64; 16]) {
    // SAFETY: reads 8, writes 16.
    unsafe { floor_eight_sincos(q.as_ptr(), out.as_mut_ptr()) }
}

/// f64 reference of the same kinematics, written independently of `peers_gen.py`.
pub mod reference {
    use super::Case;

    type M3 = [[f64; 3]; 3];
    /// Rigid transform (R, p).
    #[derive(Clone, Copy, Debug)]
    pub struct Tf {
        /// Rotation.
        pub r: M3,
        /// Translation.
        pub p: [f64; 3],
    }

    const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn axis(a: u8) -> [f64; 3] {
        match a {
            b'x' => [1.0, 0.0, 0.0],
            b'y' => [0.0, 1.0, 0.0],
            _ => [0.0, 0.0, 1.0],
        }
    }

    /// Trans(o) Rot(axis, q).
    pub fn joint(o: [f64; 3], a: u8, q: f64) -> Tf {
        let (s, c) = q.sin_cos();
        let r = match a {
            b'x' => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
            b'y' => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
            _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        };
        Tf { r, p: o }
    }

    /// g h.
    pub fn mul(g: &Tf, h: &Tf) -> Tf {
        let mut r = [[0.0; 3]; 3];
        let mut p = g.p;
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| g.r[i][k] * h.r[k][j]).sum();
            }
            p[i] += (0..3).map(|k| g.r[i][k] * h.p[k]).sum::<f64>();
        }
        Tf { r, p }
    }

    /// Ad_g^{-1} (v, w) = (R^T (v - p x w), R^T w).
    pub fn ad_inv(g: &Tf, xi: [f64; 6]) -> [f64; 6] {
        let (v, w) = ([xi[0], xi[1], xi[2]], [xi[3], xi[4], xi[5]]);
        let p = g.p;
        let pxw = [p[1] * w[2] - p[2] * w[1], p[2] * w[0] - p[0] * w[2], p[0] * w[1] - p[1] * w[0]];
        let mut out = [0.0; 6];
        for i in 0..3 {
            for k in 0..3 {
                out[i] += g.r[k][i] * (v[k] - pxw[k]);
                out[i + 3] += g.r[k][i] * w[k];
            }
        }
        out
    }

    /// Body Jacobian columns of the chain `tfs` with tip `tip`.
    pub fn body_jacobian(tfs: &[Tf], axes: &[u8], tip: &Tf) -> Vec<[f64; 6]> {
        let mut cols = vec![[0.0; 6]; tfs.len()];
        let mut g = *tip;
        for k in (0..tfs.len()).rev() {
            let a = axis(axes[k]);
            cols[k] = ad_inv(&g, [0.0, 0.0, 0.0, a[0], a[1], a[2]]);
            g = mul(&tfs[k], &g);
        }
        cols
    }

    /// Thesis bases: (3.23) for r = 1, (3.27) for r = 2 (columns).
    pub fn lambda_sharp(bidirectional: bool, la: f64) -> Vec<[f64; 6]> {
        let mut cols = vec![
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0 / la],
            [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        ];
        if bidirectional {
            cols[2][3] = -1.0 / la;
            cols.remove(3);
        }
        cols
    }

    /// J^r columns (3.15) for the joints after the constraint.
    pub fn jr(after: &[Tf], axes: &[u8], tip: &Tf, bidirectional: bool, la: f64) -> Vec<[f64; 6]> {
        let mut g_ie = *tip;
        for t in after.iter().rev() {
            g_ie = mul(t, &g_ie);
        }
        let mut cols: Vec<[f64; 6]> =
            lambda_sharp(bidirectional, la).into_iter().map(|c| ad_inv(&g_ie, c)).collect();
        cols.extend(body_jacobian(after, axes, tip));
        cols
    }

    /// dia10_like joint origins (relative to the parent frame) and axes.
    pub const DIA_ORIGINS: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [0.194, 0.0, 1.037],
        [0.0, 0.38, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.39, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.33, 0.0],
        [0.0, 0.0, 0.0],
    ];
    /// dia10_like axes, zy wrist.
    pub const DIA_AXES_ZY: [u8; 8] = *b"zxxyxyzy";

    /// dia10_like FK g_0e.
    pub fn dia_fk(q: &[f64]) -> Tf {
        let mut g = Tf { r: I3, p: [0.0, 0.21, 0.0] };
        for k in (0..8).rev() {
            g = mul(&joint(DIA_ORIGINS[k], DIA_AXES_ZY[k], q[k]), &g);
        }
        g
    }

    /// Evaluates a case, column-major outputs (see the crate docs).
    pub fn eval(case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
        let mut put = |off: usize, cols: &[[f64; 6]]| {
            for (j, c) in cols.iter().enumerate() {
                out[off + 6 * j..off + 6 * j + 6].copy_from_slice(c);
            }
        };
        match case {
            Case::DiaZy => {
                let tfs: Vec<Tf> = (0..8).map(|k| joint(DIA_ORIGINS[k], DIA_AXES_ZY[k], q[k])).collect();
                let tip = Tf { r: I3, p: [0.0, 0.21, 0.0] };
                let g = dia_fk(q);
                let jb = body_jacobian(&tfs[..6], &DIA_AXES_ZY[..6], &Tf { r: I3, p: [0.0; 3] });
                let jr = jr(&tfs[6..], &DIA_AXES_ZY[6..], &tip, true, p[0]);
                put(12, &jb);
                put(48, &jr);
                for j in 0..3 {
                    for i in 0..3 {
                        out[3 * j + i] = g.r[i][j];
                    }
                }
                out[9..12].copy_from_slice(&g.p);
            }
            _ => {
                let (la, lb, l8) = (p[0], p[1], p[2]);
                let wrist = if case == Case::Bzx { b'x' } else { b'y' };
                let after = [joint([0.0, la + lb, 0.0], b'z', q[0]), joint([0.0; 3], wrist, q[1])];
                let tip = Tf { r: I3, p: [0.0, l8, 0.0] };
                put(0, &jr(&after, &[b'z', wrist], &tip, case != Case::Uni, la));
            }
        }
    }
}

/// trocar's numeric runtime (`trocar::kinematics::Chain`, `trocar::constraint::Constraint`) on
/// the same cases, built from the shipped descriptions (`RobotDescription::preset`).
pub mod numeric {
    use super::Case;
    use trocar::constraint::Constraint;
    use trocar_model::description::RobotDescription;
    use trocar::kinematics::Chain;
    use trocar::nalgebra::{SMatrix, SVector};
    use trocar_model::numeric::NumericModel as Robot;

    /// A prepared case: the typed chain and constraint, as a control loop would hold them.
    pub enum Numeric {
        /// Unidirectional preset.
        Uni(Chain<f64, 8>, Constraint<f64, 1>),
        /// A bidirectional preset.
        Bi(Chain<f64, 8>, Constraint<f64, 2>),
        /// dia10_like zy.
        Dia(Chain<f64, 8>, Constraint<f64, 2>),
    }

    impl Numeric {
        /// Builds the case with parameters `p` (presets: l_a, l_b, l_8; dia10_like: l_a).
        pub fn new(case: Case, p: &[f64]) -> Numeric {
            let (name, params): (&str, &[&str]) = match case {
                Case::Uni => ("unidirectional", &["l_a", "l_b", "l_8"]),
                Case::Bzy => ("bidirectional-zy", &["l_a", "l_b", "l_8"]),
                Case::Bzx => ("bidirectional-zx", &["l_a", "l_b", "l_8"]),
                Case::DiaZy => ("dia10_like_zy", &["l_a"]),
            };
            let d = RobotDescription::preset(name).expect("preset");
            let overrides: Vec<(String, f64)> =
                params.iter().zip(p).map(|(n, v)| (n.to_string(), *v)).collect();
            let robot = Robot::<f64>::from_description(&d, &overrides).expect("robot");
            let chain = robot.to_chain::<8>().expect("chain");
            match case {
                Case::Uni => Numeric::Uni(chain, robot.to_constraint().expect("constraint")),
                Case::Bzy | Case::Bzx => Numeric::Bi(chain, robot.to_constraint().expect("constraint")),
                Case::DiaZy => Numeric::Dia(chain, robot.to_constraint().expect("constraint")),
            }
        }

        /// Evaluates into `out` (the layout of [`super::eval`]). Presets take `q = (θ7, θ8)`
        /// (joints 1–6 are zero: J^r does not depend on them); dia10_like takes `q = θ1..θ8`
        /// and moves the constraint to `l_a = p[0]` first (`Constraint::set_offset`), as every
        /// control step must.
        #[inline(always)]
        pub fn eval(&mut self, q: &[f64], p: &[f64], out: &mut [f64]) {
            match self {
                Numeric::Uni(chain, c) => {
                    let q8 = SVector::<f64, 8>::from([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, q[0], q[1]]);
                    let jr: SMatrix<f64, 6, 7> = c.constrained_jacobian(chain, &q8);
                    out[..42].copy_from_slice(jr.as_slice());
                }
                Numeric::Bi(chain, c) => {
                    let q8 = SVector::<f64, 8>::from([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, q[0], q[1]]);
                    let jr: SMatrix<f64, 6, 6> = c.constrained_jacobian(chain, &q8);
                    out[..36].copy_from_slice(jr.as_slice());
                }
                Numeric::Dia(chain, c) => {
                    let q8 = SVector::<f64, 8>::from_column_slice(&q[..8]);
                    c.set_offset(p[0]).expect("l_a");
                    let g = chain.forward_kinematics(&q8);
                    let jb: SMatrix<f64, 6, 6> = chain.partial_body_jacobian::<6>(&q8);
                    let jr: SMatrix<f64, 6, 6> = c.constrained_jacobian(chain, &q8);
                    out[..9].copy_from_slice(g.rotation.as_slice());
                    out[9..12].copy_from_slice(g.translation.as_slice());
                    out[12..48].copy_from_slice(jb.as_slice());
                    out[48..84].copy_from_slice(jr.as_slice());
                }
            }
        }
    }
}

/// trocar's generated code (feature `ours`): the modules `Builder` writes for the shipped
/// descriptions, generic over `trocar::Real` (so f64 and f32 from the same source).
#[cfg(feature = "ours")]
pub mod ours {
    #![allow(missing_docs, clippy::all)]
    use super::Case;
    use trocar::Real;

    include!(concat!(env!("OUT_DIR"), "/unidirectional.rs"));
    include!(concat!(env!("OUT_DIR"), "/bidirectional_zy.rs"));
    include!(concat!(env!("OUT_DIR"), "/bidirectional_zx.rs"));
    include!(concat!(env!("OUT_DIR"), "/dia10_like_zy.rs"));

    /// The first `C` columns of 6 of `out`, as the generated functions return them, so a result
    /// is written straight into `out` (as the peers' C writes through its pointer).
    #[inline(always)]
    fn cols<T: Real, const C: usize>(out: &mut [T]) -> &mut [[T; 6]; C] {
        let (chunks, _) = out.as_chunks_mut::<6>();
        (&mut chunks[..C]).try_into().expect("out holds C columns")
    }

    #[inline(always)]
    fn q8<T: Real>(q: &[T]) -> [T; 8] {
        let z = T::ZERO;
        [z, z, z, z, z, z, q[0], q[1]]
    }

    /// Our generated functions called with joint values (each function does its own `sin_cos`);
    /// same layout as [`super::eval`].
    #[inline(always)]
    pub fn eval<T: Real>(case: Case, q: &[T], p: &[T], out: &mut [T]) {
        match case {
            Case::Uni => {
                let pp = unidirectional::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = unidirectional::constrained_jacobian(&q8(q), &pp);
            }
            Case::Bzy => {
                let pp = bidirectional_zy::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = bidirectional_zy::constrained_jacobian(&q8(q), &pp);
            }
            Case::Bzx => {
                let pp = bidirectional_zx::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = bidirectional_zx::constrained_jacobian(&q8(q), &pp);
            }
            Case::DiaZy => {
                // One JointTrig per control step shared by FK, J^B_0i and J^r (8 sin_cos).
                let qq: [T; 8] = core::array::from_fn(|k| q[k]);
                let pp = dia10_like_zy::Params { l_a: p[0] };
                let t = dia10_like_zy::JointTrig::new(&qq);
                let (r, pos) = dia10_like_zy::forward_kinematics_trig(&t, &pp);
                let (rows, _) = out[..12].as_chunks_mut::<3>();
                rows[..3].copy_from_slice(&r);
                rows[3] = pos;
                *cols(&mut out[12..]) = dia10_like_zy::partial_body_jacobian_trig(&t, &pp);
                *cols(&mut out[48..]) = dia10_like_zy::constrained_jacobian_trig(&t, &pp);
            }
        }
    }

    /// Precomputed trig of the case's joints (presets: θ7, θ8; dia10_like: all 8), as each
    /// module's own `JointTrig` (computed once, outside the timed loop).
    pub struct Trig<T: Real> {
        /// `JointTrig` of `unidirectional`.
        pub t: unidirectional::JointTrig<T>,
        /// `JointTrig` of `bidirectional_zy`.
        pub zy: bidirectional_zy::JointTrig<T>,
        /// `JointTrig` of `bidirectional_zx`.
        pub zx: bidirectional_zx::JointTrig<T>,
        /// `JointTrig` of dia10_like.
        pub d: dia10_like_zy::JointTrig<T>,
    }

    impl<T: Real> Trig<T> {
        /// `sin_cos` of every joint, once.
        pub fn new(case: Case, q: &[T]) -> Self {
            let qq: [T; 8] = if case == Case::DiaZy { core::array::from_fn(|k| q[k]) } else { q8(q) };
            Trig {
                t: unidirectional::JointTrig::new(&qq),
                zy: bidirectional_zy::JointTrig::new(&qq),
                zx: bidirectional_zx::JointTrig::new(&qq),
                d: dia10_like_zy::JointTrig::new(&qq),
            }
        }
    }

    /// The `_trig` functions given precomputed sines and cosines (no trigonometry inside).
    #[inline(always)]
    pub fn eval_trig<T: Real>(case: Case, t: &Trig<T>, p: &[T], out: &mut [T]) {
        match case {
            Case::Uni => {
                let pp = unidirectional::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = unidirectional::constrained_jacobian_trig(&t.t, &pp);
            }
            Case::Bzy => {
                let pp = bidirectional_zy::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = bidirectional_zy::constrained_jacobian_trig(&t.zy, &pp);
            }
            Case::Bzx => {
                let pp = bidirectional_zx::Params { l_a: p[0], l_b: p[1], l_8: p[2] };
                *cols(out) = bidirectional_zx::constrained_jacobian_trig(&t.zx, &pp);
            }
            Case::DiaZy => {
                let pp = dia10_like_zy::Params { l_a: p[0] };
                let (r, pos) = dia10_like_zy::forward_kinematics_trig(&t.d, &pp);
                let (rows, _) = out[..12].as_chunks_mut::<3>();
                rows[..3].copy_from_slice(&r);
                rows[3] = pos;
                *cols(&mut out[12..]) = dia10_like_zy::partial_body_jacobian_trig(&t.d, &pp);
                *cols(&mut out[48..]) = dia10_like_zy::constrained_jacobian_trig(&t.d, &pp);
            }
        }
    }
}
