//! Every preset, generic and monomorphic, as associated functions of unit structs.
use trocar_derive::constrained_robot;

#[constrained_robot(preset = "bidirectional-zy")]
pub struct Zy;

#[constrained_robot(preset = "bidirectional-zx", real = "f32")]
struct Zx;

#[constrained_robot(preset = "unidirectional", real = "f64", module = "uni_kin")]
struct Uni;

// Named like an item of its module (`kinematics::Kinematics`) that no delegated signature uses.
#[constrained_robot(preset = "unidirectional", real = "f64")]
struct Kinematics;

// A fused function: J^r, w and g_0e from one program, through out-parameters.
#[constrained_robot(
    preset = "bidirectional-zy",
    real = "f64",
    module = "zy_fused",
    function(step(jr, manipulability, fk))
)]
struct ZyFused;

// The fused function's `f64` entry points with FMA chosen at run time.
#[constrained_robot(
    preset = "bidirectional-zy",
    module = "zy_fma",
    function(step(jr, manipulability, fk)),
    fma_at_run_time
)]
struct ZyFma;

#[test]
fn compiles_and_runs() {
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let p: ZyParams<f64> = Zy::nominal_params();
    let jr: [[f64; 6]; 6] = Zy::constrained_jacobian(&q, &p);
    let w = Zy::manipulability(&q, &p);
    // (3.42): w = l_b² |sin θ7| / l_a².
    let expected = p.l_b * p.l_b * q[6].sin().abs() / (p.l_a * p.l_a);
    assert!((w - expected).abs() < 1e-12, "{w} vs {expected}");
    assert_eq!(jr.len(), Zy::M);
    assert_eq!(zy::N, 8);

    let (mut jr_s, mut w_s, mut g) = ([[0.0; 6]; 6], 0.0, ([[0.0; 3]; 3], [0.0; 3]));
    ZyFused::step(
        &q,
        &zy_fused::Params::nominal(),
        &mut jr_s,
        &mut w_s,
        &mut g,
    );
    assert!((w_s - expected).abs() < 1e-12, "{w_s} vs {expected}");
    let (mut jr_f, mut w_f, mut g_f) = ([[0.0; 6]; 6], 0.0, ([[0.0; 3]; 3], [0.0; 3]));
    ZyFma::step_f64(
        &q,
        &zy_fma::Params::nominal(),
        &mut jr_f,
        &mut w_f,
        &mut g_f,
    );
    assert!((w_f - w_s).abs() < 1e-12, "{w_f} vs {w_s}");
    assert!((g_f.1[2] - g.1[2]).abs() < 1e-12);
    // R_0e is a rotation: orthonormal columns.
    for a in 0..3 {
        for b in 0..3 {
            let dot: f64 = (0..3).map(|k| g.0[a][k] * g.0[b][k]).sum();
            assert!((dot - f64::from(u8::from(a == b))).abs() < 1e-12);
        }
    }

    let qf = q.map(|x| x as f32);
    let pf: ZxParams = Zx::nominal_params();
    let t: ZxJointTrig = ZxJointTrig::new(&qf);
    let jt: [[f32; 6]; 6] = Zx::constrained_jacobian_trig(&t, &pf);
    let jf: [[f32; 6]; 6] = Zx::constrained_jacobian(&qf, &pf);
    assert!(jf.iter().flatten().all(|x| x.is_finite()));
    assert_eq!(jf, jt);

    let pu = uni_kin::Params::nominal();
    let ju: [[f64; 6]; 7] = Uni::constrained_jacobian(&q, &pu);
    assert!(Uni::manipulability(&q, &pu) > 0.0);
    assert_eq!(ju.len(), 7);

    let jk: [[f64; 6]; 7] = Kinematics::constrained_jacobian(&q, &Kinematics::nominal_params());
    assert_eq!(jk, ju);
    let _glue: kinematics::Kinematics = kinematics::Kinematics::nominal();
}
