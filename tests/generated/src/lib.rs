//! Generated modules, compiled in a `#![no_std]` crate (nothing but `core` and `trocar::emitted`).
//!
//! The library has no unit tests (its tests are the crate's integration tests, which link it as
//! it is): its own test harness compiles nothing (`cfg(not(test))` below) instead of every
//! generated module a second time.
#![cfg(not(test))]
#![no_std]
#![deny(warnings)]
#![warn(missing_docs)]

macro_rules! generated {
    ($($file:literal),* $(,)?) => {
        $(include!(concat!(env!("OUT_DIR"), "/", $file));)*
    };
}

pub mod control;

generated!(
    "unidirectional.rs",
    "bidirectional_zy.rs",
    "bidirectional_zx.rs",
    "dia10_like_zy.rs",
    "dia10_like_zx.rs",
    "rotated_rcm.rs",
    "chain9_prismatic.rs",
    "chain11_wide.rs",
    "bidirectional_zy_f32.rs",
    "rotated_rcm_f32.rs",
    "dia10_like_zx_f64.rs",
    "panda_laparoscope.rs",
    "iiwa_endoscope.rs",
    "iiwa_link6.rs",
    // dia10_like with `pose_and_jacobians_trig` calling the four functions (build.rs).
    "dia10_like_zy_four_calls.rs",
);

// `f64` entry points with FMA chosen at run time (`Builder::fma_at_run_time`).
generated!("panda_fma.rs", "dia10_fma.rs");

// Scenes of several arms (`Builder::scene`): each arm's closed forms and the scene's step.
generated!("three_ports.rs", "dia10_dual.rs", "three_ports_f32.rs");

// Closed mechanisms (four-bar linkage, planar Gough–Stewart platform).
generated!("four_bar.rs", "planar_stewart.rs", "four_bar_f32.rs");

/// The runtime crate re-exported, as a crate that depends on `trocar` only through another crate
/// would see it: the modules below name it `crate::reexport::trocar`
/// (`Builder::runtime_path`).
pub mod reexport {
    pub use trocar;
}

generated!("bidirectional_zy_reexport.rs", "four_bar_reexport.rs");

// The C ABI of a module in f32 and of a generic one (C functions in f64).
generated!("panda_capi_f32.rs", "dia10_capi.rs");

// Fused functions named like the C and `fma_at_run_time` wrappers' parameters and locals.
generated!("shadowing.rs");
