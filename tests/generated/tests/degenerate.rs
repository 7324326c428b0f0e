//! The generated code at degenerate inputs, f64 and f32: where `l_a` (which the reference arm's
//! closed forms divide by) is 0, −0 or subnormal, or a joint is NaN, the manipulability is 0 —
//! never `+∞`, which a controller that damps when `w` is small would read as far from singular —
//! and the matrices that divide by `l_a` are not finite (documented on each function).

use trocar_tests_generated::bidirectional_zy_f32 as zy32;
use trocar_tests_generated::dia10_like_zy as dia10;

const Q: [f64; 8] = [0.1, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];

#[test]
fn manipulability_is_zero_where_the_closed_form_is_not_finite_f64() {
    for l_a in [0.0, -0.0, 1e-320, f64::NAN] {
        let mut p = dia10::Params::<f64>::nominal();
        p.l_a = l_a;
        let t = dia10::JointTrig::new(&Q);
        for w in [
            dia10::manipulability(&Q, &p),
            dia10::manipulability_trig(&t, &p),
            dia10::manipulability_squared(&Q, &p),
            dia10::manipulability_squared_trig(&t, &p),
        ] {
            assert_eq!(w, 0.0, "l_a = {l_a:e}");
        }
        let jr = dia10::constrained_jacobian(&Q, &p);
        assert!(jr.iter().flatten().any(|v| !v.is_finite()), "l_a = {l_a:e}");
    }
    let p = dia10::Params::<f64>::nominal();
    let mut q = Q;
    q[6] = f64::NAN;
    assert_eq!(dia10::manipulability(&q, &p), 0.0);
    // Away from the degenerate values the guard changes nothing: w > 0 and finite.
    let w = dia10::manipulability(&Q, &p);
    assert!(w.is_finite() && w > 0.0, "{w}");
}

#[test]
fn manipulability_is_zero_where_the_closed_form_is_not_finite_f32() {
    let q: [f32; 8] = Q.map(|v| v as f32);
    for l_a in [0.0f32, -0.0, 1e-45, f32::NAN] {
        let mut p = zy32::Params::nominal();
        p.l_a = l_a;
        assert_eq!(zy32::manipulability(&q, &p), 0.0, "l_a = {l_a:e}");
        assert_eq!(zy32::manipulability_squared(&q, &p), 0.0, "l_a = {l_a:e}");
    }
    let w = zy32::manipulability(&q, &zy32::Params::nominal());
    assert!(w.is_finite() && w > 0.0, "{w}");
}
