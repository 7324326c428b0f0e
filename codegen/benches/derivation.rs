//! How long the symbolic derivation takes (`trocar_codegen::derivation::derive`): dia10_like with
//! either wrist, the three thesis presets and the random nine-joint chain of the numeric tests
//! (one prismatic and one screw joint, a three-row `H`). The target is the full dia10_like set
//! within 200 ms in a release build.
//!
//! `cargo bench -p trocar-codegen --bench derivation`; `-- --test` runs each case once.

#[path = "../tests/derivation_support/mod.rs"]
mod derivation_support;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use derivation_support::{dia10_like, preset, random_chain};
use trocar_codegen::derivation::derive;

fn benches(c: &mut Criterion) {
    let cases = [
        ("dia10_like_zy", dia10_like(false)),
        ("dia10_like_zx", dia10_like(true)),
        ("unidirectional", preset("unidirectional")),
        ("bidirectional-zy", preset("bidirectional-zy")),
        ("bidirectional-zx", preset("bidirectional-zx")),
        ("random_chain", random_chain(7)),
    ];
    let mut g = c.benchmark_group("derive");
    for (name, desc) in &cases {
        g.bench_function(*name, |b| b.iter(|| derive(black_box(desc)).unwrap()));
    }
    g.finish();
}

criterion_group! {
    name = derivation;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(derivation);
