//! Every emitted function against an independent plain-`f64` computation written here from the
//! description (product of exponentials, adjoints, `Λ`, `Λ#`, `Λ†`; 3×3 blocks with nalgebra,
//! dynamic matrices, inverse and determinants with faer), at thousands
//! of random configurations and parameter values: max error ≤ 1e-12 relative to the matrix norm
//! in f64, ≤ 2e-6 in f32 ([`F32_BOUND`]); and finite differences of the emitted forward kinematics against the
//! emitted body Jacobians. Manipulability errors are measured against its natural scale, the
//! Hadamard bound `Π ‖row_i(J^r)‖`.

use faer::linalg::solvers::DenseSolveCore;
use faer::Mat;
use trocar::nalgebra::{Matrix3, Vector3};
use trocar_model::description::{JointKind, Origin, RobotDescription, Rotation, Wrist};
use trocar_tests_generated as g;

const SAMPLES: usize = 2000;

/// The stated error bound of the `f32` modules: every output within `2e-6` (≈ 34 units of
/// `f32` rounding, `2⁻²⁴ ≈ 6e-8`) of the `f64` reference, relative to the matrix norm (or 1,
/// if smaller), manipulability relative to its Hadamard bound; over the reference arms'
/// workspace (every joint in `[−3.1, 3.1]`, parameters at 0.7–1.3 × nominal), both at the
/// `f32`-rounded inputs (the arithmetic alone) and at the unrounded ones (what an `f32` caller
/// sees). Measured: at most 2.6e-7 (4.4 units), so the bound has a margin of 8.
const F32_BOUND: f64 = 2e-6;

#[derive(Clone, Copy)]
struct Se3 {
    r: Matrix3<f64>,
    p: Vector3<f64>,
}

impl Se3 {
    fn identity() -> Self {
        Se3 {
            r: Matrix3::identity(),
            p: Vector3::zeros(),
        }
    }
    fn compose(&self, h: &Se3) -> Se3 {
        Se3 {
            r: self.r * h.r,
            p: self.r * h.p + self.p,
        }
    }
    fn inverse(&self) -> Se3 {
        let rt = self.r.transpose();
        Se3 {
            r: rt,
            p: -(rt * self.p),
        }
    }
    /// `Ad_g = [[R, p̂R], [0, R]]` (2.43).
    fn adjoint(&self) -> Mat<f64> {
        let mut a = Mat::zeros(6, 6);
        let pr = hat(&self.p) * self.r;
        for i in 0..3 {
            for j in 0..3 {
                a[(i, j)] = self.r[(i, j)];
                a[(i + 3, j + 3)] = self.r[(i, j)];
                a[(i, j + 3)] = pr[(i, j)];
            }
        }
        a
    }
}

fn hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// `exp(ξ̂ θ)` (2.25)–(2.27), `ξ = (v, ω)`, `‖ω‖ = 1` or `ω = 0`.
fn exp_twist(xi: &[f64; 6], theta: f64) -> Se3 {
    let v = Vector3::new(xi[0], xi[1], xi[2]);
    let w = Vector3::new(xi[3], xi[4], xi[5]);
    if w.norm() < 1e-15 {
        return Se3 {
            r: Matrix3::identity(),
            p: v * theta,
        };
    }
    let wh = hat(&w);
    let (s, c) = theta.sin_cos();
    let r = Matrix3::identity() + wh * s + wh * wh * (1.0 - c);
    let p = (Matrix3::identity() - r) * w.cross(&v) + w * w.dot(&v) * theta;
    Se3 { r, p }
}

/// `(link i, g_ir, H rows, wrist)`.
type ConstraintRef = (usize, Se3, Vec<[f64; 6]>, Option<Wrist>);

struct Reference {
    origins: Vec<Se3>,
    twists: Vec<[f64; 6]>,
    tool: Se3,
    constraint: Option<ConstraintRef>,
}

