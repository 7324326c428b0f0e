//! The C ABI of an `f32` module and of a generic one (whose C functions are `f64`): each writes
//! its Rust function's values in the documented layout (column-major).

use trocar_tests_generated::{dia10_capi as g, dia10_fma, panda_capi_f32 as p, panda_fma};

#[test]
fn f32_functions_write_the_rust_values() {
    let q: [f32; 7] = [0.3, -0.5, 0.2, -2.1, 0.4, 1.9, 0.6];
    let params = [0.21_f32];
    let mut out = [0.0_f32; 42];
    // SAFETY: q holds N = 7 values, params PARAMS = 1, out room for J^B_0i's 42.
    let status = unsafe {
        p::panda_capi_f32_partial_body_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    let want = p::partial_body_jacobian(&q, &p::Params { l_a: 0.21 });
    assert_eq!(&out[..], want.as_flattened());
}

#[test]
fn generic_module_functions_are_f64() {
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let params = [0.15];
    let mut out = [0.0; 36];
    // SAFETY: q holds N = 8 values, params PARAMS = 1, out room for J^r's 36.
    let status = unsafe {
        g::dia10_capi_constrained_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    let want = g::constrained_jacobian::<f64>(&q, &g::Params { l_a: 0.15 });
    assert_eq!(&out[..], want.as_flattened());
    // The manipulability is a scalar: one value.
    let mut w = [f64::NAN; 1];
    // SAFETY: as above, room for one value.
    let status =
        unsafe { g::dia10_capi_manipulability(q.as_ptr(), params.as_ptr(), w.as_mut_ptr()) };
    assert_eq!(status, 0);
    assert_eq!(w[0], g::manipulability::<f64>(&q, &g::Params { l_a: 0.15 }));
    // A parameter-only function ignores q (null allowed).
    let mut lambda = [0.0; 24];
    // SAFETY: params holds one value, lambda room for Λ#'s 6 × 4 (two constrained directions).
    let status = unsafe {
        g::dia10_capi_lambda_null_space(std::ptr::null(), params.as_ptr(), lambda.as_mut_ptr())
    };
    assert_eq!(status, 0);
    assert_eq!(
        &lambda[..],
        g::lambda_null_space::<f64>(&g::Params { l_a: 0.15 }).as_flattened()
    );
}

/// A fused function's C ABI writes its outputs one after the other, each in its layout: a
/// generic module's `pose_and_jacobian` and `link_pose_and_jacobian` (`f64`) and an `f32`
/// module's, bit for bit the Rust functions' values; null pointers are refused.
#[test]
fn fused_functions_write_their_outputs_one_after_the_other() {
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let params = [0.15];
    let pp = g::Params { l_a: 0.15 };
    let mut out = [f64::NAN; 12 + 6 * 8];
    // SAFETY: q holds N = 8 values, params PARAMS = 1, out room for g_0e (12) and J^B_0e (48).
    let status =
        unsafe { g::dia10_capi_pose_and_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr()) };
    assert_eq!(status, 0);
    let (mut fk, mut jb) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; 8]);
    g::pose_and_jacobian(&q, &pp, &mut fk, &mut jb);
    assert_eq!(&out[..9], fk.0.as_flattened());
    assert_eq!(&out[9..12], &fk.1);
    assert_eq!(&out[12..], jb.as_flattened());
    // The separate functions agree to rounding (another program for the same values).
    let (r, t) = g::forward_kinematics::<f64>(&q, &pp);
    for (a, b) in out[..9]
        .iter()
        .zip(r.as_flattened())
        .chain(out[9..12].iter().zip(&t))
    {
        assert!((a - b).abs() < 1e-14, "{a} vs {b}");
    }
    // SAFETY: a null `out`, `q` or `params` (this module has a parameter) is refused before
    // anything is read or written.
    unsafe {
        let status =
            g::dia10_capi_link_pose_and_jacobian(q.as_ptr(), params.as_ptr(), std::ptr::null_mut());
        assert_eq!(status, g::C_NULL_ARGUMENT);
        let status = g::dia10_capi_link_pose_and_jacobian(
            std::ptr::null(),
            params.as_ptr(),
            out.as_mut_ptr(),
        );
        assert_eq!(status, g::C_NULL_ARGUMENT);
        let status =
            g::dia10_capi_link_pose_and_jacobian(q.as_ptr(), std::ptr::null(), out.as_mut_ptr());
        assert_eq!(status, g::C_NULL_ARGUMENT);
    }
    // A value that is not finite is reported (the values are written all the same).
    let q_nan = [f64::NAN, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    // SAFETY: as above.
    let status = unsafe {
        g::dia10_capi_pose_and_jacobian(q_nan.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, g::C_NOT_FINITE);

    let q32: [f32; 7] = [0.3, -0.5, 0.2, -2.1, 0.4, 1.9, 0.6];
    let mut out32 = [f32::NAN; 12 + 42];
    // SAFETY: q32 holds N = 7 values, params one, out32 room for g_0i (12) and J^B_0i (42).
    let status = unsafe {
        p::panda_capi_f32_link_pose_and_jacobian(
            q32.as_ptr(),
            [0.21_f32].as_ptr(),
            out32.as_mut_ptr(),
        )
    };
    assert_eq!(status, 0);
    let (mut fk, mut jb) = (([[0.0f32; 3]; 3], [0.0f32; 3]), [[0.0f32; 6]; 7]);
    p::link_pose_and_jacobian(&q32, &p::Params { l_a: 0.21 }, &mut fk, &mut jb);
    assert_eq!(&out32[..9], fk.0.as_flattened());
    assert_eq!(&out32[9..12], &fk.1);
    assert_eq!(&out32[12..], jb.as_flattened());
}

/// In a module generated with `fma_at_run_time` the fused functions' C ABI calls the `_f64`
/// entry points (FMA chosen at run time): bit for bit theirs, a scalar output included.
#[test]
fn fused_functions_of_an_fma_module_call_the_f64_entry_points() {
    let q = [0.3, -0.5, 0.2, -2.1, 0.4, 1.9, 0.6];
    let params = [0.21];
    let mut out = [f64::NAN; 12 + 42];
    // SAFETY: q holds N = 7 values, params PARAMS = 1, out room for g_0i and J^B_0i.
    let status = unsafe {
        panda_fma::panda_fma_link_pose_and_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    let (mut fk, mut jb) = (([[0.0; 3]; 3], [0.0; 3]), [[0.0; 6]; 7]);
    panda_fma::link_pose_and_jacobian_f64(&q, &panda_fma::Params { l_a: 0.21 }, &mut fk, &mut jb);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&out[..9]), bits(fk.0.as_flattened()));
    assert_eq!(bits(&out[9..12]), bits(&fk.1));
    assert_eq!(bits(&out[12..]), bits(jb.as_flattened()));

    // dia10_like's step_outputs: J^r (36), w (1), g_0e (12), J^B_0i (36), J_c (12).
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let mut out = [f64::NAN; 36 + 1 + 12 + 36 + 12];
    // SAFETY: q holds N = 8 values, params PARAMS = 1, out room for the five outputs.
    let status =
        unsafe { dia10_fma::dia10_fma_step_outputs(q.as_ptr(), [0.15].as_ptr(), out.as_mut_ptr()) };
    assert_eq!(status, 0);
    let (mut jr, mut w, mut g0e, mut jbi, mut jc) = (
        [[0.0; 6]; 6],
        0.0,
        ([[0.0; 3]; 3], [0.0; 3]),
        [[0.0; 6]; 6],
        [[0.0; 6]; 2],
    );
    dia10_fma::step_outputs_f64(
        &q,
        &dia10_fma::Params { l_a: 0.15 },
        &mut jr,
        &mut w,
        &mut g0e,
        &mut jbi,
        &mut jc,
    );
    let mut want = jr.as_flattened().to_vec();
    want.push(w);
    want.extend(g0e.0.as_flattened());
    want.extend(g0e.1);
    want.extend(jbi.as_flattened());
    want.extend(jc.as_flattened());
    assert_eq!(bits(&out), bits(&want));
}

