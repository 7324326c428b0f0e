//! The Franka Panda's F_i = panda_link7 (the constrained link of `panda-laparoscope`): g_0i +
//! J^B_0i from trocar's numeric runtime (`Chain::<f64, 7>::frame_and_partial_body_jacobian::<7>`,
//! `new`), from the same kernel as it was before the sweeps without per-joint transforms (`old`,
//! copied verbatim from `runtime/src/kinematics.rs` of 2026-11-26), and from Pinocchio's C++
//! (`computeFrameJacobian(model, data, q, frame, LOCAL, J)`, placement `data.iMf[0]` left by it:
//! `pin`; `forwardKinematics` + `updateFramePlacement` + `computeFrameJacobian`: `pin_fk`), all
//! cycling through 16 configurations, timed in turns in one process (bench/numeric-pinocchio/run.sh).
//!
//! `check`: agreement first (1000 configurations: new vs Pinocchio ≤ 1e-12, new vs old ≤ 1e-13);
//! `time ROUNDS BLOCK [IMPL..]`: per round one block of BLOCK evaluations of each implementation in
//! turn, minimum and median over the rounds (ns per evaluation); `cg IMPL N`: N evaluations inside
//! `measured_loop`, for `valgrind --tool=callgrind --toggle-collect='*measured_loop*'`.
use std::ffi::{c_char, c_int, c_void, CString};
use std::hint::black_box;
use std::time::Instant;
use trocar::kinematics::{Chain, Joint};
use trocar::nalgebra::{convert, Matrix3, RealField, SMatrix, SVector, Vector3};
use trocar::se3::{Adjoint, Se3, Twist};
use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

extern "C" {
    fn pin_panda_new(urdf: *const c_char, frame: *const c_char) -> *mut c_void;
    fn pin_panda_frame_jacobian(p: *mut c_void, q: *const f64);
    fn pin_panda_fk_frame_jacobian(p: *mut c_void, q: *const f64);
    fn pin_panda_placement(p: *const c_void, which: c_int, out: *mut f64);
    fn pin_panda_jacobian(p: *const c_void, out: *mut f64);
}

/// main's kernel before the change, verbatim (Joint::transform + body_jacobian_columns).
mod old {
    use super::*;
    #[inline]
    pub fn transform<T: RealField + Copy>(j: &Joint<T>, theta: T) -> Se3<T> {
        let v = trocar::se3::linear(&j.twist);
        let w = trocar::se3::angular(&j.twist);
        let unit = (w.norm_squared() - T::one()).abs() <= T::default_epsilon() * convert(4.0);
        if unit && v == Vector3::zeros() {
            let (s, c) = theta.sin_cos();
            let r_o = &j.origin.rotation;
            let rw = r_o * trocar::se3::hat(&w);
            let rw2 = r_o * (w * w.transpose() - Matrix3::identity());
            Se3::new(r_o + rw * s + rw2 * (T::one() - c), j.origin.translation)
        } else {
            j.origin.compose(&Se3::exp(&j.twist, theta))
        }
    }
    #[inline]
    pub fn body_jacobian_columns<T: RealField + Copy>(
        joints: &[Joint<T>],
        q: &[T],
        tool: &Se3<T>,
        columns: &mut [Twist<T>],
    ) -> Se3<T> {
        assert_eq!(joints.len(), q.len(), "one joint value per joint");
        assert_eq!(joints.len(), columns.len(), "one column per joint");
        let mut g = *tool;
        for k in (0..joints.len()).rev() {
            columns[k] = Adjoint(g).apply_inverse(&joints[k].twist);
            g = transform(&joints[k], q[k]).compose(&g);
        }
        g
    }
    #[inline]
    pub fn frame_and_partial_body_jacobian<const N: usize, const I: usize>(
        chain: &Chain<f64, N>,
        q: &SVector<f64, N>,
    ) -> (Se3<f64>, SMatrix<f64, 6, I>) {
        let mut cols = [Twist::zeros(); I];
        let g = body_jacobian_columns(
            &chain.joints[..I],
            &q.as_slice()[..I],
            &Se3::identity(),
            &mut cols,
        );
        let mut m = SMatrix::<f64, 6, I>::zeros();
        for (k, c) in cols.iter().enumerate() {
            m.set_column(k, c);
        }
        (g, m)
    }
}