fn rotation(r: &Rotation) -> Matrix3<f64> {
    match r {
        Rotation::Matrix(m) => Matrix3::from_fn(|i, j| m[i][j]),
        Rotation::Rpy([roll, pitch, yaw]) => {
            let rx = Matrix3::new(
                1.0,
                0.0,
                0.0,
                0.0,
                roll.cos(),
                -roll.sin(),
                0.0,
                roll.sin(),
                roll.cos(),
            );
            let ry = Matrix3::new(
                pitch.cos(),
                0.0,
                pitch.sin(),
                0.0,
                1.0,
                0.0,
                -pitch.sin(),
                0.0,
                pitch.cos(),
            );
            let rz = Matrix3::new(
                yaw.cos(),
                -yaw.sin(),
                0.0,
                yaw.sin(),
                yaw.cos(),
                0.0,
                0.0,
                0.0,
                1.0,
            );
            rz * ry * rx
        }
    }
}

impl Reference {
    fn new(desc: &RobotDescription, params: &[(String, f64)]) -> Self {
        let lookup = |n: &str| params.iter().find(|(m, _)| m == n).map(|(_, v)| *v);
        let scalar = |s: &trocar_model::description::Linear| s.eval(lookup).unwrap();
        let origin = |o: &Origin| Se3 {
            r: rotation(&o.rotation),
            p: Vector3::new(scalar(&o.xyz[0]), scalar(&o.xyz[1]), scalar(&o.xyz[2])),
        };
        let origins = desc.joints.iter().map(|j| origin(&j.origin)).collect();
        let twists = desc
            .joints
            .iter()
            .map(|j| match &j.kind {
                JointKind::Revolute { axis } => [0.0, 0.0, 0.0, axis[0], axis[1], axis[2]],
                JointKind::Prismatic { axis } => [axis[0], axis[1], axis[2], 0.0, 0.0, 0.0],
                JointKind::Twist { v, w } => [
                    scalar(&v[0]),
                    scalar(&v[1]),
                    scalar(&v[2]),
                    w[0],
                    w[1],
                    w[2],
                ],
            })
            .collect();
        let constraint = desc
            .constraint
            .as_ref()
            .map(|c| (c.link, origin(&c.origin), c.h.clone(), c.wrist));
        Reference {
            origins,
            twists,
            tool: origin(&desc.end_effector.origin),
            constraint,
        }
    }

    fn joint(&self, k: usize, q: &[f64]) -> Se3 {
        self.origins[k].compose(&exp_twist(&self.twists[k], q[k]))
    }

    /// `g_0k` for the first `upto` joints, then `tail`.
    fn fk(&self, q: &[f64], upto: usize, tail: Option<&Se3>) -> Se3 {
        let mut g = Se3::identity();
        for k in 0..upto {
            g = g.compose(&self.joint(k, q));
        }
        match tail {
            Some(t) => g.compose(t),
            None => g,
        }
    }

    /// Body Jacobian of joints `0..upto` then `tail`: column k is `Ad⁻¹_{g_ke} ξ_k` (2.53)–(2.55).
    fn body_jacobian(&self, q: &[f64], upto: usize, tail: Option<&Se3>) -> Mat<f64> {
        let mut j = Mat::zeros(6, upto);
        for k in 0..upto {
            let mut g = Se3::identity();
            for l in k + 1..upto {
                g = g.compose(&self.joint(l, q));
            }
            if let Some(t) = tail {
                g = g.compose(t);
            }
            let xi = Mat::from_fn(6, 1, |r, _| self.twists[k][r]);
            let col = g.inverse().adjoint() * xi;
            for r in 0..6 {
                j[(r, k)] = col[(r, 0)];
            }
        }
        j
    }