/// docs/RELIABILITY.md F28: fused functions named `q`, `p`, `out`, `o0`, `o1`, `params` (the C
/// wrappers' parameters and locals) and `fk`, `fk_fused`, `manip` (the `fma_at_run_time` entry
/// points' parameters and locals) compile (this crate builds the module `shadowing`) and their
/// C functions and `_f64` entry points write the values of the functions they wrap.
#[test]
fn fused_functions_named_like_the_wrappers_locals_work() {
    use trocar_tests_generated::shadowing as s;
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let pp = s::Params::nominal();
    let params = [pp.l_a, pp.l_b, pp.l_8];
    let (r, t) = s::forward_kinematics::<f64>(&q, &pp);
    let w = s::manipulability::<f64>(&q, &pp);
    type CFn = unsafe extern "C" fn(*const f64, *const f64, *mut f64) -> i32;
    let c: [(&str, CFn); 9] = [
        ("q", s::shadowing_q),
        ("p", s::shadowing_p),
        ("out", s::shadowing_out),
        ("o0", s::shadowing_o0),
        ("o1", s::shadowing_o1),
        ("params", s::shadowing_params),
        ("fk", s::shadowing_fk),
        ("fk_fused", s::shadowing_fk_fused),
        ("manip", s::shadowing_manip),
    ];
    for (name, f) in c {
        let mut out = [f64::NAN; 13];
        // SAFETY: q holds N = 8 values, params PARAMS = 3, out room for g_0e (12) and w (1).
        let status = unsafe { f(q.as_ptr(), params.as_ptr(), out.as_mut_ptr()) };
        assert_eq!(status, 0, "{name}");
        for (a, b) in out[..9]
            .iter()
            .zip(r.as_flattened())
            .chain(out[9..12].iter().zip(&t))
            .chain([(&out[12], &w)])
        {
            assert!((a - b).abs() < 1e-12, "{name}: {a} vs {b}");
        }
    }
    let (mut fk, mut m) = (([[0.0; 3]; 3], [0.0; 3]), 0.0);
    s::fk_fused_f64(&q, &pp, &mut fk, &mut m);
    assert!((m - w).abs() < 1e-12 && (fk.1[0] - t[0]).abs() < 1e-12);
    s::q_f64(&q, &pp, &mut fk, &mut m);
    assert!((m - w).abs() < 1e-12 && (fk.1[2] - t[2]).abs() < 1e-12);
}

