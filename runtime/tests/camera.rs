//! The endoscope's camera task (`trocar::control::scene::Camera`) against its definition: the
//! reference's tip lies on the line from the port through the point, at the camera's depth; its
//! shaft axis (the tip frame's z, the start's view axis) turns onto that line; and its velocity
//! and angular velocity are the derivatives of the reference along a moving point (central
//! differences, the roll about the view axis included); a point all but on the start's axis
//! still gives a proper rotation.

use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use trocar::control::scene::Camera;
use trocar::se3::{rotation_from_rpy, vee, Se3};

/// A point moving on a smooth curve about `centre`, and its velocity.
fn point(centre: &Vector3<f64>, w: &Vector3<f64>, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let p = centre + Vector3::new((w.x * t).sin(), (w.y * t).cos(), 0.5 * (w.z * t).sin()) * 0.03;
    let v = Vector3::new(
        w.x * (w.x * t).cos(),
        -w.y * (w.y * t).sin(),
        0.5 * w.z * (w.z * t).cos(),
    ) * 0.03;
    (p, v)
}

proptest! {
    #[test]
    fn the_camera_reference_is_on_the_view_axis_and_its_rates_are_its_derivatives(
        roll in -3.0f64..3.0, pitch in -1.0f64..1.0, yaw in -3.0f64..3.0,
        depth in 0.03f64..0.2, wx in 0.5f64..3.0, wy in 0.5f64..3.0, wz in 0.5f64..3.0,
        t in 0.0f64..5.0,
    ) {
        let port = Vector3::new(0.4, -0.1, 0.3);
        // The tip's start orientation; its z axis is the shaft, so the start's view axis.
        let r0: Matrix3<f64> = rotation_from_rpy(roll, pitch, yaw);
        let axis0: Vector3<f64> = r0.column(2).into_owned();
        let start = Se3::new(r0, port + axis0 * 0.15);
        let mut camera = Camera::at_start(port, &start).unwrap();
        prop_assert!((camera.depth - 0.15).abs() < 1e-15);
        camera.depth = depth;
        // The point ahead of the port along the start's axis, moving about there.
        let centre = port + axis0 * 0.2;
        let w = Vector3::new(wx, wy, wz);
        let (p, v) = point(&centre, &w, t);
        let r = camera.reference(&p, &v).unwrap();
        // On the line from the port through the point, at the depth.
        let u = (p - port).normalize();
        prop_assert!((r.position - (port + u * depth)).norm() < 1e-14);
        prop_assert!(camera.view_error(&r.position, &p) < 1e-7);
        // The shaft turned onto that line, the rotation orthonormal.
        let z: Vector3<f64> = r.rotation.column(2).into_owned();
        prop_assert!((z - u).norm() < 1e-12, "z {z} u {u}");
        prop_assert!((r.rotation.transpose() * r.rotation - Matrix3::identity()).norm() < 1e-12);
        // Derivatives along the point's motion.
        let h = 1e-6;
        let at = |t: f64| {
            let (p, v) = point(&centre, &w, t);
            camera.reference(&p, &v).unwrap()
        };
        let (plus, minus) = (at(t + h), at(t - h));
        let velocity = (plus.position - minus.position) / (2.0 * h);
        prop_assert!((velocity - r.velocity).norm() < 1e-7 * (1.0 + velocity.norm()),
            "velocity {velocity} vs {}", r.velocity);
        let r_dot = (plus.rotation - minus.rotation) / (2.0 * h);
        let omega = vee(&(r_dot * r.rotation.transpose()));
        prop_assert!((omega - r.angular_velocity).norm() < 1e-6 * (1.0 + omega.norm()),
            "angular velocity {omega} vs {}", r.angular_velocity);
    }
}

/// Points within rounding of the start's view axis (where an arc cosine of `u₀ · u` would see a
/// cosine above 1) give the start's orientation, finite.
#[test]
fn a_point_on_the_start_axis_gives_the_start() {
    let port = Vector3::new(0.1, 0.2, 0.3);
    let r0: Matrix3<f64> = rotation_from_rpy(0.3, -0.4, 1.1);
    let axis0: Vector3<f64> = r0.column(2).into_owned();
    let camera = Camera::at_start(port, &Se3::new(r0, port + axis0 * 0.1)).unwrap();
    for k in 0..1000 {
        let e = Vector3::new((k as f64).sin(), (k as f64 * 1.3).cos(), 0.2) * 1e-9;
        let r = camera
            .reference(&(port + axis0 * 0.2 + e), &Vector3::zeros())
            .unwrap();
        assert!(r.rotation.iter().all(|x| x.is_finite()));
        assert!((r.rotation - r0).norm() < 1e-7, "{k}");
    }
}

#[test]
fn the_camera_refuses_a_point_at_its_port_or_behind_it() {
    let port = Vector3::new(0.0, 0.0, 0.1);
    let start = Se3::new(Matrix3::identity(), port + Vector3::new(0.0, 0.0, 0.1));
    let camera = Camera::at_start(port, &start).unwrap();
    assert!(camera.reference(&port, &Vector3::zeros()).is_none());
    // Straight behind the start's axis: no least rotation.
    let behind = port - Vector3::new(0.0, 0.0, 0.2);
    assert!(camera.reference(&behind, &Vector3::zeros()).is_none());
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    assert!(camera.reference(&nan, &Vector3::zeros()).is_none());
    // No view axis: the tip at the port.
    assert!(Camera::at_start(port, &Se3::from_translation(port)).is_none());
}
