//! The controller object of the C ABI (`panda_laparoscope_controller_init`, `_update`,
//! `_reset` over caller-provided storage): configured for the QP step with the Panda's URDF
//! limits (speeds, accelerations, jerks, ranges) and insertion bounds, it steps exactly as the
//! Rust controller built from the same settings through `trocar::control` does, keeps every
//! limit along the `panda-laparoscope-limits` path, does not allocate, starts again with
//! `reset`, and refuses every input outside its rules with its return code, writing nothing.

mod common;

use common::{gains, rust_qp_controller, start, ACCELERATION, JERK, SPEED};
use trocar::control::{Gains, MethodKind, Rcm, StepStatus};
use trocar::nalgebra::{SVector, Vector3};
use trocar_counting_allocator::{allocations_during, Counting};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;
use trocar_sim::simulation::{panda_limits_reference, PANDA_DEPTH_LIMITS};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The storage a C caller declares: `CONTROLLER_SIZE` bytes aligned to `CONTROLLER_ALIGN`.
#[repr(C, align(16))]
struct Storage([u8; m::C_CONTROLLER_SIZE]);

impl Storage {
    fn zeroed() -> Box<Self> {
        Box::new(Storage([0; m::C_CONTROLLER_SIZE]))
    }
    fn ptr(&mut self) -> *mut std::ffi::c_void {
        self.0.as_mut_ptr().cast()
    }
}

/// The QP with the Panda's limits, as a C caller fills the configuration.
fn qp_config() -> m::CControllerConfig {
    let mut c = m::CControllerConfig::DEFAULT;
    c.method = 3;
    c.max_joint_speed = 0.0;
    c.acceleration = ACCELERATION;
    c.jerk = JERK;
    c.depth_limits = 1;
    c.depth = PANDA_DEPTH_LIMITS;
    c
}

fn reference_values(t: f64, g0: &trocar::se3::Se3<f64>) -> [f64; 18] {
    let r = panda_limits_reference(t, g0);
    let mut v = [0.0; 18];
    v[..3].copy_from_slice(r.position.as_slice());
    v[3..12].copy_from_slice(r.rotation.as_slice());
    v[12..15].copy_from_slice(r.velocity.as_slice());
    v[15..].copy_from_slice(r.angular_velocity.as_slice());
    v
}

/// One update through the C ABI.
fn update(
    storage: &mut Storage,
    q: &[f64; 7],
    reference: &[f64; 18],
    trocar: &[f64; 3],
    dt: f64,
) -> (i32, [f64; 7], [f64; 8]) {
    let (mut qd, mut report) = ([f64::NAN; 7], [f64::NAN; 8]);
    // SAFETY: the storage was written by `init` (or is zeroed), every array has the length
    // the function reads or writes.
    let code = unsafe {
        m::panda_laparoscope_controller_update(
            storage.ptr(),
            q.as_ptr(),
            [m::Params::nominal().l_a].as_ptr(),
            reference.as_ptr(),
            trocar.as_ptr(),
            std::ptr::null(),
            dt,
            qd.as_mut_ptr(),
            report.as_mut_ptr(),
        )
    };
    (code, qd, report)
}

fn init(storage: &mut Storage, config: &m::CControllerConfig) -> i32 {
    // SAFETY: `storage` holds `C_CONTROLLER_SIZE` bytes aligned to 16.
    unsafe { m::panda_laparoscope_controller_init(storage.ptr(), m::C_CONTROLLER_SIZE, config) }
}

#[test]
fn the_c_object_steps_as_the_rust_controller_and_keeps_the_limits() {
    let (trocar, g0) = start();
    let mut storage = Storage::zeroed();
    assert_eq!(init(&mut storage, &qp_config()), 0);
    let mut rust = rust_qp_controller();
    let kin = m::Kinematics::nominal();
    let dt = 0.002;
    let (mut q, mut q_rust) = (Q0, SVector::from(Q0));
    let limits = m::JOINT_LIMITS;
    let mut previous = [0.0f64; 7];
    let (mut worst, mut drift) = (0.0f64, 0.0f64);
    let mut allocations = 0;
    for k in 0..3000 {
        let t = k as f64 * dt;
        let reference = reference_values(t, &g0);
        let mut stepped = None;
        allocations += allocations_during(|| {
            stepped = Some(update(&mut storage, &q, &reference, &trocar, dt));
        });
        let (code, qd, report) = stepped.expect("the update ran");
        assert_eq!(code, 0, "step {k}");
        let out = rust
            .step(
                &kin,
                &q_rust,
                &panda_limits_reference(t, &g0),
                &Rcm {
                    trocar: Vector3::from(trocar),
                    dv: SVector::zeros(),
                },
                dt,
            )
            .unwrap();
        for j in 0..7 {
            worst = worst.max((qd[j] - out.qd[j]).abs());
            assert!(qd[j].abs() <= SPEED[j] * (1.0 + 1e-9));
            assert!(
                (qd[j] - previous[j]).abs() <= ACCELERATION[j] * dt * (1.0 + 1e-6) + 1e-12,
                "step {k}: joint {} accelerates",
                j + 1
            );
            q[j] += dt * qd[j];
            assert!(
                q[j] >= limits[j][0] && q[j] <= limits[j][1],
                "step {k}: q{}",
                j + 1
            );
        }
        previous = qd;
        q_rust += out.qd * dt;
        drift = drift.max(report[3]);
    }
    println!("C object against Rust: rates within {worst:.1e} rad/s; drift {drift:.1e} m");
    assert_eq!(worst, 0.0, "the C object and the Rust controller differ");
    assert!(drift <= 1e-4);
    assert_eq!(allocations, 0, "update allocated");
}

