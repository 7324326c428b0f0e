//! `panda_laparoscope_register_port` through its C ABI: the port of a recorded pivot is the
//! trocar the run held (computed from the forward kinematics at the start, not by the
//! registration), two poses give the midpoint of the two shaft lines' common perpendicular
//! (closed form), and every input outside its rules gets its return code with nothing written.

use trocar_cpp_example::panda_laparoscope as m;

const N: usize = 7;
const LEN: usize = 14;
/// What `out` holds before a call: a call that writes overwrites it.
const SENTINEL: f64 = -123.25;

/// The shaft's line at `q` from the generated forward kinematics and constraint frame: the
/// constraint frame's origin at `l_a = 0` and its direction of travel `l_a = 0 → 1`.
fn shaft_line(q: &[f64; N]) -> ([f64; 3], [f64; 3]) {
    let (r, t) = m::forward_kinematics_i(q, &m::Params::nominal());
    let at = |l_a: f64| {
        let (_, o) = m::constraint_frame(&m::Params { l_a });
        let mut p = t;
        for (row, value) in p.iter_mut().enumerate() {
            for c in 0..3 {
                *value += r[c][row] * o[c];
            }
        }
        p
    };
    let (a, b) = (at(0.0), at(1.0));
    (a, [b[0] - a[0], b[1] - a[1], b[2] - a[2]])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn axpy(a: [f64; 3], s: f64, d: [f64; 3]) -> [f64; 3] {
    [a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]]
}
fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