    /// `(J^r_0e, J_c)` (3.15), (3.33).
    fn constrained(&self, q: &[f64]) -> (Mat<f64>, Mat<f64>) {
        let (i, g_ir, h, wrist) = self.constraint.clone().unwrap();
        let n = self.twists.len();
        let r = h.len();
        let hm = Mat::from_fn(r, 6, |a, b| h[a][b]);
        let lambda = &hm * g_ir.inverse().adjoint();
        let e = |k: usize| Mat::from_fn(6, 1, |a, _| if a == k { 1.0 } else { 0.0 });
        let la = g_ir.p.y;
        let sharp = match wrist {
            Some(Wrist::Unidirectional) => {
                let cols = [&e(0) + div(&e(5), la), e(1), e(2), e(3), e(4)];
                Mat::from_fn(6, 5, |a, b| cols[b][(a, 0)])
            }
            Some(_) => {
                let cols = [&e(0) + div(&e(5), la), e(1), &e(2) - div(&e(3), la), e(4)];
                Mat::from_fn(6, 4, |a, b| cols[b][(a, 0)])
            }
            None => g_ir.adjoint() * null_basis(&hm),
        };
        assert!((&lambda * &sharp).norm_l2() < 1e-12, "Λ Λ# ≠ 0");
        let gram = &lambda * lambda.transpose();
        let pinv = lambda.transpose() * gram.partial_piv_lu().inverse();
        assert!(pinv.norm_max().is_finite(), "Λ Λᵀ is singular");
        let mut g_ie = Se3::identity();
        for k in i..n {
            g_ie = g_ie.compose(&self.joint(k, q));
        }
        g_ie = g_ie.compose(&self.tool);
        let ad_ei = g_ie.inverse().adjoint();
        let jb = self.body_jacobian(q, n, Some(&self.tool));
        let left = &ad_ei * sharp;
        let m = left.ncols() + n - i;
        let mut jr = Mat::zeros(6, m);
        jr.as_mut()
            .submatrix_mut(0, 0, 6, left.ncols())
            .copy_from(&left);
        jr.as_mut()
            .submatrix_mut(0, left.ncols(), 6, n - i)
            .copy_from(jb.as_ref().submatrix(0, i, 6, n - i));
        (jr, ad_ei * pinv)
    }
}

/// The null basis of `H` from its reduced row echelon form: one column per free coordinate,
/// increasing (the choice documented by `trocar::constraint::NullSpaceBasis::Computed`).
fn null_basis(h: &Mat<f64>) -> Mat<f64> {
    let mut m = h.clone();
    let mut pivots = Vec::new();
    let mut row = 0;
    for col in 0..6 {
        let Some(p) = (row..m.nrows()).find(|&r| m[(r, col)].abs() > 1e-12) else {
            continue;
        };
        for x in 0..6 {
            let t = m[(row, x)];
            m[(row, x)] = m[(p, x)];
            m[(p, x)] = t;
        }
        let inv = 1.0 / m[(row, col)];
        for x in 0..6 {
            m[(row, x)] *= inv;
        }
        for r in 0..m.nrows() {
            if r != row {
                let f = m[(r, col)];
                for x in 0..6 {
                    m[(r, x)] -= f * m[(row, x)];
                }
            }
        }
        pivots.push(col);
        row += 1;
        if row == m.nrows() {
            break;
        }
    }
    let free: Vec<usize> = (0..6).filter(|c| !pivots.contains(c)).collect();
    let mut n = Mat::zeros(6, free.len());
    for (k, &f) in free.iter().enumerate() {
        n[(f, k)] = 1.0;
        for (r, &pc) in pivots.iter().enumerate() {
            n[(pc, k)] = -m[(r, f)];
        }
    }
    n
}

/// `w = sqrt(det(J Jᵀ))` (3.36) — `|det J|` by LU when square, which is better conditioned — and
/// its natural scale, the Hadamard bound `Π ‖row_i(J)‖ ≥ w`, against which errors are measured.
fn manipulability_ref(j: &Mat<f64>) -> (f64, f64) {
    let w = if j.nrows() == j.ncols() {
        j.determinant().abs()
    } else {
        (j * j.transpose()).determinant().abs().sqrt()
    };
    let scale = j.row_iter().map(|r| r.norm_l2()).product::<f64>();
    (w, scale)
}

struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// `max |a − b| / max(‖b‖_F, 1)`.
fn rel_err(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    (a - b).norm_max() / b.norm_l2().max(1.0)
}

/// `m / s`, entry by entry.
fn div(m: &Mat<f64>, s: f64) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |r, c| m[(r, c)] / s)
}

fn from_cols<T: Copy + Into<f64>, const R: usize, const C: usize>(a: &[[T; R]; C]) -> Mat<f64> {
    Mat::from_fn(R, C, |r, c| a[c][r].into())
}

fn transform_matrix<T: Copy + Into<f64>>(t: &([[T; 3]; 3], [T; 3])) -> Mat<f64> {
    Mat::from_fn(3, 4, |r, c| {
        if c < 3 {
            t.0[c][r].into()
        } else {
            t.1[r].into()
        }
    })
}

fn se3_matrix(g: &Se3) -> Mat<f64> {
    Mat::from_fn(3, 4, |r, c| if c < 3 { g.r[(r, c)] } else { g.p[r] })
}

fn desc(file: &str) -> RobotDescription {
    let root = env!("CARGO_MANIFEST_DIR");
    let path = if file.starts_with("robots/") {
        format!("{root}/{file}")
    } else {
        format!("{root}/../../runtime/model/robots/{file}")
    };
    RobotDescription::from_toml_file(&path).unwrap()
}

/// Body velocity from finite differences of forward kinematics, `(Rᵀ ṗ, (Rᵀ Ṙ)^∨)`.
fn fd_body_jacobian(fk: impl Fn(&[f64]) -> Mat<f64>, q: &[f64], cols: usize) -> Mat<f64> {
    let h = 1e-6;
    let g0 = fk(q);
    let r0 = Matrix3::from_fn(|r, c| g0[(r, c)]);
    let mut j = Mat::zeros(6, cols);
    for k in 0..cols {
        let mut qp = q.to_vec();
        let mut qm = q.to_vec();
        qp[k] += h;
        qm[k] -= h;
        let d = div(&(fk(&qp) - fk(&qm)), 2.0 * h);
        let pd = r0.transpose() * Vector3::new(d[(0, 3)], d[(1, 3)], d[(2, 3)]);
        let w = r0.transpose() * Matrix3::from_fn(|r, c| d[(r, c)]);
        let col = [pd[0], pd[1], pd[2], w[(2, 1)], w[(0, 2)], w[(1, 0)]];
        for (r, x) in col.iter().enumerate() {
            j[(r, k)] = *x;
        }
    }
    j
}

