//! The moving port through the C ABI: `panda_laparoscope_shaft_line` is the runtime's shaft line
//! at the joints, `_port_follower_update` moves the estimate as `trocar::port::PortFollower`
//! does, and every input outside the rules is refused with the follower unchanged.

use trocar::control::ConstrainedKinematics;
use trocar::nalgebra::{SVector, Vector3};
use trocar::port::PortFollower;
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;

fn init(
    estimate: [f64; 3],
    compliance: f64,
    max_rate: f64,
    normal: Option<[f64; 3]>,
) -> (i32, m::CPortFollower) {
    let mut f = m::CPortFollower {
        estimate: [-9.0; 3],
        rate: [-9.0; 3],
        compliance: -9.0,
        max_rate: -9.0,
        has_normal: -9,
        normal: [-9.0; 3],
    };
    let n = normal.unwrap_or_default();
    // SAFETY: `f` is a follower, the arrays hold 3 values; `normal` null or 3 values.
    let code = unsafe {
        m::panda_laparoscope_port_follower_init(
            &mut f,
            estimate.as_ptr(),
            compliance,
            max_rate,
            if normal.is_some() {
                n.as_ptr()
            } else {
                std::ptr::null()
            },
        )
    };
    (code, f)
}

fn update(f: &mut m::CPortFollower, force: [f64; 3], q: &[f64; 7], dt: f64) -> i32 {
    // SAFETY: `f` is a follower, `force` 3 values, `q` 7, the parameters 1.
    unsafe {
        m::panda_laparoscope_port_follower_update(
            f,
            force.as_ptr(),
            q.as_ptr(),
            [0.25].as_ptr(),
            dt,
            std::ptr::null_mut(),
        )
    }
}

#[test]
fn the_c_follower_moves_as_the_runtime_one() {
    let kin = m::Kinematics::nominal();
    let q = [0.05, -0.7, 0.1, -2.3, 0.05, 1.5, 0.7];
    let mut out = [0.0; 6];
    // SAFETY: 7 joints, 1 parameter, room for 6.
    assert_eq!(
        unsafe { m::panda_laparoscope_shaft_line(q.as_ptr(), [0.25].as_ptr(), out.as_mut_ptr()) },
        0
    );
    let line = kin.shaft().line(&kin.g_0i(&SVector::from(q))).unwrap();
    assert_eq!(&out[..3], line.point.as_slice());
    assert_eq!(&out[3..], line.direction.as_slice());
    let normal = [1.0, 0.0, 1.0];
    let (code, mut c) = init([0.4, 0.0, 0.3], 1.0 / 80.0, 0.05, Some(normal));
    assert_eq!(code, 0);
    let mut rust = PortFollower::new(Vector3::new(0.4, 0.0, 0.3), 1.0 / 80.0, 0.05)
        .and_then(|f| f.with_normal(Vector3::from(normal)))
        .unwrap();
    for k in 0..200 {
        let force = [(k as f64 * 0.1).sin(), 0.3, -(k as f64 * 0.07).cos()];
        assert_eq!(update(&mut c, force, &q, 0.001), 0);
        rust.update(&Vector3::from(force), &line.direction, 0.001)
            .unwrap();
        assert_eq!(c.estimate, <[f64; 3]>::from(rust.estimate), "step {k}");
        assert_eq!(c.rate, <[f64; 3]>::from(rust.rate), "step {k}");
    }
}

#[test]
fn what_the_rules_refuse_leaves_the_follower_unchanged() {
    let untouched = |f: &m::CPortFollower| f.estimate == [-9.0; 3] && f.has_normal == -9;
    for (estimate, compliance, max_rate, normal) in [
        ([f64::NAN, 0.0, 0.0], 0.01, 0.05, None),
        ([0.0, 0.0, 1e300], 0.01, 0.05, None),
        ([0.0; 3], -0.01, 0.05, None),
        ([0.0; 3], 0.01, 0.0, None),
        ([0.0; 3], 0.01, f64::INFINITY, None),
        ([0.0; 3], 0.01, 0.05, Some([0.0; 3])),
        ([0.0; 3], 0.01, 0.05, Some([f64::NAN, 0.0, 1.0])),
    ] {
        let (code, f) = init(estimate, compliance, max_rate, normal);
        assert_eq!(
            code,
            m::C_INVALID_ARGUMENT,
            "{estimate:?} {compliance} {max_rate} {normal:?}"
        );
        assert!(untouched(&f));
    }
    let (code, mut f) = init([0.4, 0.0, 0.3], 0.01, 0.05, None);
    assert_eq!(code, 0);
    let before = f;
    for (force, dt) in [
        ([f64::NAN, 0.0, 0.0], 0.001),
        ([1e300, 0.0, 0.0], 0.001),
        ([1.0, 0.0, 0.0], -0.001),
        ([1.0, 0.0, 0.0], f64::INFINITY),
    ] {
        assert_eq!(
            update(&mut f, force, &Q0, dt),
            m::C_INVALID_ARGUMENT,
            "{force:?} {dt}"
        );
        assert_eq!(f, before);
    }
    let mut q = Q0;
    q[1] = f64::NAN;
    assert_eq!(
        update(&mut f, [1.0, 0.0, 0.0], &q, 0.001),
        m::C_INVALID_ARGUMENT
    );
    assert_eq!(f, before);
    // A state `init` did not write (zeros: no rate allowed) is refused.
    let mut zeros = m::CPortFollower {
        estimate: [0.0; 3],
        rate: [0.0; 3],
        compliance: 0.0,
        max_rate: 0.0,
        has_normal: 0,
        normal: [0.0; 3],
    };
    assert_eq!(
        update(&mut zeros, [1.0, 0.0, 0.0], &Q0, 0.001),
        m::C_INVALID_ARGUMENT
    );
    // SAFETY: null pointers are refused before anything is read or written.
    unsafe {
        assert_eq!(
            m::panda_laparoscope_port_follower_update(
                std::ptr::null_mut(),
                [0.0; 3].as_ptr(),
                Q0.as_ptr(),
                [0.25].as_ptr(),
                0.001,
                std::ptr::null_mut()
            ),
            m::C_NULL_ARGUMENT
        );
        assert_eq!(
            m::panda_laparoscope_shaft_line(Q0.as_ptr(), [0.25].as_ptr(), std::ptr::null_mut()),
            m::C_NULL_ARGUMENT
        );
    }
}
