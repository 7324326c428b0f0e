//! The C ABI against the Rust functions it wraps, and the C++ loop (`main.cpp`) against the same
//! loop written in Rust on the generated module and `trocar::control::Controller`.

use trocar::control::{
    Controller, ControllerConfig, Damping, HardLimits, Method, NullSpaceObjective, Rcm, Reference,
};
use trocar::nalgebra::{Matrix3, SVector, Vector3};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;

/// Every C function writes what its Rust function returns, in the documented layout, and
/// refuses null pointers.
#[test]
fn c_functions_write_the_rust_functions_values() {
    let q = [0.3, -0.5, 0.2, -2.1, 0.4, 1.9, 0.6];
    let params = [0.21];
    let p = m::Params { l_a: 0.21 };
    let mut out = [f64::NAN; 42];
    // SAFETY: q holds N = 7 values, params PARAMS = 1, out room for 42 (the largest result).
    let status = unsafe {
        m::panda_laparoscope_partial_body_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    let want = m::partial_body_jacobian(&q, &p);
    assert_eq!(&out[..42], want.as_flattened());
    // SAFETY: as above; the pose takes 12 values.
    let status = unsafe {
        m::panda_laparoscope_forward_kinematics(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    let (r, t) = m::forward_kinematics(&q, &p);
    assert_eq!(&out[..9], r.as_flattened());
    assert_eq!(&out[9..12], &t);
    // SAFETY: as above; J^r is 6 × 4.
    let status = unsafe {
        m::panda_laparoscope_constrained_jacobian(q.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, 0);
    assert_eq!(&out[..24], m::constrained_jacobian(&q, &p).as_flattened());
    // Null pointers: refused, nothing written.
    let before = out;
    // SAFETY: the null pointers are what is tested; the function checks before reading.
    let status = unsafe {
        m::panda_laparoscope_forward_kinematics(std::ptr::null(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, m::C_NULL_ARGUMENT);
    // SAFETY: as above.
    let status = unsafe {
        m::panda_laparoscope_forward_kinematics(q.as_ptr(), std::ptr::null(), out.as_mut_ptr())
    };
    assert_eq!(status, m::C_NULL_ARGUMENT);
    assert_eq!(out.map(f64::to_bits), before.map(f64::to_bits));
    // A non-finite result is reported.
    let bad = [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    // SAFETY: as above.
    let status = unsafe {
        m::panda_laparoscope_forward_kinematics(bad.as_ptr(), params.as_ptr(), out.as_mut_ptr())
    };
    assert_eq!(status, m::C_NOT_FINITE);
}

/// The loop of `main.cpp`, in Rust on the generated module and the typed controller: the lines
/// it prints.
fn rust_loop() -> Vec<Vec<f64>> {
    let p = m::Params::nominal();
    let (ri, ti) = m::forward_kinematics_i(&Q0, &p);
    let (_, tir) = m::constraint_frame(&p);
    let (re, te) = m::forward_kinematics(&Q0, &p);
    let mut trocar = [0.0; 3];
    for r in 0..3 {
        trocar[r] = ti[r];
        for c in 0..3 {
            trocar[r] += ri[c][r] * tir[c];
        }
    }
    let config = ControllerConfig {
        kp: 5.0,
        ko: 10.0,
        method: Method::Dls(Damping::Variable {
            alpha0: 0.05,
            w0: 1e-3,
        }),
        jb0i_damping: Some(Damping::Variable {
            alpha0: 0.05,
            w0: 0.01,
        }),
        kr: 20.0,
        max_joint_speed: Some(2.0),
    };
    let lower = SVector::from_fn(|k, _| m::JOINT_LIMITS[k][0]);
    let upper = SVector::from_fn(|k, _| m::JOINT_LIMITS[k][1]);
    // The C step keeps the joints within their ranges (over dt) as well as the speed limit.
    let mut ctrl =
        Controller::<f64, { m::N }, { m::I }, { m::R }, { m::K }, { m::M }, { m::TASK_ROWS }>::new(
            config,
        )
        .with_limits(HardLimits {
            lower,
            upper,
            ..HardLimits::none()
        })
        .with_objective(NullSpaceObjective::JointLimits {
            gain: 10.0,
            lower,
            upper,
        });
    let kin = m::Kinematics { params: p };
    let (dt, speed) = (0.002, 0.01);
    let mut q = SVector::<f64, 7>::from(Q0);
    let mut lines = Vec::new();
    for k in 0..=500 {
        let t = k as f64 * dt;
        let mut position = [0.0; 3];
        let mut velocity = [0.0; 3];
        for r in 0..3 {
            position[r] = te[r] + re[0][r] * speed * t;
            velocity[r] = re[0][r] * speed;
        }
        let reference = Reference {
            position: Vector3::from(position),
            rotation: Matrix3::from_fn(|r, c| re[c][r]),
            velocity: Vector3::from(velocity),
            angular_velocity: Vector3::zeros(),
        };
        let rcm = Rcm {
            trocar: Vector3::from(trocar),
            dv: SVector::zeros(),
        };
        let out = ctrl.step(&kin, &q, &reference, &rcm, dt).expect("a step");
        if k % 50 == 0 {
            let mut line = vec![t, out.ep.norm(), out.lateral_error.norm()];
            line.extend(q.iter());
            lines.push(line);
        }
        q += out.qd * dt;
    }
    lines
}

/// The C++ program's output (built and run by `.ci/run`, which passes its path in
/// `TROCAR_CPP_OUTPUT`) equals the Rust loop's, line by line.
#[test]
#[ignore = "needs the C++ example built and run by .ci/run (TROCAR_CPP_OUTPUT)"]
fn cpp_loop_matches_the_rust_loop() {
    let path =
        std::env::var("TROCAR_CPP_OUTPUT").expect("TROCAR_CPP_OUTPUT: the C++ program's output");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let cpp: Vec<Vec<f64>> = text
        .lines()
        .map(|l| {
            l.split_whitespace()
                .filter_map(|w| w.parse::<f64>().ok())
                .collect()
        })
        .collect();
    let rust = rust_loop();
    assert_eq!(cpp.len(), rust.len(), "lines");
    for (a, b) in cpp.iter().zip(&rust) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).abs() <= 1e-12 * (1.0 + y.abs()),
                "C++ {x} vs Rust {y} in {a:?}"
            );
        }
    }
    // The run holds the trocar and follows the tip.
    let last = rust.last().expect("lines");
    assert!(last[2] < 1e-6, "drift {}", last[2]);
    assert!(last[1] < 1e-3, "tip error {}", last[1]);
}

/// The Rust loop itself keeps the trocar and follows the tip (so the comparison above is with a
/// meaningful run).
#[test]
fn the_rust_loop_holds_the_trocar() {
    let lines = rust_loop();
    assert_eq!(lines.len(), 11);
    for l in &lines {
        assert!(l[2] < 1e-6, "drift {l:?}");
    }
    assert!(lines.last().expect("lines")[1] < 1e-3);
}
