//! The distance between two shafts (`trocar::distance`) against an independent computation and
//! its rate against finite differences: skew shafts, crossing and touching ones, parallel ones
//! whose overlap has a whole interval of witnesses, and nearly parallel ones.
//!
//! The independent distance: the minimum of `|a(s) − b(t)|²` over `[0, 1]²` is at the interior
//! critical point (where it is inside) or on an edge, where it is the distance from an endpoint
//! to the other segment (a point–segment projection): the smallest of those five candidates.

use nalgebra::{SMatrix, Vector3};
use proptest::prelude::*;
use trocar::distance::segment_distance;

fn point_segment(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let u = b - a;
    let len2 = u.norm_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(&u) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + u * s - p).norm()
}

/// The five candidates of the module's header.
fn reference(a0: &Vector3<f64>, a1: &Vector3<f64>, b0: &Vector3<f64>, b1: &Vector3<f64>) -> f64 {
    let mut best = point_segment(a0, b0, b1)
        .min(point_segment(a1, b0, b1))
        .min(point_segment(b0, a0, a1))
        .min(point_segment(b1, a0, a1));
    // The interior critical point: the 2×2 normal equations.
    let (u, v, r) = (a1 - a0, b1 - b0, a0 - b0);
    let m = nalgebra::Matrix2::new(u.dot(&u), -u.dot(&v), -u.dot(&v), v.dot(&v));
    if let Some(inv) = m.try_inverse() {
        let st = inv * nalgebra::Vector2::new(-u.dot(&r), v.dot(&r));
        if (0.0..=1.0).contains(&st[0]) && (0.0..=1.0).contains(&st[1]) {
            best = best.min((a0 + u * st[0] - b0 - v * st[1]).norm());
        }
    }
    best
}

fn vec3() -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(-0.2f64..0.2).prop_map(Vector3::from)
}

fn unit() -> impl Strategy<Value = Vector3<f64>> {
    vec3()
        .prop_filter("not too short", |v| v.norm() > 0.02)
        .prop_map(|v| v.normalize())
}

type Ends = [Vector3<f64>; 4];

fn distance_of(e: &Ends) -> f64 {
    segment_distance(&e[0], &e[1], &e[2], &e[3]).distance
}