macro_rules! check_robot {
    ($test:ident, $m:ident, $file:literal, [$($field:ident),*]) => {
        #[test]
        fn $test() {
            use g::$m as m;
            let d = desc($file);
            let names: Vec<String> = d.parameters.iter().map(|p| p.name.clone()).collect();
            let nominal: Vec<f64> = d.parameters.iter().map(|p| p.value).collect();
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
            let mut worst = [0.0f64; 8];
            let mut worst32 = [0.0f64; 8];
            // f32 outputs against f64 at the unrounded joint values and parameters: what a
            // user of the f32 module sees (input rounding included).
            let mut worst32_exact = [0.0f64; 8];
            let mut worst_fd = 0.0f64;
            // pose_and_jacobians_trig: [g_0e, J^B_0i, J^r, J_c] in f64 and in f32.
            let mut worst_step = [0.0f64; 4];
            let mut worst_step32 = [0.0f64; 4];
            // The fused functions, f64 and f32: pose_and_jacobian [g_0e, J^B_0e],
            // link_pose_and_jacobian [g_0i, J^B_0i], step_outputs [J^r, w, g_0e, J^B_0i, J_c].
            let mut worst_fused = [0.0f64; 9];
            let mut worst_fused32 = [0.0f64; 9];
            for s in 0..SAMPLES {
                let mut q = [0.0f64; m::N];
                for x in q.iter_mut() {
                    *x = rng.uniform(-3.1, 3.1);
                }
                let values: Vec<f64> = nominal.iter().map(|v| v * rng.uniform(0.7, 1.3)).collect();
                let pairs: Vec<(String, f64)> = names.iter().cloned().zip(values.iter().copied()).collect();
                let mut p = m::Params::<f64>::nominal();
                let mut p32 = m::Params::<f32>::nominal();
                for (name, v) in &pairs {
                    $(
                        if name == stringify!($field) {
                            p.$field = *v;
                            p32.$field = *v as f32;
                        }
                    )*
                }
                // f32 reference at the f32-rounded parameters.
                let pairs32: Vec<(String, f64)> =
                    pairs.iter().map(|(n, v)| (n.clone(), f64::from(*v as f32))).collect();
                let refm32 = Reference::new(&d, &pairs32);
                let refm = Reference::new(&d, &pairs);
                let q32: [f32; m::N] = core::array::from_fn(|k| q[k] as f32);
                let q32_64: Vec<f64> = q32.iter().map(|&x| x as f64).collect();

                // Forward kinematics (2.21).
                let fk_ref = se3_matrix(&refm.fk(&q, m::N, Some(&refm.tool)));
                worst[0] = worst[0].max(rel_err(&transform_matrix(&m::forward_kinematics(&q, &p)), &fk_ref));
                let fk_ref32 = se3_matrix(&refm32.fk(&q32_64, m::N, Some(&refm32.tool)));
                worst32[0] = worst32[0].max(rel_err(&transform_matrix(&m::forward_kinematics(&q32, &p32)), &fk_ref32));
                // Body Jacobian (2.53)–(2.55).
                let jb_ref = refm.body_jacobian(&q, m::N, Some(&refm.tool));
                worst[1] = worst[1].max(rel_err(&from_cols(&m::body_jacobian(&q, &p)), &jb_ref));
                let jb_ref32 = refm32.body_jacobian(&q32_64, m::N, Some(&refm32.tool));
                worst32[1] = worst32[1].max(rel_err(&from_cols(&m::body_jacobian(&q32, &p32)), &jb_ref32));
                // Constrained part.
                let i = m::I;
                let fki_ref = se3_matrix(&refm.fk(&q, i, None));
                worst[2] = worst[2].max(rel_err(&transform_matrix(&m::forward_kinematics_i(&q, &p)), &fki_ref));
                let jbi_ref = refm.body_jacobian(&q, i, None);
                worst[3] = worst[3].max(rel_err(&from_cols(&m::partial_body_jacobian(&q, &p)), &jbi_ref));
                let (jr_ref, jc_ref) = refm.constrained(&q);
                worst[4] = worst[4].max(rel_err(&from_cols(&m::constrained_jacobian(&q, &p)), &jr_ref));
                worst[5] = worst[5].max(rel_err(&from_cols(&m::constraint_jacobian_c(&q, &p)), &jc_ref));
                let (w_ref, scale) = manipulability_ref(&jr_ref);
                let w2_ref = w_ref * w_ref;
                worst[6] = worst[6].max((m::manipulability_squared(&q, &p) - w2_ref).abs() / (scale * scale));
                worst[7] = worst[7].max((m::manipulability(&q, &p) - w_ref).abs() / scale);
                let (jr_ref32, jc_ref32) = refm32.constrained(&q32_64);
                let jbi_ref32 = refm32.body_jacobian(&q32_64, i, None);
                worst32[3] = worst32[3].max(rel_err(&from_cols(&m::partial_body_jacobian(&q32, &p32)), &jbi_ref32));
                worst32[4] = worst32[4].max(rel_err(&from_cols(&m::constrained_jacobian(&q32, &p32)), &jr_ref32));
                worst32[5] = worst32[5].max(rel_err(&from_cols(&m::constraint_jacobian_c(&q32, &p32)), &jc_ref32));
                let (w_ref32, scale32) = manipulability_ref(&jr_ref32);
                worst32[7] = worst32[7].max((f64::from(m::manipulability(&q32, &p32)) - w_ref32).abs() / scale32);
                worst32_exact[0] = worst32_exact[0].max(rel_err(&transform_matrix(&m::forward_kinematics(&q32, &p32)), &fk_ref));
                worst32_exact[1] = worst32_exact[1].max(rel_err(&from_cols(&m::body_jacobian(&q32, &p32)), &jb_ref));
                worst32_exact[3] = worst32_exact[3].max(rel_err(&from_cols(&m::partial_body_jacobian(&q32, &p32)), &jbi_ref));
                worst32_exact[4] = worst32_exact[4].max(rel_err(&from_cols(&m::constrained_jacobian(&q32, &p32)), &jr_ref));
                worst32_exact[5] = worst32_exact[5].max(rel_err(&from_cols(&m::constraint_jacobian_c(&q32, &p32)), &jc_ref));
                worst32_exact[7] = worst32_exact[7].max((f64::from(m::manipulability(&q32, &p32)) - w_ref).abs() / scale);

                // The `_trig` variants are the same functions.
                let t = m::JointTrig::new(&q);
                assert_eq!(m::constrained_jacobian_trig(&t, &p), m::constrained_jacobian(&q, &p));
                assert_eq!(m::forward_kinematics_trig(&t, &p), m::forward_kinematics(&q, &p));
                assert_eq!(m::partial_body_jacobian_trig(&t, &p), m::partial_body_jacobian(&q, &p));
                assert_eq!(m::manipulability_trig(&t, &p), m::manipulability(&q, &p));

                // The step's four outputs from one program (one pass along the chain).
                let (g0e, jbi, jr, jc) = m::pose_and_jacobians_trig(&t, &p);
                for (w, e) in worst_step.iter_mut().zip([
                    rel_err(&transform_matrix(&g0e), &fk_ref),
                    rel_err(&from_cols(&jbi), &jbi_ref),
                    rel_err(&from_cols(&jr), &jr_ref),
                    rel_err(&from_cols(&jc), &jc_ref),
                ]) {
                    *w = w.max(e);
                }
                let (g0e, jbi, jr, jc) = m::pose_and_jacobians_trig(&m::JointTrig::new(&q32), &p32);
                for (w, e) in worst_step32.iter_mut().zip([
                    rel_err(&transform_matrix(&g0e), &fk_ref32),
                    rel_err(&from_cols(&jbi), &jbi_ref32),
                    rel_err(&from_cols(&jr), &jr_ref32),
                    rel_err(&from_cols(&jc), &jc_ref32),
                ]) {
                    *w = w.max(e);
                }

                // The fused functions, every output against the reference.
                {
                    let (mut fk, mut jb0e) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; m::N]);
                    m::pose_and_jacobian(&q, &p, &mut fk, &mut jb0e);
                    let (mut fk0i, mut jb0i) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; m::I]);
                    m::link_pose_and_jacobian_trig(&t, &p, &mut fk0i, &mut jb0i);
                    let (mut jr, mut manip, mut g0e, mut jbi, mut jc) = (
                        [[0.0; 6]; m::M],
                        0.0,
                        ([[0.0; 3]; 3], [0.0; 3]),
                        [[0.0; 6]; m::I],
                        [[0.0; 6]; m::R],
                    );
                    m::step_outputs(&q, &p, &mut jr, &mut manip, &mut g0e, &mut jbi, &mut jc);
                    for (w, e) in worst_fused.iter_mut().zip([
                        rel_err(&transform_matrix(&fk), &fk_ref),
                        rel_err(&from_cols(&jb0e), &jb_ref),
                        rel_err(&transform_matrix(&fk0i), &fki_ref),
                        rel_err(&from_cols(&jb0i), &jbi_ref),
                        rel_err(&from_cols(&jr), &jr_ref),
                        (manip - w_ref).abs() / scale,
                        rel_err(&transform_matrix(&g0e), &fk_ref),
                        rel_err(&from_cols(&jbi), &jbi_ref),
                        rel_err(&from_cols(&jc), &jc_ref),
                    ]) {
                        *w = w.max(e);
                    }
                    let (mut fk, mut jb0e) = (([[0.0f32; 3]; 3], [0.0; 3]), [[0.0f32; 6]; m::N]);
                    m::pose_and_jacobian_trig(&m::JointTrig::new(&q32), &p32, &mut fk, &mut jb0e);
                    let (mut fk0i, mut jb0i) = (([[0.0f32; 3]; 3], [0.0; 3]), [[0.0f32; 6]; m::I]);
                    m::link_pose_and_jacobian(&q32, &p32, &mut fk0i, &mut jb0i);
                    let (mut jr, mut manip, mut g0e, mut jbi, mut jc) = (
                        [[0.0f32; 6]; m::M],
                        0.0f32,
                        ([[0.0f32; 3]; 3], [0.0; 3]),
                        [[0.0f32; 6]; m::I],
                        [[0.0f32; 6]; m::R],
                    );
                    m::step_outputs_trig(
                        &m::JointTrig::new(&q32),
                        &p32,
                        &mut jr,
                        &mut manip,
                        &mut g0e,
                        &mut jbi,
                        &mut jc,
                    );
                    let fki_ref32 = se3_matrix(&refm32.fk(&q32_64, i, None));
                    for (w, e) in worst_fused32.iter_mut().zip([
                        rel_err(&transform_matrix(&fk), &fk_ref32),
                        rel_err(&from_cols(&jb0e), &jb_ref32),
                        rel_err(&transform_matrix(&fk0i), &fki_ref32),
                        rel_err(&from_cols(&jb0i), &jbi_ref32),
                        rel_err(&from_cols(&jr), &jr_ref32),
                        (f64::from(manip) - w_ref32).abs() / scale32,
                        rel_err(&transform_matrix(&g0e), &fk_ref32),
                        rel_err(&from_cols(&jbi), &jbi_ref32),
                        rel_err(&from_cols(&jc), &jc_ref32),
                    ]) {
                        *w = w.max(e);
                    }
                }

                // Finite differences of the emitted FK vs the emitted body Jacobians.
                if s % 10 == 0 {
                    let fk = |x: &[f64]| {
                        let a: [f64; m::N] = core::array::from_fn(|k| x[k]);
                        transform_matrix(&m::forward_kinematics(&a, &p))
                    };
                    let fd = fd_body_jacobian(fk, &q, m::N);
                    worst_fd = worst_fd.max(rel_err(&fd, &from_cols(&m::body_jacobian(&q, &p))));
                    let fki = |x: &[f64]| {
                        let a: [f64; m::N] = core::array::from_fn(|k| x[k]);
                        transform_matrix(&m::forward_kinematics_i(&a, &p))
                    };
                    let fd = fd_body_jacobian(fki, &q, m::I);
                    worst_fd = worst_fd.max(rel_err(&fd, &from_cols(&m::partial_body_jacobian(&q, &p))));
                }
            }
            println!(
                "{}: f64 worst [fk, jb, fk_i, jb_i, jr, jc, w², w] = {:?}; f32 = {:?}; f32 against f64 at the unrounded inputs = {:?}; finite differences {:.2e}",
                stringify!($m), worst, worst32, worst32_exact, worst_fd
            );
            for (k, e) in worst.iter().enumerate() {
                assert!(*e <= 1e-12, "f64 output {k}: error {e:e}");
            }
            for (k, e) in worst32.iter().enumerate() {
                assert!(*e <= F32_BOUND, "f32 output {k}: error {e:e}");
            }
            for (k, e) in worst32_exact.iter().enumerate() {
                assert!(*e <= F32_BOUND, "f32 output {k} against f64 at the unrounded inputs: error {e:e}");
            }
            assert!(worst_fd <= 1e-6, "finite differences: {worst_fd:e}");
            println!("pose_and_jacobians_trig: f64 worst {worst_step:?}; f32 {worst_step32:?}");
            for (k, e) in worst_step.iter().enumerate() {
                assert!(*e <= 1e-12, "pose_and_jacobians_trig f64 output {k}: error {e:e}");
            }
            for (k, e) in worst_step32.iter().enumerate() {
                assert!(*e <= F32_BOUND, "pose_and_jacobians_trig f32 output {k}: error {e:e}");
            }
            println!("fused functions: f64 worst {worst_fused:?}; f32 {worst_fused32:?}");
            for (k, e) in worst_fused.iter().enumerate() {
                assert!(*e <= 1e-12, "fused f64 output {k}: error {e:e}");
            }
            for (k, e) in worst_fused32.iter().enumerate() {
                assert!(*e <= F32_BOUND, "fused f32 output {k}: error {e:e}");
            }
        }
    };
}

