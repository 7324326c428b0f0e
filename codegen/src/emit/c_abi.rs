//! What every part of a module's C ABI shares ([`super::c_api`], [`super::c_controller`],
//! [`super::c_port`], [`super::cpp_header`]): the number rule's bound, the C type of the
//! module's reals, and whether the module has a controller.

use crate::ir::{ModuleSpec, Real};

/// The largest magnitude the C functions accept for any value they read: the number rule of
/// every number trocar takes from a user (`trocar_model::validity::MAX_MAGNITUDE`).
pub const C_MAX_MAGNITUDE: f64 = trocar_model::validity::MAX_MAGNITUDE;

/// The C type of a module's reals: `float` for an `f32` module, else `double` (a generic
/// module's C ABI is `f64`).
pub(crate) fn c_type(real: Real) -> &'static str {
    if matches!(real, Real::F32) {
        "float"
    } else {
        "double"
    }
}

/// Whether the module has `Kinematics` (a constraint frame that slides along its link), and so
/// the controller step and object, the port's registration and follower, and the path's
/// reference.
pub(crate) fn has_controller(spec: &ModuleSpec) -> bool {
    spec.controller.as_ref().is_some_and(|c| c.offset.is_some())
}
