//! Properties of the numeric core: Adjoint identities, exp/log, and the body Jacobian against
//! central finite differences of forward kinematics on random chains.

use proptest::prelude::*;
use trocar::finite_diff;
use trocar::kinematics::{self, Joint};
use trocar::nalgebra::{Matrix6, Vector3};
use trocar::se3::{self, exp_so3, Adjoint, Se3, Twist};

fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn unit3() -> impl Strategy<Value = Vector3<f64>> {
    vec3(1.0)
        .prop_filter("not too short", |v| v.norm() > 0.1)
        .prop_map(|v| v.normalize())
}

fn se3() -> impl Strategy<Value = Se3<f64>> {
    (vec3(3.0), vec3(2.0)).prop_map(|(w, p)| Se3::new(exp_so3(&w), p))
}

/// A random joint: revolute (axis through a random point of its frame), prismatic, or a general
/// screw with a random pitch; origin a random rigid motion.
fn joint() -> impl Strategy<Value = Joint<f64>> {
    (se3(), 0..3u8, unit3(), vec3(1.0), -0.5..0.5f64).prop_map(
        |(origin, kind, axis, point, pitch)| {
            let xi = match kind {
                0 => se3::revolute_twist(&axis, &point),
                1 => se3::prismatic_twist(&axis),
                _ => {
                    se3::revolute_twist(&axis, &point)
                        + se3::twist(&(axis * pitch), &Vector3::zeros())
                }
            };
            Joint::from_twist(origin, xi)
        },
    )
}

fn chain_and_q() -> impl Strategy<Value = (Vec<Joint<f64>>, Se3<f64>, Vec<f64>)> {
    (1..10usize).prop_flat_map(|n| {
        (
            prop::collection::vec(joint(), n),
            se3(),
            prop::collection::vec(-3.2..3.2f64, n),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// (2.54)–(2.55) against central differences through the SE(3) log, to 1e-7.
    #[test]
    fn body_jacobian_equals_finite_differences((joints, tool, q) in chain_and_q()) {
        let n = joints.len();
        let mut jb = vec![Twist::zeros(); n];
        kinematics::body_jacobian_columns(&joints, &q, &tool, &mut jb);
        let mut fd = vec![Twist::zeros(); n];
        let mut qq = q.clone();
        finite_diff::body_jacobian_columns(&joints, &mut qq, &tool, 1e-5, &mut fd);
        prop_assert_eq!(&qq, &q);
        for k in 0..n {
            let err = (jb[k] - fd[k]).amax();
            prop_assert!(err < 1e-7, "column {} differs by {:e}: {} vs {}", k, err, jb[k], fd[k]);
        }
        // Spatial Jacobian (2.53): J^S = Ad_{g_0e} J^B.
        let mut js = vec![Twist::zeros(); n];
        kinematics::spatial_jacobian_columns(&joints, &q, &mut js);
        let g = kinematics::forward_kinematics(&joints, &q, &tool);
        for k in 0..n {
            prop_assert!((js[k] - Adjoint(g).apply(&jb[k])).amax() < 1e-10);
        }
    }

    /// Ad_g Ad_h = Ad_gh and Ad_g⁻¹ = Ad_{g⁻¹} (2.43).
    #[test]
    fn adjoint_is_a_homomorphism(g in se3(), h in se3()) {
        let (ag, ah) = (g.adjoint().matrix(), h.adjoint().matrix());
        prop_assert!((ag * ah - (g * h).adjoint().matrix()).amax() < 1e-12);
        prop_assert!((g.adjoint().inverse_matrix() - g.inverse().adjoint().matrix()).amax() < 1e-12);
        prop_assert!((ag * g.adjoint().inverse_matrix() - Matrix6::identity()).amax() < 1e-12);
    }

    /// exp of a revolute twist (2.27) keeps the points of its axis fixed (and rotates by θ).
    #[test]
    fn revolute_exp_fixes_its_axis(w in unit3(), q in vec3(2.0), t in -3.0..3.0f64, th in -6.0..6.0f64) {
        let g = se3::exp_twist(&se3::revolute_twist(&w, &q), th);
        let x = q + w * t;
        prop_assert!((g.transform_point(&x) - x).norm() < 1e-12);
        // A point off the axis keeps its distance to the axis.
        let off = q + w.cross(&Vector3::new(0.3, -0.2, 0.5)).normalize() * 0.7;
        let y = g.transform_point(&off);
        let dist = |p: Vector3<f64>| ((p - q) - w * w.dot(&(p - q))).norm();
        prop_assert!((dist(y) - 0.7).abs() < 1e-12);
    }

    /// log ∘ exp is the identity for rotation angles below π; exp ∘ log always.
    #[test]
    fn log_exp_round_trip(v in vec3(3.0), w in vec3(1.8)) {
        let xi = se3::twist(&v, &w);
        let g = se3::exp_twist(&xi, 1.0);
        prop_assert!((se3::log(&g) - xi).amax() < 1e-10);
        let back = se3::exp_twist(&se3::log(&g), 1.0);
        prop_assert!((back.to_homogeneous() - g.to_homogeneous()).amax() < 1e-12);
    }
}

#[test]
fn exp_log_near_pi() {
    let w = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    for a in [
        std::f64::consts::PI,
        std::f64::consts::PI - 1e-6,
        1e-10,
        0.0,
    ] {
        let g = se3::exp_twist(&se3::twist(&Vector3::new(0.3, 0.1, -0.4), &w), a);
        let back = se3::exp_twist(&se3::log(&g), 1.0);
        assert!(
            (back.to_homogeneous() - g.to_homogeneous()).amax() < 1e-9,
            "angle {a}"
        );
    }
}