check_robot!(
    unidirectional,
    unidirectional,
    "unidirectional.toml",
    [l_a, l_b, l_8]
);
check_robot!(
    bidirectional_zy,
    bidirectional_zy,
    "bidirectional-zy.toml",
    [l_a, l_b, l_8]
);
check_robot!(
    bidirectional_zx,
    bidirectional_zx,
    "bidirectional-zx.toml",
    [l_a, l_b, l_8]
);
check_robot!(dia10_like_zy, dia10_like_zy, "dia10_like_zy.toml", [l_a]);
check_robot!(dia10_like_zx, dia10_like_zx, "dia10_like_zx.toml", [l_a]);
// pose_and_jacobians_trig written as the four functions called in turn.
check_robot!(
    dia10_like_zy_four_calls,
    dia10_like_zy_four_calls,
    "dia10_like_zy.toml",
    [l_a]
);
check_robot!(
    rotated_rcm,
    rotated_rcm,
    "robots/rotated_rcm.toml",
    [l_a, l_8]
);
// J^r 6 × 9: the manipulability by Gram–Schmidt on the emitted J^r.
check_robot!(
    chain11_wide,
    chain11_wide,
    "robots/chain11_wide.toml",
    [l_a]
);
check_robot!(
    chain9_prismatic,
    chain9_prismatic,
    "robots/chain9_prismatic.toml",
    [l_a, d_1]
);