/// The recorded pivot (`examples/ports/panda-laparoscope-pivot.csv`), one pose a row.
fn pivot() -> Vec<[f64; N]> {
    let text = include_str!("../../ports/panda-laparoscope-pivot.csv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('q'))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect()
}

fn register(poses: &[[f64; N]], least: f64, forgetting: f64) -> (i32, [f64; LEN]) {
    let mut out = [SENTINEL; LEN];
    let flat: Vec<f64> = poses.iter().flatten().copied().collect();
    let params = [m::Params::nominal().l_a];
    // SAFETY: `flat` holds `poses.len() · N` values, `params` one, `out` 14.
    let code = unsafe {
        m::panda_laparoscope_register_port(
            flat.as_ptr(),
            poses.len(),
            params.as_ptr(),
            least,
            forgetting,
            out.as_mut_ptr(),
        )
    };
    (code, out)
}

#[test]
fn the_port_of_a_recorded_pivot_is_the_trocar_it_held() {
    let poses = pivot();
    assert_eq!(poses.len(), 51);
    // The run's trocar: the constraint frame's origin at the start (its `l_a` nominal).
    let (r, t) = m::forward_kinematics_i(&poses[0], &m::Params::nominal());
    let (_, o) = m::constraint_frame(&m::Params::nominal());
    let mut trocar = t;
    for (row, value) in trocar.iter_mut().enumerate() {
        for c in 0..3 {
            *value += r[c][row] * o[c];
        }
    }
    let (code, out) = register(&poses, 1f64.to_radians(), 1.0);
    assert_eq!(code, 0);
    let port = [out[0], out[1], out[2]];
    assert!(distance(port, trocar) < 1e-6, "{port:?} against {trocar:?}");
    // The shaft stayed within 1e-7 m of the trocar: so does the residual.
    assert!(out[12] >= 0.0 && out[12] < 1e-6, "residual {}", out[12]);
    assert!(out[13] > 1f64.to_radians() && out[13] < trocar::port::LARGEST_SPREAD);
    // The covariance: symmetric, positive semi-definite on its diagonal, and small (a residual
    // of 1e-7 m over 50 lines).
    for rr in 0..3 {
        assert!(out[3 + 4 * rr] >= 0.0 && out[3 + 4 * rr] < 1e-10);
        for c in 0..3 {
            assert_eq!(out[3 + 3 * c + rr], out[3 + 3 * rr + c]);
        }
    }
    // With forgetting, the same pivot about a still port gives the same port.
    let (code, forgot) = register(&poses, 1f64.to_radians(), 0.9);
    assert_eq!(code, 0);
    assert!(distance([forgot[0], forgot[1], forgot[2]], trocar) < 1e-6);
}

#[test]
fn two_poses_give_the_midpoint_of_the_common_perpendicular() {
    let poses = pivot();
    // The second pose moved off the pivot (joints 1, 3 and 6), so that the lines are skew, a
    // few centimetres apart.
    for (j, k, off) in [(0, 20, 0.05), (5, 45, -0.08), (10, 30, 0.02), (0, 50, 0.2)] {
        let mut moved = poses[k];
        moved[0] += off;
        moved[2] -= off;
        moved[5] += off / 2.0;
        let (a, u) = shaft_line(&poses[j]);
        let (b, v) = shaft_line(&moved);
        // The closest points a + s u, b + t v of two skew lines (the normal equations of the
        // 2 × 2 least-squares problem).
        let w = sub(a, b);
        let (uu, uv, vv, uw, vw) = (dot(u, u), dot(u, v), dot(v, v), dot(u, w), dot(v, w));
        let det = uu * vv - uv * uv;
        let s = (uv * vw - vv * uw) / det;
        let t = (uu * vw - uv * uw) / det;
        let (pa, pb) = (axpy(a, s, u), axpy(b, t, v));
        let mid = [
            (pa[0] + pb[0]) / 2.0,
            (pa[1] + pb[1]) / 2.0,
            (pa[2] + pb[2]) / 2.0,
        ];
        let (code, out) = register(&[poses[j], moved], 0.0, 1.0);
        assert_eq!(code, 0, "poses {j} and {k}");
        let port = [out[0], out[1], out[2]];
        assert!(
            distance(port, mid) < 1e-9,
            "poses {j}, {k}: {port:?} against {mid:?}"
        );
        // The residual: each line's distance from the midpoint is half the gap.
        let gap = distance(pa, pb);
        assert!(gap > 1e-3, "poses {j}, {k}: the lines are {gap} m apart");
        assert!(
            (out[12] - gap / 2.0).abs() < 1e-9,
            "{} against {}",
            out[12],
            gap / 2.0
        );
    }
}

#[test]
fn what_cannot_locate_a_port_is_refused_with_nothing_written() {
    let poses = pivot();
    let one_degree = 1f64.to_radians();
    let untouched = |out: &[f64; LEN]| out.iter().all(|&v| v == SENTINEL);
    // Fewer than two poses.
    for few in [&poses[..0], &poses[..1]] {
        let (code, out) = register(few, one_degree, 1.0);
        assert_eq!(code, m::C_TOO_FEW_LINES);
        assert!(untouched(&out));
    }
    // The same pose twice: parallel lines; only the spread (0) is written.
    let (code, out) = register(&[poses[3], poses[3]], one_degree, 1.0);
    assert_eq!(code, m::C_NEAR_PARALLEL);
    assert!(out[..13].iter().all(|&v| v == SENTINEL));
    assert!(out[13] < 1e-6);
    // A pivot smaller than the spread asked: its spread written.
    let (code, out) = register(&poses[..3], 20f64.to_radians(), 1.0);
    assert_eq!(code, m::C_NEAR_PARALLEL);
    assert!(out[13] > 0.0 && out[13] < 20f64.to_radians());
    // Values outside the number rule, anywhere in the joints.
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300, 1e-310] {
        let mut with_bad = poses[..10].to_vec();
        with_bad[7][4] = bad;
        let (code, out) = register(&with_bad, one_degree, 1.0);
        assert_eq!(code, m::C_INVALID_ARGUMENT, "{bad}");
        assert!(untouched(&out));
    }
    // Settings out of range.
    for (least, forgetting) in [
        (-0.1, 1.0),
        (1.0, 1.0),
        (f64::NAN, 1.0),
        (one_degree, 0.5),
        (one_degree, 1.01),
        (one_degree, f64::NAN),
        (one_degree, 0.0),
    ] {
        let (code, out) = register(&poses, least, forgetting);
        assert_eq!(code, m::C_INVALID_ARGUMENT, "{least}, {forgetting}");
        assert!(untouched(&out));
    }
    // A parameter outside the rule.
    let mut out = [SENTINEL; LEN];
    let flat: Vec<f64> = poses.iter().flatten().copied().collect();
    // SAFETY: as in `register`.
    let code = unsafe {
        m::panda_laparoscope_register_port(
            flat.as_ptr(),
            poses.len(),
            [f64::NAN].as_ptr(),
            one_degree,
            1.0,
            out.as_mut_ptr(),
        )
    };
    assert_eq!(code, m::C_INVALID_ARGUMENT);
    assert!(untouched(&out));
    // A count of poses whose values could not be in memory is refused before anything is read.
    for count in [usize::MAX, usize::MAX / N + 1, usize::MAX / 8] {
        // SAFETY: the count is refused before `joints` is read (what this checks).
        let code = unsafe {
            m::panda_laparoscope_register_port(
                flat.as_ptr(),
                count,
                [0.0].as_ptr(),
                one_degree,
                1.0,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(code, m::C_INVALID_ARGUMENT, "{count}");
        assert!(untouched(&out));
    }
    // Null pointers.
    // SAFETY: null pointers are refused before anything is read or written.
    unsafe {
        let params = [0.0];
        assert_eq!(
            m::panda_laparoscope_register_port(
                std::ptr::null(),
                2,
                params.as_ptr(),
                one_degree,
                1.0,
                out.as_mut_ptr()
            ),
            m::C_NULL_ARGUMENT
        );
        assert_eq!(
            m::panda_laparoscope_register_port(
                flat.as_ptr(),
                2,
                params.as_ptr(),
                one_degree,
                1.0,
                std::ptr::null_mut()
            ),
            m::C_NULL_ARGUMENT
        );
        assert_eq!(
            m::panda_laparoscope_register_port(
                flat.as_ptr(),
                2,
                std::ptr::null(),
                one_degree,
                1.0,
                out.as_mut_ptr()
            ),
            m::C_NULL_ARGUMENT
        );
    }
    assert!(untouched(&out));
}
