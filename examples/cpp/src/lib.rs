//! # trocar-cpp-example — the generated kinematics and the controller from C++
//!
//! `build.rs` generates the shipped `panda-laparoscope` in `f64` with its C ABI
//! (`Builder::c_api(true)`): every function of the module is also
//! `int panda_laparoscope_<function>(const double *q, const double *params, double *out)`, and
//! `panda_laparoscope_controller_step` runs one step of the runtime's constrained controller on
//! the generated kinematics. Built as a `staticlib`, this crate is what `main.cpp` links; the C
//! header is `trocar generate panda-laparoscope --c-header panda_laparoscope.h` (the build also
//! writes it to `OUT_DIR`). See `examples/cpp/README.md`.

include!(concat!(env!("OUT_DIR"), "/panda_laparoscope.rs"));

/// The Panda's start configuration `(0, −π/4, 0, −3π/4, 0, π/2, π/4)` (rad), where `main.cpp`
/// and the tests start.
pub const Q0: [f64; 7] = [
    0.0,
    -core::f64::consts::FRAC_PI_4,
    0.0,
    -3.0 * core::f64::consts::FRAC_PI_4,
    0.0,
    core::f64::consts::FRAC_PI_2,
    core::f64::consts::FRAC_PI_4,
];