const LIMITS: [(f64, f64); 7] = [
    (-2.8973, 2.8973),
    (-1.7628, 1.7628),
    (-2.8973, 2.8973),
    (-3.0718, -0.0698),
    (-2.8973, 2.8973),
    (-0.0175, 3.7525),
    (-2.8973, 2.8973),
];

fn configs(n: usize) -> Vec<[f64; 7]> {
    let mut qs = vec![[0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8]];
    let mut seed = 0x5eed_u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    while qs.len() < n {
        qs.push(core::array::from_fn(|k| {
            LIMITS[k].0 + (LIMITS[k].1 - LIMITS[k].0) * next()
        }));
    }
    qs
}

struct Pin(*mut c_void);
impl Pin {
    fn new() -> Pin {
        let urdf = CString::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../runtime/model/robots/urdf/panda.urdf"
        ))
        .unwrap();
        let frame = CString::new("panda_link7").unwrap();
        // SAFETY: two NUL-terminated strings.
        let p = unsafe { pin_panda_new(urdf.as_ptr(), frame.as_ptr()) };
        assert!(!p.is_null());
        Pin(p)
    }
    #[inline(always)]
    fn eval(&mut self, fk: bool, q: &[f64; 7]) {
        // SAFETY: live pointer, reads 7 doubles.
        unsafe {
            if fk {
                pin_panda_fk_frame_jacobian(self.0, q.as_ptr())
            } else {
                pin_panda_frame_jacobian(self.0, q.as_ptr())
            }
        }
    }
    fn read(&self, fk: bool, out: &mut [f64; 54]) {
        // SAFETY: writes 12 + 42 doubles.
        unsafe {
            pin_panda_placement(self.0, fk as c_int, out.as_mut_ptr());
            pin_panda_jacobian(self.0, out.as_mut_ptr().add(12));
        }
    }
}

fn chain() -> Chain<f64, 7> {
    let d = RobotDescription::preset("panda-laparoscope").expect("preset");
    let robot = NumericModel::<f64>::from_description(&d, &[("l_a".into(), 0.25)]).expect("robot");
    robot.to_chain::<7>().expect("chain")
}

#[inline(always)]
fn put(g: &Se3<f64>, j: &SMatrix<f64, 6, 7>, out: &mut [f64; 54]) {
    out[..9].copy_from_slice(g.rotation.as_slice());
    out[9..12].copy_from_slice(g.translation.as_slice());
    out[12..54].copy_from_slice(j.as_slice());
}

#[inline(never)]
fn eval_new(c: &Chain<f64, 7>, q: &[f64; 7], out: &mut [f64; 54]) {
    let q = SVector::<f64, 7>::from(*q);
    let (g, j) = c.frame_and_partial_body_jacobian::<7>(&q);
    put(&g, &j, out);
}
#[inline(never)]
fn eval_old(c: &Chain<f64, 7>, q: &[f64; 7], out: &mut [f64; 54]) {
    let q = SVector::<f64, 7>::from(*q);
    let (g, j) = old::frame_and_partial_body_jacobian::<7, 7>(c, &q);
    put(&g, &j, out);
}
#[inline(never)]
fn eval_new_fk(c: &Chain<f64, 7>, q: &[f64; 7], out: &mut [f64; 54]) {
    let q = SVector::<f64, 7>::from(*q);
    let g = c.forward_kinematics(&q);
    out[..9].copy_from_slice(g.rotation.as_slice());
    out[9..12].copy_from_slice(g.translation.as_slice());
}

const IMPLS: [&str; 5] = ["new", "old", "pin", "pin_fk", "new_fk"];

#[inline(never)]
fn measured_loop(n: usize, f: &mut dyn FnMut()) {
    for _ in 0..n {
        f();
    }
}

