//! What the tests of the C ABI's controller object share: the Panda's limits, the same
//! controller built in Rust from `trocar::control`, and the start of the limits path.
// Each test file that includes this module uses a part of it.
#![allow(dead_code)]

use trocar::control::{Controller, Gains, HardLimits, MethodKind, NullSpaceObjective};
use trocar::nalgebra::{SVector, Vector3};
use trocar_cpp_example::panda_laparoscope as m;
use trocar_cpp_example::Q0;
use trocar_sim::simulation::{PANDA_DEPTH_LIMITS, PANDA_TIP_DEPTH};

/// The Panda's joint speed limits (the URDF's `velocity`).
pub const SPEED: [f64; 7] = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];
/// libfranka's acceleration and jerk limits (the URDF 1.2 `<limit>`s of the shipped Panda).
pub const ACCELERATION: [f64; 7] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];
pub const JERK: [f64; 7] = [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0];

/// The gains of the C configuration's defaults, written out.
pub fn gains() -> Gains<f64> {
    Gains {
        kp: 5.0,
        ko: 10.0,
        kr: 20.0,
        dls_alpha0: 0.05,
        dls_w0_task: 1e-3,
        dls_w0_jb0i: 0.01,
        fi_gamma: 5.0,
        qp_kappa: 1e-3,
        max_joint_speed: None,
    }
}

/// The same controller built in Rust from `trocar::control`, independently of the C object.
pub type RustController = Controller<f64, 7, 7, 2, 4, 4, 4>;

pub fn rust_qp_controller() -> RustController {
    let limits = m::JOINT_LIMITS;
    let lower = SVector::from_fn(|k, _| limits[k][0]);
    let upper = SVector::from_fn(|k, _| limits[k][1]);
    let gains = gains();
    let speed = SVector::from(SPEED);
    Controller::new(gains.config(MethodKind::Qp))
        .with_limits(
            HardLimits::none()
                .with_joint_limits(lower, upper)
                .with_speed_limits(speed)
                .with_acceleration_limits(SVector::from(ACCELERATION))
                .with_jerk_limits(SVector::from(JERK))
                .with_depth(PANDA_DEPTH_LIMITS[0], PANDA_DEPTH_LIMITS[1]),
        )
        .with_objective(NullSpaceObjective::JointLimits {
            gain: 10.0,
            lower,
            upper,
        })
}

/// The trocar and the start pose from the generated kinematics.
pub fn start() -> ([f64; 3], trocar::se3::Se3<f64>) {
    let p = m::Params::nominal();
    let (r, t) = m::forward_kinematics(&Q0, &p);
    let g0 = trocar::se3::Se3::new(
        trocar::nalgebra::Matrix3::from_fn(|i, j| r[j][i]),
        Vector3::from(t),
    );
    let trocar = g0.translation - g0.rotation.column(2) * PANDA_TIP_DEPTH;
    ([trocar.x, trocar.y, trocar.z], g0)
}