/// The monomorphic modules (`--real f32`, `--real f64`) compute exactly what the generic ones do.
#[test]
fn monomorphic_modules_match_generic() {
    let mut rng = Rng(7);
    for _ in 0..SAMPLES {
        let q: [f64; 8] = core::array::from_fn(|_| rng.uniform(-3.1, 3.1));
        let q32: [f32; 8] = core::array::from_fn(|k| q[k] as f32);
        let p32 = g::bidirectional_zy::Params::<f32>::nominal();
        let m32 = g::bidirectional_zy_f32::Params::nominal();
        assert_eq!(
            g::bidirectional_zy_f32::constrained_jacobian(&q32, &m32),
            g::bidirectional_zy::constrained_jacobian(&q32, &p32)
        );
        assert_eq!(
            g::bidirectional_zy_f32::forward_kinematics(&q32, &m32),
            g::bidirectional_zy::forward_kinematics(&q32, &p32)
        );
        let r32 = g::rotated_rcm::Params::<f32>::nominal();
        assert_eq!(
            g::rotated_rcm_f32::constraint_jacobian_c(&q32, &g::rotated_rcm_f32::Params::nominal()),
            g::rotated_rcm::constraint_jacobian_c(&q32, &r32)
        );
        let p64 = g::dia10_like_zx::Params::<f64>::nominal();
        let m64 = g::dia10_like_zx_f64::Params::nominal();
        assert_eq!(
            g::dia10_like_zx_f64::body_jacobian(&q, &m64),
            g::dia10_like_zx::body_jacobian(&q, &p64)
        );
        assert_eq!(
            g::dia10_like_zx_f64::manipulability(&q, &m64),
            g::dia10_like_zx::manipulability(&q, &p64)
        );
    }
}
