//! The C ABI of an `f32` module and of a generic one (whose C functions are `f64`): each writes
//! its Rust function's values in the documented layout (column-major).

use trocar_tests_generated::{dia10_capi as g, panda_capi_f32 as p};

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
