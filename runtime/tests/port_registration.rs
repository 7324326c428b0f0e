//! The port located from the shaft's lines (`trocar::port`), against independent computations:
//!
//! - two skew lines: the midpoint of their common perpendicular, from the closed form of the
//!   two lines' nearest points (the 2 × 2 normal equations in the lines' parameters);
//! - lines through one point: that point;
//! - any lines, with or without forgetting: the estimate is where the weighted sum of squared
//!   distances (each distance computed as `|(x − a) × d|`) has zero gradient, by central
//!   differences, and a step away from it in any direction does not lower the sum; its residual
//!   is that sum's root mean square; taking lines one at a time is the same as taking the
//!   weighted sums at once;
//! - 20 noisy poses of an instrument pivoting up to 20° about a port (0.1 mm, 0.1° of noise) locate it
//!   within 0.5 mm, and the covariance's deviation is of the size of the error;
//! - nearly parallel lines, one line, and lines with NaN are refused with what is wrong.

use nalgebra::{Rotation3, Unit, Vector3};
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use trocar::port::{Line, PortError, PortRegistration};

fn vector() -> impl Strategy<Value = Vector3<f64>> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn direction() -> impl Strategy<Value = Vector3<f64>> {
    vector().prop_filter("a direction", |d| d.norm() > 0.2)
}

