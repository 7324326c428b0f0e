//! # trocar-cpp-scene-example — a scene of three arms from C and C++
//!
//! `build.rs` generates the shipped scene `three-ports` (two instrument arms and an endoscope
//! arm, Pandas on their own bases, each through its own port, their shafts kept 10 mm apart) in
//! `f64` with its C ABI (`Builder::c_api(true)`): the scene object `three_ports_scene_init`,
//! `_update`, `_reset`, its start, its couplings' distances and the endoscope's camera, beside
//! the arms' own C ABI (`panda_laparoscope_...`). The C++ program `three_ports.cpp` links the
//! same code as the package `trocar generate three-ports --cmake DIR` builds; the tests here
//! call the functions from Rust and compare the C++ run with the Rust one. See
//! `examples/cpp/README.md`.

include!(concat!(env!("OUT_DIR"), "/three_ports.rs"));
