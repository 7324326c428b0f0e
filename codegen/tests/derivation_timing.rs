//! Derivation time and expression sizes for dia10_like and the presets. Prints a table
//! (`cargo test --release -p trocar-codegen --test derivation_timing -- --nocapture`); in release
//! builds it asserts the 200 ms budget of the full dia10_like set.

mod derivation_support;

use derivation_support::*;
use std::time::Instant;
use trocar_codegen::derivation::derive;

#[test]
fn derivation_time_and_sizes() {
    let cases = [
        ("dia10_like_zy", dia10_like(false)),
        ("dia10_like_zx", dia10_like(true)),
        ("unidirectional", preset("unidirectional")),
        ("bidirectional-zy", preset("bidirectional-zy")),
        ("bidirectional-zx", preset("bidirectional-zx")),
    ];
    for (name, desc) in cases {
        // best of 5 (the first run also interns the Inv atoms)
        let mut best = f64::INFINITY;
        let mut d = None;
        for _ in 0..5 {
            let t = Instant::now();
            let r = derive(&desc).unwrap();
            best = best.min(t.elapsed().as_secs_f64() * 1e3);
            d = Some(r);
        }
        let d = d.unwrap();
        assert!(d.fk_e.is_some() && d.body_jacobian_e.is_some());
        let sizes: Vec<String> = d
            .sizes()
            .iter()
            .map(|(n, r, c, t)| format!("{n} {r}x{c}: {t}"))
            .collect();
        println!("{name}: {best:.2} ms; terms: {}", sizes.join(", "));
        if !cfg!(debug_assertions) {
            assert!(best < 200.0, "{name}: {best} ms");
        }
    }
}
