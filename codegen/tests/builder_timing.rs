//! Generation time of the full `dia10_like` module (derivation + optimisation + emission +
//! formatting). The target (< 200 ms) is for release builds: run
//! `cargo test -p trocar-codegen --release --test builder_timing -- --nocapture`.

use std::time::Instant;
use trocar_codegen::{generate_module_string, ModuleOptions};
use trocar_model::description::RobotDescription;

#[test]
fn dia10_like_generation_time() {
    for name in ["dia10_like_zy", "dia10_like_zx"] {
        let desc = RobotDescription::preset(name).unwrap();
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let t0 = Instant::now();
            let text = generate_module_string(&desc, &ModuleOptions::default()).unwrap();
            best = best.min(t0.elapsed().as_secs_f64());
            assert!(text.len() > 1000);
        }
        println!(
            "{name}: full module generated in {:.1} ms (best of 5)",
            best * 1e3
        );
        if !cfg!(debug_assertions) {
            assert!(best < 0.2, "{name}: {best} s");
        }
    }
}
