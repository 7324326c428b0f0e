//! Bench-only harness: the peers' generated C behind safe wrappers, and an f64 reference of the same
//! kinematics written independently in Rust (checked against the thesis's closed forms and against
//! finite differences in `tests/check.rs`).
//!
//! Cases (inputs `q`, parameters `p`, outputs column-major):
//! - `uni`, `bzy`, `bzx`: J^r of the presets (docs/reference-robots.md); `q = (θ7, θ8)`, `p = (l_a, l_b, l_8)`;
//!   6×7, 6×6, 6×6.
//! - `dia_zy`: dia10_like (docs/reference-robots.md) with the zy wrist; `q = θ1..θ8`, `p = (l_a)`; outputs FK
//!   (R column-major then p, 12), J^B_0i (6×6), J^r (6×6).
//! - `panda`: the Franka Panda (trocar's shipped `urdf/panda.urdf`), pose and body Jacobian
//!   (6×7) of the flange `panda_link8`, what a Panda user asks Pinocchio for
//!   (`computeFrameJacobian(.., LOCAL, ..)` and the frame placement); `q = θ1..θ7`, `p = (l_a)`
//!   (unused by these outputs); outputs FK (12), J (42).
//! - `panda_i`: the same of `panda_link7`, the constrained link frame F_i of the shipped
//!   `panda-laparoscope` (panda_joint8's fixed 0.107 m is folded into its g_ir): trocar's
//!   `forward_kinematics_i` + `partial_body_jacobian` (J^B_0i).
//! - `oblique7`: a generic 7-DOF chain (`oblique7.toml`, from `bench/chains.py --peers`): oblique
//!   float axes and offsets, the constraint on link 6 with H as two explicit rows; `q = θ1..θ7`,
//!   `p = (l_a)`; outputs FK g_0e (12), J^B_0i (6×6), J^r (6×5), as for dia10_like.
//! - `panda_rcm`: the Panda with the constraint on the middle link panda_link6
//!   (`panda-link6-rcm.toml`, H = x, z), the end effector at panda_link8; the same outputs.
//!
//! The two generic robots' Λ# is the computed basis (no thesis preset), and their reference is
//! trocar's numeric runtime ([`numeric`]), which `trocar verify` checks against finite
//! differences; the peers and our generated code are checked against it.
//!
//! The Panda cases are timed over [`Case::configs`] (16 configurations within the joint limits,
//! cycled), the others at the fixed [`Case::inputs`].

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
    /// Panda: pose + body Jacobian of `panda_link8` (the flange).
    Panda,
    /// Panda: pose + body Jacobian of `panda_link7`, panda-laparoscope's F_i (g_0i + J^B_0i).
    PandaI,
    /// Generic 7-DOF chain, oblique float axes, RCM on link 6 with 2 explicit H rows:
    /// FK + J^B_0i + J^r.
    Oblique7,
    /// The Panda with the RCM on panda_link6 (H = x, z): FK + J^B_0i + J^r.
    PandaRcm,
}

/// Every case.
pub const CASES: [Case; 8] = [
    Case::Uni,
    Case::Bzy,
    Case::Bzx,
    Case::DiaZy,
    Case::Panda,
    Case::PandaI,
    Case::Oblique7,
    Case::PandaRcm,
];

/// The generic 7-DOF chain's description (`bench/chains.py --peers`).
pub const OBLIQUE7_TOML: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/oblique7.toml");
/// The Panda with the RCM on panda_link6.
pub const PANDA_RCM_TOML: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/panda-link6-rcm.toml");

/// The Panda's joint limits (`urdf/panda.urdf`, `<limit lower upper>`).
pub const PANDA_LIMITS: [(f64, f64); 7] = [
    (-2.8973, 2.8973),
    (-1.7628, 1.7628),
    (-2.8973, 2.8973),
    (-3.0718, -0.0698),
    (-2.8973, 2.8973),
    (-0.0175, 3.7525),
    (-2.8973, 2.8973),
];

/// The shipped Panda URDF (`runtime/model/robots/urdf/panda.urdf`).
pub const PANDA_URDF: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../runtime/model/robots/urdf/panda.urdf"
);