fn moved(e: &Ends, v: &Ends, h: f64) -> Ends {
    [0, 1, 2, 3].map(|k| e[k] + v[k] * h)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

    /// The distance is the independent one's, and its witnesses give it.
    #[test]
    fn the_distance_is_the_smallest_of_the_candidates(
        a0 in vec3(), a1 in vec3(), b0 in vec3(), b1 in vec3(),
    ) {
        let d = segment_distance(&a0, &a1, &b0, &b1);
        let want = reference(&a0, &a1, &b0, &b1);
        prop_assert!((d.distance - want).abs() <= 1e-12, "{} vs {want}", d.distance);
        let (pa, pb) = d.closest_points();
        prop_assert!(((pa - pb).norm() - d.distance).abs() <= 1e-15);
        for &(s, t) in d.witnesses() {
            prop_assert!((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t));
        }
    }

    /// Skew segments apart: the rate (D2) and its row of joint rates against central
    /// differences of the distance.
    #[test]
    fn the_rate_of_skew_segments_is_the_derivative(
        a0 in vec3(), a1 in vec3(), b0 in vec3(), b1 in vec3(),
        v in prop::array::uniform4(vec3()),
    ) {
        let e = [a0, a1, b0, b1];
        let d = segment_distance(&a0, &a1, &b0, &b1);
        let (u, w) = (a1 - a0, b1 - b0);
        prop_assume!(d.distance > 1e-3 && u.norm() > 1e-2 && w.norm() > 1e-2);
        prop_assume!(u.cross(&w).norm() > 1e-2 * u.norm() * w.norm());
        let h = 1e-6;
        let fd = (distance_of(&moved(&e, &v, h)) - distance_of(&moved(&e, &v, -h))) / (2.0 * h);
        let rate = d.rate(&v).unwrap();
        let scale = v.iter().map(|x| x.norm()).fold(0.0, f64::max);
        // The central difference's error: h² times the third derivative, which grows as 1/d²
        // near the witnesses' switches between the inside and the edges.
        prop_assert!((rate - fd).abs() <= 1e-6 * scale * (1.0 + 1e-3 / d.distance), "{rate} vs {fd}");
        // The squared distance's rate.
        let fd2 = (distance_of(&moved(&e, &v, h)).powi(2) - distance_of(&moved(&e, &v, -h)).powi(2)) / (2.0 * h);
        prop_assert!((d.squared_rate(&v) - fd2).abs() <= 1e-7 * scale, "{} vs {fd2}", d.squared_rate(&v));
        // The row: each endpoint's velocity a linear map of 5 joint rates.
        let jac: [SMatrix<f64, 3, 5>; 4] = core::array::from_fn(|k| {
            SMatrix::<f64, 3, 5>::from_fn(|i, j| ((k * 15 + i * 5 + j) as f64 * 0.7).sin())
        });
        let qd = SMatrix::<f64, 5, 1>::from_fn(|j, _| v[j % 4][j % 3]);
        let velocities = jac.map(|j| j * qd);
        let rows = d.rate_row(&jac).unwrap();
        prop_assert!(((rows[0] * qd)[0] - d.rate(&velocities).unwrap()).abs() <= 1e-12);
    }

    /// Parallel segments whose projections overlap: every point of the overlap is a witness,
    /// `d` has no derivative, and its one-sided derivative is the smallest of (D2) over the two
    /// ends of the overlap, not (D2) at any one witness.
    #[test]
    fn parallel_segments_move_apart_at_the_slower_end_of_their_overlap(
        a0 in vec3(), axis in unit(), side in unit(), length in 0.05f64..0.3,
        offset in 0.002f64..0.05, slide in -0.8f64..0.8, b_length in 0.05f64..0.3,
        v in prop::array::uniform4(vec3()),
    ) {
        let normal = (side - axis * side.dot(&axis)).normalize();
        prop_assume!(normal.norm() > 0.5);
        // Overlapping by 1 cm at least.
        prop_assume!(slide * length + b_length > 0.01 && slide * length < length - 0.01);
        let a1 = a0 + axis * length;
        let b0 = a0 + normal * offset + axis * (slide * length);
        let b1 = b0 + axis * b_length;
        let e = [a0, a1, b0, b1];
        let d = segment_distance(&a0, &a1, &b0, &b1);
        prop_assert!((d.distance - offset).abs() <= 1e-12);
        prop_assert_eq!(d.count, 2, "the overlap's two ends");
        let (s0, s1) = (d.witnesses[0].0, d.witnesses[1].0);
        prop_assert!(s1 != s0);
        // One-sided differences, forward: their error is h times the second derivative.
        let h = 1e-8;
        let fd = (distance_of(&moved(&e, &v, h)) - d.distance) / h;
        let rate = d.rate(&v).unwrap();
        let scale = v.iter().map(|x| x.norm()).fold(0.0, f64::max);
        prop_assert!((rate - fd).abs() <= 1e-5 * scale * (1.0 + scale / offset), "{rate} vs {fd}");
        // Backward, the other sign of the motion: the smallest rate of -v.
        let minus = v.map(|x| -x);
        let fd_back = (distance_of(&moved(&e, &v, -h)) - d.distance) / h;
        prop_assert!((d.rate(&minus).unwrap() - fd_back).abs() <= 1e-5 * scale * (1.0 + scale / offset));
    }

    /// Crossing segments (`d = 0`): the normal is the common normal of their lines, and the
    /// distance grows at `|nᵀ(ȧ − ḃ)|` as they separate; `d²` does not change to first order.
    #[test]
    fn crossing_segments_separate_along_their_common_normal(
        centre in vec3(), u in unit(), w in unit(), s in 0.1f64..0.9, t in 0.1f64..0.9,
        v in prop::array::uniform4(vec3()),
    ) {
        prop_assume!(u.cross(&w).norm() > 0.1);
        let (a0, a1) = (centre - u * (0.2 * s), centre + u * (0.2 * (1.0 - s)));
        let (b0, b1) = (centre - w * (0.2 * t), centre + w * (0.2 * (1.0 - t)));
        let e = [a0, a1, b0, b1];
        let d = segment_distance(&a0, &a1, &b0, &b1);
        // The endpoints are rounded, so the lines cross to rounding; the closest points come from
        // a 2 × 2 system of determinant sin²θ (θ the angle between the lines), which amplifies
        // that rounding by 1/sin²θ (up to 100 here, the lines as near parallel as 0.1 rad).
        let sin = u.cross(&w).norm();
        prop_assert!(d.distance <= 1e-15 / (sin * sin), "{} at sin θ = {sin}", d.distance);
        let n = d.normal.unwrap();
        prop_assert!((n.dot(&u)).abs() <= 1e-12 && (n.dot(&w)).abs() <= 1e-12);
        let h = 1e-7;
        let fd = distance_of(&moved(&e, &v, h)) / h;
        let rate = d.rate(&v).unwrap();
        let scale = v.iter().map(|x| x.norm()).fold(0.0, f64::max);
        prop_assert!((rate.abs() - fd).abs() <= 1e-5 * scale, "{rate} vs {fd}");
        prop_assert!(d.squared_rate(&v).abs() <= 1e-15);
    }

    /// Nearly parallel segments (1e-4 rad apart, beyond the rounding): one witness, and the
    /// rate is still the derivative.
    #[test]
    fn nearly_parallel_segments_have_one_witness_and_its_rate(
        a0 in vec3(), axis in unit(), side in unit(), offset in 0.005f64..0.05,
        v in prop::array::uniform4(vec3()),
    ) {
        let normal = (side - axis * side.dot(&axis)).normalize();
        prop_assume!(normal.norm() > 0.5);
        // b's line passes a's at `offset`, 1e-4 rad off parallel, closest at b's middle.
        let lateral = normal.cross(&axis);
        let a1 = a0 + axis * 0.2;
        let b0 = a0 + normal * offset + axis * 0.05 - lateral * 1e-5;
        let tilt = (axis + lateral * 1e-4).normalize();
        let b1 = b0 + tilt * 0.2;
        let e = [a0, a1, b0, b1];
        let d = segment_distance(&a0, &a1, &b0, &b1);
        prop_assert_eq!(d.count, 1);
        prop_assert!((d.distance - reference(&a0, &a1, &b0, &b1)).abs() <= 1e-12);
        // The witness moves by `offset · (rotation) / angle²` along the shafts: at 1e-4 rad a
        // motion of 1e-8 already takes it to an end, so the difference needs a step within that.
        let h = 1e-10;
        let fd = (distance_of(&moved(&e, &v, h)) - distance_of(&moved(&e, &v, -h))) / (2.0 * h);
        let scale = v.iter().map(|x| x.norm()).fold(0.0, f64::max);
        let rate = d.rate(&v).unwrap();
        prop_assert!((rate - fd).abs() <= 1e-5 * scale + 1e-7, "{rate} vs {fd}");
    }
}

