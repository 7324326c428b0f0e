//! `panda_laparoscope_trajectory_reference`: the reference a C loop takes along a path of rows is
//! the one `trocar simulate ROBOT --trajectory F.csv` builds (`trocar_api::Trajectory::reference`,
//! from the CSV as the command line reads it), at row times and between them, for a roll (turned
//! through the trocar), quaternions and position only; what it refuses writes nothing.

use std::path::Path;
use trocar::nalgebra::{Matrix3, Vector3};
use trocar::se3::Se3;
use trocar_api::{Orientation, Trajectory};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;

/// The flat rows of a trajectory: `t, x, y, z` and its orientation's columns.
fn flat(tr: &Trajectory) -> (Vec<f64>, i32) {
    let mut v = Vec::new();
    for k in 0..tr.t.len() {
        v.push(tr.t[k]);
        v.extend(tr.position[k]);
        match &tr.orientation {
            Orientation::None => {}
            Orientation::Roll(r) => v.push(r[k]),
            Orientation::Quaternion(q) => v.extend(q[k]),
        }
    }
    let code = match tr.orientation {
        Orientation::None => 0,
        Orientation::Roll(_) => 1,
        Orientation::Quaternion(_) => 2,
    };
    (v, code)
}

fn c_reference(
    rows: &[f64],
    count: usize,
    code: i32,
    t: f64,
    q: &[f64; 7],
    trocar: &[f64; 3],
) -> (i32, [f64; 18]) {
    let mut out = [-5.0; 18];
    // SAFETY: `rows` holds `count` rows of the orientation's columns, the joints 7 values, the
    // parameters 1, the trocar 3, `out` room for 18.
    let status = unsafe {
        m::panda_laparoscope_trajectory_reference(
            rows.as_ptr(),
            count,
            code,
            t,
            Q0.as_ptr(),
            q.as_ptr(),
            [m::Params::nominal().l_a].as_ptr(),
            trocar.as_ptr(),
            out.as_mut_ptr(),
        )
    };
    (status, out)
}

/// The start pose from the generated kinematics, and a trocar 0.15 m up the shaft.
fn start() -> (Se3<f64>, [f64; 3]) {
    let (r, p) = m::forward_kinematics(&Q0, &m::Params::nominal());
    let g0 = Se3::new(Matrix3::from_fn(|i, j| r[j][i]), Vector3::from(p));
    let trocar = g0.translation - g0.rotation.column(2) * 0.15;
    (g0, [trocar.x, trocar.y, trocar.z])
}

fn compare(tr: &Trajectory, q: &[f64; 7]) -> f64 {
    let (g0, trocar) = start();
    let (rows, code) = flat(tr);
    let (r, _) = m::forward_kinematics(q, &m::Params::nominal());
    let current = Matrix3::from_fn(|i, j| r[j][i]);
    let end = tr.t[tr.t.len() - 1];
    let mut worst = 0.0f64;
    for k in 0..=400 {
        // Past both ends too, at row times and between them.
        let t = -0.5 + (end + 1.0) * k as f64 / 400.0;
        let want = tr.reference(t, &g0, &Vector3::from(trocar));
        let (status, got) = c_reference(&rows, tr.t.len(), code, t, q, &trocar);
        assert_eq!(status, 0, "t = {t}");
        let rotation = want
            .rotation
            .map_or(current, |r| Matrix3::from_fn(|i, j| r[i][j]));
        let expected: Vec<f64> = want
            .position
            .iter()
            .chain(rotation.as_slice())
            .chain(&want.velocity)
            .chain(&want.angular_velocity)
            .copied()
            .collect();
        for (a, b) in got.iter().zip(&expected) {
            worst = worst.max((a - b).abs());
        }
    }
    worst
}

#[test]
fn the_c_reference_is_the_command_lines() {
    let circle = Path::new(env!("CARGO_MANIFEST_DIR")).join("../trajectories/panda-circle.csv");
    let mut tr = Trajectory::from_csv(&circle).unwrap();
    // A roll that changes, so that its rate and its turn through the trocar are exercised.
    if let Orientation::Roll(r) = &mut tr.orientation {
        for (k, v) in r.iter_mut().enumerate() {
            *v = 0.3 * (k as f64 * 0.05).sin();
        }
    } else {
        panic!("the circle gives a roll");
    }
    let q = [0.01, -0.8, 0.02, -2.3, 0.01, 1.6, 0.8];
    let roll = compare(&tr, &q);
    // The same path with quaternions (a rotation about a tilted axis growing along it), and
    // position only.
    let quaternions = (0..tr.t.len())
        .map(|k| {
            let half = 0.2 * k as f64 / tr.t.len() as f64;
            let axis = Vector3::new(0.3, -0.5, 0.8).normalize() * half.sin();
            [half.cos(), axis.x, axis.y, axis.z]
        })
        .collect();
    let mut with_q = tr.clone();
    with_q.orientation = Orientation::Quaternion(quaternions);
    let quaternion = compare(&with_q, &q);
    let mut position_only = tr.clone();
    position_only.orientation = Orientation::None;
    let none = compare(&position_only, &q);
    println!("C reference against the command line's: roll {roll:.1e}, quaternion {quaternion:.1e}, position only {none:.1e}");
    assert!(roll <= 1e-12 && quaternion <= 1e-12 && none <= 1e-12);
}

#[test]
fn what_cannot_be_a_path_is_refused_with_nothing_written() {
    let (_, trocar) = start();
    let rows = [0.0, 0.1, 0.2, 0.3, 0.0, 1.0, 0.1, 0.2, 0.4, 0.1];
    let untouched = |out: &[f64; 18]| out.iter().all(|v| *v == -5.0);
    let cases: [(Vec<f64>, usize, i32); 7] = [
        (rows.to_vec(), 1, 1),                                          // one row
        (rows.to_vec(), 2, 3),                                          // no such orientation
        (vec![0.0, 0.1, 0.2, 0.3, 0.0, 0.0, 0.1, 0.2, 0.4, 0.1], 2, 1), // times not increasing
        (
            vec![0.0, 0.1, 0.2, 0.3, f64::NAN, 1.0, 0.1, 0.2, 0.4, 0.1],
            2,
            1,
        ), // not a number
        (
            vec![0.0, 0.1, 0.2, 1e300, 0.0, 1.0, 0.1, 0.2, 0.4, 0.1],
            2,
            1,
        ), // beyond the rule
        (
            vec![
                0.0, 0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 0.0, 1.0, 0.1, 0.2, 0.4, 1.0, 0.0, 0.0, 0.0,
            ],
            2,
            2,
        ), // a quaternion of no length
        (rows.to_vec(), usize::MAX / 2, 1),                             // more rows than memory
    ];
    for (values, count, code) in cases {
        let (status, out) = c_reference(&values, count, code, 0.5, &Q0, &trocar);
        assert_eq!(status, m::C_INVALID_ARGUMENT, "{values:?} {count} {code}");
        assert!(untouched(&out));
    }
    let (status, out) = c_reference(&rows, 2, 1, f64::INFINITY, &Q0, &trocar);
    assert_eq!(status, m::C_INVALID_ARGUMENT);
    assert!(untouched(&out));
}
