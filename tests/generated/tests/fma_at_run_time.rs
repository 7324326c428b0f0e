//! The `f64` entry points of modules generated with `fma_at_run_time` (`trocar::emitted::fma`).
//!
//! On a CPU with AVX2 and FMA, in a build whose target lacks FMA, `name_f64` runs `name` on
//! `FusedF64` compiled for those: its results must be bit for bit `name::<FusedF64>` evaluated
//! here, outside any FMA function, where every `mul_add` is `std`'s correctly rounded software
//! `mul_add` (one rounding has one result, so any `mul_add` left unfused, any other operation
//! contracted, or any output written to the wrong place shows). Elsewhere `name_f64` must be
//! `name::<f64>` bit for bit. Either way the results must agree, to rounding, with the module
//! generated without the option (`panda_laparoscope`, `dia10_like_zy`), which `agree.rs` checks
//! against an independent computation and finite differences.

use trocar::emitted::fma::{self, FusedF64};
use trocar_tests_generated::{dia10_fma, dia10_like_zy, panda_fma, panda_laparoscope};

/// A deterministic spread of configurations (xorshift), inside ±π and beyond it.
fn configs<const N: usize>(count: usize) -> Vec<[f64; N]> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|k| {
            let scale = if k % 10 == 9 { 12.0 } else { 3.2 };
            core::array::from_fn(|_| (2.0 * next() - 1.0) * scale)
        })
        .collect()
}

fn bits<const R: usize, const C: usize>(m: &[[f64; R]; C]) -> Vec<u64> {
    m.iter().flatten().map(|v| v.to_bits()).collect()
}

fn fused_bits<const R: usize, const C: usize>(m: &[[FusedF64; R]; C]) -> Vec<u64> {
    m.iter().flatten().map(|v| v.0.to_bits()).collect()
}

fn pose_bits(g: &([[f64; 3]; 3], [f64; 3])) -> Vec<u64> {
    let mut b = bits(&g.0);
    b.extend(g.1.iter().map(|v| v.to_bits()));
    b
}

fn fused_pose_bits(g: &([[FusedF64; 3]; 3], [FusedF64; 3])) -> Vec<u64> {
    let mut b = fused_bits(&g.0);
    b.extend(g.1.iter().map(|v| v.0.to_bits()));
    b
}

/// Largest difference relative to the largest entry of `b` (1 when `b` is all zeros).
fn rel(a: &[u64], b: &[u64]) -> f64 {
    let (a, b): (Vec<f64>, Vec<f64>) = (
        a.iter().map(|&x| f64::from_bits(x)).collect(),
        b.iter().map(|&x| f64::from_bits(x)).collect(),
    );
    let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max)
}

/// A pose `(R, p)`.
type Pose<T> = ([[T; 3]; 3], [T; 3]);

/// The bits of an `f64` pose and `6 × C` matrix filled by `f`.
fn run<const C: usize>(f: impl Fn(&mut Pose<f64>, &mut [[f64; 6]; C])) -> Vec<u64> {
    let (mut g, mut jb) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; C]);
    f(&mut g, &mut jb);
    let mut b = pose_bits(&g);
    b.extend(bits(&jb));
    b
}

/// One of the Panda's fused functions of a pose and a `6 × C` Jacobian (`what`) at `q`: the
/// entry point from `q` (`entry`) and from `JointTrig` (`entry_trig`) give the same bits (where
/// `fma::path()` is `Avx512`, `entry_trig` runs the function compiled for AVX-512 and `entry`
/// the AVX2 + FMA one, so this compares the two); they
/// are the fused program (`fused`, `name::<FusedF64>` outside any FMA function) where FMA is
/// available and `plain` (`name::<f64>` of the module generated without the option) elsewhere,
/// and `plain` to rounding always. Returns whether the entry point's bits differ from `plain`'s.
fn check_pose_and_jacobian<const C: usize>(
    what: &str,
    q: &[f64],
    entry: impl Fn(&mut Pose<f64>, &mut [[f64; 6]; C]),
    entry_trig: impl Fn(&mut Pose<f64>, &mut [[f64; 6]; C]),
    fused: impl Fn(&mut Pose<FusedF64>, &mut [[FusedF64; 6]; C]),
    plain: impl Fn(&mut Pose<f64>, &mut [[f64; 6]; C]),
) -> bool {
    let got = run(entry);
    assert_eq!(
        got,
        run(entry_trig),
        "{what} from q and given JointTrig at {q:?}"
    );
    let (mut gf, mut jbf) = (
        ([[FusedF64(0.0); 3]; 3], [FusedF64(0.0); 3]),
        [[FusedF64(0.0); 6]; C],
    );
    fused(&mut gf, &mut jbf);
    let mut fused = fused_pose_bits(&gf);
    fused.extend(fused_bits(&jbf));
    let plain = run(plain);
    if fma::available() {
        assert_eq!(got, fused, "{what}: the fused program at {q:?}");
    } else {
        assert_eq!(got, plain, "{what}: name::<f64> at {q:?}");
    }
    assert!(
        rel(&got, &plain) < 1e-13,
        "{what}: {} at {q:?}",
        rel(&got, &plain)
    );
    got != plain
}