#[test]
fn reset_starts_again_from_rest() {
    let (trocar, g0) = start();
    let reference = reference_values(2.0, &g0);
    let mut a = Storage::zeroed();
    let mut b = Storage::zeroed();
    assert_eq!(init(&mut a, &qp_config()), 0);
    assert_eq!(init(&mut b, &qp_config()), 0);
    let first = update(&mut a, &Q0, &reference, &trocar, 0.002);
    for _ in 0..5 {
        update(&mut a, &Q0, &reference, &trocar, 0.002);
    }
    // SAFETY: `a` was written by `init`.
    assert_eq!(unsafe { m::panda_laparoscope_controller_reset(a.ptr()) }, 0);
    let again = update(&mut a, &Q0, &reference, &trocar, 0.002);
    let fresh = update(&mut b, &Q0, &reference, &trocar, 0.002);
    assert_eq!(again.1, fresh.1);
    assert_eq!(again.1, first.1);
}

#[test]
fn the_status_names_the_constraint_that_gave_way() {
    let (trocar, g0) = start();
    let reference = reference_values(0.0, &g0);
    let mut s = Storage::zeroed();
    assert_eq!(init(&mut s, &qp_config()), 0);
    // The port 5 cm off the shaft: the trocar cannot be held within the limits in one step.
    let off = [trocar[0] + 0.05, trocar[1], trocar[2]];
    let (code, qd, _) = update(&mut s, &Q0, &reference, &off, 0.002);
    assert_eq!(code, m::C_TROCAR_YIELDED);
    assert!(qd.iter().all(|v| v.is_finite()));
    // A joint beyond its range, with the DLS step and with the QP: the code is the status the
    // Rust controller reports for the same step.
    let mut q = Q0;
    q[3] = m::JOINT_LIMITS[3][1] + 0.05;
    let kin = m::Kinematics::nominal();
    for method in [1, 3] {
        let mut config = qp_config();
        config.method = method;
        let mut s = Storage::zeroed();
        assert_eq!(init(&mut s, &config), 0);
        let (code, _, _) = update(&mut s, &q, &reference, &trocar, 0.002);
        let mut rust = rust_qp_controller();
        if method == 1 {
            rust.config = Gains {
                max_joint_speed: None,
                ..gains()
            }
            .config(MethodKind::Dls);
        }
        let status = rust
            .step(
                &kin,
                &SVector::from(q),
                &panda_limits_reference(0.0, &g0),
                &Rcm {
                    trocar: Vector3::from(trocar),
                    dv: SVector::zeros(),
                },
                0.002,
            )
            .unwrap()
            .status;
        let expected = match status {
            StepStatus::Held => 0,
            StepStatus::TrocarYielded => m::C_TROCAR_YIELDED,
            StepStatus::JointOutside => m::C_JOINT_OUTSIDE,
            StepStatus::DepthOutside => m::C_DEPTH_OUTSIDE,
        };
        assert_ne!(status, StepStatus::Held, "method {method}");
        assert_eq!(code, expected, "method {method}: {status:?}");
    }
}