fn run(
    name: &str,
    c: &Chain<f64, 7>,
    pin: &mut Pin,
    qs: &[[f64; 7]],
    n: usize,
    out: &mut [f64; 54],
) {
    let mut k = 0usize;
    match name {
        "new" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            eval_new(c, &qs[k], out);
            black_box(&mut *out);
        }),
        "old" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            eval_old(c, &qs[k], out);
            black_box(&mut *out);
        }),
        "new_fk" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            eval_new_fk(c, &qs[k], out);
            black_box(&mut *out);
        }),
        "pin" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            pin.eval(false, &qs[k]);
        }),
        "pin_fk" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            pin.eval(true, &qs[k]);
        }),
        "trig" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            black_box(trocar::emitted::fast::sin_cos_f64_array(&qs[k]));
        }),
        "trig1" => measured_loop(n, &mut || {
            k = black_box(k + 1) & 15;
            let q = &qs[k];
            black_box(core::array::from_fn::<_, 7, _>(|i| {
                trocar::emitted::fast::sin_cos_f64(q[i])
            }));
        }),
        _ => panic!("impl"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let c = chain();
    let mut pin = Pin::new();
    let qs = configs(16);
    let mut out = [0.0; 54];
    match args[1].as_str() {
        "check" => {
            let mut worst_pin = 0.0f64;
            let mut worst_old = 0.0f64;
            for q in configs(1000) {
                let mut a = [0.0; 54];
                let mut b = [0.0; 54];
                let mut p = [0.0; 54];
                let mut pf = [0.0; 54];
                eval_new(&c, &q, &mut a);
                eval_old(&c, &q, &mut b);
                pin.eval(false, &q);
                pin.read(false, &mut p);
                pin.eval(true, &q);
                pin.read(true, &mut pf);
                let mut fk = [0.0; 54];
                eval_new_fk(&c, &q, &mut fk);
                for i in 0..54 {
                    worst_pin = worst_pin.max((a[i] - p[i]).abs()).max((a[i] - pf[i]).abs());
                    worst_old = worst_old.max((a[i] - b[i]).abs());
                }
                // FK of the whole chain (to the laparoscope tip) vs old transform composition.
                let qv = SVector::<f64, 7>::from(q);
                let mut g = Se3::identity();
                for (j, &t) in c.joints.iter().zip(q.iter()) {
                    g = g.compose(&old::transform(j, t));
                }
                let g = g.compose(&c.tool);
                let g2 = c.forward_kinematics(&qv);
                worst_old = worst_old
                    .max((g.rotation - g2.rotation).amax())
                    .max((g.translation - g2.translation).amax());
            }
            println!("max |new - pinocchio| = {worst_pin:.3e}; max |new - old| = {worst_old:.3e} (1000 configurations)");
            assert!(worst_pin <= 1e-12 && worst_old <= 1e-13);
        }
        "time" => {
            let rounds: usize = args[2].parse().unwrap();
            let block: usize = args[3].parse().unwrap();
            let impls: Vec<&str> = if args.len() > 4 {
                args[4..].iter().map(|s| s.as_str()).collect()
            } else {
                IMPLS.to_vec()
            };
            let mut best = vec![f64::INFINITY; impls.len()];
            let mut all: Vec<Vec<f64>> = vec![vec![]; impls.len()];
            for name in &impls {
                run(name, &c, &mut pin, &qs, block, &mut out);
            }
            for _ in 0..rounds {
                for (i, name) in impls.iter().enumerate() {
                    let t0 = Instant::now();
                    run(name, &c, &mut pin, &qs, block, &mut out);
                    let ns = t0.elapsed().as_nanos() as f64 / block as f64;
                    best[i] = best[i].min(ns);
                    all[i].push(ns);
                }
            }
            for (i, name) in impls.iter().enumerate() {
                let mut v = all[i].clone();
                v.sort_by(f64::total_cmp);
                println!(
                    "{name:8} min {:7.1} ns  median {:7.1} ns",
                    best[i],
                    v[v.len() / 2]
                );
            }
            let ip = impls.iter().position(|&s| s == "pin");
            if let Some(ip) = ip {
                for (i, name) in impls.iter().enumerate() {
                    println!("{name:8} / pin (min) = {:.3}", best[i] / best[ip]);
                }
            }
        }
        "cg" => {
            let n: usize = args[3].parse().unwrap();
            run(&args[2], &c, &mut pin, &qs, n, &mut out);
        }
        _ => panic!("usage"),
    }
}
