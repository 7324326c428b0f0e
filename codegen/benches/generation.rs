//! How long generating a module takes: every preset's full module (derivation, programs, tokens,
//! formatting; `generate_module_string`, generic scalar), the stages of dia10_like_zy one by one,
//! and the `#[constrained_robot]` attribute's expansion of dia10_like_zy in `f32`. The target is
//! each dia10_like module within 200 ms in a release build.
//!
//! `cargo bench -p trocar-codegen --bench generation`; `-- --test` runs each case once.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use quote::quote;
use trocar_codegen::derivation::derive;
use trocar_codegen::emit::{format_file, module_tokens};
use trocar_codegen::lower::module_spec;
use trocar_codegen::Real;
use trocar_codegen::{attribute, generate_module_string, ModuleOptions};
use trocar_model::description::{preset_names, RobotDescription};

fn modules(c: &mut Criterion) {
    let mut g = c.benchmark_group("generate_module");
    for name in preset_names() {
        let desc = RobotDescription::preset(name).unwrap();
        g.bench_function(name, |b| {
            b.iter(|| generate_module_string(black_box(&desc), &ModuleOptions::default()).unwrap())
        });
    }
    g.finish();
}

fn stages(c: &mut Criterion) {
    let desc = RobotDescription::preset("dia10_like_zy").unwrap();
    let d = derive(&desc).unwrap();
    let spec = module_spec(&d, "dia10_like_zy");
    let tokens = module_tokens(&spec, Real::Generic);
    let mut g = c.benchmark_group("dia10_like_zy");
    g.bench_function("derive", |b| b.iter(|| derive(black_box(&desc)).unwrap()));
    g.bench_function("programs", |b| {
        b.iter(|| module_spec(black_box(&d), "dia10_like_zy"))
    });
    g.bench_function("tokens", |b| {
        b.iter(|| module_tokens(black_box(&spec), Real::Generic))
    });
    g.bench_function("format", |b| {
        b.iter(|| format_file(black_box(tokens.clone())).unwrap())
    });
    g.bench_function("attribute_f32", |b| {
        b.iter(|| {
            attribute::expand(
                quote!(preset = "dia10_like_zy", real = "f32"),
                quote!(
                    pub struct Arm;
                ),
            )
        })
    });
    g.finish();
}

criterion_group! {
    name = generation;
    config = Criterion::default().sample_size(10);
    targets = modules, stages
}
criterion_main!(generation);