impl Case {
    /// Short name used in file and bench names.
    pub fn name(self) -> &'static str {
        match self {
            Case::Uni => "uni",
            Case::Bzy => "bzy",
            Case::Bzx => "bzx",
            Case::DiaZy => "dia_zy",
            Case::Panda => "panda",
            Case::PandaI => "panda_i",
            Case::Oblique7 => "oblique7",
            Case::PandaRcm => "panda_rcm",
        }
    }
    /// Parses [`Case::name`].
    pub fn from_name(s: &str) -> Option<Case> {
        CASES.into_iter().find(|c| c.name() == s)
    }
    /// Whether this is one of the Panda cases.
    pub fn is_panda(self) -> bool {
        matches!(self, Case::Panda | Case::PandaI)
    }
    /// Whether this is one of the generic robots with a computed Λ# ([`Case::Oblique7`],
    /// [`Case::PandaRcm`]).
    pub fn is_generic(self) -> bool {
        matches!(self, Case::Oblique7 | Case::PandaRcm)
    }
    /// Number of joint inputs.
    pub fn nq(self) -> usize {
        match self {
            Case::DiaZy => 8,
            Case::Panda | Case::PandaI | Case::Oblique7 | Case::PandaRcm => 7,
            _ => 2,
        }
    }
    /// Number of parameters.
    pub fn np(self) -> usize {
        match self {
            Case::DiaZy | Case::Panda | Case::PandaI | Case::Oblique7 | Case::PandaRcm => 1,
            _ => 3,
        }
    }
    /// The joint configurations a benchmark cycles through: for the Panda, [`Case::inputs`]
    /// then 15 pseudo-random configurations uniform within the joint limits (fixed seed); for the
    /// other cases only [`Case::inputs`].
    pub fn configs(self) -> Vec<Vec<f64>> {
        let mut qs = vec![self.inputs().0];
        if self.is_panda() {
            let mut seed = 0x5eed_u64;
            let mut next = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((seed >> 11) as f64) / ((1u64 << 53) as f64)
            };
            while qs.len() < 16 {
                qs.push(
                    PANDA_LIMITS
                        .iter()
                        .map(|&(lo, hi)| lo + (hi - lo) * next())
                        .collect(),
                );
            }
        }
        qs
    }
    /// Output sizes (column-major blocks).
    pub fn outs(self) -> &'static [usize] {
        match self {
            Case::Uni => &[42],
            Case::Bzy | Case::Bzx => &[36],
            Case::DiaZy => &[12, 36, 36],
            Case::Panda | Case::PandaI => &[12, 42],
            Case::Oblique7 | Case::PandaRcm => &[12, 36, 30],
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
            // The configuration of the README's `trocar eval panda-laparoscope` examples.
            Case::Panda | Case::PandaI => (vec![0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8], vec![0.25]),
            Case::Oblique7 => (vec![0.4, -0.7, 1.1, 0.3, -0.5, 0.9, -0.2], vec![0.11]),
            Case::PandaRcm => (vec![0.1, -0.3, 0.2, -2.2, 0.3, 2.0, 0.8], vec![0.2]),
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
    fn casadi_uni(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_bzy(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_bzx(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_dia_zy(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_uni(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_bzy(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_bzx(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_dia_zy(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_panda(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_panda_i(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_panda(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_panda_i(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_oblique7(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_panda_rcm(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_oblique7(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;
    fn casadi_cse_panda_rcm(
        a: *const *const f64,
        r: *const *mut f64,
        iw: *mut i64,
        w: *mut f64,
        m: c_int,
    ) -> c_int;

    fn sympy_uni(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_bzy(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_bzx(q: *const f64, p: *const f64, jr: *mut f64);
    fn sympy_dia_zy(q: *const f64, p: *const f64, fk: *mut f64, jb0i: *mut f64, jr: *mut f64);
    fn sympy_panda(q: *const f64, p: *const f64, fk: *mut f64, jb: *mut f64);
    fn sympy_panda_i(q: *const f64, p: *const f64, fk: *mut f64, jb: *mut f64);
    fn sympy_oblique7(q: *const f64, p: *const f64, fk: *mut f64, jb0i: *mut f64, jr: *mut f64);
    fn sympy_panda_rcm(q: *const f64, p: *const f64, fk: *mut f64, jb0i: *mut f64, jr: *mut f64);

    fn casadi_uni_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_bzy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_bzx_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_dia_zy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_uni_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_bzy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_bzx_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_dia_zy_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_panda_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_panda_i_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_panda_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_panda_i_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_oblique7_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_panda_rcm_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_oblique7_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;
    fn casadi_cse_panda_rcm_work(a: *mut i64, r: *mut i64, iw: *mut i64, w: *mut i64) -> c_int;

    fn floor_two_sincos(q: *const f64, out: *mut f64);
    fn floor_eight_sincos(q: *const f64, out: *mut f64);
    fn floor_seven_sincos(q: *const f64, out: *mut f64);
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
    pub const ALL: [Peer; 4] = [
        Peer::Casadi,
        Peer::CasadiCse,
        Peer::Sympy,
        Peer::RustReference,
    ];
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
        (Peer::Casadi, Case::Panda) => (casadi_panda, casadi_panda_work),
        (Peer::Casadi, Case::PandaI) => (casadi_panda_i, casadi_panda_i_work),
        (Peer::CasadiCse, Case::Panda) => (casadi_cse_panda, casadi_cse_panda_work),
        (Peer::CasadiCse, Case::PandaI) => (casadi_cse_panda_i, casadi_cse_panda_i_work),
        (Peer::Casadi, Case::Oblique7) => (casadi_oblique7, casadi_oblique7_work),
        (Peer::Casadi, Case::PandaRcm) => (casadi_panda_rcm, casadi_panda_rcm_work),
        (Peer::CasadiCse, Case::Oblique7) => (casadi_cse_oblique7, casadi_cse_oblique7_work),
        (Peer::CasadiCse, Case::PandaRcm) => (casadi_cse_panda_rcm, casadi_cse_panda_rcm_work),
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

/// Doubles of CasADi work space `eval` hands to the Panda and generic functions (the only ones
/// that may have `sz_w > 0`; checked in tests against `casadi_work_sizes`).
pub const CASADI_W: usize = 64;

/// Evaluates `case` with implementation `peer` into `out` (length [`Case::out_len`]).
#[inline(always)]
pub fn eval(peer: Peer, case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
    assert!(out.len() >= case.out_len());
    assert!(q.len() >= case.nq());
    assert!(p.len() >= case.np());
    let o = out.as_mut_ptr();
    match peer {
        Peer::Casadi | Peer::CasadiCse => {
            let (f, _) = casadi_fn(peer, case);
            let arg = [q.as_ptr(), p.as_ptr()];
            // Output blocks; only the first `outs().len()` are used by the callee.
            let res: [*mut f64; 3] = [o, o.wrapping_add(12), o.wrapping_add(48)];
            if case.is_panda() || case.is_generic() {
                // The Panda (and generic) functions use sz_w ≤ CASADI_W doubles of scratch, which they write
                // before reading: uninitialised stack space, no per-call zeroing.
                let mut w = core::mem::MaybeUninit::<[f64; CASADI_W]>::uninit();
                // SAFETY: reads arg[0..2], writes res[0..2], uses w[0..sz_w] (sz_w ≤ CASADI_W,
                // sz_iw = 0: tests).
                unsafe {
                    f(
                        arg.as_ptr(),
                        res.as_ptr(),
                        core::ptr::null_mut(),
                        w.as_mut_ptr().cast(),
                        0,
                    )
                };
            } else {
                // SAFETY: SX-generated code reads arg[0..2] and writes res[0..n_out]. Its work sizes
                // sz_iw and sz_w are 0 (checked in tests: `casadi_work_sizes`), so it never touches
                // iw or w, and null is a valid work pointer (no per-call scratch to zero).
                unsafe {
                    f(
                        arg.as_ptr(),
                        res.as_ptr(),
                        core::ptr::null_mut(),
                        core::ptr::null_mut(),
                        0,
                    )
                };
            }
        }
        // SAFETY: the SymPy functions read q[0..nq], p[0..np] and write the output blocks.
        Peer::Sympy => unsafe {
            match case {
                Case::Uni => sympy_uni(q.as_ptr(), p.as_ptr(), o),
                Case::Bzy => sympy_bzy(q.as_ptr(), p.as_ptr(), o),
                Case::Bzx => sympy_bzx(q.as_ptr(), p.as_ptr(), o),
                Case::DiaZy => sympy_dia_zy(q.as_ptr(), p.as_ptr(), o, o.add(12), o.add(48)),
                Case::Panda => sympy_panda(q.as_ptr(), p.as_ptr(), o, o.add(12)),
                Case::PandaI => sympy_panda_i(q.as_ptr(), p.as_ptr(), o, o.add(12)),
                Case::Oblique7 => sympy_oblique7(q.as_ptr(), p.as_ptr(), o, o.add(12), o.add(48)),
                Case::PandaRcm => sympy_panda_rcm(q.as_ptr(), p.as_ptr(), o, o.add(12), o.add(48)),
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

/// The same for the Panda's seven joints (`q` holds at least 7).
pub fn floor_seven(q: &[f64], out: &mut [f64; 14]) {
    assert!(q.len() >= 7);
    // SAFETY: reads 7, writes 14.
    unsafe { floor_seven_sincos(q.as_ptr(), out.as_mut_ptr()) }
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
        let pxw = [
            p[1] * w[2] - p[2] * w[1],
            p[2] * w[0] - p[0] * w[2],
            p[0] * w[1] - p[1] * w[0],
        ];
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
        let mut cols: Vec<[f64; 6]> = lambda_sharp(bidirectional, la)
            .into_iter()
            .map(|c| ad_inv(&g_ie, c))
            .collect();
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
        let mut g = Tf {
            r: I3,
            p: [0.0, 0.21, 0.0],
        };
        for k in (0..8).rev() {
            g = mul(&joint(DIA_ORIGINS[k], DIA_AXES_ZY[k], q[k]), &g);
        }
        g
    }

    /// URDF `rpy`: Rot(z, y) Rot(y, p) Rot(x, r), evaluated in f64 as written (no rounding of
    /// cos(π/2) to 0).
    pub fn rpy(r: f64, p: f64, y: f64) -> M3 {
        let (sr, cr) = r.sin_cos();
        let (sp, cp) = p.sin_cos();
        let (sy, cy) = y.sin_cos();
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    }

    /// The Panda's revolute joints `(xyz, rpy)` of `<origin>` in `urdf/panda.urdf` (every axis z),
    /// copied by hand from the file (independently of `peers_gen.py`'s parser and of trocar's).
    pub const PANDA_JOINTS: [([f64; 3], [f64; 3]); 7] = [
        ([0.0, 0.0, 0.333], [0.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [-1.5707963267948966, 0.0, 0.0]),
        ([0.0, -0.316, 0.0], [1.5707963267948966, 0.0, 0.0]),
        ([0.0825, 0.0, 0.0], [1.5707963267948966, 0.0, 0.0]),
        ([-0.0825, 0.384, 0.0], [-1.5707963267948966, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.5707963267948966, 0.0, 0.0]),
        ([0.088, 0.0, 0.0], [1.5707963267948966, 0.0, 0.0]),
    ];
    /// `panda_joint8` (fixed): panda_link7 → panda_link8.
    pub const PANDA_FLANGE: [f64; 3] = [0.0, 0.0, 0.107];

    /// Joint k of the Panda: Trans(xyz) Rot_rpy Rot(z, q).
    pub fn panda_joint(k: usize, q: f64) -> Tf {
        let (xyz, [r, p, y]) = PANDA_JOINTS[k];
        mul(
            &Tf {
                r: rpy(r, p, y),
                p: xyz,
            },
            &joint([0.0; 3], b'z', q),
        )
    }

    /// Pose and body Jacobian (7 columns) of `panda_link8` (`flange`) or `panda_link7`.
    pub fn panda(q: &[f64], flange: bool) -> (Tf, Vec<[f64; 6]>) {
        let tfs: Vec<Tf> = (0..7).map(|k| panda_joint(k, q[k])).collect();
        let tip = Tf {
            r: I3,
            p: if flange { PANDA_FLANGE } else { [0.0; 3] },
        };
        let mut g = tip;
        for t in tfs.iter().rev() {
            g = mul(t, &g);
        }
        (g, body_jacobian(&tfs, b"zzzzzzz", &tip))
    }

    /// Evaluates a case, column-major outputs (see the crate docs). The generic robots
    /// ([`Case::is_generic`]) through trocar's numeric runtime.
    pub fn eval(case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
        if case.is_generic() {
            return super::numeric::Numeric::new(case, p).eval(q, p, out);
        }
        let mut put = |off: usize, cols: &[[f64; 6]]| {
            for (j, c) in cols.iter().enumerate() {
                out[off + 6 * j..off + 6 * j + 6].copy_from_slice(c);
            }
        };
        match case {
            Case::Panda | Case::PandaI => {
                let (g, jb) = panda(q, case == Case::Panda);
                put(12, &jb);
                for j in 0..3 {
                    for i in 0..3 {
                        out[3 * j + i] = g.r[i][j];
                    }
                }
                out[9..12].copy_from_slice(&g.p);
            }
            Case::DiaZy => {
                let tfs: Vec<Tf> = (0..8)
                    .map(|k| joint(DIA_ORIGINS[k], DIA_AXES_ZY[k], q[k]))
                    .collect();
                let tip = Tf {
                    r: I3,
                    p: [0.0, 0.21, 0.0],
                };
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
                let after = [
                    joint([0.0, la + lb, 0.0], b'z', q[0]),
                    joint([0.0; 3], wrist, q[1]),
                ];
                let tip = Tf {
                    r: I3,
                    p: [0.0, l8, 0.0],
                };
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
    use trocar::kinematics::Chain;
    use trocar::nalgebra::{SMatrix, SVector};
    use trocar_model::description::RobotDescription;
    use trocar_model::numeric::NumericModel as Robot;

    /// A prepared case: the typed chain and constraint, as a control loop would hold them.
    pub enum Numeric {
        /// Unidirectional preset.
        Uni(Chain<f64, 8>, Constraint<f64, 1>),
        /// A bidirectional preset.
        Bi(Chain<f64, 8>, Constraint<f64, 2>),
        /// dia10_like zy.
        Dia(Chain<f64, 8>, Constraint<f64, 2>),
        /// Panda, F_i of panda-laparoscope: `frame_and_partial_body_jacobian::<7>` (g_0i, J^B_0i).
        PandaI(Chain<f64, 7>),
        /// A generic robot (oblique7, panda_rcm): 7 joints, constraint on link 6 with r = 2.
        Generic(Chain<f64, 7>, Constraint<f64, 2>),
    }

    impl Numeric {
        /// Builds the case with parameters `p` (presets: l_a, l_b, l_8; dia10_like: l_a).
        ///
        /// # Panics
        /// For [`Case::Panda`] (panda_link8 is not a frame of the description's chain: the numeric
        /// runtime is measured on [`Case::PandaI`]).
        pub fn new(case: Case, p: &[f64]) -> Numeric {
            if case.is_generic() {
                let file = if case == Case::Oblique7 {
                    super::OBLIQUE7_TOML
                } else {
                    super::PANDA_RCM_TOML
                };
                let d = RobotDescription::from_toml_file(file).expect("description");
                let robot =
                    Robot::<f64>::from_description(&d, &[("l_a".into(), p[0])]).expect("robot");
                return Numeric::Generic(
                    robot.to_chain::<7>().expect("chain"),
                    robot.to_constraint().expect("constraint"),
                );
            }
            if case == Case::PandaI {
                let d = RobotDescription::preset("panda-laparoscope").expect("preset");
                let robot =
                    Robot::<f64>::from_description(&d, &[("l_a".into(), p[0])]).expect("robot");
                return Numeric::PandaI(robot.to_chain::<7>().expect("chain"));
            }
            let (name, params): (&str, &[&str]) = match case {
                Case::Uni => ("unidirectional", &["l_a", "l_b", "l_8"]),
                Case::Bzy => ("bidirectional-zy", &["l_a", "l_b", "l_8"]),
                Case::Bzx => ("bidirectional-zx", &["l_a", "l_b", "l_8"]),
                Case::DiaZy => ("dia10_like_zy", &["l_a"]),
                Case::Panda | Case::PandaI | Case::Oblique7 | Case::PandaRcm => {
                    panic!("no numeric runtime for {case:?}")
                }
            };
            let d = RobotDescription::preset(name).expect("preset");
            let overrides: Vec<(String, f64)> = params
                .iter()
                .zip(p)
                .map(|(n, v)| (n.to_string(), *v))
                .collect();
            let robot = Robot::<f64>::from_description(&d, &overrides).expect("robot");
            let chain = robot.to_chain::<8>().expect("chain");
            match case {
                Case::Uni => Numeric::Uni(chain, robot.to_constraint().expect("constraint")),
                Case::Bzy | Case::Bzx => {
                    Numeric::Bi(chain, robot.to_constraint().expect("constraint"))
                }
                Case::DiaZy => Numeric::Dia(chain, robot.to_constraint().expect("constraint")),
                Case::Panda | Case::PandaI | Case::Oblique7 | Case::PandaRcm => unreachable!(),
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
                Numeric::Generic(chain, c) => {
                    let q7 = SVector::<f64, 7>::from_column_slice(&q[..7]);
                    c.set_offset(p[0]).expect("l_a");
                    let g = chain.forward_kinematics(&q7);
                    let jb: SMatrix<f64, 6, 6> = chain.partial_body_jacobian::<6>(&q7);
                    let jr: SMatrix<f64, 6, 5> = c.constrained_jacobian(chain, &q7);
                    out[..9].copy_from_slice(g.rotation.as_slice());
                    out[9..12].copy_from_slice(g.translation.as_slice());
                    out[12..48].copy_from_slice(jb.as_slice());
                    out[48..78].copy_from_slice(jr.as_slice());
                }
                Numeric::PandaI(chain) => {
                    let q7 = SVector::<f64, 7>::from_column_slice(&q[..7]);
                    let (g, jb): (_, SMatrix<f64, 6, 7>) =
                        chain.frame_and_partial_body_jacobian::<7>(&q7);
                    out[..9].copy_from_slice(g.rotation.as_slice());
                    out[9..12].copy_from_slice(g.translation.as_slice());
                    out[12..54].copy_from_slice(jb.as_slice());
                }
            }
        }
    }
}

/// The first `C` columns of 6 of `out`, as the generated functions return them, so a result
/// is written straight into `out` (as the peers' C writes through its pointer).
#[inline(always)]
fn cols<T, const C: usize>(out: &mut [T]) -> &mut [[T; 6]; C] {
    let (chunks, _) = out.as_chunks_mut::<6>();
    (&mut chunks[..C]).try_into().expect("out holds C columns")
}

/// A preset's 8 joint values from its case input `(θ7, θ8)` (the others are not used by `J^r`).
#[inline(always)]
fn q8<T: Copy + Default>(q: &[T]) -> [T; 8] {
    let z = T::default();
    [z, z, z, z, z, z, q[0], q[1]]
}

pub mod baseline;

/// One case of one implementation as a plain function of `(q, p, out)`, chosen once before a
/// timed loop ([`baseline_fn`], [`ours::eval_fn`]): inside the loop it is an indirect call, as the
/// peers' C functions are, with no dispatch on the case and the generated code inlined into it.
pub type EvalFn = fn(&[f64], &[f64], &mut [f64]);

/// `match case { Case::X => |q, p, out| f(Case::X, q, p, out), .. }`: `f` with the case fixed.
macro_rules! per_case {
    ($f:path, $case:expr; $($c:ident),*) => {
        match $case {
            $(Case::$c => |q: &[f64], p: &[f64], out: &mut [f64]| $f(Case::$c, q, p, out),)*
            #[allow(unreachable_patterns)]
            other => panic!("no function for case {}", other.name()),
        }
    };
}

pub mod paired_rows;
pub mod rust_peers;

/// [`baseline_eval`] with the case fixed ([`EvalFn`]).
pub fn baseline_fn(case: Case) -> EvalFn {
    per_case!(baseline_eval, case; Uni, Bzy, Bzx)
}

/// The frozen baseline ([`baseline`]: the presets' generated code and runtime of 2026-11-23) on a
/// preset case, called as [`ours::eval`] calls today's generated code; same layout as [`eval`].
#[inline(always)]
pub fn baseline_eval(case: Case, q: &[f64], p: &[f64], out: &mut [f64]) {
    match case {
        Case::Uni => {
            let pp = baseline::unidirectional::Params {
                l_a: p[0],
                l_b: p[1],
                l_8: p[2],
            };
            *cols(out) = baseline::unidirectional::constrained_jacobian(&q8(q), &pp);
        }
        Case::Bzy => {
            let pp = baseline::bidirectional_zy::Params {
                l_a: p[0],
                l_b: p[1],
                l_8: p[2],
            };
            *cols(out) = baseline::bidirectional_zy::constrained_jacobian(&q8(q), &pp);
        }
        Case::Bzx => {
            let pp = baseline::bidirectional_zx::Params {
                l_a: p[0],
                l_b: p[1],
                l_8: p[2],
            };
            *cols(out) = baseline::bidirectional_zx::constrained_jacobian(&q8(q), &pp);
        }
        _ => panic!("the baseline holds the presets only, not {}", case.name()),
    }
}

/// trocar's generated code (feature `ours`): the modules `Builder` writes for the shipped
/// descriptions, generic over `trocar::Real` (so f64 and f32 from the same source).
#[cfg(feature = "ours")]
pub mod ours {
    #![allow(missing_docs, clippy::all)]
    use super::{cols, q8, Case};
    use trocar::Real;

    include!(concat!(env!("OUT_DIR"), "/unidirectional.rs"));
    include!(concat!(env!("OUT_DIR"), "/bidirectional_zy.rs"));
    include!(concat!(env!("OUT_DIR"), "/bidirectional_zx.rs"));
    include!(concat!(env!("OUT_DIR"), "/dia10_like_zy.rs"));
    include!(concat!(env!("OUT_DIR"), "/panda_laparoscope.rs"));
    include!(concat!(env!("OUT_DIR"), "/panda_link8.rs"));
    include!(concat!(env!("OUT_DIR"), "/oblique7.rs"));
    include!(concat!(env!("OUT_DIR"), "/panda_link6_rcm.rs"));
    include!(concat!(env!("OUT_DIR"), "/panda_laparoscope_fma.rs"));
    include!(concat!(env!("OUT_DIR"), "/dia10_like_zy_fma.rs"));
    include!(concat!(env!("OUT_DIR"), "/oblique7_fma.rs"));
    include!(concat!(env!("OUT_DIR"), "/panda_link6_rcm_fma.rs"));

    /// g_0e, J^B_0i and J^r of a constrained module, by the fused `step_outputs` (from `q`)
    /// or `step_outputs_trig` (given a `JointTrig`) that the build script asks the generator
    /// for: one program for exactly these three outputs, as CasADi's one function with three
    /// outputs, the Jacobians written in place.
    macro_rules! step_outputs {
        ($f:path, $arg:expr, $pp:expr, $out:expr) => {{
            let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
            let (head, jr) = $out.split_at_mut(48);
            $f($arg, &$pp, &mut g, cols(&mut head[12..]), cols(jr));
            put_pose($out, g);
        }};
    }

    /// As `step_outputs!`, the pose written in place into `$g` (the caller's, as the peers
    /// write theirs) instead of a local copied into `out[..12]`.
    macro_rules! step_outputs_in_place {
        ($f:path, $arg:expr, $pp:expr, $g:expr, $out:expr) => {{
            let (head, jr) = $out.split_at_mut(48);
            $f($arg, &$pp, $g, cols(&mut head[12..]), cols(jr));
        }};
    }

    /// The first `N` joint values (zeros past the end of `q`).
    #[inline(always)]
    fn first<T: Real, const N: usize>(q: &[T]) -> [T; N] {
        core::array::from_fn(|k| q.get(k).copied().unwrap_or(T::ZERO))
    }

    /// The first `N` joint values, borrowed in place (as a controller holds them): a copy made
    /// element by element just before the call would be read back as vectors while its stores
    /// are in flight, a store-to-load forwarding stall the callers do not have.
    #[inline(always)]
    fn joints<T: Real, const N: usize>(q: &[T]) -> &[T; N] {
        q[..N].try_into().expect("q holds the robot's joint values")
    }

    /// `(R, p)` into `out[..12]` (R column-major, then p).
    #[inline(always)]
    fn put_pose<T: Real>(out: &mut [T], (r, pos): ([[T; 3]; 3], [T; 3])) {
        let (rows, _) = out[..12].as_chunks_mut::<3>();
        rows[..3].copy_from_slice(&r);
        rows[3] = pos;
    }

    /// Our generated functions called with joint values (each function does its own `sin_cos`);
    /// same layout as [`super::eval`].
    #[inline(always)]
    pub fn eval<T: Real>(case: Case, q: &[T], p: &[T], out: &mut [T]) {
        match case {
            Case::Uni => {
                let pp = unidirectional::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = unidirectional::constrained_jacobian(&q8(q), &pp);
            }
            Case::Bzy => {
                let pp = bidirectional_zy::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = bidirectional_zy::constrained_jacobian(&q8(q), &pp);
            }
            Case::Bzx => {
                let pp = bidirectional_zx::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = bidirectional_zx::constrained_jacobian(&q8(q), &pp);
            }
            Case::DiaZy => {
                // One sin_cos_array of the 8 joints shared by FK, J^B_0i and J^r.
                let pp = dia10_like_zy::Params { l_a: p[0] };
                step_outputs!(dia10_like_zy::step_outputs, joints(q), pp, out);
            }
            Case::Panda => {
                // panda_link8 (bench-local description, no constraint): the fused
                // pose_and_jacobian (g_0e and J^B_0e from one program, its own sin_cos_array),
                // J^B_0e written in place.
                let pp = panda_link8::Params::nominal();
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_link8::pose_and_jacobian(joints(q), &pp, &mut g, cols(&mut out[12..]));
                put_pose(out, g);
            }
            Case::PandaI => {
                // panda-laparoscope: the fused link_pose_and_jacobian (g_0i and J^B_0i of the
                // constrained link from one program).
                let pp = panda_laparoscope::Params { l_a: p[0] };
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_laparoscope::link_pose_and_jacobian(
                    joints(q),
                    &pp,
                    &mut g,
                    cols(&mut out[12..]),
                );
                put_pose(out, g);
            }
            Case::Oblique7 => {
                let pp = oblique7::Params { l_a: p[0] };
                step_outputs!(oblique7::step_outputs, joints(q), pp, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm::Params { l_a: p[0] };
                step_outputs!(panda_link6_rcm::step_outputs, joints(q), pp, out);
            }
        }
    }

    /// [`eval`] in `f64` with the case fixed ([`super::EvalFn`]).
    pub fn eval_fn(case: Case) -> super::EvalFn {
        per_case!(eval, case; Uni, Bzy, Bzx, DiaZy, Panda, PandaI, Oblique7, PandaRcm)
    }

    /// The Panda cases' outputs in the generated functions' own layout, `(R, p)` and the
    /// column-major `6 × 7` Jacobian, for [`eval_panda_in_place`] and
    /// [`eval_trig_panda_in_place`].
    pub struct PandaOut<T: Real> {
        /// The pose `(R, p)`, `R` column-major.
        pub g: ([[T; 3]; 3], [T; 3]),
        /// The body Jacobian, column-major.
        pub jb: [[T; 6]; 7],
    }

    impl<T: Real> Default for PandaOut<T> {
        fn default() -> Self {
            PandaOut {
                g: ([[T::ZERO; 3]; 3], [T::ZERO; 3]),
                jb: [[T::ZERO; 6]; 7],
            }
        }
    }

    /// [`eval`] of a Panda case writing into `out` in the functions' own layout: the outputs
    /// written in place, as the Rust peers write theirs into the caller's arrays, without the
    /// copy of the pose from a local into the flat buffer that [`eval`] makes.
    #[inline(always)]
    pub fn eval_panda_in_place<T: Real>(case: Case, q: &[T], p: &[T], out: &mut PandaOut<T>) {
        match case {
            Case::Panda => {
                let pp = panda_link8::Params::nominal();
                panda_link8::pose_and_jacobian(joints(q), &pp, &mut out.g, &mut out.jb);
            }
            Case::PandaI => {
                let pp = panda_laparoscope::Params { l_a: p[0] };
                panda_laparoscope::link_pose_and_jacobian(joints(q), &pp, &mut out.g, &mut out.jb);
            }
            other => panic!("{} is not a Panda case", other.name()),
        }
    }

    /// [`eval_trig`] of a Panda case writing into `out` in place ([`eval_panda_in_place`]).
    #[inline(always)]
    pub fn eval_trig_panda_in_place<T: Real>(
        case: Case,
        t: &Trig<T>,
        p: &[T],
        out: &mut PandaOut<T>,
    ) {
        match case {
            Case::Panda => {
                let pp = panda_link8::Params::nominal();
                panda_link8::pose_and_jacobian_trig(&t.p8, &pp, &mut out.g, &mut out.jb);
            }
            Case::PandaI => {
                let pp = panda_laparoscope::Params { l_a: p[0] };
                panda_laparoscope::link_pose_and_jacobian_trig(&t.pi, &pp, &mut out.g, &mut out.jb);
            }
            other => panic!("{} is not a Panda case", other.name()),
        }
    }

    /// The fused cases from `q` in two calls, as a caller holding a `JointTrig` would make
    /// them: the module's `JointTrig::new`, then its fused `_trig` function (the same
    /// arithmetic as [`eval`]'s one function, with the trigonometry in a call of its own).
    #[inline(always)]
    pub fn eval_split<T: Real>(case: Case, q: &[T], p: &[T], out: &mut [T]) {
        match case {
            Case::DiaZy => {
                let t = dia10_like_zy::JointTrig::new(joints(q));
                let pp = dia10_like_zy::Params { l_a: p[0] };
                step_outputs!(dia10_like_zy::step_outputs_trig, &t, pp, out);
            }
            Case::Oblique7 => {
                let t = oblique7::JointTrig::new(joints(q));
                let pp = oblique7::Params { l_a: p[0] };
                step_outputs!(oblique7::step_outputs_trig, &t, pp, out);
            }
            Case::PandaRcm => {
                let t = panda_link6_rcm::JointTrig::new(joints(q));
                let pp = panda_link6_rcm::Params { l_a: p[0] };
                step_outputs!(panda_link6_rcm::step_outputs_trig, &t, pp, out);
            }
            Case::PandaI => {
                let t = panda_laparoscope::JointTrig::new(joints(q));
                let pp = panda_laparoscope::Params { l_a: p[0] };
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_laparoscope::link_pose_and_jacobian_trig(
                    &t,
                    &pp,
                    &mut g,
                    cols(&mut out[12..]),
                );
                put_pose(out, g);
            }
            Case::Panda => {
                let t = panda_link8::JointTrig::new(joints(q));
                let pp = panda_link8::Params::nominal();
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_link8::pose_and_jacobian_trig(&t, &pp, &mut g, cols(&mut out[12..]));
                put_pose(out, g);
            }
            _ => eval(case, q, p, out),
        }
    }

    /// [`eval_split`] in `f64` with the case fixed ([`super::EvalFn`]).
    pub fn split_fn(case: Case) -> super::EvalFn {
        per_case!(eval_split, case; Uni, Bzy, Bzx, DiaZy, Panda, PandaI, Oblique7, PandaRcm)
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
        /// `JointTrig` of panda-laparoscope.
        pub pi: panda_laparoscope::JointTrig<T>,
        /// `JointTrig` of the bench's panda_link8.
        pub p8: panda_link8::JointTrig<T>,
        /// `JointTrig` of oblique7.
        pub o7: oblique7::JointTrig<T>,
        /// `JointTrig` of panda_link6_rcm.
        pub p6: panda_link6_rcm::JointTrig<T>,
    }

    impl<T: Real> Trig<T> {
        /// `sin_cos` of every joint, once.
        pub fn new(case: Case, q: &[T]) -> Self {
            let qq: [T; 8] = if case == Case::DiaZy { first(q) } else { q8(q) };
            let q7: [T; 7] = first(q);
            Trig {
                t: unidirectional::JointTrig::new(&qq),
                zy: bidirectional_zy::JointTrig::new(&qq),
                zx: bidirectional_zx::JointTrig::new(&qq),
                d: dia10_like_zy::JointTrig::new(&first(q)),
                pi: panda_laparoscope::JointTrig::new(&q7),
                p8: panda_link8::JointTrig::new(&q7),
                o7: oblique7::JointTrig::new(&q7),
                p6: panda_link6_rcm::JointTrig::new(&q7),
            }
        }
    }

    /// The Panda's trigonometry alone: `JointTrig::new` of panda-laparoscope (one
    /// `sin_cos_array` of the 7 joints), the part of [`eval`] that [`eval_trig`] leaves out.
    #[inline(always)]
    pub fn panda_trig<T: Real>(q: &[T]) -> panda_laparoscope::JointTrig<T> {
        panda_laparoscope::JointTrig::new(joints(q))
    }

    /// [`eval`] of the fused cases through the `_f64` entry points of the modules generated with
    /// `fma_at_run_time` (`<module>_fma`: FMA chosen at run time), the pose written in place
    /// into `panda.g` (the Panda's Jacobian into `panda.jb` as [`eval_panda_in_place`] writes
    /// it, the step cases' into `out[12..]` as [`eval_step_in_place`] writes them).
    #[inline(always)]
    pub fn eval_fma(case: Case, q: &[f64], p: &[f64], out: &mut [f64], panda: &mut PandaOut<f64>) {
        let g = &mut panda.g;
        match case {
            Case::PandaI => {
                let pp = panda_laparoscope_fma::Params { l_a: p[0] };
                panda_laparoscope_fma::link_pose_and_jacobian_f64(
                    joints(q),
                    &pp,
                    &mut panda.g,
                    &mut panda.jb,
                );
            }
            Case::DiaZy => {
                let pp = dia10_like_zy_fma::Params { l_a: p[0] };
                step_outputs_in_place!(dia10_like_zy_fma::step_outputs_f64, joints(q), pp, g, out);
            }
            Case::Oblique7 => {
                let pp = oblique7_fma::Params { l_a: p[0] };
                step_outputs_in_place!(oblique7_fma::step_outputs_f64, joints(q), pp, g, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm_fma::Params { l_a: p[0] };
                step_outputs_in_place!(
                    panda_link6_rcm_fma::step_outputs_f64,
                    joints(q),
                    pp,
                    g,
                    out
                );
            }
            other => panic!("{} has no module with FMA chosen at run time", other.name()),
        }
    }

    /// The `JointTrig` of the `<module>_fma` modules ([`eval_trig_fma`]).
    pub struct TrigFma {
        /// `JointTrig` of panda_laparoscope_fma.
        pub pi: panda_laparoscope_fma::JointTrig<f64>,
        /// `JointTrig` of dia10_like_zy_fma.
        pub d: dia10_like_zy_fma::JointTrig<f64>,
        /// `JointTrig` of oblique7_fma.
        pub o7: oblique7_fma::JointTrig<f64>,
        /// `JointTrig` of panda_link6_rcm_fma.
        pub p6: panda_link6_rcm_fma::JointTrig<f64>,
    }

    impl TrigFma {
        /// `sin_cos` of every joint, once.
        pub fn new(q: &[f64]) -> Self {
            let q7: [f64; 7] = first(q);
            TrigFma {
                pi: panda_laparoscope_fma::JointTrig::new(&q7),
                d: dia10_like_zy_fma::JointTrig::new(&first(q)),
                o7: oblique7_fma::JointTrig::new(&q7),
                p6: panda_link6_rcm_fma::JointTrig::new(&q7),
            }
        }
    }

    /// [`eval`] of the step cases (dia10_like, oblique7, the Panda RCM) with the pose written in
    /// place into `g` ([`eval_fma`]'s layout), the Jacobians into `out[12..]`.
    #[inline(always)]
    pub fn eval_step_in_place<T: Real>(
        case: Case,
        q: &[T],
        p: &[T],
        g: &mut ([[T; 3]; 3], [T; 3]),
        out: &mut [T],
    ) {
        match case {
            Case::DiaZy => {
                let pp = dia10_like_zy::Params { l_a: p[0] };
                step_outputs_in_place!(dia10_like_zy::step_outputs, joints(q), pp, g, out);
            }
            Case::Oblique7 => {
                let pp = oblique7::Params { l_a: p[0] };
                step_outputs_in_place!(oblique7::step_outputs, joints(q), pp, g, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm::Params { l_a: p[0] };
                step_outputs_in_place!(panda_link6_rcm::step_outputs, joints(q), pp, g, out);
            }
            other => panic!("{} is not a step case", other.name()),
        }
    }

    /// [`eval_step_in_place`] given precomputed sines and cosines.
    #[inline(always)]
    pub fn eval_trig_step_in_place<T: Real>(
        case: Case,
        t: &Trig<T>,
        p: &[T],
        g: &mut ([[T; 3]; 3], [T; 3]),
        out: &mut [T],
    ) {
        match case {
            Case::DiaZy => {
                let pp = dia10_like_zy::Params { l_a: p[0] };
                step_outputs_in_place!(dia10_like_zy::step_outputs_trig, &t.d, pp, g, out);
            }
            Case::Oblique7 => {
                let pp = oblique7::Params { l_a: p[0] };
                step_outputs_in_place!(oblique7::step_outputs_trig, &t.o7, pp, g, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm::Params { l_a: p[0] };
                step_outputs_in_place!(panda_link6_rcm::step_outputs_trig, &t.p6, pp, g, out);
            }
            other => panic!("{} is not a step case", other.name()),
        }
    }

    /// [`eval_fma`] given precomputed sines and cosines (the `_trig_f64` entry points).
    #[inline(always)]
    pub fn eval_trig_fma(
        case: Case,
        t: &TrigFma,
        p: &[f64],
        out: &mut [f64],
        panda: &mut PandaOut<f64>,
    ) {
        let g = &mut panda.g;
        match case {
            Case::PandaI => {
                let pp = panda_laparoscope_fma::Params { l_a: p[0] };
                panda_laparoscope_fma::link_pose_and_jacobian_trig_f64(
                    &t.pi,
                    &pp,
                    &mut panda.g,
                    &mut panda.jb,
                );
            }
            Case::DiaZy => {
                let pp = dia10_like_zy_fma::Params { l_a: p[0] };
                step_outputs_in_place!(dia10_like_zy_fma::step_outputs_trig_f64, &t.d, pp, g, out);
            }
            Case::Oblique7 => {
                let pp = oblique7_fma::Params { l_a: p[0] };
                step_outputs_in_place!(oblique7_fma::step_outputs_trig_f64, &t.o7, pp, g, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm_fma::Params { l_a: p[0] };
                step_outputs_in_place!(
                    panda_link6_rcm_fma::step_outputs_trig_f64,
                    &t.p6,
                    pp,
                    g,
                    out
                );
            }
            other => panic!("{} has no module with FMA chosen at run time", other.name()),
        }
    }

    /// The `_trig` functions given precomputed sines and cosines (no trigonometry inside).
    #[inline(always)]
    pub fn eval_trig<T: Real>(case: Case, t: &Trig<T>, p: &[T], out: &mut [T]) {
        match case {
            Case::Uni => {
                let pp = unidirectional::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = unidirectional::constrained_jacobian_trig(&t.t, &pp);
            }
            Case::Bzy => {
                let pp = bidirectional_zy::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = bidirectional_zy::constrained_jacobian_trig(&t.zy, &pp);
            }
            Case::Bzx => {
                let pp = bidirectional_zx::Params {
                    l_a: p[0],
                    l_b: p[1],
                    l_8: p[2],
                };
                *cols(out) = bidirectional_zx::constrained_jacobian_trig(&t.zx, &pp);
            }
            Case::DiaZy => {
                let pp = dia10_like_zy::Params { l_a: p[0] };
                step_outputs!(dia10_like_zy::step_outputs_trig, &t.d, pp, out);
            }
            Case::Panda => {
                let pp = panda_link8::Params::nominal();
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_link8::pose_and_jacobian_trig(&t.p8, &pp, &mut g, cols(&mut out[12..]));
                put_pose(out, g);
            }
            Case::PandaI => {
                let pp = panda_laparoscope::Params { l_a: p[0] };
                let mut g = ([[T::ZERO; 3]; 3], [T::ZERO; 3]);
                panda_laparoscope::link_pose_and_jacobian_trig(
                    &t.pi,
                    &pp,
                    &mut g,
                    cols(&mut out[12..]),
                );
                put_pose(out, g);
            }
            Case::Oblique7 => {
                let pp = oblique7::Params { l_a: p[0] };
                step_outputs!(oblique7::step_outputs_trig, &t.o7, pp, out);
            }
            Case::PandaRcm => {
                let pp = panda_link6_rcm::Params { l_a: p[0] };
                step_outputs!(panda_link6_rcm::step_outputs_trig, &t.p6, pp, out);
            }
        }
    }
}

/// Pinocchio's C++ (feature `pinocchio`, `c/pinocchio_panda.cpp`, built by g++ -O3 at the
/// default x86-64 ISA against the pip wheel `pin`): the Panda model read from [`PANDA_URDF`] once
/// (`pinocchio::urdf::buildModel`), then per evaluation the LOCAL frame Jacobian of a frame and
/// its placement.
#[cfg(feature = "pinocchio")]
pub mod pinocchio {
    use super::Case;
    use core::ffi::{c_char, c_int, c_void};
    use std::ffi::CString;

    extern "C" {
        fn pin_panda_new(urdf: *const c_char, frame: *const c_char) -> *mut c_void;
        fn pin_panda_free(p: *mut c_void);
        fn pin_panda_nq(p: *const c_void) -> c_int;
        fn pin_panda_nv(p: *const c_void) -> c_int;
        fn pin_panda_frame_jacobian(p: *mut c_void, q: *const f64);
        fn pin_panda_fk_frame_jacobian(p: *mut c_void, q: *const f64);
        fn pin_panda_placement(p: *const c_void, which: c_int, out: *mut f64);
        fn pin_panda_jacobian(p: *const c_void, out: *mut f64);
    }

    /// How the pose is obtained beside `computeFrameJacobian(model, data, q, frame, LOCAL, J)`.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub enum Variant {
        /// `computeFrameJacobian` alone: its LOCAL backward pass leaves the frame's placement in
        /// the world in `data.iMf[0]` (no other work).
        FrameJacobian,
        /// `forwardKinematics` + `updateFramePlacement` (`data.oMf[frame]`) +
        /// `computeFrameJacobian`: the documented route to both.
        FkFrameJacobian,
    }

    impl Variant {
        /// Both.
        pub const ALL: [Variant; 2] = [Variant::FrameJacobian, Variant::FkFrameJacobian];
        /// Bench / driver name.
        pub fn name(self) -> &'static str {
            match self {
                Variant::FrameJacobian => "pinocchio",
                Variant::FkFrameJacobian => "pinocchio_fk",
            }
        }
        /// Parses [`Variant::name`].
        pub fn from_name(s: &str) -> Option<Variant> {
            Variant::ALL.into_iter().find(|v| v.name() == s)
        }
    }

    /// Model, Data, q and J of one frame (owned by the C++ side).
    pub struct Pinocchio {
        ptr: *mut c_void,
        nq: usize,
    }

    impl Pinocchio {
        /// The Panda from [`super::PANDA_URDF`], for the frame of `case`: `panda_link8`
        /// ([`Case::Panda`]) or `panda_link7` ([`Case::PandaI`]).
        ///
        /// # Panics
        /// If the URDF cannot be read or the case is not a Panda case.
        pub fn new(case: Case) -> Pinocchio {
            let frame = match case {
                Case::Panda => "panda_link8",
                Case::PandaI => "panda_link7",
                _ => panic!("Pinocchio runs the Panda cases only, not {case:?}"),
            };
            let urdf = CString::new(super::PANDA_URDF).unwrap();
            let frame = CString::new(frame).unwrap();
            // SAFETY: two NUL-terminated strings; null on failure.
            let ptr = unsafe { pin_panda_new(urdf.as_ptr(), frame.as_ptr()) };
            assert!(!ptr.is_null(), "pinocchio could not build the Panda model");
            // SAFETY: ptr is a live PinPanda.
            let (nq, nv) = unsafe { (pin_panda_nq(ptr), pin_panda_nv(ptr)) };
            assert_eq!((nq, nv), (7, 7), "the Panda has 7 revolute joints");
            Pinocchio { ptr, nq: 7 }
        }

        /// One evaluation at `q` (length ≥ 7); the results stay in Pinocchio's `Data` and `J`
        /// ([`Pinocchio::read`]).
        #[inline(always)]
        pub fn eval(&mut self, variant: Variant, q: &[f64]) {
            assert!(q.len() >= self.nq);
            // SAFETY: ptr is live; the C++ side reads nq doubles.
            unsafe {
                match variant {
                    Variant::FrameJacobian => pin_panda_frame_jacobian(self.ptr, q.as_ptr()),
                    Variant::FkFrameJacobian => pin_panda_fk_frame_jacobian(self.ptr, q.as_ptr()),
                }
            }
        }

        /// The last results in the layout of [`super::eval`]: the pose (12: `data.iMf[0]` for
        /// [`Variant::FrameJacobian`], `data.oMf[frame]` for [`Variant::FkFrameJacobian`]) and J
        /// (42, column-major).
        pub fn read(&self, variant: Variant, out: &mut [f64]) {
            assert!(out.len() >= 54);
            let which = if variant == Variant::FrameJacobian {
                0
            } else {
                1
            };
            // SAFETY: ptr is live; writes 12 and 42 doubles.
            unsafe {
                pin_panda_placement(self.ptr, which, out.as_mut_ptr());
                pin_panda_jacobian(self.ptr, out.as_mut_ptr().add(12));
            }
        }
    }

    impl Drop for Pinocchio {
        fn drop(&mut self) {
            // SAFETY: allocated by pin_panda_new, freed once.
            unsafe { pin_panda_free(self.ptr) }
        }
    }
}