/// The weighted sum of squared distances, each `|(x − a) × d|` for a unit `d`.
fn sum_of_squares(lines: &[(Line<f64>, f64)], x: &Vector3<f64>) -> f64 {
    lines
        .iter()
        .map(|(l, w)| w * (x - l.point).cross(&l.direction).norm_squared())
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn two_skew_lines_meet_at_the_midpoint_of_their_common_perpendicular(
        a in vector(), u in direction(), b in vector(), v in direction(),
    ) {
        let (u, v) = (u.normalize(), v.normalize());
        let sine = u.cross(&v).norm();
        prop_assume!(sine > 0.05);
        // min |a + s u − b − t v|²: [1 −c; −c 1] [s; t] = [−u·r; v·r], r = a − b, c = u·v.
        let (r, c) = (a - b, u.dot(&v));
        let det = 1.0 - c * c;
        let (ur, vr) = (u.dot(&r), v.dot(&r));
        let s = (-ur + c * vr) / det;
        let t = (vr - c * ur) / det;
        let midpoint = (a + u * s + b + v * t) / 2.0;
        let mut reg = PortRegistration::new();
        reg.add(&Line::new(a, u).unwrap()).unwrap();
        reg.add(&Line::new(b, v).unwrap()).unwrap();
        let e = reg.estimate(0.0).unwrap();
        prop_assert!((e.point - midpoint).norm() <= 1e-9, "{} from {}", e.point, midpoint);
        // Both lines are half the perpendicular's length from it.
        let half = (a + u * s - b - v * t).norm() / 2.0;
        prop_assert!((e.residual - half).abs() <= 1e-9);
        prop_assert_eq!(e.lines, 2);
    }

    #[test]
    fn lines_through_one_point_meet_there(
        port in vector(),
        directions in prop::collection::vec(direction(), 2..12),
        along in prop::collection::vec(-0.5..0.5f64, 12),
    ) {
        let mut reg = PortRegistration::new();
        for (d, t) in directions.iter().zip(&along) {
            // The line's point anywhere along it.
            reg.add(&Line::new(port + d.normalize() * *t, *d).unwrap()).unwrap();
        }
        match reg.estimate(0.01) {
            Ok(e) => {
                prop_assert!((e.point - port).norm() <= 1e-9, "{} from {}", e.point, port);
                prop_assert!(e.residual <= 1e-7, "residual {:e}", e.residual);
            }
            Err(PortError::NearParallel { spread, .. }) => prop_assert!(spread < 0.01),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    #[test]
    fn the_estimate_minimises_the_weighted_squared_distances(
        points in prop::collection::vec(vector(), 3..10),
        directions in prop::collection::vec(direction(), 10),
        forgetting in prop_oneof![Just(1.0f64), 0.55..1.0f64],
    ) {
        let mut reg = PortRegistration::with_forgetting(forgetting).unwrap();
        let n = points.len();
        let mut lines = Vec::new();
        for (k, (a, d)) in points.iter().zip(&directions).enumerate() {
            let line = Line::new(*a, *d).unwrap();
            reg.add(&line).unwrap();
            lines.push((line, forgetting.powi((n - 1 - k) as i32)));
        }
        let e = match reg.estimate(0.05) {
            Ok(e) => e,
            Err(PortError::NearParallel { .. }) => return Ok(()),
            // Three lines forgotten fast weigh less than two.
            Err(PortError::TooFewLines { .. }) if forgetting < 1.0 => return Ok(()),
            Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
        };
        let f = |x: &Vector3<f64>| sum_of_squares(&lines, x);
        let h = 1e-5;
        for axis in 0..3 {
            let step = Vector3::ith(axis, h);
            let gradient = (f(&(e.point + step)) - f(&(e.point - step))) / (2.0 * h);
            prop_assert!(gradient.abs() <= 1e-6 * (1.0 + f(&e.point)), "gradient {gradient:e}");
        }
        for d in &directions {
            prop_assert!(f(&(e.point + d.normalize() * 1e-3)) >= f(&e.point) - 1e-12);
        }
        let weight: f64 = lines.iter().map(|(_, w)| w).sum();
        prop_assert!((e.residual - (f(&e.point) / weight).sqrt()).abs() <= 1e-7);
        // The same lines again, the sums built at once from the weights: the same estimate.
        let mut a = nalgebra::Matrix3::zeros();
        let mut b = Vector3::zeros();
        for (l, w) in &lines {
            let p = nalgebra::Matrix3::identity() - l.direction * l.direction.transpose();
            a += p * *w;
            b += p * l.point * *w;
        }
        let batch = a.try_inverse().unwrap() * b;
        prop_assert!((batch - e.point).norm() <= 1e-8 * (1.0 + batch.norm()));
        prop_assert_eq!(e.lines, n);
    }
}

/// `n` shaft lines of an instrument pivoting about `port`: directions within `cone` of the
/// mean direction `axis`, each line's point somewhere along the shaft, then the noise: the
/// point moved by a normal deviate of `position` in each coordinate and the direction turned by
/// a normal deviate of `angle` about a random axis.
fn pivoting(
    r: &mut StdRng,
    port: &Vector3<f64>,
    axis: &Vector3<f64>,
    cone: f64,
    n: usize,
    position: f64,
    angle: f64,
) -> Vec<Line<f64>> {
    let normal = |r: &mut StdRng| {
        // Box–Muller.
        let (u1, u2): (f64, f64) = (r.gen::<f64>().max(1e-300), r.gen());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    };
    let random_axis = |r: &mut StdRng| loop {
        let v = Vector3::new(
            r.gen_range(-1.0..1.0),
            r.gen_range(-1.0..1.0),
            r.gen_range(-1.0..1.0),
        );
        if v.norm() > 0.1 && v.norm() <= 1.0 {
            return Unit::new_normalize(v);
        }
    };
    (0..n)
        .map(|_| {
            let tilt =
                Rotation3::from_axis_angle(&random_axis(r), r.gen_range(0.0..1.0f64).sqrt() * cone);
            let d = tilt * axis.normalize();
            let along = r.gen_range(-0.15..0.05);
            let noise = Vector3::new(normal(r), normal(r), normal(r)) * position;
            let turn = Rotation3::from_axis_angle(&random_axis(r), normal(r) * angle);
            Line::new(port + d * along + noise, turn * d).unwrap()
        })
        .collect()
}

#[test]
fn twenty_noisy_poses_locate_the_port_within_half_a_millimetre() {
    let port = Vector3::new(0.45, -0.1, 0.32);
    let axis = Vector3::new(0.2, 0.1, -1.0);
    let mut worst: f64 = 0.0;
    let mut worst_deviation: f64 = 0.0;
    for seed in 0..200 {
        let mut r = StdRng::seed_from_u64(seed);
        let lines = pivoting(
            &mut r,
            &port,
            &axis,
            20f64.to_radians(),
            20,
            1e-4,
            0.1f64.to_radians(),
        );
        let mut reg = PortRegistration::new();
        for l in &lines {
            reg.add(l).unwrap();
        }
        let e = reg.estimate(2f64.to_radians()).unwrap();
        let error = (e.point - port).norm();
        assert!(error <= 5e-4, "seed {seed}: {:.3} mm off", error * 1e3);
        // The covariance speaks of the error's size: within four deviations.
        assert!(
            error <= 4.0 * e.covariance.trace().sqrt(),
            "seed {seed}: {:.3} mm off, deviation {:.3} mm",
            error * 1e3,
            e.covariance.trace().sqrt() * 1e3
        );
        worst = worst.max(error);
        worst_deviation = worst_deviation.max(e.largest_deviation());
    }
    println!(
        "20 noisy poses, 200 draws: at most {:.3} mm from the port; largest deviation {:.3} mm",
        worst * 1e3,
        worst_deviation * 1e3
    );
}

#[test]
fn a_port_that_moves_is_followed_with_forgetting() {
    // The port moves 10 mm along the wall's normal; lines taken one a step.
    let mut r = StdRng::seed_from_u64(3);
    let axis = Vector3::new(0.0, 0.0, -1.0);
    let mut reg = PortRegistration::with_forgetting(0.9).unwrap();
    let mut all = PortRegistration::new();
    let start = Vector3::new(0.4, 0.0, 0.3);
    let moved = start + Vector3::new(0.0, 0.0, 0.01);
    for port in [start, moved] {
        for l in pivoting(&mut r, &port, &axis, 15f64.to_radians(), 100, 0.0, 0.0) {
            reg.add(&l).unwrap();
            all.add(&l).unwrap();
        }
    }
    let followed = reg.estimate(0.01).unwrap();
    let averaged = all.estimate(0.01).unwrap();
    assert!(
        (followed.point - moved).norm() <= 1e-4,
        "{}",
        followed.point
    );
    // Without forgetting the estimate stays between the two places.
    assert!((averaged.point - moved).norm() >= 3e-3);
    assert_eq!(followed.lines, 200);
}

#[test]
fn what_cannot_locate_the_port_is_refused_with_what_is_wrong() {
    let mut reg = PortRegistration::<f64>::new();
    assert_eq!(reg.estimate(0.0), Err(PortError::TooFewLines { lines: 0 }));
    let z = Vector3::<f64>::z();
    reg.add(&Line::new(Vector3::zeros(), z).unwrap()).unwrap();
    assert_eq!(reg.estimate(0.0), Err(PortError::TooFewLines { lines: 1 }));
    // Parallel lines, and lines within 0.5° of each other.
    for tilt in [0.0f64, 0.5] {
        let mut reg = PortRegistration::<f64>::new();
        for k in 0..10 {
            let turn = Rotation3::from_axis_angle(
                &Vector3::x_axis(),
                (k as f64 - 4.5) / 4.5 * tilt.to_radians(),
            );
            reg.add(&Line::new(Vector3::new(k as f64 * 1e-3, 0.0, 0.0), turn * z).unwrap())
                .unwrap();
        }
        match reg.estimate(2f64.to_radians()) {
            Err(e @ PortError::NearParallel { spread, least }) => {
                assert!(spread < 0.5f64.to_radians() && (least - 2f64.to_radians()).abs() < 1e-12);
                let message = e.to_string();
                assert!(
                    message.contains("nearly parallel") && message.contains("2.000°"),
                    "{message}"
                );
            }
            other => panic!("tilt {tilt}°: {other:?}"),
        }
    }
    // NaN, a direction of no length, a forgetting factor out of range: refused, nothing taken.
    let mut reg = PortRegistration::<f64>::new();
    let bad = Line {
        point: Vector3::new(f64::NAN, 0.0, 0.0),
        direction: z,
    };
    assert_eq!(reg.add(&bad), Err(PortError::Invalid));
    let flat = Line {
        point: Vector3::zeros(),
        direction: Vector3::zeros(),
    };
    assert_eq!(reg.add(&flat), Err(PortError::Invalid));
    assert_eq!(reg.lines(), 0);
    assert!(Line::<f64>::new(Vector3::zeros(), Vector3::zeros()).is_none());
    for lambda in [0.0, -0.5, 0.5, 1.5, f64::NAN] {
        assert_eq!(
            PortRegistration::<f64>::with_forgetting(lambda),
            Err(PortError::Invalid)
        );
    }
}

/// The follower (R2) in an ideal loop — the shaft through the estimate along a fixed direction,
/// the wall's spring on it — against the first-order lag it should be: a port that stepped by
/// `s` is followed as `s e^(−t/τ)` across the shaft, and with the wall's normal known along the
/// shaft too; the rate never passes its bound; a bad input changes nothing.
#[test]
fn the_follower_closes_on_a_port_that_moved() {
    let wall = trocar::port::Wall::<f64> {
        stiffness: 4000.0,
        damping: 0.0,
    };
    let tau = 0.02;
    let d = Vector3::new(0.0, 0.0, -1.0);
    let n = Vector3::new(1.0, 0.0, 1.0).normalize();
    let start = Vector3::new(0.3, 0.0, 0.34);
    let moved = start + n * 0.004;
    let dt = 1e-4;
    for with_normal in [false, true] {
        let mut f =
            trocar::port::PortFollower::new(start, 1.0 / (wall.stiffness * tau), 1.0).unwrap();
        if with_normal {
            f = f.with_normal(n).unwrap();
        }
        let mut t = 0.0;
        while t < 5.0 * tau {
            let shaft = Line::new(f.estimate, d).unwrap();
            let force = wall.force(&shaft.offset_from(&moved), &Vector3::zeros());
            f.update(&force, &d, dt).unwrap();
            t += dt;
        }
        let across = Line::new(f.estimate, d).unwrap().distance(&moved);
        let lag = (0.004 * std::f64::consts::FRAC_1_SQRT_2) * (-t / tau).exp();
        assert!(
            (across - lag).abs() <= 0.02 * lag,
            "across {across:e}, first order {lag:e}"
        );
        let along = (f.estimate - moved).dot(&d).abs();
        if with_normal {
            assert!(along <= 0.02 * 0.004, "along the shaft {along:e}");
        } else {
            assert!((along - 0.004 * std::f64::consts::FRAC_1_SQRT_2).abs() <= 1e-12);
        }
    }
    // The bound on the rate, and inputs refused.
    let mut f = trocar::port::PortFollower::new(start, 1.0, 0.05).unwrap();
    let rate = f.update(&Vector3::new(1000.0, 0.0, 0.0), &d, 1e-3).unwrap();
    assert!((rate.norm() - 0.05).abs() <= 1e-15);
    let before = f;
    for (force, direction, dt) in [
        (Vector3::new(f64::NAN, 0.0, 0.0), d, 1e-3),
        (Vector3::zeros(), Vector3::zeros(), 1e-3),
        (Vector3::zeros(), d, -1.0),
        (Vector3::zeros(), d, f64::INFINITY),
    ] {
        assert_eq!(f.update(&force, &direction, dt), Err(PortError::Invalid));
        assert_eq!(f, before);
    }
    assert!(trocar::port::PortFollower::new(start, -1.0, 0.05).is_err());
    assert!(trocar::port::PortFollower::new(start, 1.0, 0.0).is_err());
    assert!(trocar::port::PortFollower::new(start, 1.0, 0.05)
        .unwrap()
        .with_normal(Vector3::zeros())
        .is_err());
}