/// Touching cases one by one: an end on the other segment (a T), two ends meeting, touching
/// parallel segments (no normal), and points.
#[test]
fn touching_segments() {
    let x = Vector3::<f64>::x();
    let y = Vector3::<f64>::y();
    let o = Vector3::<f64>::zeros();
    // A T: b's end at the middle of a.
    let d = segment_distance(&(-x), &x, &o, &y);
    assert_eq!(d.distance, 0.0);
    let n = d.normal.unwrap();
    assert!((n.z.abs() - 1.0).abs() < 1e-15);
    // Moving b up along its own axis separates them at rate 1 (an end leaving), which d² sees
    // as zero to first order.
    let v = [o, o, y, y];
    let moved = segment_distance(&(-x), &x, &(y * 1e-6), &(y * (1.0 + 1e-6)));
    assert!((moved.distance - 1e-6).abs() < 1e-15);
    assert_eq!(d.squared_rate(&v), 0.0);
    // Two ends meeting at an angle.
    let d = segment_distance(&o, &x, &o, &y);
    assert_eq!(d.distance, 0.0);
    assert!(d.normal.is_some());
    // Touching parallel segments: no normal, no rate; d² has rate zero.
    let d = segment_distance(&o, &x, &(x * 0.5), &(x * 2.0));
    assert_eq!(d.distance, 0.0);
    assert!(d.normal.is_none() && d.rate(&[x, x, y, y]).is_none());
    assert_eq!(d.squared_rate(&[x, x, y, y]), 0.0);
    // Points.
    let d = segment_distance(&o, &o, &y, &y);
    assert_eq!(d.distance, 1.0);
    assert_eq!(d.rate(&[y, y, o, o]), Some(-1.0));
    // Parallel without overlap: the nearer ends, one witness.
    let d = segment_distance(&o, &x, &(x * 2.0 + y), &(x * 3.0 + y));
    assert_eq!(d.count, 1);
    assert!((d.distance - 2f64.sqrt()).abs() < 1e-15);
    assert_eq!(d.witnesses[0], (1.0, 0.0));
}