/// The Panda's `link_pose_and_jacobian` (g_0i, J^B_0i) and `pose_and_jacobian` (g_0e, J^B_0e),
/// from `q` and given `JointTrig`.
#[test]
fn panda_entry_points_are_the_fused_program() {
    use panda_fma as m;
    let p = m::Params::<f64>::nominal();
    let pf = m::Params::<FusedF64> {
        l_a: FusedF64(p.l_a),
    };
    let p0 = panda_laparoscope::Params::<f64>::nominal();
    let mut differ = 0usize;
    for q in configs::<{ m::N }>(300) {
        let t = m::JointTrig::new(&q);
        let qf = q.map(FusedF64);
        differ += usize::from(check_pose_and_jacobian::<{ m::I }>(
            "link_pose_and_jacobian",
            &q,
            |g, jb| m::link_pose_and_jacobian_f64(&q, &p, g, jb),
            |g, jb| m::link_pose_and_jacobian_trig_f64(&t, &p, g, jb),
            |g, jb| m::link_pose_and_jacobian(&qf, &pf, g, jb),
            // `panda_fma`'s own program in `f64` (a module generated with `fma_at_run_time`
            // keeps the program where `panda_laparoscope` walks with rows as pairs).
            |g, jb| m::link_pose_and_jacobian(&q, &p, g, jb),
        ));
        // The flange.
        differ += usize::from(check_pose_and_jacobian::<{ m::N }>(
            "pose_and_jacobian",
            &q,
            |g, jb| m::pose_and_jacobian_f64(&q, &p, g, jb),
            |g, jb| m::pose_and_jacobian_trig_f64(&t, &p, g, jb),
            |g, jb| m::pose_and_jacobian_trig(&m::JointTrig::new(&qf), &pf, g, jb),
            |g, jb| panda_laparoscope::pose_and_jacobian(&q, &p0, g, jb),
        ));
    }
    // With FMA taken, rounding once must change some last bits over 300 configurations;
    // without it nothing may change.
    if fma::available() {
        assert!(
            differ > 0,
            "no result differs from name::<f64>: the fused program did not run"
        );
    } else {
        assert_eq!(differ, 0);
    }
}

/// dia10_like's `step_outputs` (J^r, manipulability, g_0e, J^B_0i, J_c): a scalar output, a
/// pose and three matrices, from `q` and given `JointTrig`.
#[test]
fn dia10_step_outputs_entry_points() {
    let p = dia10_fma::Params::<f64>::nominal();
    let pf = dia10_fma::Params::<FusedF64> {
        l_a: FusedF64(p.l_a),
    };
    let p0 = dia10_like_zy::Params::<f64>::nominal();
    type Out<T> = (
        [[T; 6]; dia10_fma::M],
        T,
        ([[T; 3]; 3], [T; 3]),
        [[T; 6]; dia10_fma::I],
        [[T; 6]; dia10_fma::R],
    );
    fn zeros<T: trocar::Real>() -> Out<T> {
        (
            [[T::ZERO; 6]; dia10_fma::M],
            T::ZERO,
            ([[T::ZERO; 3]; 3], [T::ZERO; 3]),
            [[T::ZERO; 6]; dia10_fma::I],
            [[T::ZERO; 6]; dia10_fma::R],
        )
    }
    fn flat(o: &Out<f64>) -> Vec<u64> {
        let mut b = bits(&o.0);
        b.push(o.1.to_bits());
        b.extend(pose_bits(&o.2));
        b.extend(bits(&o.3));
        b.extend(bits(&o.4));
        b
    }
    let mut differ = 0usize;
    for q in configs::<{ dia10_fma::N }>(300) {
        let mut o = zeros::<f64>();
        dia10_fma::step_outputs_f64(&q, &p, &mut o.0, &mut o.1, &mut o.2, &mut o.3, &mut o.4);
        let mut ot = zeros::<f64>();
        let t = dia10_fma::JointTrig::new(&q);
        dia10_fma::step_outputs_trig_f64(
            &t, &p, &mut ot.0, &mut ot.1, &mut ot.2, &mut ot.3, &mut ot.4,
        );
        assert_eq!(flat(&o), flat(&ot), "from q and given JointTrig at {q:?}");

        let mut of = zeros::<FusedF64>();
        dia10_fma::step_outputs(
            &q.map(FusedF64),
            &pf,
            &mut of.0,
            &mut of.1,
            &mut of.2,
            &mut of.3,
            &mut of.4,
        );
        let mut fused = fused_bits(&of.0);
        fused.push(of.1 .0.to_bits());
        fused.extend(fused_pose_bits(&of.2));
        fused.extend(fused_bits(&of.3));
        fused.extend(fused_bits(&of.4));
        let mut o0 = zeros::<f64>();
        dia10_like_zy::step_outputs(
            &q, &p0, &mut o0.0, &mut o0.1, &mut o0.2, &mut o0.3, &mut o0.4,
        );
        let (got, plain) = (flat(&o), flat(&o0));
        if fma::available() {
            assert_eq!(got, fused, "the fused program at {q:?}");
        } else {
            assert_eq!(got, plain, "name::<f64> at {q:?}");
        }
        // J^r and the manipulability grow near singular configurations: each output against
        // its own scale.
        let n_jr = 6 * dia10_fma::M;
        assert!(rel(&got[..n_jr], &plain[..n_jr]) < 1e-11, "J^r at {q:?}");
        let w = (o.1 - o0.1).abs() / o0.1.abs().max(1.0);
        assert!(w < 1e-11, "manipulability {} vs {} at {q:?}", o.1, o0.1);
        assert!(
            rel(&got[n_jr + 1..], &plain[n_jr + 1..]) < 1e-13,
            "g_0e, J^B_0i, J_c at {q:?}"
        );
        differ += usize::from(got != plain);
    }
    if fma::available() {
        assert!(
            differ > 0,
            "no result differs from name::<f64>: the fused program did not run"
        );
    } else {
        assert_eq!(differ, 0);
    }
}
