//! How long generating a module takes: every preset's full module (derivation, programs, tokens,
//! formatting; `generate_module_string`, generic scalar), the stages of dia10_like_zy one by one,
//! and the `#[constrained_robot]` attribute's expansion of dia10_like_zy in `f32`. The target is
//! each dia10_like module within 200 ms in a release build.
//!
//! Scenes (`scenes/<scene>/scene`): a shipped scene's whole module (`generate_scene_string`)
//! against `scenes/<scene>/arms_alone`, every arm's description generated alone, one after the
//! other (the sum of its branches): the scene may be no slower.
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

fn scenes(c: &mut Criterion) {
    use trocar_model::scene::SceneDescription;
    for name in ["three-ports", "dia10-dual"] {
        let scene = SceneDescription::shipped(name).unwrap();
        let mut g = c.benchmark_group(format!("scenes/{name}"));
        g.bench_function("scene", |b| {
            b.iter(|| {
                trocar_codegen::scene::generate_scene_string(
                    black_box(&scene),
                    &ModuleOptions::default(),
                )
                .unwrap()
            })
        });
        g.bench_function("arms_alone", |b| {
            b.iter(|| {
                for arm in &scene.arms {
                    generate_module_string(black_box(&arm.robot), &ModuleOptions::default())
                        .unwrap();
                }
            })
        });
        g.finish();
    }
}

criterion_group! {
    name = generation;
    config = Criterion::default().sample_size(10);
    targets = modules, stages, scenes
}
criterion_main!(generation);