/// docs/RELIABILITY.md F30: a parameter that is not finite is reported by every C function, also
/// where the result is finite: `manipulability` with `l_a` NaN returned 0 with w = 0 (its value
/// is 0 where it is not finite), while the others returned `C_NOT_FINITE`. A non-finite `q`
/// likewise; finite inputs still give 0.
#[test]
fn a_non_finite_input_is_reported_where_the_result_is_finite() {
    let q = [0.0, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let mut w = [f64::NAN; 1];
    for bad in [f64::NAN, f64::INFINITY] {
        // SAFETY: q holds N = 8 values, params PARAMS = 1, w room for one value.
        let status =
            unsafe { g::dia10_capi_manipulability(q.as_ptr(), [bad].as_ptr(), w.as_mut_ptr()) };
        assert_eq!(status, g::C_NOT_FINITE, "l_a = {bad}");
        let mut q_bad = q;
        q_bad[3] = bad;
        // SAFETY: as above.
        let status = unsafe {
            g::dia10_capi_manipulability(q_bad.as_ptr(), [0.15].as_ptr(), w.as_mut_ptr())
        };
        assert_eq!(status, g::C_NOT_FINITE, "q[3] = {bad}");
        // A fused function with a scalar output (dia10_fma's step_outputs holds w).
        let mut out = [0.0; 36 + 1 + 12 + 36 + 12];
        // SAFETY: q holds N = 8 values, params one, out room for the five outputs.
        let status = unsafe {
            dia10_fma::dia10_fma_step_outputs(q.as_ptr(), [bad].as_ptr(), out.as_mut_ptr())
        };
        assert_eq!(status, dia10_fma::C_NOT_FINITE, "l_a = {bad}");
        // A function of the parameters alone.
        let mut lambda = [0.0; 24];
        // SAFETY: params holds one value, lambda room for 6 × 4.
        let status = unsafe {
            g::dia10_capi_lambda_null_space(std::ptr::null(), [bad].as_ptr(), lambda.as_mut_ptr())
        };
        assert_eq!(status, g::C_NOT_FINITE, "l_a = {bad}");
    }
    // SAFETY: as above.
    let status =
        unsafe { g::dia10_capi_manipulability(q.as_ptr(), [0.15].as_ptr(), w.as_mut_ptr()) };
    assert_eq!(status, 0);
    assert!(w[0] > 0.0);
    // The f32 module as well.
    let q32: [f32; 7] = [0.3, -0.5, 0.2, -2.1, 0.4, 1.9, 0.6];
    let mut w32 = [f32::NAN; 1];
    // SAFETY: q32 holds N = 7 values, params one, w32 room for one value.
    let status = unsafe {
        p::panda_capi_f32_manipulability(q32.as_ptr(), [f32::NAN].as_ptr(), w32.as_mut_ptr())
    };
    assert_eq!(status, p::C_NOT_FINITE);
}

/// docs/RELIABILITY.md F27 in an `f32` module: a sample time that is not a number and a value beyond
/// the number rule are refused with `qd` set to zeros, and a trocar 0.2 m off the shaft keeps
/// the speed limit and says the trocar yielded.
#[test]
fn f32_controller_step_refuses_and_keeps_the_speed_limit() {
    let q: [f32; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];
    let pp = p::Params { l_a: 0.25 };
    let (ri, ti) = p::forward_kinematics_i(&q, &pp);
    let (_, tir) = p::constraint_frame(&pp);
    let (re, te) = p::forward_kinematics(&q, &pp);
    let mut trocar = [0.0_f32; 3];
    for r in 0..3 {
        trocar[r] = ti[r] + (0..3).map(|c| ri[c][r] * tir[c]).sum::<f32>();
    }
    let mut target = [0.0_f32; 18];
    target[..3].copy_from_slice(&te);
    target[3..12].copy_from_slice(re.as_flattened());
    let gains: [f32; 8] = [5.0, 10.0, 20.0, 0.05, 1e-3, 0.01, 2.0, 10.0];
    let step = |trocar: [f32; 3], dt: f32, gains: [f32; 8]| {
        let mut qd = [f32::NAN; 7];
        let mut report = [f32::NAN; 8];
        // SAFETY: q holds N = 7 values, params PARAMS = 1, target 18, trocar 3, gains 8, qd
        // room for 7 and report for 8.
        let status = unsafe {
            p::panda_capi_f32_controller_step(
                q.as_ptr(),
                [0.25_f32].as_ptr(),
                target.as_ptr(),
                trocar.as_ptr(),
                dt,
                gains.as_ptr(),
                qd.as_mut_ptr(),
                report.as_mut_ptr(),
            )
        };
        (status, qd, report)
    };
    let (status, qd, report) = step(trocar, 0.002, gains);
    assert_eq!(status, 0);
    assert!(qd.iter().chain(&report).all(|v| v.is_finite()));
    for (dt, kr) in [
        (f32::NAN, 20.0),
        (0.002, 2e6),
        (0.002, -20.0),
        (0.002, 1000.0),
    ] {
        let mut g = gains;
        g[2] = kr;
        let (status, qd, report) = step(trocar, dt, g);
        assert_eq!(status, p::C_INVALID_ARGUMENT, "dt {dt}, K_r {kr}");
        assert_eq!(qd, [0.0; 7]);
        assert!(report.iter().all(|v| v.is_nan()), "report not written");
    }
    let mut off = trocar;
    off[0] += 0.2;
    let (status, qd, report) = step(off, 0.002, gains);
    assert_eq!(status, p::C_TROCAR_YIELDED);
    assert!(qd.iter().all(|v| v.abs() <= 2.0), "{qd:?}");
    assert!(report.iter().all(|v| v.is_finite()));
}

/// The port's registration in an `f32` module: the recorded pivot's port within 0.1 mm of the
/// trocar the run held (computed from the forward kinematics at its first pose), and a pose
/// beyond the number rule refused with nothing written.
#[test]
fn f32_register_port_finds_the_pivot() {
    let text = include_str!("../../../examples/ports/panda-laparoscope-pivot.csv");
    let poses: Vec<f32> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('q'))
        .flat_map(|l| {
            l.split(',')
                .map(|x| x.trim().parse::<f64>().unwrap() as f32)
        })
        .collect();
    let count = poses.len() / 7;
    assert_eq!(count * 7, poses.len());
    // The pivot was recorded with the constraint frame at `l_a` = 0.25.
    let pp = p::Params { l_a: 0.25 };
    let q0: [f32; 7] = poses[..7].try_into().unwrap();
    let (ri, ti) = p::forward_kinematics_i(&q0, &pp);
    let (_, tir) = p::constraint_frame(&pp);
    let mut trocar = [0.0_f32; 3];
    for r in 0..3 {
        trocar[r] = ti[r] + (0..3).map(|c| ri[c][r] * tir[c]).sum::<f32>();
    }
    let register = |poses: &[f32]| {
        let mut out = [-7.0_f32; 14];
        // SAFETY: `poses` holds `poses.len() / 7` rows of 7 values, params 1, out room for 14.
        let code = unsafe {
            p::panda_capi_f32_register_port(
                poses.as_ptr(),
                poses.len() / 7,
                [0.25_f32].as_ptr(),
                1f32.to_radians(),
                1.0,
                out.as_mut_ptr(),
            )
        };
        (code, out)
    };
    let (code, out) = register(&poses);
    assert_eq!(code, 0);
    let off: f32 = (0..3)
        .map(|k| (out[k] - trocar[k]).powi(2))
        .sum::<f32>()
        .sqrt();
    assert!(off < 1e-4, "{off} m from the trocar");
    let mut bad = poses.clone();
    bad[30] = f32::MIN_POSITIVE / 4.0;
    let (code, out) = register(&bad);
    assert_eq!(code, p::C_INVALID_ARGUMENT);
    assert!(out.iter().all(|&v| v == -7.0));
}