#[test]
fn what_the_rules_refuse_is_refused_with_nothing_written() {
    let (trocar, g0) = start();
    let reference = reference_values(0.0, &g0);
    // Configurations: every scalar and array entry beyond the number rule, a method that does
    // not exist, negative gains and limits, ranges and insertion bounds out of order.
    let mut bad = Vec::new();
    for v in [f64::NAN, f64::INFINITY, 1e300, -1e300, 1e-310] {
        let mut c = qp_config();
        c.kp = v;
        bad.push(c);
        let mut c = qp_config();
        c.qp_kappa = v;
        bad.push(c);
        let mut c = qp_config();
        c.jerk[4] = v;
        bad.push(c);
        let mut c = qp_config();
        c.depth[1] = v;
        bad.push(c);
    }
    for edit in [
        |c: &mut m::CControllerConfig| c.method = 4,
        |c: &mut m::CControllerConfig| c.method = -1,
        |c: &mut m::CControllerConfig| c.kr = -1.0,
        |c: &mut m::CControllerConfig| c.limit_gain = -1.0,
        |c: &mut m::CControllerConfig| c.speed[2] = -1.0,
        |c: &mut m::CControllerConfig| c.acceleration[0] = -0.1,
        |c: &mut m::CControllerConfig| c.lower[5] = c.upper[5],
        |c: &mut m::CControllerConfig| c.depth = [0.2, 0.1],
        |c: &mut m::CControllerConfig| c.depth_limits = 2,
        |c: &mut m::CControllerConfig| c.max_joint_speed = -2.0,
    ] {
        let mut c = qp_config();
        edit(&mut c);
        bad.push(c);
    }
    for c in &bad {
        let mut s = Storage::zeroed();
        assert_eq!(init(&mut s, c), m::C_INVALID_ARGUMENT, "{c:?}");
        assert!(s.0.iter().all(|b| *b == 0), "init wrote storage it refused");
    }
    // Storage: too small, misaligned, not written by init, null.
    let mut s = Storage::zeroed();
    // SAFETY: the storage is larger than the size given; a refused call writes nothing.
    unsafe {
        assert_eq!(
            m::panda_laparoscope_controller_init(s.ptr(), 64, &qp_config()),
            m::C_BAD_STORAGE
        );
        let misaligned = s.0.as_mut_ptr().add(8).cast();
        assert_eq!(
            m::panda_laparoscope_controller_init(
                misaligned,
                m::C_CONTROLLER_SIZE - 8,
                &qp_config()
            ),
            m::C_BAD_STORAGE
        );
        assert_eq!(
            m::panda_laparoscope_controller_init(
                std::ptr::null_mut(),
                m::C_CONTROLLER_SIZE,
                &qp_config()
            ),
            m::C_NULL_ARGUMENT
        );
        assert_eq!(
            m::panda_laparoscope_controller_init(s.ptr(), m::C_CONTROLLER_SIZE, std::ptr::null()),
            m::C_NULL_ARGUMENT
        );
        assert_eq!(
            m::panda_laparoscope_controller_reset(s.ptr()),
            m::C_BAD_STORAGE
        );
        assert_eq!(
            m::panda_laparoscope_controller_reset(std::ptr::null_mut()),
            m::C_NULL_ARGUMENT
        );
    }
    assert!(s.0.iter().all(|b| *b == 0));
    let (code, _, report) = update(&mut s, &Q0, &reference, &trocar, 0.002);
    assert_eq!(code, m::C_BAD_STORAGE);
    assert!(report.iter().all(|v| v.is_nan()));
    // Steps: every input beyond the number rule, a sample time that is not positive, a gain
    // times dt beyond its bound; the rates set to zeros, the report not written.
    assert_eq!(init(&mut s, &qp_config()), 0);
    for v in [f64::NAN, f64::INFINITY, 1e300, 1e-310] {
        let mut q = Q0;
        q[2] = v;
        let (code, qd, report) = update(&mut s, &q, &reference, &trocar, 0.002);
        assert_eq!(code, m::C_INVALID_ARGUMENT, "q {v}");
        assert_eq!(qd, [0.0; 7]);
        assert!(report.iter().all(|r| r.is_nan()));
        let mut r = reference;
        r[16] = v;
        assert_eq!(
            update(&mut s, &Q0, &r, &trocar, 0.002).0,
            m::C_INVALID_ARGUMENT
        );
        let mut tr = trocar;
        tr[0] = v;
        assert_eq!(
            update(&mut s, &Q0, &reference, &tr, 0.002).0,
            m::C_INVALID_ARGUMENT
        );
        assert_eq!(
            update(&mut s, &Q0, &reference, &trocar, v).0,
            m::C_INVALID_ARGUMENT
        );
    }
    // Orientations that are not proper rotations: scaled, reflected, sheared.
    for edit in [
        |r: &mut [f64; 18]| r[3..12].iter_mut().for_each(|v| *v *= 2.0),
        |r: &mut [f64; 18]| r[9..12].iter_mut().for_each(|v| *v = -*v),
        |r: &mut [f64; 18]| r[4] += 1e-3,
    ] {
        let mut r = reference;
        edit(&mut r);
        let (code, qd, report) = update(&mut s, &Q0, &r, &trocar, 0.002);
        assert_eq!(code, m::C_INVALID_ARGUMENT);
        assert_eq!(qd, [0.0; 7]);
        assert!(report.iter().all(|v| v.is_nan()));
    }
    for dt in [0.0, -0.002] {
        assert_eq!(
            update(&mut s, &Q0, &reference, &trocar, dt).0,
            m::C_INVALID_ARGUMENT
        );
    }
    // K_r dt = 20 × 0.2 = 4 is beyond its bound of 2.
    assert_eq!(
        update(&mut s, &Q0, &reference, &trocar, 0.2).0,
        m::C_INVALID_ARGUMENT
    );
    // Null pointers: nothing written.
    let (mut qd, params) = ([-1.0; 7], [0.25]);
    // SAFETY: null pointers are refused before anything is read or written.
    let code = unsafe {
        m::panda_laparoscope_controller_update(
            s.ptr(),
            std::ptr::null(),
            params.as_ptr(),
            reference.as_ptr(),
            trocar.as_ptr(),
            std::ptr::null(),
            0.002,
            qd.as_mut_ptr(),
            std::ptr::null_mut(),
        )
    };
    assert_eq!(code, m::C_NULL_ARGUMENT);
    assert_eq!(qd, [-1.0; 7]);
}
